// loadMesh (rthdist/io.hpp): the faces of every format that has them, written
// small by each test: triangles and polygons (fan-triangulated), OBJ's index
// forms, PLY's ascii and both binary orders, OFF, STL's facets, glTF's
// primitive modes; degenerate faces kept; an index out of range, a short
// face and a file without faces each an error naming the file and the face.
#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

using MeshLoader = TempDirTest;

void expectBadInput(const Result<TriangleMesh>& r, const std::string& path, const std::string& part) {
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, ErrorCode::kBadInput);
    EXPECT_EQ(r.error().message.rfind(path + ": ", 0), 0u) << r.error().message;
    EXPECT_NE(r.error().message.find(part), std::string::npos) << r.error().message;
}

const std::vector<uint32_t> kSquareFan{0, 1, 2, 0, 2, 3};

TEST_F(MeshLoader, ObjTrianglesQuadsAndIndexForms) {
    const std::string path = write("m.obj",
                                   "# a square and a degenerate triangle\n"
                                   "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
                                   "vt 0 0\nvn 0 0 1\n"
                                   "f 1/1/1 2/1/1 3//1 4\n"
                                   "f -4 -4 -2\n");
    auto r = loadMesh(path);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->vertices.size(), 4u);
    EXPECT_EQ(r->indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 0, 0, 2}));
    EXPECT_EQ(r->triangleCount(), 3u);
    EXPECT_EQ(r->view().vertices.count, 4u);
}

TEST_F(MeshLoader, ObjRelativeIndicesCountTheVerticesSoFar) {
    auto r = loadMesh(write("rel.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 5 5 5\nf -1 -2 -3\n"));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->indices, (std::vector<uint32_t>{0, 1, 2, 3, 2, 1}));
}

TEST_F(MeshLoader, ObjIndexOutOfRangeNamesTheLineAndFace) {
    const std::string path = write("bad.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n");
    expectBadInput(loadMesh(path), path, "line 5: face 1: vertex index 3 out of range (3 vertices)");
}

TEST_F(MeshLoader, ObjZeroIndexAndShortFaceAreErrors) {
    const std::string zero = write("zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
    expectBadInput(loadMesh(zero), zero, "line 4: face 0: '0' is not a vertex index");
    const std::string two = write("two.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2\n");
    expectBadInput(loadMesh(two), two, "line 4: face 0 has 2 vertices (a face needs at least 3)");
}

TEST_F(MeshLoader, ObjWithoutFacesIsAnError) {
    const std::string path = write("pts.obj", "v 0 0 0\nv 1 0 0\n");
    expectBadInput(loadMesh(path), path, "has no triangles");
}

TEST_F(MeshLoader, OffPolygonsAndColours) {
    const std::string path = write("m.off",
                                   "OFF\n# square and triangle\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n"
                                   "4 0 1 2 3 255 0 0\n3 3 3 1\n");
    auto r = loadMesh(path);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 3, 3, 1}));
}

TEST_F(MeshLoader, OffIndexOutOfRangeAndTruncatedFaces) {
    const std::string bad = write("bad.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n");
    expectBadInput(loadMesh(bad), bad, "line 6: face 0: vertex index 7 out of range (3 vertices)");
    const std::string cut = write("cut.off", "OFF\n3 2 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n");
    expectBadInput(loadMesh(cut), cut, "file ends at face 1 of 2");
}

TEST_F(MeshLoader, PlyAsciiFaces) {
    const std::string path =
        write("m.ply",
              "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
              "property float y\nproperty float z\nelement face 2\n"
              "property list uchar int vertex_indices\nproperty uchar flags\nend_header\n"
              "0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3 7\n3 1 1 1 0\n");
    auto r = loadMesh(path);
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 1, 1, 1}));
}

std::string binaryPly(bool bigEndian, int32_t lastIndex) {
    ByteBuilder b(bigEndian);
    b.text(std::string("ply\nformat ") + (bigEndian ? "binary_big_endian" : "binary_little_endian") +
           " 1.0\nelement vertex 4\nproperty double x\nproperty double y\nproperty double z\n"
           "element face 2\nproperty uchar red\nproperty list uchar uint vertex_indices\nend_header\n");
    for (const glm::dvec3& v :
         {glm::dvec3(0, 0, 0), glm::dvec3(1, 0, 0), glm::dvec3(1, 1, 0), glm::dvec3(0, 1, 0)})
        b.put(v.x).put(v.y).put(v.z);
    b.put(uint8_t(9)).put(uint8_t(4)).put(uint32_t(0)).put(uint32_t(1)).put(uint32_t(2)).put(uint32_t(3));
    b.put(uint8_t(9)).put(uint8_t(3)).put(uint32_t(2)).put(uint32_t(3)).put(uint32_t(lastIndex));
    return b.str();
}

TEST_F(MeshLoader, PlyBinaryFacesInBothByteOrders) {
    for (bool big : {false, true}) {
        auto r = loadMesh(write(big ? "be.ply" : "le.ply", binaryPly(big, 1)));
        ASSERT_TRUE(r) << r.error().message;
        EXPECT_EQ(r->vertices.scalar, Scalar::kFloat64);
        EXPECT_EQ(r->indices, (std::vector<uint32_t>{0, 1, 2, 0, 2, 3, 2, 3, 1}));
    }
}

TEST_F(MeshLoader, PlyBinaryIndexOutOfRangeNamesTheFaceAndOffset) {
    const std::string path = write("bad.ply", binaryPly(false, 4));
    expectBadInput(loadMesh(path), path, "face 1: vertex index 4 out of range (4 vertices)");
    expectBadInput(loadMesh(path), path, "byte offset ");
}

TEST_F(MeshLoader, PlyWithoutFaceElementIsAnError) {
    const std::string path = write("pts.ply",
                                   "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\n"
                                   "property float y\nproperty float z\nend_header\n0 0 0\n");
    expectBadInput(loadMesh(path), path, "header: no 'face' element");
}

TEST_F(MeshLoader, StlFacetsAreTriangles) {
    ByteBuilder b;
    b.text(std::string(80, ' ')).put(uint32_t(2));
    for (int f = 0; f < 2; ++f) {
        b.put(0.0f).put(0.0f).put(1.0f);
        for (const glm::vec3& v : {glm::vec3(0, 0, f), glm::vec3(1, 0, f), glm::vec3(0, 1, f)})
            b.put(v.x).put(v.y).put(v.z);
        b.put(uint16_t(0));
    }
    auto r = loadMesh(write("m.stl", b.str()));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->vertices.size(), 6u);
    EXPECT_EQ(r->indices, (std::vector<uint32_t>{0, 1, 2, 3, 4, 5}));
    auto ascii = loadMesh(write("a.stl",
                                "solid t\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\n"
                                "vertex 0 1 0\nendloop\nendfacet\nendsolid t\n"));
    ASSERT_TRUE(ascii) << ascii.error().message;
    EXPECT_EQ(ascii->indices, (std::vector<uint32_t>{0, 1, 2}));
}

// One mesh of 4 vertices (a square), primitives given as JSON.
std::string gltfSquare(const std::string& primitives, const std::string& extraAccessors = "",
                       const std::string& indexBytes = "") {
    ByteBuilder b;
    for (const glm::vec3& v :
         {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(1, 1, 0), glm::vec3(0, 1, 0)})
        b.put(v.x).put(v.y).put(v.z);
    const std::string bin = b.str() + indexBytes;
    return R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":)" + std::to_string(bin.size()) +
           R"(,"uri":"data:application/octet-stream;base64,)" + base64(bin) +
           R"("}],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":48},{"buffer":0,"byteOffset":48,"byteLength":)" +
           std::to_string(indexBytes.size()) +
           R"(}],"accessors":[{"bufferView":0,"componentType":5126,"count":4,"type":"VEC3"})" +
           extraAccessors + R"(],"meshes":[{"primitives":)" + primitives +
           R"(}],"nodes":[{"mesh":0,"translation":[10,0,0]}],"scenes":[{"nodes":[0]}],"scene":0})";
}

std::string u16(std::initializer_list<uint16_t> values) {
    ByteBuilder b;
    for (uint16_t v : values) b.put(v);
    return b.str();
}

TEST_F(MeshLoader, GltfIndexedTrianglesWithTheNodeTransform) {
    const std::string json = gltfSquare(R"([{"attributes":{"POSITION":0},"indices":1,"mode":4}])",
                                        R"(,{"bufferView":1,"componentType":5123,"count":6,"type":"SCALAR"})",
                                        u16({0, 1, 2, 0, 2, 3}));
    auto r = loadMesh(write("m.gltf", json));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->indices, kSquareFan);
    EXPECT_EQ(r->vertices.floats[2], glm::vec3(11, 1, 0));
}

TEST_F(MeshLoader, GltfStripFanAndUnindexedPrimitives) {
    // Strip 0 1 3 2, fan 0 1 2 3, unindexed triangles (vertices 0 1 2), points (none).
    const std::string json = gltfSquare(
        R"([{"attributes":{"POSITION":0},"indices":1,"mode":5},{"attributes":{"POSITION":0},"mode":6},)"
        R"({"attributes":{"POSITION":0}},{"attributes":{"POSITION":0},"mode":0}])",
        R"(,{"bufferView":1,"componentType":5123,"count":4,"type":"SCALAR"})", u16({0, 1, 3, 2}));
    auto r = loadMesh(write("s.gltf", json));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->vertices.size(), 16u);
    // Strip: (0 1 3), (3 1 2) winding kept; fan over points 4..7; triangle list over 8..11 (one triangle).
    EXPECT_EQ(r->indices, (std::vector<uint32_t>{0, 1, 3, 3, 1, 2, 4, 5, 6, 4, 6, 7, 8, 9, 10}));
}

TEST_F(MeshLoader, GltfIndexOutOfRangeNamesTheNodeAndAccessor) {
    const std::string json =
        gltfSquare(R"([{"attributes":{"POSITION":0},"indices":1}])",
                   R"(,{"bufferView":1,"componentType":5123,"count":3,"type":"SCALAR"})", u16({0, 1, 9}));
    const std::string path = write("bad.gltf", json + " ");
    expectBadInput(loadMesh(path), path,
                   "node 0, accessor 1: face vertex 2: vertex index 9 out of range (4 vertices)");
}

TEST_F(MeshLoader, FormatsWithoutFacesAreRefused) {
    const std::string path = write("p.xyz", "0 0 0\n1 1 1\n");
    expectBadInput(loadMesh(path), path, "'.xyz' files have no faces");
}

TEST_F(MeshLoader, GzippedMeshesKeepTheirFaces) {
    auto r = loadMesh(write("m.off.gz", gzip("OFF\n4 1 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n4 0 1 2 3\n")));
    ASSERT_TRUE(r) << r.error().message;
    EXPECT_EQ(r->indices, kSquareFan);
}

}  // namespace
}  // namespace rthdist::io::test
