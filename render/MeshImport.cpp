#include "render/MeshImport.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <array>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

namespace rend::render {

namespace {

constexpr const char* kExpected = "expected a triangle mesh in OBJ, PLY, glTF or GLB";

std::runtime_error importError(const std::filesystem::path& file, const std::string& what) {
    return std::runtime_error("mesh " + file.string() + ": " + what + "; " + kExpected);
}

/// Joins the scene's meshes into one, merging vertices at bitwise equal positions.
class MeshBuilder {
public:
    explicit MeshBuilder(double scale) : scale_(scale) {}

    void addNode(const aiScene& scene, const aiNode& node, const aiMatrix4x4& parent) {
        const aiMatrix4x4 transform = parent * node.mTransformation;
        for (unsigned m = 0; m < node.mNumMeshes; ++m)
            addMesh(*scene.mMeshes[node.mMeshes[m]], transform);
        for (unsigned c = 0; c < node.mNumChildren; ++c)
            addNode(scene, *node.mChildren[c], transform);
    }

    sim::TriangleMesh take() { return std::move(mesh_); }

private:
    void addMesh(const aiMesh& mesh, const aiMatrix4x4& transform) {
        std::vector<int> index(mesh.mNumVertices);
        for (unsigned v = 0; v < mesh.mNumVertices; ++v)
            index[v] = vertex(transform * mesh.mVertices[v]);
        for (unsigned f = 0; f < mesh.mNumFaces; ++f) {
            const aiFace& face = mesh.mFaces[f];
            if (face.mNumIndices != 3) continue;  // a point or a line
            const std::array<int, 3> t{index[face.mIndices[0]], index[face.mIndices[1]],
                                       index[face.mIndices[2]]};
            if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0]) mesh_.triangles.push_back(t);
        }
    }

    int vertex(const aiVector3D& p) {
        const std::array<double, 3> key{scale_ * p.x, scale_ * p.y, scale_ * p.z};
        const auto [it, added] = ids_.try_emplace(key, int(mesh_.vertices.size()));
        if (added) mesh_.vertices.emplace_back(key[0], key[1], key[2]);
        return it->second;
    }

    double scale_;
    sim::TriangleMesh mesh_;
    std::map<std::array<double, 3>, int> ids_;
};

/// glTF is y up by rule and OBJ by convention (Blender, Maya and Houdini write and read it so):
/// such files are turned into rend's z-up world, (x, y, z) -> (x, -z, y), the inverse of
/// MeshExport.h's toYUp. Other formats (PLY, STL) are taken as they are, as Blender does.
aiMatrix4x4 worldFrame(const std::filesystem::path& file) {
    std::string extension = file.extension().string();
    std::transform(extension.begin(), extension.end(), extension.begin(),
                   [](unsigned char c) { return char(std::tolower(c)); });
    if (extension != ".obj" && extension != ".gltf" && extension != ".glb") return {};
    return aiMatrix4x4(1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1);
}

}  // namespace

sim::TriangleMesh importTriangleMesh(const std::filesystem::path& file, double scale) {
    if (!(scale > 0.0) || !std::isfinite(scale))
        throw std::invalid_argument("mesh " + file.string() + ": scale " + std::to_string(scale) +
                                    " must be positive and finite");
    std::error_code ec;
    if (!std::filesystem::is_regular_file(file, ec)) throw importError(file, "no such file");
    Assimp::Importer importer;
    const aiScene* scene =
        importer.ReadFile(file.string(), aiProcess_Triangulate | aiProcess_JoinIdenticalVertices);
    if (!scene || !scene->mRootNode)
        throw importError(file,
                          std::string("assimp cannot read it (") + importer.GetErrorString() + ")");
    MeshBuilder builder(scale);
    builder.addNode(*scene, *scene->mRootNode, worldFrame(file));
    sim::TriangleMesh mesh = builder.take();
    if (mesh.triangles.empty()) throw importError(file, "the file holds no triangles");
    return mesh;
}

std::size_t openEdgeCount(const sim::TriangleMesh& mesh) {
    std::map<std::pair<int, int>, int> uses;
    for (const auto& t : mesh.triangles)
        for (int k = 0; k < 3; ++k) {
            const int a = t[k], b = t[(k + 1) % 3];
            ++uses[{std::min(a, b), std::max(a, b)}];
        }
    std::size_t open = 0;
    for (const auto& [edge, count] : uses) open += count != 2;
    return open;
}

}  // namespace rend::render
