#include "render/MeshExport.h"

#include <assimp/material.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Exporter.hpp>
#include <assimp/IOStream.hpp>
#include <assimp/IOSystem.hpp>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>
#include <system_error>
#include <vector>

#include "render/AtomicFile.h"
#include "render/ObjExport.h"

namespace rend::render {

namespace {

namespace fs = std::filesystem;

const char* assimpFormatId(MeshFormat format) {
    switch (format) {
        case MeshFormat::Ply:
            return "plyb";  // unused: see writePly
        case MeshFormat::Obj:
            return "obj";  // unused: see writeObj
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
    if (mesh.points.size() == n) {  // glTF's TEXCOORD_0: the rest UV
        const std::vector<Eigen::Vector2f> uv = restUv(mesh);
        out.mTextureCoords[0] = new aiVector3D[n];
        out.mNumUVComponents[0] = 2;
        for (std::size_t v = 0; v < n; ++v)
            out.mTextureCoords[0][v] = aiVector3D(uv[v].x(), uv[v].y(), 0);
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

// assimp's own file streams ignore fwrite's and fclose's results, so a full disk leaves a
// truncated file. The exporter writes into memory instead, one buffer per file it opens (the OBJ
// opens its .mtl too), and writeFileAtomic puts them on disk with every write checked.
class MemoryStream : public Assimp::IOStream {
public:
    explicit MemoryStream(std::string& bytes) : bytes_(bytes) {}
    size_t Read(void*, size_t, size_t) override { return 0; }
    size_t Write(const void* data, size_t size, size_t count) override {
        const std::size_t n = size * count;
        if (position_ + n > bytes_.size()) bytes_.resize(position_ + n);
        std::memcpy(bytes_.data() + position_, data, n);
        position_ += n;
        return count;
    }
    aiReturn Seek(size_t offset, aiOrigin origin) override {
        const std::size_t base = origin == aiOrigin_SET   ? 0
                                 : origin == aiOrigin_CUR ? position_
                                                          : bytes_.size();
        position_ = base + offset;  // past the end, as in a file: the gap reads as zeros
        if (position_ > bytes_.size()) bytes_.resize(position_);
        return aiReturn_SUCCESS;
    }
    size_t Tell() const override { return position_; }
    size_t FileSize() const override { return bytes_.size(); }
    void Flush() override {}

private:
    std::string& bytes_;
    std::size_t position_ = 0;
};

/// Files by the name the exporter opened them with, in the order it opened them.
using MemoryFiles = std::vector<std::pair<std::string, std::string>>;

class MemoryIoSystem : public Assimp::IOSystem {
public:
    explicit MemoryIoSystem(MemoryFiles& files) : files_(files) { files_.reserve(8); }
    bool Exists(const char* name) const override {
        return std::any_of(files_.begin(), files_.end(),
                           [&](const auto& file) { return file.first == name; });
    }
    char getOsSeparator() const override { return '/'; }
    Assimp::IOStream* Open(const char* name, const char* mode) override {
        if (std::string_view(mode).find('r') != std::string_view::npos) return nullptr;
        // reserve() above keeps the references valid for the handful of files an export opens.
        if (files_.size() == files_.capacity()) return nullptr;
        files_.emplace_back(name, std::string());
        return new MemoryStream(files_.back().second);
    }
    void Close(Assimp::IOStream* stream) override { delete stream; }

private:
    MemoryFiles& files_;
};

// Writes every file the exporter produced next to `target`, the main file last: a reader who
// finds the OBJ then also finds its complete .mtl.
std::vector<fs::path> writeWithAssimp(const Mesh& mesh, const fs::path& path, MeshFormat format) {
    const std::unique_ptr<aiScene> scene = makeScene(mesh);
    MemoryFiles files;
    Assimp::Exporter exporter;
    exporter.SetIOHandler(new MemoryIoSystem(files));  // the exporter owns and deletes it
    if (exporter.Export(scene.get(), assimpFormatId(format), path.string()) != AI_SUCCESS)
        throw std::runtime_error(exporter.GetErrorString());
    std::stable_partition(files.begin(), files.end(),
                          [&](const auto& file) { return fs::path(file.first) != path; });
    std::vector<fs::path> written;
    try {
        for (const auto& [name, bytes] : files) {
            const fs::path file = path.parent_path() / fs::path(name).filename();
            writeFileAtomic(file, bytes);
            written.push_back(file);
        }
    } catch (...) {
        std::error_code ignored;  // an .mtl without its .obj is no output
        for (const fs::path& file : written) fs::remove(file, ignored);
        throw;
    }
    return written;
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
    try {
        return writeWithAssimp(mesh, path, format);
    } catch (const std::system_error&) {
        throw;  // already names the file and the reason
    } catch (const std::exception& e) {
        throw std::runtime_error("cannot export " + path.string() + ": " + e.what());
    }
}

}  // namespace rend::render
