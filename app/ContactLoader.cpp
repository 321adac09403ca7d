// [contact] and [[collider]]: the ground, self-contact and kinematic colliders (sim/Contact.h),
// with each collider's look for the renderers. Mesh colliders are read with assimp here, so sim/
// sees only triangles.

#include "app/ContactLoader.h"

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "app/SceneError.h"
#include "app/SceneNames.h"
#include "render/MeshImport.h"

namespace rend {
namespace {

using scene::formatNumber;
using scene::TableReader;

constexpr double kDegree = std::numbers::pi / 180.0;

/// Degrees about x, then y, then z (world axes), as Blender's XYZ Euler and Houdini's default.
Eigen::Quaterniond rotationOf(const Eigen::Vector3d& degrees) {
    const Eigen::Vector3d r = degrees * kDegree;
    return Eigen::Quaterniond(Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
                              Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
                              Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()));
}

sim::Friction readFriction(const TableReader& t, std::string_view kinetic,
                           std::string_view stiction, double fallback) {
    sim::Friction f;
    f.kinetic = t.number(kinetic).value_or(fallback);
    f.stiction = t.number(stiction).value_or(f.kinetic);
    if (f.stiction < f.kinetic) {
        t.fail(stiction,
               "a static friction at least the kinetic one (" + formatNumber(f.kinetic) + ")",
               formatNumber(f.stiction),
               "Raise " + std::string(stiction) + ", or lower " + std::string(kinetic) + ".");
    }
    return f;
}

/// A key of one shape is an error for another, so a forgotten shape cannot silently change it.
void requireForShape(const TableReader& t, sim::ColliderShape shape) {
    struct Rule {
        std::string_view key;
        bool sphere, box, capsule, mesh;
    };
    constexpr Rule kRules[] = {{"radius", true, false, true, false},
                               {"size", false, true, false, false},
                               {"length", false, false, true, false},
                               {"file", false, false, false, true},
                               {"scale", false, false, false, false}};
    const std::string name(names::kColliderShapes[std::size_t(shape)]);
    for (const Rule& r : kRules) {
        const bool wanted = shape == sim::ColliderShape::Sphere    ? r.sphere
                            : shape == sim::ColliderShape::Box     ? r.box
                            : shape == sim::ColliderShape::Capsule ? r.capsule
                                                                   : r.mesh;
        const bool allowed = wanted || (r.key == "scale" && shape == sim::ColliderShape::Mesh);
        if (wanted && !t.has(r.key)) t.missing(r.key, "for shape = \"" + name + "\"");
        if (!allowed && t.has(r.key)) {
            t.fail(r.key, "no " + std::string(r.key) + " for shape = \"" + name + "\"",
                   scene::describeType(*t.find(r.key)),
                   "Remove " + std::string(r.key) + ", or change the shape.");
        }
    }
}

std::shared_ptr<const sim::TriangleMesh> readMesh(const TableReader& t, const Scene& scene) {
    const std::filesystem::path file = scene.file.parent_path() / *t.string("file");
    const double scale = t.number("scale").value_or(1.0);
    sim::TriangleMesh mesh;
    try {
        mesh = render::importTriangleMesh(file, scale);
    } catch (const std::exception& e) {
        t.fail("file", "a triangle mesh in OBJ, PLY, glTF or GLB", e.what(),
               "Give a path relative to the scene file, to a mesh assimp can read.");
    }
    if (const std::size_t open = render::openEdgeCount(mesh); open > 0) {
        t.fail(
            "file",
            "a closed mesh, every edge shared by two triangles (inside must differ from outside)",
            std::to_string(open) + " open edges in " + file.string(),
            "Close the mesh (e.g. Blender's Fill Holes), or use a box or sphere collider.");
    }
    return std::make_shared<const sim::TriangleMesh>(std::move(mesh));
}

std::vector<sim::ColliderKeyframe> readKeyframes(const TableReader& t,
                                                 const sim::ColliderParams& c) {
    std::vector<sim::ColliderKeyframe> keys;
    for (const TableReader& k : t.entries("keyframe")) {
        sim::ColliderKeyframe key;
        key.time = k.requiredNumber("time");
        key.position = k.vec3("position").value_or(c.position);
        key.rotation = k.has("rotation") ? rotationOf(*k.vec3("rotation")) : c.rotation;
        if (!keys.empty() && key.time <= keys.back().time) {
            k.fail("time",
                   "keyframe times that increase (the last was " + formatNumber(keys.back().time) +
                       " s)",
                   formatNumber(key.time), "Order the keyframes by time.");
        }
        keys.push_back(key);
    }
    for (const std::string_view motion : {"velocity", "spin"}) {
        if (!keys.empty() && t.has(motion)) {
            t.fail(motion, "no " + std::string(motion) + " on a keyframed collider",
                   scene::describeType(*t.find(motion)),
                   "Remove " + std::string(motion) + ", or the keyframes.");
        }
    }
    return keys;
}

render::ColliderLook readLook(const TableReader& t) {
    render::ColliderLook look;
    look.color = t.vec3("color").value_or(look.color);
    look.roughness = t.number("roughness").value_or(look.roughness);
    look.metal = t.boolean("metal").value_or(look.metal);
    return look;
}

sim::ColliderParams readCollider(const TableReader& t, const Scene& scene) {
    sim::ColliderParams c;
    if (!t.has("shape")) t.missing("shape", scene::oneOf(names::kColliderShapes));
    c.shape = sim::ColliderShape(*t.choice("shape"));
    requireForShape(t, c.shape);
    c.radius = t.number("radius").value_or(c.radius);
    c.size = t.vec3("size").value_or(c.size);
    c.length = t.number("length").value_or(c.length);
    if (c.shape == sim::ColliderShape::Mesh) c.mesh = readMesh(t, scene);
    c.position = t.vec3("position").value_or(c.position);
    c.rotation = rotationOf(t.vec3("rotation").value_or(Eigen::Vector3d::Zero()));
    c.velocity = t.vec3("velocity").value_or(c.velocity);
    c.spin = t.vec3("spin").value_or(Eigen::Vector3d::Zero()) * kDegree;
    c.keyframes = readKeyframes(t, c);
    c.friction = readFriction(t, "friction", "static_friction", 0.5);
    return c;
}

/// Particles farther apart at rest than the horizon R are not bonded, so a contact thickness of R
/// or more would have the sheet repel itself where it lies flat.
void checkThickness(const TableReader& t, double thickness, const sim::SheetParams& sheet) {
    const double horizon = sheet.horizonFactor * sheet.dx;
    if (thickness < horizon) return;
    t.fail("thickness",
           "a contact thickness below the horizon R = " + formatNumber(horizon) +
               " m at this quality's spacing, or the sheet repels itself where it lies flat",
           formatNumber(thickness),
           "Remove thickness (the default is dx / 2 at every quality), or use e.g. thickness = " +
               formatNumber(0.5 * sheet.dx) + ".");
}

}  // namespace

void readContact(const TableReader& root, Scene& scene) {
    const TableReader t = root.section("contact");
    sim::ContactParams& c = scene.sim.contact;
    c.ground.enabled = t.boolean("ground").value_or(scene.render.ground);
    c.ground.height = scene.render.groundHeight;
    c.ground.friction = readFriction(t, "ground_friction", "ground_static_friction", 0.5);
    c.self.enabled = t.boolean("self").value_or(false);
    c.self.thickness = t.number("thickness").value_or(0.0);
    checkThickness(t, c.self.thickness, scene.sim.sheet);
    c.self.friction = readFriction(t, "friction", "static_friction", 0.3);
    for (const TableReader& entry : root.entries("collider")) {
        c.colliders.push_back(readCollider(entry, scene));
        scene.render.colliderLooks.push_back(readLook(entry));
    }
}

}  // namespace rend
