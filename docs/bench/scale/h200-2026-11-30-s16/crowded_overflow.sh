set -u
for v in before after; do
  VK_LAYER_PATH=$PWD/.devt/layers RTHDIST_TEST_BACKEND=rt-pipeline timeout 200 .devt/gpu_tests_$v --gtest_filter='LargeSizes.CrowdedCells*' > $OUT/$v.txt 2>&1; echo "$v exit $?"
  grep -E 'FAILED|PASSED|converge|pairs ' $OUT/$v.txt | head -12
done
