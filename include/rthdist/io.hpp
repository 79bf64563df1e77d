// rthdist — point-set loaders.
//
// Formats (chosen by extension, case-insensitive; ".gz" is unwrapped first):
//   .ply  ascii, binary_little_endian, binary_big_endian; vertex x/y/z as any
//         numeric type (float/double/int...); other vertex properties, list
//         properties and other elements (faces, tristrips, range_grid) are
//         skipped, but must be in the file as declared: ascii bodies hold one
//         item per line with exactly its properties' values; binary bodies
//         are walked item by item to the end of the file (only blank or NUL
//         padding may follow). An element name may appear once per file
//         (a second "vertex" element is refused, not skipped), a property
//         name once per element, and an element may declare at most 65,536
//         properties.
//   .xyz / .txt  one "x y z" per line (extra columns ignored, '#' comments);
//         values separated by blanks, ',' or ';'; a line that separates them
//         both by blanks alone and by commas ("1,5 2,5 3,5": decimal commas)
//         is refused, not read as 1, 5, 2.
//   .obj  "v x y z" lines only.
//   .gltf / .glb  POSITION of every primitive of every mesh instanced by the
//         scene's nodes (the file's default `scene`, refused when it names
//         no scene; without one, every scene's: a node two scenes list
//         counts twice), with node
//         transforms applied (tinygltf); a sparse
//         POSITION accessor is refused (kBadInput naming it), and so is one
//         of a componentType glTF 2.0 does not allow for POSITION (it allows
//         FLOAT, and BYTE, UNSIGNED_BYTE, SHORT, UNSIGNED_SHORT, normalized
//         or not, with KHR_mesh_quantization): UNSIGNED_INT, INT and DOUBLE
//         are refused, not rounded to float. External
//         buffers are read only from regular files inside the glTF file's own
//         directory (no absolute path, no "..", no current-directory lookup,
//         no symbolic link whose real path leaves the directory's real path);
//         data: URIs are decoded; images are never read.
//   .stl  ascii and binary (every facet vertex, duplicates kept); binary when
//         the size is 84 + 50 * facets or the file holds a NUL byte, whatever
//         the header's first word. Ascii: every facet holds exactly three
//         vertex lines of x y z before its endfacet (a vertex outside a
//         facet, a facet of two or four, a file ending inside a facet are
//         refused, naming the facet and line). Binary: at most 49 bytes
//         may follow the declared facets (50 or more could be facets the
//         count leaves out: refused).
//   .off  OFF / COFF / NOFF headers, vertices only; the body must hold
//         exactly the header's vertices and faces (the faces are parsed and
//         their indices checked, then dropped), so a vertex line past the
//         count, a missing face or a line after the last face is refused
//   .pcd  ascii, binary and binary_compressed (x y z fields, any size/type;
//         POINTS rows exactly: an ascii row past them, or a nonzero byte
//         after the binary rows (PCL pads with zeros), is refused;
//         binary_compressed is PCL's: the fields' columns LZF-compressed,
//         inflated by liblzf into a buffer of their declared size, at most
//         4 GiB - 1 and 88 times the compressed bytes, then converted)
//   .las  LAS 1.0-1.4, point data formats 0-10 (src/io/las_reader.hpp): X/Y/Z
//         int32 times scale plus offset, in double; variable-length records
//         are skipped (the points start at the header's offset to point
//         data); 1.4's 64-bit point count. The header size, the offset to the
//         points, the record length (at least the format's size) and the
//         point count times the record length are checked against the file;
//         a scale of 0, a non-finite scale or offset, and a coordinate that
//         is NaN or infinite after scaling are refused, each naming the byte
//         offset (or point). LoadOptions::lasClasses keeps only the
//         points of those classification values. Compressed LAS (.laz) is
//         refused with kBadInput saying how to decompress it (Debian 12 has
//         no LAZ library): `laszip -i in.laz -o out.las` or
//         `pdal translate in.laz out.las`.
// Text (every format's text parts): a leading UTF-8 byte order mark is
// skipped; "\n", "\r\n" and a lone "\r" all end a line.
//
// Contract: on success, at least one point and every coordinate finite (in
// the cloud's precision: a double beyond the float range is finite). Every
// failure is ErrorCode::kBadInput with a message "<path>: <where>: <what>"
// (where = line N, vertex N, byte offset N, element name, gzip, glTF...).
// Declared counts are checked against the file before anything is allocated,
// so a lying header cannot cause a huge allocation; for .gz files and glTF the
// limits below do the same, each refused with kBadInput before the memory is
// spent:
//   .gz    the first 64 KiB are inflated and the format's header checked;
//          a binary PLY, binary STL or .glb may then inflate to no more than
//          its header declares (+ 64 KiB); and no file inflates past 64 times
//          its compressed size or 256 MiB, whichever is larger.
//   glTF   JSON nesting at most 256 deep, at most 2,000,000 JSON values and
//          500,000 top-level objects (nodes, meshes, accessors...), checked
//          before parsing; at most 100,000,000 instanced points and
//          10,000,000 node instances over the scene, counted before any point
//          is read; external buffer files at most 4 GiB.
//
// Precision: loadPointCloud keeps the file's precision. Decimal text (ascii
// PLY, XYZ/TXT, OBJ, OFF, ascii STL, ascii PCD) is converted straight to the
// nearest double (std::from_chars); binary PLY and PCD whose x, y or z is a
// double or a 32/64-bit integer are read as double (64-bit integers rounded
// to the nearest double), other binary types (float, 8/16-bit integers) as
// float; LAS is double (scale and offset applied in double); binary STL and
// glTF are float. A double cloud takes 24 bytes per point, a float one 12.
// loadPoints rounds a double cloud to the nearest floats (a coordinate beyond
// the float range is then an error): kept for callers that want float32;
// for decimal text it can differ from a direct float conversion by one unit
// in the last place when the decimal lies almost halfway between two floats.
// Reading: a regular file is memory-mapped read-only and parsed in place;
// binary PLY vertices without list properties, binary PCD rows and LAS
// points are converted in parallel chunks straight into the cloud, and text
// bodies (XYZ/TXT, ascii PLY, OBJ, OFF, ascii PCD) are cut at line ends into
// chunks parsed in parallel (LoadOptions::threads). Points, precision and
// errors are those of a serial parse: an error names the first bad place in
// the file. A .gz file is inflated into memory first; a file that is not
// regular (a FIFO, a device) is refused. A file truncated by another
// process while it is being loaded ends the process with SIGBUS, as with
// any reader of a mapped file. Memory: the cloud (24 bytes per point in
// double, 12 in float) beside the page cache's copy of the file; the binary
// readers write each point once, in the pass that converts and checks it,
// into an array nothing has zeroed first (PointAllocator), so that the
// threads that convert a chunk are the first to touch its memory.
// Limits: extended VLRs and LAS waveform data after the points are not
// read. A glTF mesh instanced by
// several nodes gives its points once per instance; NaN points (e.g. in
// organized PCD clouds) are rejected, not dropped; a binary PLY whose vertex
// count is one too high can go unnoticed when the bytes it takes happen to
// leave a valid rest (e.g. 12-byte vertices before uchar/int triangles).
// Reentrant: no shared state, safe to call from several threads (each call
// starts and joins its own parsing threads).
#pragma once

#include <glm/vec3.hpp>

#include <cstddef>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "rthdist/export.hpp"
#include "rthdist/mesh.hpp"
#include "rthdist/point_view.hpp"
#include "rthdist/result.hpp"

namespace rthdist::io {

namespace detail {
// PointAllocator's memory: arrays of 4 MiB and more are mapped on their own
// and marked for transparent huge pages (Linux; one page fault per 2 MiB),
// smaller ones come from operator new. Throws std::bad_alloc.
[[nodiscard]] RTHDIST_IO_API void* allocatePointBytes(size_t bytes);
RTHDIST_IO_API void freePointBytes(void* p, size_t bytes) noexcept;
}  // namespace detail

// The allocator of PointCloud's arrays: resize(n) leaves the new points
// unwritten (a loader writes every point of a file once, chunk by chunk in
// parallel, instead of one thread zeroing gigabytes first); resize(n, value),
// copies and moves behave as in any std::vector. Whoever grows an array
// with resize(n) writes the new points before reading them.
template <class T>
struct PointAllocator {
    static_assert(std::is_trivially_copyable_v<T>);
    using value_type = T;

    PointAllocator() = default;
    template <class U>
    PointAllocator(const PointAllocator<U>&) noexcept {}

    [[nodiscard]] T* allocate(size_t n) { return static_cast<T*>(detail::allocatePointBytes(n * sizeof(T))); }
    void deallocate(T* p, size_t n) noexcept { detail::freePointBytes(p, n * sizeof(T)); }

    // Construction without a value writes nothing; with values, as usual.
    template <class U, class... Args>
    void construct(U* p, Args&&... args) {
        if constexpr (sizeof...(Args) == 0) {
            ::new (static_cast<void*>(p)) U;
        } else {
            ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
        }
    }

    friend bool operator==(const PointAllocator&, const PointAllocator&) noexcept { return true; }
};

template <class T>
using PointArray = std::vector<T, PointAllocator<T>>;

// A loaded point set in the precision of its file: exactly one of floats
// (scalar kFloat32) and doubles (kFloat64) holds the points.
struct RTHDIST_IO_API PointCloud {
    Scalar scalar = Scalar::kFloat32;
    PointArray<glm::vec3> floats;
    PointArray<glm::dvec3> doubles;

    [[nodiscard]] size_t size() const;
    // A view of the points for hausdorff() / Engine::compute(); valid while
    // this cloud lives and is not modified.
    [[nodiscard]] PointView view() const;
};

struct LoadOptions {
    // LAS only: keep the points whose classification is one of these
    // (0..255; formats 0-5 store 0..31). Empty: every point. Other formats
    // have no classification and ignore it. A filter that keeps no point is
    // kBadInput naming the classes.
    std::vector<int> lasClasses;
    // Threads that parse one file: 0 (default) every hardware thread, 1 the
    // calling thread only. The points and the errors do not depend on it.
    unsigned threads = 0;
};

[[nodiscard]] RTHDIST_IO_API Result<PointCloud> loadPointCloud(const std::string& path,
                                                               const LoadOptions& options = {});

// A loaded triangle mesh (loadMesh): its vertices in the file's precision
// (as loadPointCloud reads them) and three vertex indices per triangle.
struct RTHDIST_IO_API TriangleMesh {
    PointCloud vertices;
    std::vector<uint32_t> indices;  // 3 per triangle, each below vertices.size()

    [[nodiscard]] size_t triangleCount() const { return indices.size() / 3; }
    // A view for hausdorffToSurface (rthdist/surface.hpp); valid while this
    // mesh lives and is not modified.
    [[nodiscard]] MeshView view() const;
};

// The faces of a mesh file with its vertices (the formats with faces):
//   .obj  "f" lines (v, v/vt, v//vn, v/vt/vn; 1-based, negative = relative
//         to the vertices defined so far); other lines ignored.
//   .ply  the element "face" with a list property "vertex_indices" (or
//         "vertex_index") of any integer type; ascii and binary.
//   .off  the face block after the vertices ("n i0 .. in-1", colours after
//         the indices ignored).
//   .stl  every facet is a triangle (its three vertices, unshared).
//   .gltf / .glb  every primitive of mode TRIANGLES, TRIANGLE_STRIP or
//         TRIANGLE_FAN with its indices accessor (or the vertices in order),
//         node transforms applied as for points; POINTS and LINES primitives
//         give vertices but no triangles.
// Polygons of n > 3 vertices are fan-triangulated (i0 i1 i2, i0 i2 i3, ...);
// degenerate triangles (repeated or collinear vertices) are kept. Errors
// (kBadInput, "<path>: <where>: <what>"): a vertex index out of range or
// not an integer, and a face of fewer than 3 vertices, each naming the face
// and its line or byte offset; a file with no triangle; a format without
// faces (xyz, txt, pcd, las). Vertices as loadPointCloud (finite; the same
// precision rules); more than 2^32 - 1 vertices is an error.
[[nodiscard]] RTHDIST_IO_API Result<TriangleMesh> loadMesh(const std::string& path,
                                                           const LoadOptions& options = {});

// The points rounded to float32 (earlier releases' loader).
[[nodiscard]] RTHDIST_IO_API Result<std::vector<glm::vec3>> loadPoints(const std::string& path);

// Writes a binary little-endian PLY with float x/y/z vertices only.
[[nodiscard]] RTHDIST_IO_API Result<bool> writePlyPoints(const std::string& path,
                                                         const std::vector<glm::vec3>& points);

}  // namespace rthdist::io
