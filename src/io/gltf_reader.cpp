// glTF 2.0 (Khronos, "glTF 2.0 Specification", 2021) through tinygltf; the
// accessor reads and the node walk are ours, with every index and byte range
// checked, because tinygltf leaves those checks to the caller.
#define TINYGLTF_IMPLEMENTATION
#define TINYGLTF_NO_STB_IMAGE
#define TINYGLTF_NO_STB_IMAGE_WRITE
#define TINYGLTF_NO_EXTERNAL_IMAGE
#include <tiny_gltf.h>

#include "io/gltf_reader.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat4x4.hpp>

#include <cstdint>
#include <filesystem>
#include <limits>

#include "io/gltf_file_access.hpp"
#include "io/gltf_json_limits.hpp"
#include "io/gzip_inflate.hpp"
#include "io/io_error.hpp"
#include "io/number_parse.hpp"
#include "io/scalar_type.hpp"

namespace rthdist::io {
namespace {

// Images are irrelevant to point sets: accept them without decoding.
bool skipImage(tinygltf::Image*, const int, std::string*, std::string*, int, int, const unsigned char*, int,
               void*) {
    return true;
}

// tinygltf's FsCallbacks, all through GltfFileAccess (user data).
bool fileExists(const std::string& path, void* access) {
    return static_cast<GltfFileAccess*>(access)->exists(path);
}
std::string expandFilePath(const std::string& path, void*) { return path; }  // no "~", no $VAR
bool readWholeFile(std::vector<unsigned char>* out, std::string* err, const std::string& path, void* access) {
    std::string why;
    const bool ok = static_cast<GltfFileAccess*>(access)->read(*out, why, path);
    if (!ok && err != nullptr) *err = why;
    return ok;
}
bool refuseWrite(std::string* err, const std::string&, const std::vector<unsigned char>&, void*) {
    if (err != nullptr) *err = "writing is not supported";
    return false;
}

std::string trimmed(std::string s) {
    while (!s.empty() && (s.back() == '\n' || s.back() == ' ')) s.pop_back();
    for (char& c : s) {
        if (c == '\n') c = ';';
    }
    return s;
}

glm::dmat4 localTransform(const tinygltf::Node& node) {
    if (node.matrix.size() == 16) return glm::make_mat4(node.matrix.data());  // column-major, as glTF
    glm::dmat4 m(1.0);
    if (node.translation.size() == 3) {
        m = glm::translate(m, glm::dvec3(node.translation[0], node.translation[1], node.translation[2]));
    }
    if (node.rotation.size() == 4) {  // glTF stores x, y, z, w
        m *= glm::mat4_cast(
            glm::dquat(node.rotation[3], node.rotation[0], node.rotation[1], node.rotation[2]));
    }
    if (node.scale.size() == 3) m = glm::scale(m, glm::dvec3(node.scale[0], node.scale[1], node.scale[2]));
    return m;
}

std::optional<ScalarType> componentScalar(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return ScalarType::kInt8;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return ScalarType::kUInt8;
        case TINYGLTF_COMPONENT_TYPE_SHORT: return ScalarType::kInt16;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return ScalarType::kUInt16;
        case TINYGLTF_COMPONENT_TYPE_INT: return ScalarType::kInt32;
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return ScalarType::kUInt32;
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return ScalarType::kFloat32;
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return ScalarType::kFloat64;
        default: return std::nullopt;
    }
}

// The name glTF gives a componentType (tinygltf's DOUBLE and INT included).
const char* componentName(int componentType) {
    switch (componentType) {
        case TINYGLTF_COMPONENT_TYPE_BYTE: return "BYTE";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE: return "UNSIGNED_BYTE";
        case TINYGLTF_COMPONENT_TYPE_SHORT: return "SHORT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT: return "UNSIGNED_SHORT";
        case TINYGLTF_COMPONENT_TYPE_INT: return "INT";
        case TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT: return "UNSIGNED_INT";
        case TINYGLTF_COMPONENT_TYPE_FLOAT: return "FLOAT";
        case TINYGLTF_COMPONENT_TYPE_DOUBLE: return "DOUBLE";
        default: return "unknown";
    }
}

// The component types glTF 2.0 allows for POSITION (its table of mesh
// attributes: FLOAT; with KHR_mesh_quantization also bytes and shorts,
// signed or unsigned, normalized or not). UNSIGNED_INT was read and rounded to float
// (16777217 -> 16777216); INT and DOUBLE are no glTF 2.0 types at all.
bool positionComponentAllowed(int componentType) {
    return componentType == TINYGLTF_COMPONENT_TYPE_FLOAT || componentType == TINYGLTF_COMPONENT_TYPE_BYTE ||
           componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_BYTE ||
           componentType == TINYGLTF_COMPONENT_TYPE_SHORT ||
           componentType == TINYGLTF_COMPONENT_TYPE_UNSIGNED_SHORT;
}

// Normalized integer components map to [-1, 1] or [0, 1] (glTF 3.11).
double normalize(double v, ScalarType t) {
    switch (t) {
        case ScalarType::kInt8: return std::max(v / 127.0, -1.0);
        case ScalarType::kUInt8: return v / 255.0;
        case ScalarType::kInt16: return std::max(v / 32767.0, -1.0);
        case ScalarType::kUInt16: return v / 65535.0;
        default: return v;
    }
}

// Walks the node hierarchy twice: first counting the points every instance
// adds (so the total is checked against kMaxGltfInstancedPoints and reserved
// once, before anything is read), then reading them with the transforms.
class PointCollector {
public:
    PointCollector(const tinygltf::Model& model, const std::string& path) : m_model(model), m_path(path) {}

    // Pass 1: every accessor checked, the instanced points counted.
    std::optional<Error> count(const std::vector<int>& roots) {
        uint64_t total = 0;
        return walk(roots,
                    [&](const tinygltf::Primitive&, int accessor, const glm::dmat4&,
                        const std::string& where) -> std::optional<Error> {
                        auto view = checkedAccessor(accessor);
                        if (!view) return view.error();
                        total += view->count;
                        if (total > kMaxGltfInstancedPoints) {
                            return badInput(m_path, where,
                                            "the scene instances more than " +
                                                std::to_string(kMaxGltfInstancedPoints) +
                                                " points (limit of this loader)");
                        }
                        m_total = total;
                        return std::nullopt;
                    });
    }

    // Pass 2: the points, transformed.
    std::optional<Error> read(const std::vector<int>& roots) {
        m_points.reserve(static_cast<size_t>(m_total));
        return walk(roots,
                    [&](const tinygltf::Primitive& prim, int accessor, const glm::dmat4& world,
                        const std::string& where) -> std::optional<Error> {
                        auto view = checkedAccessor(accessor);
                        if (!view) return view.error();
                        if (m_faces) {
                            if (auto err = addTriangles(prim, view->count, where)) return err;
                        }
                        for (size_t k = 0; k < view->count; ++k) {
                            const char* p = view->base + k * view->stride;
                            glm::dvec4 v(0.0, 0.0, 0.0, 1.0);
                            for (int c = 0; c < 3; ++c) {
                                const double raw =
                                    loadScalar(p + c * scalarSize(view->scalar), view->scalar, false);
                                v[c] = view->normalized ? normalize(raw, view->scalar) : raw;
                            }
                            const glm::dvec4 w = world * v;
                            m_points.emplace_back(narrowToFloat(w.x), narrowToFloat(w.y), narrowToFloat(w.z));
                        }
                        return std::nullopt;
                    });
    }

    PointArray<glm::vec3> take() { return std::move(m_points); }

    // With read(): also the triangles of every TRIANGLES, TRIANGLE_STRIP and
    // TRIANGLE_FAN primitive, by index into the points read.
    void collectTriangles() { m_faces = true; }
    std::vector<uint32_t> takeTriangles() { return std::move(m_triangles); }

private:
    struct AccessorView {
        const char* base = nullptr;
        uint64_t stride = 0;
        size_t count = 0;
        ScalarType scalar = ScalarType::kFloat32;
        bool normalized = false;
    };

    // Depth-first, parents before children, without recursion (a long chain
    // of nodes must not exhaust the stack); visit(accessor, world, where) for
    // every POSITION of every primitive of every mesh instance. At most
    // kMaxGltfNodeVisits node instances (a root listed by several scenes is
    // walked once per scene).
    template <class Visit>
    std::optional<Error> walk(const std::vector<int>& roots, Visit&& visit) {
        struct Pending {
            int node;
            glm::dmat4 parent;
        };
        uint64_t visited = 0;
        for (int root : roots) {
            std::vector<Pending> stack{{root, glm::dmat4(1.0)}};
            size_t visitedHere = 0;
            while (!stack.empty()) {
                const Pending top = stack.back();
                stack.pop_back();
                const std::string where = "node " + std::to_string(top.node);
                if (top.node < 0 || static_cast<size_t>(top.node) >= m_model.nodes.size()) {
                    return badInput(m_path, where, "index out of range");
                }
                if (++visitedHere > m_model.nodes.size())
                    return badInput(m_path, where, "cycle in the node hierarchy");
                if (++visited > kMaxGltfNodeVisits) {
                    return badInput(m_path, where,
                                    "the scenes instance more than " + std::to_string(kMaxGltfNodeVisits) +
                                        " nodes (limit of this loader)");
                }
                const tinygltf::Node& n = m_model.nodes[static_cast<size_t>(top.node)];
                const glm::dmat4 world = top.parent * localTransform(n);
                if (n.mesh >= 0) {
                    if (static_cast<size_t>(n.mesh) >= m_model.meshes.size()) {
                        return badInput(m_path, where, "mesh index out of range");
                    }
                    for (const tinygltf::Primitive& prim :
                         m_model.meshes[static_cast<size_t>(n.mesh)].primitives) {
                        const auto it = prim.attributes.find("POSITION");
                        if (it == prim.attributes.end()) continue;
                        if (auto err = visit(prim, it->second, world, where)) return err;
                    }
                }
                for (auto child = n.children.rbegin(); child != n.children.rend(); ++child) {
                    stack.push_back({*child, world});
                }
            }
        }
        return std::nullopt;
    }

    // The primitive's vertex numbers in drawing order: its indices accessor
    // (SCALAR, unsigned byte, short or int; every value below `count`), or
    // 0 .. count - 1.
    Result<std::vector<uint32_t>> drawOrder(const tinygltf::Primitive& prim, size_t count,
                                            const std::string& where) const {
        std::vector<uint32_t> order;
        if (prim.indices < 0) {
            order.resize(count);
            for (size_t k = 0; k < count; ++k) order[k] = uint32_t(k);
            return order;
        }
        auto view = checkedAccessor(prim.indices, TINYGLTF_TYPE_SCALAR, "indices");
        if (!view) return view.error();
        if (view->scalar != ScalarType::kUInt8 && view->scalar != ScalarType::kUInt16 &&
            view->scalar != ScalarType::kUInt32) {
            return badInput(m_path, "accessor " + std::to_string(prim.indices),
                            "indices are not unsigned byte, short or int");
        }
        order.resize(view->count);
        for (size_t k = 0; k < view->count; ++k) {
            const double v = loadScalar(view->base + k * view->stride, view->scalar, false);
            if (v >= double(count)) {
                return badInput(m_path, where + ", accessor " + std::to_string(prim.indices),
                                "face vertex " + std::to_string(k) + ": vertex index " +
                                    std::to_string(uint64_t(v)) + " out of range (" + std::to_string(count) +
                                    " vertices)");
            }
            order[k] = uint32_t(v);
        }
        return order;
    }

    std::optional<Error> addTriangles(const tinygltf::Primitive& prim, size_t count,
                                      const std::string& where) {
        const int mode = prim.mode < 0 ? TINYGLTF_MODE_TRIANGLES : prim.mode;
        if (mode != TINYGLTF_MODE_TRIANGLES && mode != TINYGLTF_MODE_TRIANGLE_STRIP &&
            mode != TINYGLTF_MODE_TRIANGLE_FAN) {
            return std::nullopt;  // points and lines: vertices only
        }
        auto order = drawOrder(prim, count, where);
        if (!order) return order.error();
        const auto base = uint32_t(m_points.size());
        const std::vector<uint32_t>& o = *order;
        if (m_triangles.size() / 3 + o.size() > kMaxGltfInstancedTriangles) {
            return badInput(m_path, where,
                            "the scene instances more than " + std::to_string(kMaxGltfInstancedTriangles) +
                                " triangles (limit of this loader)");
        }
        auto add = [&](size_t i, size_t j, size_t k) {
            m_triangles.insert(m_triangles.end(), {base + o[i], base + o[j], base + o[k]});
        };
        if (mode == TINYGLTF_MODE_TRIANGLES) {
            for (size_t t = 0; t + 2 < o.size(); t += 3) add(t, t + 1, t + 2);
        } else if (mode == TINYGLTF_MODE_TRIANGLE_STRIP) {
            for (size_t t = 0; t + 2 < o.size(); ++t)
                t % 2 == 0 ? add(t, t + 1, t + 2) : add(t + 1, t, t + 2);
        } else {
            for (size_t t = 1; t + 1 < o.size(); ++t) add(0, t, t + 1);
        }
        return std::nullopt;
    }

    // The accessor's elements, every index and byte range checked.
    Result<AccessorView> checkedAccessor(int index, int type = TINYGLTF_TYPE_VEC3,
                                         const char* what = "POSITION") const {
        const std::string where = "accessor " + std::to_string(index);
        if (index < 0 || static_cast<size_t>(index) >= m_model.accessors.size()) {
            return badInput(m_path, where, "index out of range");
        }
        const tinygltf::Accessor& acc = m_model.accessors[static_cast<size_t>(index)];
        if (acc.sparse.isSparse)
            return badInput(m_path, where, std::string("sparse ") + what + " accessors are not supported");
        if (acc.type != type)
            return badInput(
                m_path, where,
                std::string(what) + (type == TINYGLTF_TYPE_VEC3 ? " is not VEC3" : " is not SCALAR"));
        const auto scalar = componentScalar(acc.componentType);
        if (!scalar)
            return badInput(m_path, where, "unknown componentType " + std::to_string(acc.componentType));
        if (type == TINYGLTF_TYPE_VEC3 && !positionComponentAllowed(acc.componentType)) {
            return badInput(m_path, where,
                            std::string(what) + " componentType " + std::to_string(acc.componentType) + " (" +
                                componentName(acc.componentType) +
                                ") is not one glTF 2.0 allows (FLOAT; BYTE, UNSIGNED_BYTE, SHORT or "
                                "UNSIGNED_SHORT with KHR_mesh_quantization)");
        }
        if (acc.count == 0) return AccessorView{};
        if (acc.bufferView < 0 || static_cast<size_t>(acc.bufferView) >= m_model.bufferViews.size()) {
            return badInput(m_path, where, "bufferView missing or out of range");
        }
        const tinygltf::BufferView& view = m_model.bufferViews[static_cast<size_t>(acc.bufferView)];
        if (view.buffer < 0 || static_cast<size_t>(view.buffer) >= m_model.buffers.size()) {
            return badInput(m_path, "bufferView " + std::to_string(acc.bufferView),
                            "buffer index out of range");
        }
        const std::vector<unsigned char>& data = m_model.buffers[static_cast<size_t>(view.buffer)].data;
        if (view.byteOffset > data.size() || view.byteLength > data.size() - view.byteOffset) {
            return badInput(m_path, "bufferView " + std::to_string(acc.bufferView),
                            "byte range exceeds its buffer of " + std::to_string(data.size()) + " bytes");
        }
        const uint64_t elementSize = (type == TINYGLTF_TYPE_VEC3 ? 3 : 1) * scalarSize(*scalar);
        const uint64_t stride = view.byteStride != 0 ? view.byteStride : elementSize;
        if (stride < elementSize) return badInput(m_path, where, "byteStride smaller than an element");
        // All of count * stride must lie inside the view: checked before allocating.
        const uint64_t viewLength = view.byteLength;
        if (acc.byteOffset > viewLength || viewLength - acc.byteOffset < elementSize ||
            acc.count - 1 > (viewLength - acc.byteOffset - elementSize) / stride) {
            return badInput(m_path, where,
                            std::to_string(acc.count) + " elements do not fit bufferView " +
                                std::to_string(acc.bufferView) + " (" + std::to_string(viewLength) +
                                " bytes)");
        }
        return AccessorView{reinterpret_cast<const char*>(data.data()) + view.byteOffset + acc.byteOffset,
                            stride, acc.count, *scalar, acc.normalized};
    }

    const tinygltf::Model& m_model;
    const std::string& m_path;
    uint64_t m_total = 0;
    PointArray<glm::vec3> m_points;
    bool m_faces = false;
    std::vector<uint32_t> m_triangles;
};

// The scene's root nodes: the default scene's, else every scene's, else (no
// scenes at all) every node that is nobody's child.
Result<std::vector<int>> rootNodes(const tinygltf::Model& model, const std::string& path) {
    std::vector<int> parents(model.nodes.size(), 0);
    for (size_t i = 0; i < model.nodes.size(); ++i) {
        for (int child : model.nodes[i].children) {
            if (child < 0 || static_cast<size_t>(child) >= model.nodes.size()) {
                return badInput(path, "node " + std::to_string(i),
                                "child index " + std::to_string(child) + " out of range");
            }
            if (++parents[static_cast<size_t>(child)] > 1) {
                return badInput(path, "node " + std::to_string(child), "has more than one parent");
            }
        }
    }
    std::vector<int> roots;
    std::vector<size_t> listed(model.nodes.size(), 0);  // 1 + the last scene that listed the node
    auto addScene = [&](size_t s) -> std::optional<Error> {
        for (int n : model.scenes[s].nodes) {
            if (n < 0 || static_cast<size_t>(n) >= model.nodes.size()) {
                return badInput(path, "scene " + std::to_string(s),
                                "node index " + std::to_string(n) + " out of range");
            }
            if (parents[static_cast<size_t>(n)] != 0) {
                return badInput(path, "scene " + std::to_string(s),
                                "node " + std::to_string(n) + " is not a root node");
            }
            if (listed[static_cast<size_t>(n)] == s + 1) {
                return badInput(path, "scene " + std::to_string(s),
                                "node " + std::to_string(n) + " is listed twice");
            }
            listed[static_cast<size_t>(n)] = s + 1;
            roots.push_back(n);
        }
        return std::nullopt;
    };
    // tinygltf leaves -1 where "scene" is absent; any other index must name a
    // scene ("scene": 5 of one scene was read as no default scene).
    if (model.defaultScene < -1 ||
        (model.defaultScene >= 0 && static_cast<size_t>(model.defaultScene) >= model.scenes.size())) {
        return badInput(path, "glTF",
                        "default scene " + std::to_string(model.defaultScene) + " out of range (" +
                            std::to_string(model.scenes.size()) + " scene(s))");
    }
    if (model.defaultScene >= 0) {
        if (auto err = addScene(static_cast<size_t>(model.defaultScene))) return *err;
    } else if (!model.scenes.empty()) {
        for (size_t s = 0; s < model.scenes.size(); ++s) {
            if (auto err = addScene(s)) return *err;
        }
    } else {
        for (size_t i = 0; i < model.nodes.size(); ++i) {
            if (parents[i] == 0) roots.push_back(static_cast<int>(i));
        }
    }
    return roots;
}

// The JSON text of a .gltf, or the JSON chunk of a .glb (the container's
// own checks are tinygltf's), and its offset in the file.
std::pair<std::string_view, size_t> jsonText(std::string_view bytes, bool binary) {
    if (!binary) return {bytes, 0};
    if (bytes.size() < 20) return {{}, 0};
    const uint64_t length = static_cast<uint64_t>(loadScalar(bytes.data() + 12, ScalarType::kUInt32, false));
    return {bytes.substr(20, static_cast<size_t>(std::min<uint64_t>(length, bytes.size() - 20))), 20};
}

}  // namespace

namespace {

Result<tinygltf::Model> loadModel(std::string_view bytes, const std::string& path) {
    if (bytes.size() > std::numeric_limits<unsigned int>::max()) {
        return badInput(path, "file", "larger than 4 GiB, beyond what tinygltf reads");
    }
    const bool binary = bytes.size() >= 4 && bytes.substr(0, 4) == "glTF";
    const auto [json, jsonOffset] = jsonText(bytes, binary);
    if (auto err = checkGltfJsonLimits(json, jsonOffset, path)) return *err;

    GltfFileAccess files(path);
    tinygltf::Model model;
    std::string err;
    std::string warn;
    bool ok = false;
    try {
        tinygltf::TinyGLTF loader;
        loader.SetImageLoader(&skipImage, nullptr);
        loader.SetFsCallbacks(
            tinygltf::FsCallbacks{&fileExists, &expandFilePath, &readWholeFile, &refuseWrite, &files});
        if (binary) {
            ok = loader.LoadBinaryFromMemory(&model, &err, &warn,
                                             reinterpret_cast<const unsigned char*>(bytes.data()),
                                             static_cast<unsigned int>(bytes.size()), files.baseDir());
        } else {
            ok = loader.LoadASCIIFromString(&model, &err, &warn, bytes.data(),
                                            static_cast<unsigned int>(bytes.size()), files.baseDir());
        }
    } catch (const std::exception& e) {
        return badInput(path, "glTF", std::string("malformed: ") + e.what());
    }
    if (!ok && !files.refusal().empty()) return badInput(path, "glTF", "buffer " + files.refusal());
    if (!ok)
        return badInput(path, "glTF",
                        "malformed: " + (err.empty() ? std::string("tinygltf failed") : trimmed(err)));

    return model;
}

}  // namespace

Result<PointArray<glm::vec3>> readGltf(std::string_view bytes, const std::string& path) {
    Result<tinygltf::Model> model = loadModel(bytes, path);
    if (!model) return model.error();
    auto roots = rootNodes(*model, path);
    if (!roots) return roots.error();
    PointCollector collector(*model, path);
    if (auto e = collector.count(*roots)) return *e;
    if (auto e = collector.read(*roots)) return *e;
    return collector.take();
}

Result<GltfMesh> readGltfMesh(std::string_view bytes, const std::string& path) {
    Result<tinygltf::Model> model = loadModel(bytes, path);
    if (!model) return model.error();
    auto roots = rootNodes(*model, path);
    if (!roots) return roots.error();
    PointCollector collector(*model, path);
    collector.collectTriangles();
    if (auto e = collector.count(*roots)) return *e;
    if (auto e = collector.read(*roots)) return *e;
    return GltfMesh{collector.take(), collector.takeTriangles()};
}

Result<uint64_t> glbInflatedBound(std::string_view head, bool whole, const std::string& path) {
    (void)whole;
    (void)path;
    if (head.size() < 12 || head.substr(0, 4) != "glTF") return kNoInflatedBound;  // .gltf JSON
    return static_cast<uint64_t>(loadScalar(head.data() + 8, ScalarType::kUInt32, false));
}

}  // namespace rthdist::io
