#include "io/gltf_file_access.hpp"

#include <sys/stat.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <string_view>

namespace rthdist::io {
namespace {

struct FileCloser {
    void operator()(std::FILE* f) const { std::fclose(f); }
};

// Why uri may not name a file below the base directory, or "" if it may.
std::string uriProblem(std::string_view uri) {
    if (uri.empty()) return "empty URI";
    if (uri.front() == '/') return "absolute path";
    if (uri.find('\0') != std::string_view::npos) return "NUL byte in the path";
    size_t start = 0;
    while (start <= uri.size()) {
        const size_t slash = std::min(uri.find('/', start), uri.size());
        if (uri.substr(start, slash - start) == "..") return "'..' leaves the glTF file's directory";
        start = slash + 1;
    }
    if (uri.back() == '/') return "names a directory";
    return "";
}

}  // namespace

GltfFileAccess::GltfFileAccess(const std::string& gltfPath) {
    const std::filesystem::path dir = std::filesystem::path(gltfPath).parent_path();
    m_baseDir = dir.empty() ? std::string("./") : (dir / "").string();  // with a trailing '/'
}

std::string GltfFileAccess::resolve(const std::string& joined, uint64_t* size) {
    // tinygltf tries baseDir + uri, then "./" + uri: only the first may pass.
    if (!joined.starts_with(m_baseDir)) {
        // The first refusal (of baseDir + uri) is the one worth reporting.
        if (m_refusal.empty()) m_refusal = "'" + joined + "' is outside the glTF file's directory";
        return "";
    }
    const std::string uri = joined.substr(m_baseDir.size());
    if (const std::string why = uriProblem(uri); !why.empty()) {
        m_refusal = "URI '" + uri + "': " + why;
        return "";
    }
    // Symbolic links are followed, but the file reached must lie inside the
    // directory's own real path: a link to a file (or a directory) outside
    // it was read as if it were inside.
    std::error_code ec;
    const std::filesystem::path realBase = std::filesystem::canonical(m_baseDir, ec);
    if (ec) {
        m_refusal = "the glTF file's directory '" + m_baseDir + "': " + ec.message();
        return "";
    }
    const std::filesystem::path real = std::filesystem::canonical(joined, ec);
    if (ec) {
        m_refusal = "URI '" + uri + "': " + ec.message();
        return "";
    }
    const std::string inside = (realBase / "").string();  // with a trailing '/'
    if (!real.string().starts_with(inside)) {
        m_refusal =
            "URI '" + uri + "': its real path '" + real.string() + "' is outside the glTF file's directory";
        return "";
    }
    struct stat st {};
    if (::stat(real.c_str(), &st) != 0) {
        m_refusal = "URI '" + uri + "': " + std::strerror(errno);
        return "";
    }
    if (!S_ISREG(st.st_mode)) {
        m_refusal = "URI '" + uri + "': not a regular file";
        return "";
    }
    if (static_cast<uint64_t>(st.st_size) > kMaxGltfExternalFileBytes) {
        m_refusal = "URI '" + uri + "': " + std::to_string(st.st_size) + " bytes, more than the " +
                    std::to_string(kMaxGltfExternalFileBytes) + " this loader reads";
        return "";
    }
    if (size != nullptr) *size = static_cast<uint64_t>(st.st_size);
    return real.string();
}

bool GltfFileAccess::exists(const std::string& joined) { return !resolve(joined, nullptr).empty(); }

bool GltfFileAccess::read(std::vector<unsigned char>& out, std::string& err, const std::string& joined) {
    uint64_t size = 0;
    const std::string real = resolve(joined, &size);
    if (real.empty()) {
        err = m_refusal;
        return false;
    }
    std::unique_ptr<std::FILE, FileCloser> file(std::fopen(real.c_str(), "rb"));
    if (!file) {
        err = std::strerror(errno);
        return false;
    }
    // The file may grow after stat: read at most the size checked, plus one
    // byte to notice.
    out.resize(static_cast<size_t>(size) + 1);
    out.resize(std::fread(out.data(), 1, out.size(), file.get()));
    if (std::ferror(file.get()) || out.size() > size) {
        err = std::ferror(file.get()) ? "read error" : "file changed while read";
        return false;
    }
    return true;
}

}  // namespace rthdist::io
