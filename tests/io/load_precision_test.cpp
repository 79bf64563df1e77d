// Loaders keep the file's precision (issue 10): decimal text and binary
// double / 32-bit integer coordinates come back as doubles, exactly; float
// files stay float (no doubled memory); loadPoints still rounds to float.
// 5400000.01 is the probe: float32 spacing at 5.4e6 is 0.5 m, so a loader
// that goes through float loses the centimetre.
#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

class LoadPrecision : public TempDirTest {};

const glm::dvec3 kUtm(512000.03, 5400000.01, 231.007);
const glm::dvec3 kUtm2(-512000.5, 5400123.45, -0.001);

std::string plyHeader(const std::string& format, const std::string& type, size_t n) {
    return "ply\nformat " + format + " 1.0\nelement vertex " + std::to_string(n) + "\nproperty " + type +
           " x\nproperty " + type + " y\nproperty " + type + " z\nend_header\n";
}

void expectDoubles(const Result<PointCloud>& r, const std::vector<glm::dvec3>& want) {
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->scalar, Scalar::kFloat64);
    EXPECT_TRUE(r->floats.empty());
    ASSERT_EQ(r->doubles.size(), want.size());
    for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(r->doubles[i], want[i]) << "point " << i;
    const PointView v = r->view();
    EXPECT_EQ(v.scalar, Scalar::kFloat64);
    EXPECT_EQ(v.count, want.size());
    EXPECT_EQ(v.at(want.size() - 1), want.back());
}

void expectFloats(const Result<PointCloud>& r, const std::vector<glm::vec3>& want) {
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->scalar, Scalar::kFloat32);
    EXPECT_TRUE(r->doubles.empty());
    ASSERT_EQ(r->floats.size(), want.size());
    for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(r->floats[i], want[i]) << "point " << i;
    EXPECT_TRUE(r->view().packedFloat());
}

TEST_F(LoadPrecision, BinaryDoublePlyIsDoubleExactly) {
    for (bool bigEndian : {false, true}) {
        ByteBuilder b(bigEndian);
        b.text(plyHeader(bigEndian ? "binary_big_endian" : "binary_little_endian", "double", 2));
        for (const glm::dvec3& p : {kUtm, kUtm2}) b.put(p.x).put(p.y).put(p.z);
        expectDoubles(loadPointCloud(write("d.ply", b.str())), {kUtm, kUtm2});
    }
}

TEST_F(LoadPrecision, BinaryInt32PlyIsDouble) {
    // 16777217 = 2^24 + 1 has no float32.
    ByteBuilder b;
    b.text(plyHeader("binary_little_endian", "int", 1))
        .put<int32_t>(16777217)
        .put<int32_t>(-7)
        .put<int32_t>(0);
    expectDoubles(loadPointCloud(write("i.ply", b.str())), {{16777217.0, -7.0, 0.0}});
}

TEST_F(LoadPrecision, OneDoubleAxisMakesTheCloudDouble) {
    ByteBuilder b;
    b.text(
        "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty float x\n"
        "property double y\nproperty float z\nend_header\n");
    b.put(1.5f).put(5400000.01).put(-2.0f);
    expectDoubles(loadPointCloud(write("m.ply", b.str())), {{1.5, 5400000.01, -2.0}});
}

TEST_F(LoadPrecision, BinaryFloatAndShortPlyStayFloat) {
    ByteBuilder f;
    f.text(plyHeader("binary_little_endian", "float", 2)).put(1.5f).put(-2.25f).put(3.0f);
    f.put(5400000.0f).put(0.1f).put(-0.0f);
    expectFloats(loadPointCloud(write("f.ply", f.str())), {{1.5f, -2.25f, 3.0f}, {5400000.0f, 0.1f, -0.0f}});
    ByteBuilder s;
    s.text(plyHeader("binary_little_endian", "short", 1))
        .put<int16_t>(-32768)
        .put<int16_t>(7)
        .put<int16_t>(0);
    expectFloats(loadPointCloud(write("s.ply", s.str())), {{-32768.0f, 7.0f, 0.0f}});
}

TEST_F(LoadPrecision, AsciiPlyIsDoubleExactly) {
    const std::string body =
        plyHeader("ascii", "float", 2) + "512000.03 5400000.01 231.007\n" + "-512000.5 5400123.45 -0.001\n";
    // The declared type does not matter for text: the decimal is the value.
    expectDoubles(loadPointCloud(write("a.ply", body)), {kUtm, kUtm2});
}

TEST_F(LoadPrecision, PcdBinaryDoubleAndFloat) {
    const std::string header8 =
        "VERSION .7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA "
        "binary\n";
    ByteBuilder d;
    d.text(header8);
    for (const glm::dvec3& p : {kUtm, kUtm2}) d.put(p.x).put(p.y).put(p.z);
    expectDoubles(loadPointCloud(write("d.pcd", d.str())), {kUtm, kUtm2});

    const std::string header4 =
        "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA "
        "binary\n";
    ByteBuilder f;
    f.text(header4).put(1.5f).put(5400000.0f).put(-3.0f);
    expectFloats(loadPointCloud(write("f.pcd", f.str())), {{1.5f, 5400000.0f, -3.0f}});

    const std::string headerI =
        "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE I I I\nCOUNT 1 1 1\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA "
        "binary\n";
    ByteBuilder i;
    i.text(headerI).put<int32_t>(16777217).put<int32_t>(1).put<int32_t>(2);
    expectDoubles(loadPointCloud(write("i.pcd", i.str())), {{16777217.0, 1.0, 2.0}});
}

TEST_F(LoadPrecision, PcdAsciiIsDouble) {
    const std::string pcd =
        "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA "
        "ascii\n"
        "512000.03 5400000.01 231.007\n-512000.5 5400123.45 -0.001\n";
    expectDoubles(loadPointCloud(write("a.pcd", pcd)), {kUtm, kUtm2});
}

TEST_F(LoadPrecision, TextFormatsAreDoubleExactly) {
    const std::string lines = "512000.03 5400000.01 231.007\n-512000.5 5400123.45 -0.001\n";
    expectDoubles(loadPointCloud(write("p.xyz", lines)), {kUtm, kUtm2});
    expectDoubles(loadPointCloud(write("p.txt", "512000.03,5400000.01,231.007\n")), {kUtm});
    expectDoubles(
        loadPointCloud(write("p.obj", "v 512000.03 5400000.01 231.007\nv -512000.5 5400123.45 -0.001\n")),
        {kUtm, kUtm2});
    expectDoubles(loadPointCloud(write("p.off", "OFF\n2 0 0\n" + lines)), {kUtm, kUtm2});
    expectDoubles(loadPointCloud(write("p.stl",
                                       "solid s\nfacet normal 0 0 1\nouter loop\n"
                                       "vertex 512000.03 5400000.01 231.007\n"
                                       "vertex -512000.5 5400123.45 -0.001\n"
                                       "vertex 512000.03 5400000.01 231.007\n"
                                       "endloop\nendfacet\nendsolid s\n")),
                  {kUtm, kUtm2, kUtm});
}

TEST_F(LoadPrecision, BinaryStlAndGlbStayFloat) {
    ByteBuilder stl;
    stl.text(std::string(80, ' ')).put<uint32_t>(1);
    for (int i = 0; i < 3; ++i) stl.put(0.0f);  // normal
    for (const glm::vec3& p : threePoints()) stl.put(p.x).put(p.y).put(p.z);
    stl.put<uint16_t>(0);
    expectFloats(loadPointCloud(write("b.stl", stl.str())), threePoints());

    ByteBuilder bin;
    for (const glm::vec3& p : threePoints()) bin.put(p.x).put(p.y).put(p.z);
    const std::string json =
        R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[{"mesh":0}],)"
        R"("meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
        R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3"}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36}],"buffers":[{"byteLength":36}]})";
    expectFloats(loadPointCloud(write("m.glb", glb(json, bin.str()))), threePoints());
}

TEST_F(LoadPrecision, LoadPointsRoundsADoubleCloudToFloat) {
    auto r = loadPoints(write("r.xyz", "512000.03 5400000.01 231.007\n"));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ((*r)[0], glm::vec3(512000.03f, 5400000.0f, 231.007f));
}

TEST_F(LoadPrecision, DoubleBeyondFloatRange) {
    // Finite in double: loadPointCloud keeps it, loadPoints cannot.
    const std::string path = write("big.xyz", "1 2 1e39\n");
    expectDoubles(loadPointCloud(path), {{1.0, 2.0, 1e39}});
    EXPECT_TRUE(
        isBadInput(loadPoints(path), path, "vertex 0: coordinate z is infinite (or beyond float range)"));
    const std::string inf = write("inf.xyz", "1 2 1e400\n");
    EXPECT_TRUE(isBadInput(loadPointCloud(inf), inf, "vertex 0: coordinate z is infinite"));
    const std::string nan = write("nan.ply", plyHeader("ascii", "double", 1) + "nan 0 0\n");
    EXPECT_TRUE(isBadInput(loadPointCloud(nan), nan, "vertex 0: coordinate x is NaN"));
}

}  // namespace
}  // namespace rthdist::io::test
