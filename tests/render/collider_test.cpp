// Colliders as the renderers draw them: the tessellation of each shape (on the analytic surface,
// normals outward, closed), mesh import through assimp, and both renderers drawing a collider in
// its own look while a frame without colliders keeps its pixels.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "TestSupport.h"
#include "render/ColliderMesh.h"
#include "render/EmbreeRenderer.h"
#include "render/GlMath.h"
#include "render/MeshImport.h"
#include "render/OsmesaRenderer.h"

using rend::render::colliderMesh;
using rend::render::EmbreeRenderer;
using rend::render::FrameLayers;
using rend::render::Image;
using rend::render::importTriangleMesh;
using rend::render::Mesh;
using rend::render::openEdgeCount;
using rend::render::OsmesaRenderer;
using rend::render::RenderSettings;
using rend::sim::ColliderParams;
using rend::sim::ColliderPose;
using rend::sim::ColliderShape;
using rend::sim::TriangleMesh;
using rend::test::pixel;
using Vec3 = Eigen::Vector3d;

namespace {

// The meshes are float: positions of order 1 m carry a rounding error of about 1e-7 m.
constexpr double kOnSurface = 1e-5;

/// Off the axes and turned about an oblique axis, so no coordinate lines up by accident.
ColliderPose obliquePose() {
    ColliderPose pose;
    pose.position = Vec3(0.3, -0.2, 0.7);
    pose.rotation = Eigen::AngleAxisd(0.9, Vec3(1.0, 2.0, -0.5).normalized());
    return pose;
}

Vec3 position(const Mesh& mesh, std::uint32_t v) { return mesh.positions[v].cast<double>(); }

/// The face's normal by its winding (counter-clockwise: toward the viewer), unit length.
Vec3 faceNormal(const Mesh& mesh, const std::array<std::uint32_t, 3>& t) {
    return (position(mesh, t[1]) - position(mesh, t[0]))
        .cross(position(mesh, t[2]) - position(mesh, t[0]))
        .normalized();
}

Vec3 centroid(const Mesh& mesh, const std::array<std::uint32_t, 3>& t) {
    return (position(mesh, t[0]) + position(mesh, t[1]) + position(mesh, t[2])) / 3.0;
}

/// The mesh with vertices at equal positions merged: a flat-shaded box repeats each corner once
/// per face, yet is closed.
TriangleMesh welded(const Mesh& mesh) {
    TriangleMesh out;
    std::map<std::array<float, 3>, int> ids;
    std::vector<int> index;
    for (const Eigen::Vector3f& p : mesh.positions) {
        const auto [it, added] = ids.try_emplace({p.x(), p.y(), p.z()}, int(out.vertices.size()));
        if (added) out.vertices.push_back(p.cast<double>());
        index.push_back(it->second);
    }
    for (const auto& t : mesh.triangles)
        out.triangles.push_back({index[t[0]], index[t[1]], index[t[2]]});
    return out;
}

/// Every vertex at distance `radius` from `axisPoint(p)`, its normal along p - axisPoint(p),
/// every face turned away from it; the mesh closed. Spheres use the centre, capsules the
/// segment's nearest point.
template <class AxisPoint>
void expectRoundSurface(const Mesh& mesh, double radius, AxisPoint axisPoint) {
    for (std::uint32_t v = 0; v < mesh.positions.size(); ++v) {
        const Vec3 p = position(mesh, v);
        const Vec3 out = p - axisPoint(p);
        ASSERT_NEAR(out.norm(), radius, kOnSurface) << "vertex " << v;
        ASSERT_LT((mesh.normals[v].cast<double>() - out / radius).norm(), 1e-5) << "vertex " << v;
    }
    for (const auto& t : mesh.triangles) {
        const Vec3 c = centroid(mesh, t);
        ASSERT_GT(faceNormal(mesh, t).dot(c - axisPoint(c)), 0.0);
    }
    EXPECT_EQ(openEdgeCount(welded(mesh)), 0u);
}

}  // namespace

// ---- Tessellation ------------------------------------------------------------------------------

TEST(ColliderMesh, SphereLiesOnTheSphereWithOutwardNormalsAndIsClosed) {
    ColliderParams sphere;
    sphere.radius = 0.4;
    const ColliderPose pose = obliquePose();
    const Mesh mesh = colliderMesh(sphere, pose);
    // Round at 1280x720 (ColliderMesh.h): thousands of triangles, not tens of thousands.
    EXPECT_GT(mesh.triangles.size(), 2000u);
    EXPECT_LT(mesh.triangles.size(), 10000u);
    expectRoundSurface(mesh, 0.4, [&](const Vec3&) { return pose.position; });
}

TEST(ColliderMesh, CapsuleLiesOnTheCapsuleWithOutwardNormalsAndIsClosed) {
    ColliderParams capsule;
    capsule.shape = ColliderShape::Capsule;
    capsule.radius = 0.25;
    capsule.length = 1.1;
    const ColliderPose pose = obliquePose();
    const Vec3 a = pose.toWorld(Vec3(0.0, 0.0, -0.55)), b = pose.toWorld(Vec3(0.0, 0.0, 0.55));
    const auto nearest = [&](const Vec3& p) {
        const double s = std::clamp((p - a).dot(b - a) / (b - a).squaredNorm(), 0.0, 1.0);
        return Vec3(a + s * (b - a));
    };
    const Mesh mesh = colliderMesh(capsule, pose);
    expectRoundSurface(mesh, 0.25, nearest);
    // The cylinder is there: faces span the segment between the two hemispheres.
    int onCylinder = 0;
    for (const auto& t : mesh.triangles) {
        const double s = (centroid(mesh, t) - a).dot(b - a) / (b - a).squaredNorm();
        onCylinder += s > 0.25 && s < 0.75;
    }
    EXPECT_EQ(onCylinder, 2 * rend::render::kColliderSegments);
}

TEST(ColliderMesh, BoxHasTwelveFlatOutwardFacesOnItsSurfaceAndIsClosed) {
    ColliderParams box;
    box.shape = ColliderShape::Box;
    box.size = Vec3(0.4, 1.0, 0.6);
    const ColliderPose pose = obliquePose();
    const Mesh mesh = colliderMesh(box, pose);
    ASSERT_EQ(mesh.triangles.size(), 12u);
    const Vec3 half = 0.5 * box.size;
    for (std::uint32_t v = 0; v < mesh.positions.size(); ++v) {
        // Every vertex is a corner: each local coordinate at plus or minus the half extent.
        const Vec3 local = pose.toLocal(position(mesh, v));
        for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::abs(local[k]), half[k], kOnSurface) << v;
    }
    for (const auto& t : mesh.triangles) {
        const Vec3 n = faceNormal(mesh, t);
        EXPECT_GT(n.dot(centroid(mesh, t) - pose.position), 0.0);
        // Flat: all three vertex normals are the face's normal, which is a box axis.
        for (std::uint32_t v : t) EXPECT_LT((mesh.normals[v].cast<double>() - n).norm(), 1e-5);
        EXPECT_NEAR(pose.rotation.conjugate().operator*(n).cwiseAbs().maxCoeff(), 1.0, 1e-5);
    }
    EXPECT_EQ(openEdgeCount(welded(mesh)), 0u);
}

TEST(ColliderMesh, MeshColliderKeepsItsTrianglesAtThePoseWithOutwardVertexNormals) {
    // An octahedron: by symmetry each vertex normal points away from the centre along the axis.
    auto octahedron = std::make_shared<TriangleMesh>();
    octahedron->vertices = {Vec3(1, 0, 0),  Vec3(-1, 0, 0), Vec3(0, 1, 0),
                            Vec3(0, -1, 0), Vec3(0, 0, 1),  Vec3(0, 0, -1)};
    octahedron->triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                             {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
    ColliderParams collider;
    collider.shape = ColliderShape::Mesh;
    collider.mesh = octahedron;
    const ColliderPose pose = obliquePose();
    const Mesh mesh = colliderMesh(collider, pose);
    ASSERT_EQ(mesh.positions.size(), 6u);
    ASSERT_EQ(mesh.triangles.size(), 8u);
    for (std::uint32_t v = 0; v < 6; ++v) {
        EXPECT_LT((position(mesh, v) - pose.toWorld(octahedron->vertices[v])).norm(), kOnSurface);
        const Vec3 out = pose.rotation * octahedron->vertices[v];
        EXPECT_LT((mesh.normals[v].cast<double>() - out).norm(), 1e-5) << v;
    }
    for (const auto& t : mesh.triangles)
        EXPECT_GT(faceNormal(mesh, t).dot(centroid(mesh, t) - pose.position), 0.0);
    EXPECT_EQ(openEdgeCount(welded(mesh)), 0u);
}

TEST(ColliderMesh, RefusesAMeshColliderWithoutAMeshAndAFrameWithoutPoses) {
    ColliderParams collider;
    collider.shape = ColliderShape::Mesh;
    EXPECT_THROW(colliderMesh(collider, ColliderPose{}), std::invalid_argument);
    const std::vector<ColliderParams> colliders(2);
    const std::vector<ColliderPose> poses(1);
    rend::sim::FrameView frame;
    frame.colliders = colliders;
    frame.colliderPoses = poses;
    EXPECT_THROW(rend::render::colliderMeshes(frame), std::invalid_argument);
}

// ---- Mesh import -------------------------------------------------------------------------------

namespace {

std::filesystem::path writeFile(const std::string& name, const std::string& text) {
    const std::filesystem::path path = rend::test::scratchDir() / name;
    std::ofstream(path) << text;
    return path;
}

/// A unit cube from 0 to 1 with quad faces, counter-clockwise from outside, and per-face
/// normals, which split each corner three ways until the import merges it.
const char* kCubeObj = R"(v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1
vn 0 0 -1
vn 0 0 1
vn 0 -1 0
vn 0 1 0
vn -1 0 0
vn 1 0 0
f 1//1 4//1 3//1 2//1
f 5//2 6//2 7//2 8//2
f 1//3 2//3 6//3 5//3
f 4//4 8//4 7//4 3//4
f 1//5 5//5 8//5 4//5
f 2//6 3//6 7//6 6//6
)";

std::string messageOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const std::runtime_error& e) {
        return e.what();
    }
    return "(no exception)";
}

}  // namespace

TEST(MeshImport, ReadsAnObjCubeAsEightVerticesAndTwelveTrianglesScaled) {
    const auto path = writeFile("cube.obj", kCubeObj);
    const TriangleMesh mesh = importTriangleMesh(path, 2.0);
    ASSERT_EQ(mesh.vertices.size(), 8u);
    ASSERT_EQ(mesh.triangles.size(), 12u);
    EXPECT_EQ(openEdgeCount(mesh), 0u);
    EXPECT_TRUE(rend::render::isClosed(mesh));
    // Every corner scaled to 0 or 2, and turned from the OBJ's y up: its y is -z here.
    for (const Vec3& v : mesh.vertices)
        for (int k = 0; k < 3; ++k)
            EXPECT_TRUE(v[k] == 0.0 || v[k] == (k == 1 ? -2.0 : 2.0)) << v.transpose();
    // The winding survives: every face turns away from the cube's centre.
    const Vec3 centre(1.0, -1.0, 1.0);
    for (const auto& t : mesh.triangles) {
        const Vec3& a = mesh.vertices[t[0]];
        const Vec3 n = (mesh.vertices[t[1]] - a).cross(mesh.vertices[t[2]] - a);
        EXPECT_GT(n.dot(a - centre), 0.0);
    }
}

// A post 3 tall along the file's y: upright in rend's z-up world from an OBJ (y up, as
// Blender writes it), along y from a PLY (taken as it is, as Blender reads it).
TEST(MeshImport, AYUpObjStandsUpAndAPlyIsTakenAsItIs) {
    const auto bounds = [](const TriangleMesh& mesh) {
        Vec3 low = Vec3::Constant(1e30), high = -low;
        for (const Vec3& v : mesh.vertices) low = low.cwiseMin(v), high = high.cwiseMax(v);
        return Eigen::Vector3d(high - low);
    };
    std::string obj, ply =
                         "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\n"
                         "property float y\nproperty float z\nelement face 2\n"
                         "property list uchar int vertex_indices\nend_header\n";
    for (const char* v : {"0 0 0", "1 0 0", "1 3 0", "0 3 0"}) {
        obj += std::string("v ") + v + "\n";
        ply += std::string(v) + "\n";
    }
    obj += "f 1 2 3\nf 1 3 4\n";
    ply += "3 0 1 2\n3 0 2 3\n";
    EXPECT_TRUE(bounds(importTriangleMesh(writeFile("post.obj", obj))).isApprox(Vec3(1, 0, 3)));
    EXPECT_TRUE(bounds(importTriangleMesh(writeFile("post.ply", ply))).isApprox(Vec3(1, 3, 0)));
}

TEST(MeshImport, CountsTheRimOfAnOpenMesh) {
    const auto path = writeFile("quad.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n");
    const TriangleMesh mesh = importTriangleMesh(path);
    EXPECT_EQ(mesh.triangles.size(), 2u);
    EXPECT_EQ(openEdgeCount(mesh), 4u);  // the diagonal is shared; the four sides are not
    EXPECT_FALSE(rend::render::isClosed(mesh));
}

TEST(MeshImport, RefusesAMissingAndAnEmptyFileNamingIt) {
    const auto missing = rend::test::scratchDir() / "no_such_mesh.obj";
    std::filesystem::remove(missing);
    const std::string a = messageOf([&] { importTriangleMesh(missing); });
    EXPECT_NE(a.find("no_such_mesh.obj"), std::string::npos) << a;
    EXPECT_NE(a.find("no such file"), std::string::npos) << a;
    const auto empty = writeFile("empty_mesh.obj", "");
    const std::string b = messageOf([&] { importTriangleMesh(empty); });
    EXPECT_NE(b.find("empty_mesh.obj"), std::string::npos) << b;
    EXPECT_NE(b.find("expected a triangle mesh"), std::string::npos) << b;
    const auto points = writeFile("points_only.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\n");
    const std::string c = messageOf([&] { importTriangleMesh(points); });
    EXPECT_NE(c.find("points_only.obj"), std::string::npos) << c;
    EXPECT_THROW(importTriangleMesh(writeFile("cube.obj", kCubeObj), 0.0), std::invalid_argument);
}

// ---- Drawing -----------------------------------------------------------------------------------

namespace {

const Vec3 kRed(0.8, 0.05, 0.05);

/// A small frame looking at `target` from the front and above, the default sun behind the camera.
RenderSettings smallFrame(const Vec3& target) {
    RenderSettings settings;
    settings.width = 96;
    settings.height = 64;
    settings.supersample = 1;
    settings.camera.position = target + Vec3(0.0, -3.0, 1.2);
    settings.camera.lookAt = target;
    settings.pathTracing.samplesPerPixel = 4;
    return settings;
}

/// A flat grey-blue sheet 2 m wide at height z, with theta = 0.7 everywhere.
Mesh sheet(double z) {
    Mesh mesh = rend::test::gridMesh(3, 3, [&](int i, int j) {
        return rend::test::GridVertex{Eigen::Vector3f(float(i - 1), float(j - 1), float(z)),
                                      Eigen::Vector3f::UnitZ(), Eigen::Vector3f(0.45f, 0.5f, 0.7f)};
    });
    mesh.theta.assign(mesh.positions.size(), 0.7f);
    return mesh;
}

std::vector<Mesh> sphereAt(const Vec3& centre, double radius) {
    ColliderParams sphere;
    sphere.radius = radius;
    ColliderPose pose;
    pose.position = centre;
    return {colliderMesh(sphere, pose)};
}

/// Where `p` lands in the image, in pixels (x right, y down).
Eigen::Vector2d project(const RenderSettings& s, const Vec3& p) {
    const auto basis =
        rend::render::detail::viewBasis(s.camera.position, s.camera.lookAt, s.camera.up);
    const Vec3 d = p - s.camera.position;
    const double tanHalf = std::tan(s.camera.fovYDegrees * std::numbers::pi / 360.0);
    const double aspect = double(s.width) / s.height;
    const double ndcX = d.dot(basis.right) / (d.dot(basis.forward) * tanHalf * aspect);
    const double ndcY = d.dot(basis.up) / (d.dot(basis.forward) * tanHalf);
    return {0.5 * (ndcX + 1.0) * s.width, 0.5 * (1.0 - ndcY) * s.height};
}

/// Every pixel of the 5 x 5 block around (x, y) is clearly red: red above 80 and at least
/// twice green and blue.
void expectRedAround(const Image& image, int x, int y, const char* who) {
    for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) {
            const std::uint8_t* p = pixel(image, x + dx, y + dy);
            EXPECT_GT(p[0], 80) << who << " at " << x + dx << "," << y + dy;
            EXPECT_GT(p[0], 2 * std::max(p[1], p[2])) << who << " at " << x + dx << "," << y + dy;
        }
}

double luminance(const std::uint8_t* p) { return 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]; }

}  // namespace

TEST(ColliderDrawing, BothRenderersDrawARedSphereInItsOwnLook) {
    const Vec3 centre(0.0, 0.0, 0.3);
    RenderSettings settings = smallFrame(centre);
    settings.colliderLooks = {{.color = kRed}};
    const std::vector<Mesh> colliders = sphereAt(centre, 0.35);
    const Mesh underneath = sheet(-0.2);
    const Image traced = EmbreeRenderer().render(underneath, settings, nullptr, colliders);
    const Image raster = OsmesaRenderer().render(underneath, settings, colliders);
    const Eigen::Vector2d c = project(settings, centre);
    expectRedAround(traced, int(c.x()), int(c.y()), "Embree");
    expectRedAround(raster, int(c.x()), int(c.y()), "OSMesa");
    // Without its look the sphere has the default grey: no longer red.
    settings.colliderLooks.clear();
    const Image grey = OsmesaRenderer().render(underneath, settings, colliders);
    const std::uint8_t* p = pixel(grey, int(c.x()), int(c.y()));
    EXPECT_LT(p[0], p[1] + 30);
}

TEST(ColliderDrawing, AFrameWithoutCollidersKeepsItsPixelsOnARendererThatDrewThem) {
    // The renderers keep state between frames (Embree's scene, GL's material): a metal collider
    // in one frame must leave no trace in the next frame, which has none.
    const Vec3 centre(0.0, 0.0, 0.3);
    RenderSettings settings = smallFrame(centre);
    settings.colliderLooks = {{.color = kRed, .roughness = 0.3, .metal = true}};
    const std::vector<Mesh> colliders = sphereAt(centre, 0.35);
    const Mesh underneath = sheet(-0.2);
    EmbreeRenderer embree;
    const Image traced = embree.render(underneath, settings);
    EXPECT_NE(embree.render(underneath, settings, nullptr, colliders).rgb, traced.rgb);
    EXPECT_EQ(embree.render(underneath, settings).rgb, traced.rgb);
    EXPECT_EQ(EmbreeRenderer().render(underneath, settings).rgb, traced.rgb);
    OsmesaRenderer osmesa;
    const Image raster = osmesa.render(underneath, settings);
    EXPECT_NE(osmesa.render(underneath, settings, colliders).rgb, raster.rgb);
    EXPECT_EQ(osmesa.render(underneath, settings).rgb, raster.rgb);
}

TEST(ColliderDrawing, PathTracedSphereCastsAShadowOnTheGround) {
    // Sun at 45 degrees from +x: the shadow of a sphere 0.5 m above the ground falls 0.5 m
    // toward -x, beside the sphere as seen from straight above.
    RenderSettings settings;
    settings.width = settings.height = 64;
    settings.camera.position = Vec3(0.0, 0.0, 3.0);
    settings.camera.lookAt = Vec3::Zero();
    settings.camera.up = Vec3::UnitY();
    settings.groundHeight = 0.0;
    settings.sun.direction = Vec3(1.0, 0.0, 1.0);
    settings.pathTracing.samplesPerPixel = 8;
    const Eigen::Vector2d shadow = project(settings, Vec3(-0.5, 0.0, 0.0));
    EmbreeRenderer renderer;
    const Image open = renderer.render(Mesh{}, settings);
    const Image shaded =
        renderer.render(Mesh{}, settings, nullptr, sphereAt(Vec3(0.0, 0.0, 0.5), 0.2));
    const int x = int(shadow.x()), y = int(shadow.y());
    // The sky still lights the umbra: it loses the sun's share, about 40 of 200 levels here.
    EXPECT_LT(luminance(pixel(shaded, x, y)), luminance(pixel(open, x, y)) - 25.0);
}

TEST(ColliderDrawing, ExrThetaIsZeroOnAColliderInFrontOfTheSheet) {
    // Looking straight down at a sheet whose theta is 0.7, through a sphere: its top is the first
    // hit of the middle pixel, 3 - 1.2 m from the camera.
    RenderSettings settings;
    settings.width = settings.height = 33;
    settings.camera.position = Vec3(0.0, 0.0, 3.0);
    settings.camera.lookAt = Vec3::Zero();
    settings.camera.up = Vec3::UnitY();
    settings.pathTracing.samplesPerPixel = 1;
    FrameLayers layers;
    EmbreeRenderer().render(sheet(0.0), settings, &layers, sphereAt(Vec3(0.0, 0.0, 1.0), 0.2));
    const std::size_t middle = 16 * 33 + 16, corner = 2 * 33 + 2;
    ASSERT_EQ(layers.theta.size(), 33u * 33u);
    EXPECT_EQ(layers.theta[middle], 0.0f);
    EXPECT_NEAR(layers.depth[middle], 1.8, 1e-4);
    EXPECT_NEAR(layers.theta[corner], 0.7f, 1e-6);  // the sheet, beside the sphere
}
