#include "render/MeshExport.h"

#include <assimp/material.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <fstream>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

namespace rend::render {

namespace {

namespace fs = std::filesystem;

const char* assimpFormatId(MeshFormat format) {
    switch (format) {
        case MeshFormat::Ply:
            return "plyb";  // unused: see writePly
        case MeshFormat::Obj:
            return "obj";
        case MeshFormat::Glb:
            return "glb2";
    }
    throw std::invalid_argument("unknown mesh format");
}

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
    out.reserve(mesh.positions.size() * 27 + mesh.triangles.size() * 13);
    for (std::size_t v = 0; v < mesh.positions.size(); ++v) {
        for (int k = 0; k < 3; ++k) append(out, mesh.positions[v][k]);
        if (normals)
            for (int k = 0; k < 3; ++k) append(out, mesh.normals[v][k]);
        if (colors)
            for (int k = 0; k < 3; ++k) append(out, displayByte(mesh.colors[v][k]));
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
    std::ofstream out(path, std::ios::binary);
    out.write(header.data(), std::streamsize(header.size()));
    out.write(body.data(), std::streamsize(body.size()));
    out.close();
    if (!out) throw std::runtime_error("write failed");
}

aiMaterial* defaultMaterial() {
    auto* material = new aiMaterial;
    const aiString name("membrane");
    material->AddProperty(&name, AI_MATKEY_NAME);
    // White, so that viewers which multiply vertex colours by the material show them unchanged.
    const aiColor3D white(1.0f, 1.0f, 1.0f);
    material->AddProperty(&white, 1, AI_MATKEY_COLOR_DIFFUSE);
    return material;
}

void fillVertices(const Mesh& mesh, aiMesh& out) {
    const std::size_t n = mesh.positions.size();
    out.mNumVertices = unsigned(n);
    out.mVertices = new aiVector3D[n];
    for (std::size_t v = 0; v < n; ++v) {
        const auto& p = mesh.positions[v];
        out.mVertices[v] = aiVector3D(p.x(), p.y(), p.z());
    }
    if (mesh.normals.size() == n) {
        out.mNormals = new aiVector3D[n];
        for (std::size_t v = 0; v < n; ++v) {
            const auto& m = mesh.normals[v];
            out.mNormals[v] = aiVector3D(m.x(), m.y(), m.z());
        }
    }
    if (mesh.colors.size() == n) {
        out.mColors[0] = new aiColor4D[n];
        for (std::size_t v = 0; v < n; ++v) {
            const auto& c = mesh.colors[v];
            out.mColors[0][v] = aiColor4D(c.x(), c.y(), c.z(), 1.0f);
        }
    }
}

void fillFaces(const Mesh& mesh, aiMesh& out) {
    out.mPrimitiveTypes = aiPrimitiveType_TRIANGLE;
    out.mNumFaces = unsigned(mesh.triangles.size());
    out.mFaces = new aiFace[mesh.triangles.size()];
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
        aiFace& face = out.mFaces[t];
        face.mNumIndices = 3;
        face.mIndices = new unsigned[3];
        std::copy(mesh.triangles[t].begin(), mesh.triangles[t].end(), face.mIndices);
    }
}

// One mesh, one material, one root node referencing the mesh. aiScene's destructor frees all
// of it, so everything is allocated with new as assimp expects.
std::unique_ptr<aiScene> makeScene(const Mesh& mesh) {
    auto scene = std::make_unique<aiScene>();
    scene->mNumMaterials = 1;
    scene->mMaterials = new aiMaterial* [1] { defaultMaterial() };
    auto* out = new aiMesh;
    out->mName = aiString("membrane");
    out->mMaterialIndex = 0;
    scene->mNumMeshes = 1;
    scene->mMeshes = new aiMesh* [1] { out };
    fillVertices(mesh, *out);
    fillFaces(mesh, *out);
    scene->mRootNode = new aiNode("root");
    scene->mRootNode->mNumMeshes = 1;
    scene->mRootNode->mMeshes = new unsigned[1]{0};
    return scene;
}

void writeWithAssimp(const Mesh& mesh, const fs::path& path, MeshFormat format) {
    const std::unique_ptr<aiScene> scene = makeScene(mesh);
    Assimp::Exporter exporter;
    if (exporter.Export(scene.get(), assimpFormatId(format), path.string()) != AI_SUCCESS)
        throw std::runtime_error(exporter.GetErrorString());
}

// Moves every file the writer put into `staging` next to `target`, the main file last: a reader
// who finds the OBJ then also finds its complete .mtl.
void publish(const fs::path& staging, const fs::path& target) {
    const fs::path main = staging / target.filename();
    std::vector<fs::path> written;
    for (const auto& entry : fs::directory_iterator(staging))
        if (entry.path() != main) written.push_back(entry.path());
    for (const auto& file : written) fs::rename(file, target.parent_path() / file.filename());
    fs::rename(main, target);
}

}  // namespace

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

void exportMesh(const Mesh& mesh, const std::filesystem::path& path, MeshFormat format) {
    fs::path staging = path;
    staging += ".tmp";
    std::error_code ignored;
    fs::remove_all(staging, ignored);  // left over from a crashed run
    try {
        fs::create_directories(staging);
        const fs::path staged = staging / path.filename();
        if (format == MeshFormat::Ply)
            writePly(mesh, staged);
        else
            writeWithAssimp(mesh, staged, format);
        publish(staging, path);
        fs::remove_all(staging);
    } catch (const std::exception& e) {
        fs::remove_all(staging, ignored);
        throw std::runtime_error("cannot export " + path.string() + ": " + e.what());
    }
}

}  // namespace rend::render
