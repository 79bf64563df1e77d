// rthdist-masks on hostile volume files (issue 36): every refusal is exit 3
// with the file, the field and the limit on stderr, never a signal, a hang
// or a wrong number; --max-volume-mib raises the volume cap.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <string>

#include "cli/cli_runner.hpp"
#include "volume_files.hpp"

namespace rthdist::masks_test {
namespace {

using cli_test::CliRun;
using cli_test::runCli;
using cli_test::TempDir;

// `timeout` ends a run that blocks (a FIFO read) with 124 instead of hanging the suite.
CliRun masks(const std::vector<std::string>& args) { return runCli(args, "", "timeout -s KILL 60"); }

void expectExit3(const CliRun& r, const std::string& path, const std::vector<std::string>& words) {
    EXPECT_EQ(r.exitCode, 3) << r;
    EXPECT_NE(r.err.find(path), std::string::npos) << r;
    for (const std::string& w : words) EXPECT_NE(r.err.find(w), std::string::npos) << r;
}

std::string goodNpy() {
    return npy("{'descr': '|u1', 'fortran_order': False, 'shape': (2, 2, 2), }",
               std::string("\1\0\0\0\0\0\0\1", 8));
}

TEST(MasksCli, Nifti2Dim0OutsideOneToSevenExitsThree) {
    TempDir dir;
    for (int64_t dim0 : {0, -1, 8, 9}) {
        const std::string bad = dir.write("dim0.nii", nifti2(dim0, 4, 4, 4));
        const std::string good = dir.write("good.nii", nifti2(3, 4, 4, 4));
        expectExit3(masks({good, bad}), bad, {"dim[0] = " + std::to_string(dim0), "1..7"});
    }
}

TEST(MasksCli, NanPixdimExitsThree) {
    TempDir dir;
    Nifti1 n(4, 4, 4, 2, 1);
    n.pixdim(2, std::nanf(""));
    const std::string bad = dir.write("nan.nii", n.bytes());
    expectExit3(masks({bad, bad}), bad, {"pixdim[2] = nan"});
}

TEST(MasksCli, NpyShapeOverflowExitsThreeNotACrash) {
    TempDir dir;
    const std::string bad =
        dir.write("overflow.npy",
                  npy("{'descr': '|u1', 'fortran_order': False, 'shape': (4294967296, 4294967296, 2), }",
                      std::string(8, '\1')));
    const std::string good = dir.write("good.npy", goodNpy());
    expectExit3(masks({good, bad}), bad, {"overflows 64 bits"});
}

TEST(MasksCli, NpyBadNumberExitsThreeNamingTheField) {
    TempDir dir;
    const std::string bad = dir.write(
        "big.npy",
        npy("{'descr': '|u1', 'fortran_order': False, 'shape': (99999999999999999999, 1, 1), }", ""));
    const CliRun r = masks({bad, bad});
    expectExit3(r, bad, {"shape[0]", "2^63 - 1"});
    EXPECT_EQ(r.err.find("stoll"), std::string::npos) << r;
}

TEST(MasksCli, NpyFortranOrderNotBooleanExitsThree) {
    TempDir dir;
    const std::string bad = dir.write(
        "order.npy",
        npy("{'descr': '|u1', 'fortran_order': 'NotTrue', 'shape': (2, 2, 2), }", std::string(8, '\1')));
    expectExit3(masks({bad, bad}), bad, {"fortran_order must be True or False"});
}

TEST(MasksCli, FifoAndDevZeroExitThreeWithoutReading) {
    TempDir dir;
    const std::string good = dir.write("good.npy", goodNpy());
    const std::string fifo = (dir.path() / "pipe.npy").string();
    ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
    expectExit3(masks({good, fifo}), fifo, {"FIFO"});
    const std::string fifoNii = (dir.path() / "pipe.nii.gz").string();
    ASSERT_EQ(::mkfifo(fifoNii.c_str(), 0600), 0);
    expectExit3(masks({fifoNii, good}), fifoNii, {"FIFO"});
    const std::string zero = (dir.path() / "zero.npy").string();
    std::filesystem::create_symlink("/dev/zero", zero);
    expectExit3(masks({zero, good}), zero, {"character device"});
}

TEST(MasksCli, VolumeCapIsAnOptionAndNamedWhenHit) {
    TempDir dir;
    // 128^3 uint8: 2 MiB of voxels, a few KiB gzipped.
    Nifti1 n(128, 128, 128, 2, 1);
    const std::string path = (dir.path() / "big.nii.gz").string();
    writeGz(path, n.bytes());
    expectExit3(masks({path, path, "--max-volume-mib", "1"}), path,
                {"volume limit of 1048576 bytes", "--max-volume-mib"});
    const CliRun ok = masks({path, path, "--max-volume-mib", "2", "--csv"});
    EXPECT_EQ(ok.exitCode, 0) << ok;
    const CliRun usage = masks({path, path, "--max-volume-mib", "0"});
    EXPECT_EQ(usage.exitCode, 2) << usage;
}

TEST(MasksCli, SpacingBelowTheLimitExitsThree) {
    TempDir dir;
    const std::string good = dir.write("good.npy", goodNpy());
    expectExit3(masks({good, good, "--spacing", "1,1e-40,1"}), good, {"spacing", "1e-30"});
    const CliRun ok = masks({good, good, "--spacing", "1,1e-29,1", "--csv"});
    EXPECT_EQ(ok.exitCode, 0) << ok;
}

}  // namespace
}  // namespace rthdist::masks_test
