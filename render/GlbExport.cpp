#include "render/GlbExport.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "render/AtomicFile.h"
#include "render/MeshExport.h"

namespace rend::render {
namespace {

constexpr int kFloat = 5126, kUnsignedInt = 5125;                 // accessor componentType
constexpr int kVertexTarget = 34962, kIndexTarget = 34963;        // bufferView target
constexpr std::uint32_t kMagic = 0x46546C67, kJson = 0x4E4F534A;  // "glTF", "JSON"
constexpr std::uint32_t kBin = 0x004E4942;                        // "BIN\0"

/// The binary chunk and the JSON of its views and accessors, one view per accessor.
class Buffers {
public:
    /// Appends `count` elements of `width` floats (or uint32 indices) and returns the accessor.
    template <class T>
    int add(const std::vector<T>& values, int width, bool indices = false) {
        const std::size_t bytes = values.size() * sizeof(T);
        const std::size_t offset = bin_.size();
        bin_.resize(offset + (bytes + 3) / 4 * 4, '\0');  // 4-byte aligned
        if (bytes) std::memcpy(bin_.data() + offset, values.data(), bytes);
        const std::size_t count = values.size() / std::size_t(width);
        const int index = int(views_.size());
        views_.push_back(R"({"buffer":0,"byteOffset":)" + std::to_string(offset) +
                         R"(,"byteLength":)" + std::to_string(bytes) + R"(,"target":)" +
                         std::to_string(indices ? kIndexTarget : kVertexTarget) + "}");
        std::string accessor = R"({"bufferView":)" + std::to_string(index) +
                               R"(,"componentType":)" +
                               std::to_string(indices ? kUnsignedInt : kFloat) + R"(,"count":)" +
                               std::to_string(count) + R"(,"type":")" + typeName(width) + "\"";
        accessors_.push_back(accessor);
        return index;
    }
    /// Adds glTF's required min and max to the last accessor (POSITION needs them).
    void addBounds(const std::vector<float>& xyz) {
        std::array<float, 3> low, high;
        low.fill(std::numeric_limits<float>::max());
        high.fill(std::numeric_limits<float>::lowest());
        for (std::size_t k = 0; k < xyz.size(); ++k) {
            low[k % 3] = std::min(low[k % 3], xyz[k]);
            high[k % 3] = std::max(high[k % 3], xyz[k]);
        }
        accessors_.back() += R"(,"min":)" + list(low) + R"(,"max":)" + list(high);
    }
    std::string json() const {
        return R"("buffers":[{"byteLength":)" + std::to_string(bin_.size()) +
               R"(}],"bufferViews":[)" + join(views_) + R"(],"accessors":[)" +
               join(accessors_, "}") + "]";
    }
    const std::string& bin() const { return bin_; }

private:
    static const char* typeName(int width) {
        return width == 1 ? "SCALAR" : width == 2 ? "VEC2" : "VEC3";
    }
    static std::string list(const std::array<float, 3>& v) {
        std::string out = "[";
        for (std::size_t k = 0; k < 3; ++k) {
            if (k) out += ',';
            out += std::to_string(v[k]);
        }
        return out + "]";
    }
    static std::string join(const std::vector<std::string>& items, const char* close = "") {
        std::string out;
        for (const std::string& item : items) {
            if (!out.empty()) out += ',';
            out += item;
            out += close;
        }
        return out;
    }
    std::string bin_;
    std::vector<std::string> views_, accessors_;
};

template <class Get>
std::vector<float> perVertex(std::size_t n, int width, Get get) {
    std::vector<float> out;
    out.reserve(n * std::size_t(width));
    for (std::size_t v = 0; v < n; ++v) get(v, out);
    return out;
}

void push(std::vector<float>& out, const Eigen::Vector3f& p) {
    out.insert(out.end(), {p.x(), p.y(), p.z()});
}

/// A position or direction, in glTF's y-up frame.
void pushYUp(std::vector<float>& out, const Eigen::Vector3f& p) { push(out, toYUp(p)); }

/// The primitive's "attributes" object, each attribute's accessor added to `buffers`.
std::string attributes(const Mesh& mesh, Buffers& buffers) {
    const std::size_t n = mesh.positions.size();
    const std::vector<float> xyz =
        perVertex(n, 3, [&](std::size_t v, auto& out) { pushYUp(out, mesh.positions[v]); });
    std::string a = R"("POSITION":)" + std::to_string(buffers.add(xyz, 3));
    buffers.addBounds(xyz);
    const auto vec3 = [&](const char* name, auto get, bool direction = true) {
        a += ",\"" + std::string(name) + "\":" +
             std::to_string(buffers.add(perVertex(n, 3,
                                                  [&](std::size_t v, auto& out) {
                                                      direction ? pushYUp(out, get(v))
                                                                : push(out, get(v));
                                                  }),
                                        3));
    };
    const auto scalar = [&](const char* name, auto get) {
        a += ",\"" + std::string(name) + "\":" +
             std::to_string(buffers.add(
                 perVertex(n, 1, [&](std::size_t v, auto& out) { out.push_back(get(v)); }), 1));
    };
    if (mesh.normals.size() == n) vec3("NORMAL", [&](std::size_t v) { return mesh.normals[v]; });
    if (mesh.colors.size() == n)
        vec3(
            "COLOR_0", [&](std::size_t v) { return mesh.colors[v]; }, /*direction=*/false);
    if (mesh.points.size() == n) {
        const std::vector<Eigen::Vector2f> uv = restUv(mesh);
        a += R"(,"TEXCOORD_0":)" +
             std::to_string(
                 buffers.add(perVertex(n, 2,
                                       [&](std::size_t v, auto& out) {
                                           out.insert(out.end(), {uv[v].x(), 1.0f - uv[v].y()});
                                       }),
                             2));
        scalar("_ID", [&](std::size_t v) { return float(mesh.points[v].id); });
        vec3("_VELOCITY", [&](std::size_t v) { return mesh.points[v].velocity; });
        scalar("_DAMAGE", [&](std::size_t v) { return mesh.points[v].damage; });
        vec3("_REST", [&](std::size_t v) { return mesh.points[v].rest; });
    }
    if (mesh.theta.size() == n) scalar("_THETA", [&](std::size_t v) { return mesh.theta[v]; });
    return a;
}

void appendChunk(std::string& out, std::uint32_t type, const std::string& data) {
    const std::uint32_t header[2] = {std::uint32_t(data.size()), type};
    out.append(reinterpret_cast<const char*>(header), sizeof header);
    out += data;
}

}  // namespace

std::string glbBytes(const Mesh& mesh) {
    Buffers buffers;
    std::string meshes;
    if (!mesh.positions.empty() && !mesh.triangles.empty()) {  // glTF: no empty accessor
        const std::string a = attributes(mesh, buffers);
        std::vector<std::uint32_t> indices;
        indices.reserve(3 * mesh.triangles.size());
        for (const auto& t : mesh.triangles) indices.insert(indices.end(), t.begin(), t.end());
        meshes = R"(,"meshes":[{"name":"membrane","primitives":[{"attributes":{)" + a +
                 R"(},"indices":)" + std::to_string(buffers.add(indices, 1, true)) +
                 R"(,"material":0,"mode":4}]}])";
    }
    std::string json =
        R"({"asset":{"version":"2.0","generator":"rend"},"scene":0,"scenes":[{"nodes":[0]}],)"
        R"("nodes":[{"name":"membrane")" +
        std::string(meshes.empty() ? "" : R"(,"mesh":0)") +
        R"(}],"materials":[{"name":"membrane","pbrMetallicRoughness":{"baseColorFactor":)"
        R"([1,1,1,1],"metallicFactor":0,"roughnessFactor":0.5},"doubleSided":true}])" +
        meshes;
    if (!buffers.bin().empty()) json += ',' + buffers.json();
    json += '}';
    json.resize((json.size() + 3) / 4 * 4, ' ');  // the JSON chunk is padded with spaces
    std::string out;
    const std::uint32_t header[3] = {kMagic, 2, 0};
    out.append(reinterpret_cast<const char*>(header), sizeof header);
    appendChunk(out, kJson, json);
    if (!buffers.bin().empty()) appendChunk(out, kBin, buffers.bin());
    const std::uint32_t length = std::uint32_t(out.size());
    std::memcpy(out.data() + 8, &length, sizeof length);
    return out;
}

std::vector<std::filesystem::path> writeGlb(const Mesh& mesh, const std::filesystem::path& path) {
    writeFileAtomic(path, glbBytes(mesh));
    return {path};
}

}  // namespace rend::render
