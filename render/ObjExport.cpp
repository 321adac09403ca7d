#include "render/ObjExport.h"

#include <charconv>
#include <string>
#include <system_error>

#include "render/AtomicFile.h"
#include "render/MeshExport.h"

namespace rend::render {

namespace {

namespace fs = std::filesystem;

void appendNumber(std::string& out, float value) {
    char text[32];
    const auto end = std::to_chars(text, text + sizeof text, value).ptr;  // shortest round trip
    out += ' ';
    out.append(text, end);
}

void appendIndex(std::string& out, std::uint32_t index, bool uv, bool normals) {
    const std::string one = std::to_string(index + 1);  // OBJ counts from 1
    out += ' ';
    out += one;
    if (uv || normals) out += '/' + (uv ? one : std::string());
    if (normals) out += '/' + one;
}

std::string objText(const Mesh& mesh, const std::string& library) {
    const std::size_t n = mesh.positions.size();
    const bool normals = mesh.normals.size() == n, colors = mesh.colors.size() == n;
    const std::vector<Eigen::Vector2f> uv = restUv(mesh);
    std::string out =
        "# rend membrane surface: vertex i is the mesh's vertex i, the particles "
        "first, in order\nmtllib " +
        library + "\no membrane\n";
    out.reserve(out.size() + n * (colors ? 90 : 50) * (normals ? 2 : 1) +
                mesh.triangles.size() * 40);
    for (std::size_t v = 0; v < n; ++v) {
        out += 'v';
        const Eigen::Vector3f p = toYUp(mesh.positions[v]);
        for (int k = 0; k < 3; ++k) appendNumber(out, p[k]);
        if (colors)  // the common "v x y z r g b" extension, linear as in the mesh
            for (int k = 0; k < 3; ++k) appendNumber(out, mesh.colors[v][k]);
        out += '\n';
    }
    for (const Eigen::Vector2f& t : uv) {  // the rest UV, so textures stay on the sheet
        out += "vt";
        appendNumber(out, t.x()), appendNumber(out, t.y());
        out += '\n';
    }
    for (std::size_t v = 0; normals && v < n; ++v) {
        out += "vn";
        const Eigen::Vector3f normal = toYUp(mesh.normals[v]);
        for (int k = 0; k < 3; ++k) appendNumber(out, normal[k]);
        out += '\n';
    }
    out += "usemtl membrane\n";
    // Smoothing group 1: Blender's importer (3.4) leaves faces flat without it, and with them
    // flat it ignores the vn normals it keeps as custom normals.
    if (normals) out += "s 1\n";
    for (const auto& t : mesh.triangles) {
        out += 'f';
        for (const std::uint32_t i : t) appendIndex(out, i, !uv.empty(), normals);
        out += '\n';
    }
    return out;
}

}  // namespace

std::vector<fs::path> writeObj(const Mesh& mesh, const fs::path& path) {
    fs::path library = path;
    library.replace_extension(".mtl");
    // White, so that viewers which multiply vertex colours by the material show them unchanged.
    writeFileAtomic(library, "newmtl membrane\nKd 1 1 1\n");
    try {
        writeFileAtomic(path, objText(mesh, library.filename().string()));
    } catch (...) {
        std::error_code ignored;  // an .mtl without its .obj is no output
        fs::remove(library, ignored);
        throw;
    }
    return {library, path};
}

}  // namespace rend::render
