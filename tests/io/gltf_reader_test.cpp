// glTF: .gltf with external and embedded buffers, .glb, node transforms down
// the hierarchy, scene selection, and malformed files.
#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

using GltfReader = TempDirTest;

std::string positions(const std::vector<glm::vec3>& pts) {
    ByteBuilder b;
    for (const glm::vec3& p : pts) b.put(p.x).put(p.y).put(p.z);
    return b.str();
}

struct GltfParts {
    std::string bufferJson;  // the buffers[0] object
    size_t byteLength = 36;
    size_t count = 3;
    std::string nodes = R"([{"mesh":0}])";
    std::string scenes = R"("scenes":[{"nodes":[0]}],"scene":0)";
    std::string accessorType = "VEC3";
};

std::string gltfJson(const GltfParts& p) {
    return R"({"asset":{"version":"2.0"},"buffers":[)" + p.bufferJson +
           R"(],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" + std::to_string(p.byteLength) +
           R"(}],"accessors":[{"bufferView":0,"componentType":5126,"count":)" + std::to_string(p.count) +
           R"(,"type":")" + p.accessorType +
           R"("}],"meshes":[{"primitives":[{"attributes":{"POSITION":0},"mode":4}]}],"nodes":)" + p.nodes +
           "," + p.scenes + "}";
}

std::string embedded(const std::vector<glm::vec3>& pts) {
    const std::string bin = positions(pts);
    return R"({"byteLength":)" + std::to_string(bin.size()) +
           R"(,"uri":"data:application/octet-stream;base64,)" + base64(bin) + R"("})";
}

void expectNear(const std::vector<glm::vec3>& got, const std::vector<glm::vec3>& want) {
    ASSERT_EQ(got.size(), want.size());
    for (size_t i = 0; i < got.size(); ++i) {
        for (int a = 0; a < 3; ++a)
            EXPECT_NEAR(got[i][a], want[i][a], 1e-4) << "point " << i << " axis " << a;
    }
}

TEST_F(GltfReader, ExternalBin) {
    write("pos.bin", positions(threePoints()));
    GltfParts p;
    p.bufferJson = R"({"byteLength":36,"uri":"pos.bin"})";
    auto r = loadPoints(write("a.gltf", gltfJson(p)));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(GltfReader, EmbeddedDataUriAndGzip) {
    GltfParts p;
    p.bufferJson = embedded(threePoints());
    auto r = loadPoints(write("a.gltf.gz", gzip(gltfJson(p))));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(GltfReader, Glb) {
    GltfParts p;
    p.bufferJson = R"({"byteLength":36})";
    auto r = loadPoints(write("a.glb", glb(gltfJson(p), positions(threePoints()))));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(GltfReader, NodeTransformsThroughTheHierarchy) {
    const std::vector<glm::vec3> one = {{1, 2, 3}};
    GltfParts p;
    p.bufferJson = embedded(one);
    p.byteLength = 12;
    p.count = 1;
    // 0: translate (10,0,0) -> child 1: scale 2 (mesh) -> child 2: rotate 90 deg about z (mesh)
    // 3: column-major matrix translating by (0,0,5) (mesh); 4: not in the scene.
    p.nodes = R"([{"children":[1],"translation":[10,0,0]},
                  {"mesh":0,"scale":[2,2,2],"children":[2]},
                  {"mesh":0,"rotation":[0,0,0.70710678118654752,0.70710678118654752]},
                  {"mesh":0,"matrix":[1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,5,1]},
                  {"mesh":0,"translation":[99,99,99]}])";
    p.scenes = R"("scenes":[{"nodes":[0,3]}],"scene":0)";
    auto r = loadPoints(write("t.gltf", gltfJson(p)));
    ASSERT_TRUE(r.ok()) << r.error().message;
    // node 2 world = T(10,0,0) * S(2) * Rz(90): (1,2,3) -> (-2,1,3) -> (-4,2,6) -> (6,2,6)
    expectNear(*r, {{12, 4, 6}, {6, 2, 6}, {1, 2, 8}});
}

TEST_F(GltfReader, DefaultSceneElseAllScenes) {
    GltfParts p;
    p.bufferJson = embedded(threePoints());
    p.nodes = R"([{"mesh":0},{"mesh":0,"translation":[1,0,0]}])";
    p.scenes = R"("scenes":[{"nodes":[0]},{"nodes":[1]}],"scene":1)";
    auto r = loadPoints(write("d.gltf", gltfJson(p)));
    ASSERT_TRUE(r.ok()) << r.error().message;
    ASSERT_EQ(r->size(), 3u);
    EXPECT_EQ((*r)[0], threePoints()[0] + glm::vec3(1, 0, 0));
    p.scenes = R"("scenes":[{"nodes":[0]},{"nodes":[1]}])";
    auto all = loadPoints(write("all.gltf", gltfJson(p)));
    ASSERT_TRUE(all.ok()) << all.error().message;
    EXPECT_EQ(all->size(), 6u);
}

TEST_F(GltfReader, MalformedJson) {
    const std::string path = write("bad.gltf", R"({"asset":{"version":"2.0"},"buffers":[)");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "glTF: malformed"));
}

TEST_F(GltfReader, MissingExternalBuffer) {
    GltfParts p;
    p.bufferJson = R"({"byteLength":36,"uri":"missing.bin"})";
    const std::string path = write("m.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "glTF: malformed"));
}

TEST_F(GltfReader, AccessorCountLies) {
    GltfParts p;
    p.bufferJson = embedded(threePoints());
    p.count = 1000000000;
    const std::string path = write("lie.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "accessor 0"));
}

TEST_F(GltfReader, BufferViewBeyondBuffer) {
    GltfParts p;
    p.bufferJson = embedded(threePoints());
    p.byteLength = 4000;
    const std::string path = write("view.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "bufferView 0"));
}

TEST_F(GltfReader, PositionNotVec3) {
    GltfParts p;
    p.bufferJson = embedded(threePoints());
    p.accessorType = "VEC4";
    p.count = 2;
    const std::string path = write("v4.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "accessor 0: POSITION is not VEC3"));
}

TEST_F(GltfReader, NodeCycleAndBadIndices) {
    GltfParts p;
    p.bufferJson = embedded(threePoints());
    p.nodes = R"([{"mesh":0,"children":[1]},{"children":[0]}])";
    const std::string cycle = write("cycle.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(cycle), cycle, "node 0"));
    p.nodes = R"([{"mesh":0,"children":[7]}])";
    const std::string child = write("child.gltf", gltfJson(p));
    auto r = loadPoints(child);
    EXPECT_FALSE(r.ok());
    if (!r.ok()) EXPECT_EQ(r.error().code, ErrorCode::kBadInput);
    p.nodes = R"([{"mesh":3}])";
    const std::string mesh = write("mesh.gltf", gltfJson(p));
    auto m = loadPoints(mesh);
    EXPECT_FALSE(m.ok());
    if (!m.ok()) EXPECT_EQ(m.error().code, ErrorCode::kBadInput);
}

TEST_F(GltfReader, TruncatedGlb) {
    GltfParts p;
    p.bufferJson = R"({"byteLength":36})";
    const std::string full = glb(gltfJson(p), positions(threePoints()));
    const std::string path = write("cut.glb", full.substr(0, full.size() - 20));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "glTF: malformed"));
}

TEST_F(GltfReader, NoMeshesHasNoPoints) {
    const std::string path =
        write("empty.gltf", R"({"asset":{"version":"2.0"},"nodes":[{}],"scenes":[{"nodes":[0]}]})");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "contains no points"));
}

}  // namespace
}  // namespace rthdist::io::test
