#!/usr/bin/env bash
# The installed package, as a user gets it: for a static and a shared build
# (build-pkg-static/, build-pkg-shared/; library only), `cmake --install` to a
# temporary prefix, then tests/package/consumer built and run against it
#   1. with CMake (find_package(rthdist [COMPONENTS io masks]); the compiler's
#      default C++ standard, so the targets must carry cxx_std_20),
#   2. with pkg-config (g++ -std=c++20 $(pkg-config --cflags --libs rthdist)).
# The shared libraries must export rthdist's public API only, and README.md's
# C++ example must be the consumer's main.cpp.
# RTHDIST_JOBS sets the build parallelism (default 2). RTHDIST_PKG_STATIC_FROM
# names an existing Release build of the default options (static; e.g. the
# release preset's build/, as .ci/run has just built it) to install the static
# package from instead of building build-pkg-static/: the same library, one
# build fewer.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=${RTHDIST_JOBS:-2}
consumer=tests/package/consumer
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# The README's C++ example is the consumer's source, verbatim.
awk '/^## Library \(C\+\+\)$/ { section = 1; next }
     section && /^```cpp$/ { code = 1; next }
     code && /^```$/ { exit }
     code { print }' README.md | diff -u - "$consumer/main.cpp" ||
  { echo "README.md: the code block under '## Library (C++)' is not $consumer/main.cpp"; exit 1; }

for kind in static shared; do
  echo "== package ($kind)"
  build=build-pkg-$kind
  shared=OFF
  [[ $kind == shared ]] && shared=ON
  if [[ $kind == static && -n ${RTHDIST_PKG_STATIC_FROM:-} ]]; then
    build=$RTHDIST_PKG_STATIC_FROM
    cache=$build/CMakeCache.txt
    # Only a Release build with static libraries is the package a user builds by default.
    grep -q '^CMAKE_BUILD_TYPE:STRING=Release$' "$cache" && ! grep -q '^BUILD_SHARED_LIBS:BOOL=ON$' "$cache" ||
      { echo "RTHDIST_PKG_STATIC_FROM=$build: not a static Release build ($cache)"; exit 1; }
    echo "-- installing from $build (built already)"
  else
    # RTHDIST_MPI=OFF: rthdist_mpi is not part of the package (nothing installs
    # it), so a static library build would compile it for nothing.
    cmake -S . -B "$build" -DCMAKE_BUILD_TYPE=Release -DBUILD_SHARED_LIBS=$shared \
      -DRTHDIST_BUILD_TESTS=OFF -DRTHDIST_BUILD_TOOLS=OFF -DRTHDIST_MPI=OFF > "$work/configure-$kind.log" 2>&1 ||
      { cat "$work/configure-$kind.log"; exit 1; }
  fi
  cmake --build "$build" -j "$jobs"
  prefix=$work/$kind
  cmake --install "$build" --prefix "$prefix" > /dev/null

  echo "-- CMake consumer"
  cmake -S "$consumer" -B "$work/consumer-$kind" -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$prefix" > /dev/null
  cmake --build "$work/consumer-$kind" -j "$jobs"
  "$work/consumer-$kind/app"
  "$work/consumer-$kind/app_io"
  # The masks component: in the static package, not in the shared one.
  if [[ $kind == static ]]; then
    "$work/consumer-$kind/app_masks"
  elif [[ -e "$work/consumer-$kind/app_masks" ]]; then
    echo "the shared package has a masks component"; exit 1
  fi

  echo "-- pkg-config consumer"
  pcdir=$(dirname "$(find "$prefix" -name rthdist.pc)")
  export PKG_CONFIG_PATH=$pcdir
  libdir=$(pkg-config --variable=libdir rthdist)
  # shellcheck disable=SC2046  # pkg-config's output is a list of flags
  g++ -std=c++20 -o "$work/app-pc-$kind" "$consumer/main.cpp" $(pkg-config --cflags --libs rthdist)
  # shellcheck disable=SC2046
  g++ -std=c++20 -o "$work/app-io-pc-$kind" "$consumer/io_main.cpp" $(pkg-config --cflags --libs rthdist-io rthdist)
  LD_LIBRARY_PATH=$libdir "$work/app-pc-$kind"
  LD_LIBRARY_PATH=$libdir "$work/app-io-pc-$kind"
  unset PKG_CONFIG_PATH

  if [[ $kind == shared ]]; then
    echo "-- exported symbols"
    for lib in "$libdir/librthdist.so" "$libdir/librthdist_io.so"; do
      exported=$(nm -DC --defined-only "$lib" | grep 'rthdist::' || true)
      echo "$(basename "$lib"): $(grep -c . <<< "$exported") rthdist symbols exported"
      # Only the public API: nothing from the internal namespaces or the
      # loaders' per-format readers.
      if leaked=$(grep -E 'rthdist::(gpu|cpu|algo|render)::|rthdist::io::[a-z]+[A-Z][A-Za-z]*Reader|\(anonymous' <<< "$exported"); then
        echo "internal symbols exported from $lib:"
        echo "$leaked"
        exit 1
      fi
    done
  fi
done
echo "== package test passed (static, shared; CMake and pkg-config)"
