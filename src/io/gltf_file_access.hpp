// File access for the URIs inside a .gltf/.glb (buffers; images are never
// read): only regular files inside the glTF file's own directory. No
// absolute paths, no ".." component, no lookup in the current directory, no
// directories or devices, no symbolic link that leads out of the directory
// (the file's real path must lie inside the directory's real path; a link
// that stays inside is followed), and a size check before reading. tinygltf calls
// these through its FsCallbacks (gltf_reader.cpp); data: URIs never get here.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace rthdist::io {

// Largest external buffer file read.
inline constexpr uint64_t kMaxGltfExternalFileBytes = uint64_t{4} << 30;

class GltfFileAccess {
public:
    // gltfPath: the .gltf/.glb file; URIs resolve in its directory.
    explicit GltfFileAccess(const std::string& gltfPath);

    // The directory tinygltf is given as its base path.
    [[nodiscard]] const std::string& baseDir() const { return m_baseDir; }

    // The FsCallbacks: tinygltf joins baseDir() and the (percent-decoded)
    // URI, then asks whether the file exists and reads it.
    [[nodiscard]] bool exists(const std::string& joined);
    [[nodiscard]] bool read(std::vector<unsigned char>& out, std::string& err, const std::string& joined);

    // Why a URI was refused (the first time), "" when none was.
    [[nodiscard]] const std::string& refusal() const { return m_refusal; }

private:
    // The real path (symbolic links resolved) of joined if it is a regular
    // file of at most kMaxGltfExternalFileBytes whose real path lies inside
    // the real path of baseDir(), else "" with m_refusal set.
    std::string resolve(const std::string& joined, uint64_t* size);

    std::string m_baseDir;  // ends with '/'
    std::string m_refusal;
};

}  // namespace rthdist::io
