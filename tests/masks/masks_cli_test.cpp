// rthdist-masks on hostile volume files (issue 36): every refusal is exit 3
// with the file, the field and the limit on stderr, never a signal, a hang
// or a wrong number; --max-volume-mib raises the volume cap.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <string>

#include "cli/cli_runner.hpp"
#include "volume_files.hpp"

// Under AddressSanitizer (preset asan) the CLI's resident set holds the
// shadow memory and the quarantine: VoxelsAreHeldOnce checks the run, not the bound.
#if defined(__SANITIZE_ADDRESS__)
#define RTHDIST_TEST_ASAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define RTHDIST_TEST_ASAN 1
#endif
#endif

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
    // 0 and -1 read as a 1x1x1 grid, 8 and 9 as 4x4x4 (exit 0); 32767 and
    // 2^40 ended libnifti2 3.0.1 with SIGSEGV, -32768 with "stack smashing
    // detected" (SIGABRT).
    for (int64_t dim0 : {int64_t(0), int64_t(-1), int64_t(8), int64_t(9), int64_t(32767), int64_t(-32768),
                         int64_t(1) << 40}) {
        const std::string bad = dir.write("dim0.nii", nifti2(dim0, 4, 4, 4));
        const std::string good = dir.write("good.nii", nifti2(3, 4, 4, 4));
        expectExit3(masks({good, bad}), bad, {"dim[0] = " + std::to_string(dim0), "1..7"});
    }
}

// --device N past the device list was ignored under --backend auto (the
// CPU backend ran, exit 0); README: an index past the list is exit 4.
TEST(MasksCli, DevicePastTheListExitsFour) {
    TempDir dir;
    const std::string good = dir.write("good.nii", Nifti1(4, 4, 4, 2, 1).bytes());
    for (const char* backend : {"auto", "cpu"}) {
        SCOPED_TRACE(backend);
        const CliRun run = masks({good, good, "--backend", backend, "--device", "1023"});
        if (std::string(backend) == "cpu") {
            EXPECT_EQ(run.exitCode, 0) << run;  // the cpu backend opens no device
            continue;
        }
        EXPECT_EQ(run.exitCode, 4) << run;
        EXPECT_NE(run.err.find("device 1023 does not exist"), std::string::npos) << run;
    }
}

TEST(MasksCli, NanPixdimExitsThree) {
    TempDir dir;
    Nifti1 n(4, 4, 4, 2, 1);
    n.pixdim(2, std::nanf(""));
    const std::string bad = dir.write("nan.nii", n.bytes());
    expectExit3(masks({bad, bad}), bad, {"pixdim[2] = nan"});
}

// Zero, negative or infinite pixdim: libnifti read them as 1 mm (exit 0, a
// value in the wrong units); refused, naming the field.
TEST(MasksCli, ZeroNegativeOrInfinitePixdimExitsThree) {
    TempDir dir;
    for (const float bad : {0.0f, -1.5f, std::numeric_limits<float>::infinity()}) {
        SCOPED_TRACE(bad);
        Nifti1 n(4, 4, 4, 2, 1);
        n.pixdim(1, bad);
        const std::string path = dir.write("pixdim.nii", n.bytes());
        expectExit3(masks({path, path}), path, {"pixdim[1]", "positive finite"});
    }
}

// A NaN in a float32 volume: libnifti's reader made it label 0; refused,
// naming the voxel.
TEST(MasksCli, NanFloatVoxelExitsThree) {
    TempDir dir;
    Nifti1 n(3, 3, 3, 16, 4);  // float32
    const float one = 1.0f, nan = std::nanf("");
    std::memcpy(n.voxels.data(), &one, 4);
    std::memcpy(n.voxels.data() + 4 * 13, &nan, 4);
    const std::string path = dir.write("nanvoxel.nii", n.bytes());
    Nifti1 g(3, 3, 3, 2, 1);
    const std::string good = dir.write("good.nii", g.bytes());
    expectExit3(masks({good, path}), path, {"nan", "voxel index 13"});
}

// A NaN origin (sform or qform): not a grid; refused, naming the field.
TEST(MasksCli, NanOriginExitsThree) {
    TempDir dir;
    const float rows[12] = {1, 0, 0, std::nanf(""), 0, 1, 0, 0, 0, 0, 1, 0};
    Nifti1 s(4, 4, 4, 2, 1);
    s.sform(rows);
    const std::string sform = dir.write("sform.nii", s.bytes());
    expectExit3(masks({sform, sform}), sform, {"srow_x[3]", "not finite"});
    Nifti1 q(4, 4, 4, 2, 1);
    put<int16_t>(q.header, 252, 1);
    put<float>(q.header, 272, std::nanf(""));
    const std::string qform = dir.write("qform.nii", q.bytes());
    expectExit3(masks({qform, qform}), qform, {"qoffset_y", "not finite"});
}

// The .npy header as NumPy reads it: a 'shape' inside a string value is not
// the shape (the old reader took the first "'shape'" it saw, here (1, 1, 1)
// over 2 x 2 x 2 bytes), and a key that appears twice is refused.
TEST(MasksCli, NpyDictAsNumPyReadsItExitsThree) {
    TempDir dir;
    const std::string data(8, '\1');
    const std::string inString = dir.write(
        "string.npy",
        npy("{'descr': '|u1', 'note': \"'shape': (1, 1, 1)\", 'fortran_order': False, 'shape': (2, 2, 2), }",
            data));
    const std::string good = dir.write("good.npy", goodNpy());
    expectExit3(masks({good, inString}), inString, {"key 'note'"});
    const std::string twice = dir.write(
        "twice.npy",
        npy("{'descr': '|u1', 'fortran_order': False, 'shape': (1, 1, 1), 'shape': (2, 2, 2), }", data));
    expectExit3(masks({good, twice}), twice, {"'shape' appears twice"});
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

// The voxels are held once (issue 36: a .nii.gz pair that inflates to 1 GiB
// each peaked at 3 GB, each volume held a second time while it was read).
// Two 256 MiB uint8 volumes of a few KiB gzipped: the process's peak (the
// largest child's maximum resident set, here the only large one) stays
// within their bytes plus a quarter and 40 MiB for the process itself; the
// old reader needed 1.5 times their bytes.
TEST(MasksCli, VoxelsAreHeldOnce) {
    TempDir dir;
    const uint64_t voxelBytes = uint64_t(512) * 512 * 1024;
    std::string a, b;
    {
        Nifti1 n(512, 512, 1024, 2, 1);
        for (size_t z = 10; z < 20; ++z)
            for (size_t y = 10; y < 20; ++y) n.voxels[(z * 512 + y) * 512 + 10] = 1;
        a = (dir.path() / "a.nii.gz").string();
        writeGz(a, n.bytes());
        n.voxels[(100 * 512 + 100) * 512 + 100] = 1;
        b = (dir.path() / "b.nii.gz").string();
        writeGz(b, n.bytes());
    }
    const CliRun run = masks({"--backend", "cpu", "--csv", a, b});
    ASSERT_EQ(run.exitCode, 0) << run;
#ifdef RTHDIST_TEST_ASAN
    return;
#endif
    rusage usage{};
    ASSERT_EQ(::getrusage(RUSAGE_CHILDREN, &usage), 0);
    const double peakMiB = double(usage.ru_maxrss) / 1024.0;  // ru_maxrss is in KiB
    const double volumesMiB = 2.0 * double(voxelBytes) / double(1 << 20);
    RecordProperty("peak_mib", int(peakMiB));
    EXPECT_LE(peakMiB, 1.25 * volumesMiB + 40.0)
        << "peak " << peakMiB << " MiB for " << volumesMiB << " MiB of voxels";
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
