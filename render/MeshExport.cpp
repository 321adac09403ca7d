#include "render/MeshExport.h"

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "render/AtomicFile.h"
#include "render/GlbExport.h"
#include "render/ObjExport.h"

namespace rend::render {

namespace {

namespace fs = std::filesystem;

// ---- binary PLY, written here -------------------------------------------------------------
// assimp 5.2's "plyb" exporter (Debian 12) declares colours as uchar but writes four floats
// per vertex, so every file with vertex colours is corrupt (assimp issue #3827, fixed upstream
// only in 2024 by PR #5608). The format is simple enough to write directly.

// 8-bit PLY colours are display values (MeshLab, Blender and CloudCompare show them as sRGB),
// so the mesh's linear colours are encoded with the same 2.2 gamma that ColorMap.cpp decodes:
// a colour-mapped vertex gets back exactly its colour table's bytes.
std::uint8_t displayByte(float linear) {
    const float encoded = std::pow(std::clamp(linear, 0.0f, 1.0f), 1.0f / 2.2f);
    return static_cast<std::uint8_t>(std::lround(encoded * 255.0f));
}

std::string plyHeader(const Mesh& mesh, bool normals, bool colors) {
    std::string h = "ply\nformat ";
    h += std::endian::native == std::endian::little ? "binary_little_endian" : "binary_big_endian";
    h += " 1.0\ncomment rend membrane surface\n";
    h += "element vertex " + std::to_string(mesh.positions.size()) + "\n";
    h += "property float x\nproperty float y\nproperty float z\n";
    if (normals) h += "property float nx\nproperty float ny\nproperty float nz\n";
    if (colors) h += "property uchar red\nproperty uchar green\nproperty uchar blue\n";
    if (!mesh.points.empty()) {
        // s, t: the rest UV Blender reads; the rest as named values, with the particle id,
        // velocity (motion blur), damage and theta, which Houdini reads as point attributes.
        h += "property float s\nproperty float t\nproperty int id\n";
        h += "property float vx\nproperty float vy\nproperty float vz\nproperty float damage\n";
        h += "property float rest_x\nproperty float rest_y\nproperty float rest_z\n";
        if (!mesh.theta.empty()) h += "property float theta\n";
    }
    h += "element face " + std::to_string(mesh.triangles.size()) + "\n";
    h += "property list uchar uint vertex_indices\nend_header\n";
    return h;
}

template <typename T>
void append(std::vector<char>& out, const T& value) {
    const auto* bytes = reinterpret_cast<const char*>(&value);
    out.insert(out.end(), bytes, bytes + sizeof(T));
}

std::vector<char> plyBody(const Mesh& mesh, bool normals, bool colors) {
    std::vector<char> out;
    out.reserve(mesh.positions.size() * 75 + mesh.triangles.size() * 13);
    const std::vector<Eigen::Vector2f> uv = restUv(mesh);
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        for (int k = 0; k < 3; ++k) append(out, mesh.positions[v][k]);
        if (normals)
            for (int k = 0; k < 3; ++k) append(out, mesh.normals[v][k]);
        if (colors)
            for (int k = 0; k < 3; ++k) append(out, displayByte(mesh.colors[v][k]));
        if (mesh.points.empty()) continue;
        const Mesh::Point& p = mesh.points[v];
        append(out, uv[v].x()), append(out, uv[v].y()), append(out, p.id);
        for (int k = 0; k < 3; ++k) append(out, p.velocity[k]);
        append(out, p.damage);
        for (int k = 0; k < 3; ++k) append(out, p.rest[k]);
        if (!mesh.theta.empty()) append(out, mesh.theta[v]);
    }
    for (const auto& t : mesh.triangles) {
        append(out, std::uint8_t{3});
        for (std::uint32_t i : t) append(out, i);
    }
    return out;
}

void writePly(const Mesh& mesh, const fs::path& path) {
    const bool normals = mesh.normals.size() == mesh.positions.size();
    const bool colors = mesh.colors.size() == mesh.positions.size();
    const std::string header = plyHeader(mesh, normals, colors);
    const std::vector<char> body = plyBody(mesh, normals, colors);
    writeFileAtomic(path, header + std::string(body.begin(), body.end()));
}

}  // namespace

// Each vertex's rest position in [0, 1]^2 over the rest bounds of the sheet's vertices (its
// rest x and y): a UV map that stays put on the sheet from frame to frame.
std::vector<Eigen::Vector2f> restUv(const Mesh& mesh) {
    Eigen::Vector2f low = Eigen::Vector2f::Constant(std::numeric_limits<float>::max());
    Eigen::Vector2f high = -low;
    for (const Mesh::Point& p : mesh.points) {
        low = low.cwiseMin(p.rest.head<2>());
        high = high.cwiseMax(p.rest.head<2>());
    }
    const Eigen::Vector2f size = (high - low).cwiseMax(Eigen::Vector2f::Constant(1e-30f));
    std::vector<Eigen::Vector2f> uv;
    uv.reserve(mesh.points.size());
    for (const Mesh::Point& p : mesh.points)
        uv.push_back((p.rest.head<2>() - low).cwiseQuotient(size));
    return uv;
}

MeshFormat parseMeshFormat(std::string_view name) {
    std::string lower(name.substr(name.starts_with('.') ? 1 : 0));
    std::transform(lower.begin(), lower.end(), lower.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (lower == "ply") return MeshFormat::Ply;
    if (lower == "obj") return MeshFormat::Obj;
    if (lower == "glb") return MeshFormat::Glb;
    throw std::invalid_argument("unknown mesh format '" + std::string(name) +
                                "'; expected one of: ply, obj, glb");
}

std::string_view meshFormatExtension(MeshFormat format) {
    switch (format) {
        case MeshFormat::Ply:
            return ".ply";
        case MeshFormat::Obj:
            return ".obj";
        case MeshFormat::Glb:
            return ".glb";
    }
    return "";
}

std::vector<fs::path> exportMesh(const Mesh& mesh, const fs::path& path, MeshFormat format) {
    if (format == MeshFormat::Ply) {
        writePly(mesh, path);
        return {path};
    }
    if (format == MeshFormat::Obj) return writeObj(mesh, path);
    return writeGlb(mesh, path);
}

}  // namespace rend::render
