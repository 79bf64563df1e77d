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
    int componentType = 5126;  // FLOAT
};

std::string gltfJson(const GltfParts& p) {
    return R"({"asset":{"version":"2.0"},"buffers":[)" + p.bufferJson +
           R"(],"bufferViews":[{"buffer":0,"byteOffset":0,"byteLength":)" + std::to_string(p.byteLength) +
           R"(}],"accessors":[{"bufferView":0,"componentType":)" + std::to_string(p.componentType) +
           R"(,"count":)" + std::to_string(p.count) + R"(,"type":")" + p.accessorType +
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
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "glTF: buffer URI 'missing.bin': No such file"));
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

TEST_F(GltfReader, PositionComponentTypeTheSpecDoesNotAllowIsRefused) {
    // UNSIGNED_INT positions were read and rounded to float: 16777217 came
    // back as 16777216. glTF 2.0 allows FLOAT, and with KHR_mesh_quantization
    // (signed or unsigned) bytes and shorts.
    ByteBuilder u32;
    for (uint32_t v : {0u, 0u, 0u, 16777217u, 0u, 0u, 1u, 2u, 3u}) u32.put(v);
    GltfParts p;
    p.bufferJson =
        R"({"byteLength":36,"uri":"data:application/octet-stream;base64,)" + base64(u32.str()) + R"("})";
    p.componentType = 5125;
    const std::string uint = write("u32.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(uint), uint, "accessor 0: POSITION componentType 5125 (UNSIGNED_INT)"));
    EXPECT_TRUE(isBadInput(loadMesh(uint), uint, "accessor 0: POSITION componentType 5125 (UNSIGNED_INT)"));
    p.componentType = 5124;  // INT: not a glTF 2.0 component type at all
    const std::string sint = write("i32.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(sint), sint, "accessor 0: POSITION componentType 5124 (INT)"));
    p.componentType = 5130;  // DOUBLE: tinygltf knows it, glTF 2.0 does not
    p.count = 1;
    const std::string dbl = write("f64.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(dbl), dbl, "accessor 0: POSITION componentType 5130 (DOUBLE)"));
    // KHR_mesh_quantization's types still load: unsigned shorts, not normalized.
    ByteBuilder u16;
    for (uint16_t v : {1, 2, 3, 0, 4, 5, 6, 0}) u16.put(v);
    p.bufferJson =
        R"({"byteLength":16,"uri":"data:application/octet-stream;base64,)" + base64(u16.str()) + R"("})";
    p.byteLength = 16;
    p.count = 2;
    p.componentType = 5123;
    std::string json = gltfJson(p);
    json.replace(json.find(R"("byteLength":16})"), 16, R"("byteLength":16,"byteStride":8})");
    auto r = loadPoints(write("u16.gltf", json));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, (std::vector<glm::vec3>{{1, 2, 3}, {4, 5, 6}}));
}

TEST_F(GltfReader, DefaultSceneOutOfRangeIsAnError) {
    // "scene": 5 with one scene was taken as no default scene (every scene).
    GltfParts p;
    p.bufferJson = embedded(threePoints());
    p.scenes = R"("scenes":[{"nodes":[0]}],"scene":5)";
    const std::string path = write("scene5.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "glTF: default scene 5 out of range (1 scene(s))"));
    EXPECT_TRUE(isBadInput(loadMesh(path), path, "glTF: default scene 5 out of range (1 scene(s))"));
    p.scenes = R"("scene":0)";  // no scenes at all
    const std::string none = write("scene0.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(none), none, "glTF: default scene 0 out of range (0 scene(s))"));
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

// ---- hardening (issue 15) ----------------------------------------------------

TEST_F(GltfReader, DeeplyNestedJsonIsRefusedNotACrash) {
    // 16,000 nested arrays overflowed the stack in tinygltf's recursive parser (exit 139).
    const std::string json =
        R"({"asset":{"version":"2.0","extras":)" + std::string(16000, '[') + std::string(16000, ']') + "}}";
    const std::string path = write("deep.gltf", json);
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "byte offset 289: JSON nested deeper than 256 levels"));
    const std::string bin = write("deep.glb", glb(json, ""));
    EXPECT_TRUE(isBadInput(loadPoints(bin), bin, "byte offset 309: JSON nested deeper than 256 levels"));
}

TEST_F(GltfReader, NestingAtTheLimitLoads) {
    GltfParts p;
    p.bufferJson = embedded(threePoints());
    std::string json = gltfJson(p);
    json.insert(json.size() - 1, R"(,"extras":)" + std::string(254, '[') + std::string(254, ']'));
    auto r = loadPoints(write("deep_ok.gltf", json));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(GltfReader, MillionsOfEmptyNodesAreRefusedBeforeParsing) {
    // A 12 MB file of empty nodes took 2.2 GB inside tinygltf.
    std::string nodes = "[{}";
    for (int i = 0; i < 600000; ++i) nodes += ",{}";
    nodes += "]";
    const std::string path = write("nodes.gltf", R"({"asset":{"version":"2.0"},"nodes":)" + nodes + "}");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "more than 500000 glTF objects"));
    std::string values = "[0";
    for (int i = 0; i < 2100000; ++i) values += ",0";
    values += "]";
    const std::string extras = write("values.gltf", R"({"asset":{"version":"2.0","extras":)" + values + "}}");
    EXPECT_TRUE(isBadInput(loadPoints(extras), extras, "more than 2000000 JSON values"));
}

// The points of pos.bin in a directory next to the glTF's.
class GltfUris : public GltfReader {
public:
    void SetUp() override {
        GltfReader::SetUp();
        std::filesystem::create_directories(file("scene"));
        std::filesystem::create_directories(file("scene/sub"));
        write("pos.bin", positions(threePoints()));
        write("scene/sub/pos.bin", positions(threePoints()));
    }
    std::string gltfWithUri(const std::string& name, const std::string& uri) {
        GltfParts p;
        p.bufferJson = R"({"byteLength":36,"uri":")" + uri + R"("})";
        return write(name, gltfJson(p));
    }
};

TEST_F(GltfUris, ParentDirectoryIsRefused) {
    // "../pos.bin" was read, and its bytes came back out as points.
    const std::string path = gltfWithUri("scene/up.gltf", "../pos.bin");
    EXPECT_TRUE(
        isBadInput(loadPoints(path), path, "buffer URI '../pos.bin': '..' leaves the glTF file's directory"));
    const std::string encoded = gltfWithUri("scene/enc.gltf", "sub/%2e%2e/../pos.bin");
    EXPECT_TRUE(isBadInput(loadPoints(encoded), encoded, "'..' leaves the glTF file's directory"));
}

TEST_F(GltfUris, AbsolutePathIsRefused) {
    const std::string path = gltfWithUri("scene/abs.gltf", file("pos.bin"));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "absolute path"));
}

TEST_F(GltfUris, SubdirectoryIsAllowed) {
    auto r = loadPoints(gltfWithUri("scene/down.gltf", "sub/pos.bin"));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(*r, threePoints());
}

TEST_F(GltfUris, CurrentDirectoryIsNotSearched) {
    // An unresolved URI was looked up in the current directory as well.
    const std::string path = gltfWithUri("scene/cwd.gltf", "pos.bin");  // only in the parent and in sub/
    const std::filesystem::path before = std::filesystem::current_path();
    std::filesystem::current_path(file("scene/sub"));
    auto r = loadPoints(path);
    std::filesystem::current_path(before);
    EXPECT_TRUE(isBadInput(r, path, "buffer URI 'pos.bin': No such file"));
}

TEST_F(GltfUris, SymlinkOutOfTheDirectoryIsRefused) {
    // stat() followed a link inside the directory to a file outside it.
    std::filesystem::create_symlink(file("pos.bin"), file("scene/link.bin"));
    const std::string path = gltfWithUri("scene/link.gltf", "link.bin");
    EXPECT_TRUE(isBadInput(loadPoints(path), path,
                           "buffer URI 'link.bin': its real path '" +
                               std::filesystem::canonical(file("pos.bin")).string() +
                               "' is outside the glTF file's directory"));
    // A linked directory the same.
    std::filesystem::create_directory_symlink(file(""), file("scene/up"));
    const std::string viaDir = gltfWithUri("scene/viadir.gltf", "up/pos.bin");
    EXPECT_TRUE(isBadInput(loadPoints(viaDir), viaDir, "is outside the glTF file's directory"));
    // A link that stays inside loads, and so does a glTF reached through a linked directory.
    std::filesystem::create_symlink("sub/pos.bin", file("scene/inside.bin"));
    auto inside = loadPoints(gltfWithUri("scene/inside.gltf", "inside.bin"));
    ASSERT_TRUE(inside.ok()) << inside.error().message;
    EXPECT_EQ(*inside, threePoints());
    std::filesystem::create_directory_symlink(file("scene"), file("linked_scene"));
    gltfWithUri("scene/down.gltf", "sub/pos.bin");
    auto linked = loadPoints(file("linked_scene/down.gltf"));
    ASSERT_TRUE(linked.ok()) << linked.error().message;
    EXPECT_EQ(*linked, threePoints());
}

TEST_F(GltfUris, DirectoryIsRefused) {
    // A URI naming a directory made tinygltf attempt a 2^63-byte allocation.
    const std::string path = gltfWithUri("scene/dir.gltf", "sub");
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "buffer URI 'sub': not a regular file"));
}

// One accessor of `points` points, `primitives` primitives per mesh, `nodes` nodes.
std::string instancedGlb(size_t points, size_t primitives, size_t nodes) {
    std::string prims = "[";
    for (size_t i = 0; i < primitives; ++i)
        prims += std::string(i ? "," : "") + R"({"attributes":{"POSITION":0}})";
    std::string nodeList = "[";
    std::string sceneNodes = "[";
    for (size_t i = 0; i < nodes; ++i) {
        nodeList += std::string(i ? "," : "") + R"({"mesh":0})";
        sceneNodes += std::string(i ? "," : "") + std::to_string(i);
    }
    const std::string bin = positions(std::vector<glm::vec3>(points, glm::vec3(1, 2, 3)));
    const std::string json = R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":)" +
                             std::to_string(bin.size()) + R"(}],"bufferViews":[{"buffer":0,"byteLength":)" +
                             std::to_string(bin.size()) +
                             R"(}],"accessors":[{"bufferView":0,"componentType":5126,"count":)" +
                             std::to_string(points) + R"(,"type":"VEC3"}],"meshes":[{"primitives":)" + prims +
                             R"(]}],"nodes":)" + nodeList + R"(],"scenes":[{"nodes":)" + sceneNodes + "]}]}";
    return glb(json, bin);
}

TEST_F(GltfReader, InstancedPointsLoadInLinearTime) {
    // A million instances of one point: the reserve per instance made this quadratic.
    auto r = loadPoints(write("million.glb", instancedGlb(1, 1000, 1000)));
    ASSERT_TRUE(r.ok()) << r.error().message;
    EXPECT_EQ(r->size(), 1000000u);
    EXPECT_EQ(r->back(), glm::vec3(1, 2, 3));
}

TEST_F(GltfReader, InstancedPointsBeyondTheLimitAreRefusedBeforeAllocating) {
    // 1000 points x 100 primitives x 1001 nodes = 100.1 M points > kMaxGltfInstancedPoints.
    const std::string path = write("bomb.glb", instancedGlb(1000, 100, 1001));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "the scene instances more than 100000000 points"));
}

TEST_F(GltfReader, SceneListingANodeTwiceIsAnError) {
    GltfParts p;
    p.bufferJson = embedded(threePoints());
    p.scenes = R"("scenes":[{"nodes":[0,0]}],"scene":0)";
    const std::string path = write("twice.gltf", gltfJson(p));
    EXPECT_TRUE(isBadInput(loadPoints(path), path, "scene 0: node 0 is listed twice"));
}

}  // namespace
}  // namespace rthdist::io::test
