// Mutation smoke test standing in for a fuzzer: small valid files of every
// format, randomly damaged (fixed, printed seed), must each load or fail
// with kBadInput naming the file; never crash, hang or allocate wildly (run
// under ASan+UBSan in CI).
#include <random>

#include "io_test_support.hpp"

namespace rthdist::io::test {
namespace {

using Mutation = TempDirTest;

struct Seed {
    std::string name;
    std::string bytes;
};

std::vector<Seed> seeds() {
    const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
    std::vector<Seed> s;
    s.push_back(
        {"a.ply",
         "ply\nformat ascii 1.0\ncomment c\nelement face 1\nproperty list uchar int v\nelement vertex 3\n" +
             xyz + "property uchar q\nend_header\n3 0 1 2\n1 2 3 4\n4 5 6 7\n-7 8.5 9e-1 0\n"});
    for (bool big : {false, true}) {
        ByteBuilder b(big);
        b.text(std::string("ply\nformat ") + (big ? "binary_big_endian" : "binary_little_endian") +
               " 1.0\nelement tristrips 1\nproperty list int int vertex_indices\nelement vertex 4\n"
               "property double x\nproperty short y\nproperty float z\nproperty list uchar uchar "
               "n\nend_header\n");
        b.put<int32_t>(3).put<int32_t>(0).put<int32_t>(-1).put<int32_t>(2);
        for (int i = 0; i < 4; ++i)
            b.put<double>(i * 0.5).put<int16_t>(-i).put<float>(i * 2.0f).put<uint8_t>(1).put<uint8_t>(9);
        s.push_back({big ? "be.ply" : "le.ply", b.str()});
    }
    s.push_back({"z.ply.gz", gzip(s[0].bytes)});
    s.push_back({"a.xyz", "# c\n1 2 3\n4,5,6\n7 8 9 10\n"});
    s.push_back({"a.obj", "v 1 2 3\nvn 0 0 1\nv 4 5 6 1\nf 1 2 1\n"});
    s.push_back({"a.off", "OFF\n# c\n3 1 0\n1 2 3\n4 5 6\n7 8 9\n3 0 1 2\n"});
    s.push_back(
        {"a.stl",
         "solid t\nfacet normal 0 0 1\nouter loop\nvertex 1 2 3\nvertex 4 5 6\nvertex 7 8 9\nendloop\n"
         "endfacet\nendsolid t\n"});
    {
        ByteBuilder b;
        b.text(std::string(80, ' ')).put<uint32_t>(1);
        for (int i = 0; i < 12; ++i) b.put<float>(float(i));
        b.put<uint16_t>(0);
        s.push_back({"b.stl", b.str()});
    }
    s.push_back(
        {"a.pcd",
         "VERSION .7\nFIELDS x y z rgb\nSIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH 2\nHEIGHT 1\n"
         "POINTS 2\nDATA ascii\n1 2 3 4\n5 6 7 8\n"});
    {
        ByteBuilder b;
        b.text("FIELDS x y z\nSIZE 4 8 2\nTYPE F F I\nCOUNT 1 1 1\nPOINTS 2\nDATA binary\n");
        b.put(1.0f).put(2.0).put<int16_t>(3).put(4.0f).put(5.0).put<int16_t>(6);
        s.push_back({"b.pcd", b.str()});
    }
    ByteBuilder bin;
    for (int i = 0; i < 9; ++i) bin.put<float>(float(i));
    const std::string json =
        R"({"asset":{"version":"2.0"},"buffers":[{"byteLength":36URI}],)"
        R"("bufferViews":[{"buffer":0,"byteLength":36}],"accessors":[{"bufferView":0,)"
        R"("componentType":5126,"count":3,"type":"VEC3"}],"meshes":[{"primitives":[{"attributes":)"
        R"({"POSITION":0}}]}],"nodes":[{"children":[1],"translation":[1,2,3]},{"mesh":0,)"
        R"("rotation":[0,0,0,1],"scale":[2,2,2]}],"scenes":[{"nodes":[0]}],"scene":0})";
    std::string gltf = json;
    gltf.replace(gltf.find("URI"), 3,
                 R"(,"uri":"data:application/octet-stream;base64,)" + base64(bin.str()) + "\"");
    s.push_back({"a.gltf", gltf});
    std::string glbJson = json;
    glbJson.replace(glbJson.find("URI"), 3, "");
    s.push_back({"a.glb", glb(glbJson, bin.str())});
    return s;
}

TEST_F(Mutation, SeedsLoad) {
    for (const Seed& seed : seeds()) {
        auto r = loadPoints(write(seed.name, seed.bytes));
        EXPECT_TRUE(r.ok()) << seed.name << ": " << r.error().message;
    }
}

TEST_F(Mutation, DamagedFilesLoadOrFailCleanly) {
    constexpr unsigned kSeed = 7919;
    constexpr int kPerFormat = 150;
    std::mt19937 rng(kSeed);
    const std::string digits = "0123456789-+.e \n";
    for (const Seed& seed : seeds()) {
        for (int i = 0; i < kPerFormat; ++i) {
            std::string s = seed.bytes;
            const int edits = 1 + static_cast<int>(rng() % 4);
            for (int m = 0; m < edits && !s.empty(); ++m) {
                const size_t pos = rng() % s.size();
                switch (rng() % 5) {
                    case 0: s[pos] = static_cast<char>(rng()); break;
                    case 1: s.resize(pos); break;
                    case 2: s.insert(pos, 1 + rng() % 3, digits[rng() % digits.size()]); break;
                    case 3: s.erase(pos, 1 + rng() % 8); break;
                    case 4: s.insert(rng() % s.size(), s.substr(pos, 1 + rng() % 16)); break;
                }
            }
            const std::string path = write(seed.name, s);
            auto r = loadPoints(path);
            if (r.ok()) continue;
            EXPECT_EQ(r.error().code, ErrorCode::kBadInput)
                << "seed " << kSeed << " " << seed.name << " #" << i;
            EXPECT_EQ(r.error().message.rfind(path + ": ", 0), 0u)
                << "seed " << kSeed << " " << seed.name << " #" << i << ": " << r.error().message;
        }
    }
}

}  // namespace
}  // namespace rthdist::io::test
