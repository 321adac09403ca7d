// Every documented key changes the run or its output: for each key of the schema, a short run
// with the key at a non-default value differs from the run without it in the state hash,
// stats.csv, run.json's counts, an output file, or whether the scene is accepted at all. A key
// that changed nothing would be a key the loader reads and the pipeline ignores, as
// `[output] stats = false` once was.

#include <gtest/gtest.h>

#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "app/Pipeline.h"
#include "app/Scene.h"
#include "app/SceneError.h"
#include "app/SceneReader.h"
#include "tests/ScratchDir.h"

using namespace rend;
namespace fs = std::filesystem;

namespace {

/// Every section and key, two frames of a 0.2 m sheet rendered at 32 x 32.
constexpr const char* kBase = R"([sheet]
size = [0.2, 0.2]
dx = 0.02
perturbation = 1e-4

[material]
E = 2e4
density = 5000
fracture_energy = 11.3
conductivity = 0.01
expansion = 0.1

[[boundary]]
type = "velocity"
edge = "left"
velocity = [-0.1, 0.0, 0.0]

[[boundary]]
type = "pinned"
box = { min = [0.08, -0.1], max = [0.1, 0.1] }

[[notch]]
points = [[-0.1, 0.0], [-0.05, 0.0]]

[[diffusion.spot]]
center = [0.0, 0.0]
radius = 0.05
rate = 1.0

[[diffusion.scatter]]
count = 3
radius = 0.02
rate = 1.0

[[diffusion.edge]]
edge = "top"
value = 1.0

[[diffusion.edge]]
box = { min = [-0.1, -0.1], max = [-0.05, -0.05] }
value = 0.5

[time]
duration = 0.0834

[render]
width = 32
height = 32
supersample = 1
)";

struct Variation {
    std::string key;                                ///< as the README table names it
    std::vector<std::string> sets;                  ///< the variant only
    std::vector<std::string> context = {};          ///< both runs
    std::pair<std::string, std::string> edit = {};  ///< base text replaced, both runs
    bool setUpOnly = false;  ///< compare loading and set-up only (the run would be slow)
};

const std::pair<std::string, std::string> kDisc = {"size = [0.2, 0.2]",
                                                   "shape = \"disc\"\nradius = 0.1"};

/// A collider just under the sheet's middle (its top 2 mm below, within the contact offset), so
/// it lifts the sheet at once; `shape` gives its shape keys.
std::pair<std::string, std::string> collider(const std::string& shape) {
    return {"[time]", "[[collider]]\n" + shape + "\n\n[time]"};
}
/// A material map before [time]; `keys` gives its keys.
std::pair<std::string, std::string> map(const std::string& keys) {
    return {"[time]", "[[material.map]]\nproperty = \"E\"\n" + keys + "\n\n[time]"};
}
const std::string kMapBox = "shape = \"box\"\nmin = [-0.1, -0.1]\nmax = [0.0, 0.1]\nfactor = 0.5";
const std::string kMapDisc = "shape = \"disc\"\ncenter = [0.0, 0.0]\nradius = 0.05\nfactor = 0.5";
const std::string kMapPolygon =
    "shape = \"polygon\"\npoints = [[-0.1, -0.1], [0.1, -0.1], [0.0, 0.1]]\nfactor = 0.5";
const std::string kMapNoise = "shape = \"noise\"\nscale = [0.05, 0.05]";
const std::string kMapImage =
    "shape = \"image\"\nfile = \"" REND_SOURCE_DIR "/tests/data/map_gradient.png\"";
const std::string kSphere = "shape = \"sphere\"\nradius = 0.05\nposition = [0.0, 0.0, -0.052]";
const std::string kBox = "shape = \"box\"\nsize = [0.1, 0.1, 0.1]\nposition = [0.0, 0.0, -0.052]";
const std::string kCube = "shape = \"mesh\"\nfile = \"" REND_SOURCE_DIR
                          "/tests/data/collider_cube.obj\"\nscale = 0.1\nposition = [0.0, 0.0, "
                          "-0.052]";
const std::string kKeyed = kSphere +
                           "\n[[collider.keyframe]]\ntime = 0.0\n[[collider.keyframe]]\ntime = "
                           "0.05\nposition = [0.0, 0.0, -0.03]";

std::vector<Variation> variations() {
    const std::vector<std::string> embree = {"render.renderer=embree", "render.spp=2"};
    const std::vector<std::string> vdb = {"render.surface=vdb"};
    // Pulled fast enough that bonds near the notch reach their critical stretch.
    const std::vector<std::string> pull = {"boundary.0.velocity=[-2.0, 0.0, 0.0]"};
    // The sheet falls onto the ground just below it, or is pushed together from its left edge
    // until parts of it not bonded at rest touch.
    const std::vector<std::string> fall = {"forces.gravity=[0.0, 0.0, -50.0]",
                                           "render.ground_height=-0.004"};
    const std::vector<std::string> touching = {"contact.self=true", "contact.thickness=0.025",
                                               "boundary.0.velocity=[1.0, 0.0, 0.0]"};
    return {
        {"solver", {"solver=fem_cst"}},
        {"sheet.shape", {"sheet.shape=disc"}, {}, {"size = [0.2, 0.2]", "radius = 0.1"}},
        {"sheet.size", {"sheet.size=[0.24, 0.2]"}},
        {"sheet.radius", {"sheet.radius=0.12"}, {}, kDisc},
        {"sheet.center", {"sheet.center=[0.01, 0.0, 0.0]"}},
        {"sheet.lattice", {"sheet.lattice=square"}},
        {"sheet.dx", {"sheet.dx=0.025"}},
        {"sheet.quality", {"sheet.quality=final"}, {"sheet.dx_final=0.01"}},
        {"sheet.dx_final",
         {"sheet.dx_final=0.01"},
         {"sheet.quality=final", "sheet.dx_final=0.0125"}},
        {"sheet.horizon", {"sheet.horizon=2.5"}},
        {"sheet.thickness", {"sheet.thickness=0.002"}},
        {"sheet.perturbation", {"sheet.perturbation=2e-4"}},
        {"sheet.seed", {"sheet.seed=9"}},
        {"material.preset", {"material.preset=paper_towel_wet"}},
        {"material.name", {"material.name=rubber"}},
        {"material.E", {"material.E=3e4"}},
        {"material.poisson", {"material.poisson=0.2"}, {"material.micromodulus=paper"}},
        {"material.density", {"material.density=4000"}},
        {"material.micromodulus", {"material.micromodulus=paper"}},
        {"material.law", {"material.law=elastoplastic"}},
        {"material.power_ratio", {"material.power_ratio=-0.5"}, {"material.law=power_law"}},
        {"material.power_exponent",
         {"material.power_exponent=2"},
         {"material.law=power_law", "material.power_ratio=-0.5"}},
        {"material.yield_strain", {"material.yield_strain=1e-3"}, {"material.law=elastoplastic"}},
        {"material.softening", {"material.softening=3"}, {"material.law=elastoplastic"}},
        {"material.fracture_energy", {"material.fracture_energy=0.5"}, pull},
        {"material.critical_stretch",
         {"material.critical_stretch=paper"},
         {"boundary.0.velocity=[-2.0, 0.0, 0.0]", "material.fracture_energy=0.5"}},
        {"material.strength_loss", {"material.strength_loss=0.9"}, pull},
        {"material.surface_correction", {"material.surface_correction=true"}},
        {"remesh.every", {"remesh.every=5"}, {"boundary.0.velocity=[-2.0, 0.0, 0.0]"}},
        {"mpm.grid", {"mpm.grid=2.0"}, {"solver=mpm", "boundary.0.velocity=[-2.0, 0.0, 0.0]"}},
        {"mpm.enrich",
         {"mpm.enrich=false"},
         {"solver=mpm", "boundary.0.velocity=[-2.0, 0.0, 0.0]", "material.fracture_energy=0.5"}},
        {"material.capacity", {"material.capacity=2"}},
        {"material.conductivity", {"material.conductivity=0.05"}},
        {"material.expansion", {"material.expansion=0.3"}},
        {"material.stiffness_loss", {"material.stiffness_loss=0.5"}},
        {"boundary[].type", {"boundary.1.type=velocity", "boundary.1.velocity=[0.1, 0.0, 0.0]"}},
        {"boundary[].edge", {"boundary.0.edge=bottom"}},
        {"boundary[].depth", {"boundary.0.depth=0.04"}},
        {"boundary[].box.min", {"boundary.1.box.min=[0.06, -0.1]"}},
        {"boundary[].box.max", {"boundary.1.box.max=[0.1, 0.05]"}},
        {"boundary[].velocity", {"boundary.0.velocity=[-0.2, 0.0, 0.0]"}},
        {"boundary[].ramp", {"boundary.0.ramp=0.02"}},
        {"notch[].points", {"notch.0.points=[[-0.1, 0.02], [-0.05, 0.02]]"}},
        {"diffusion.initial", {"diffusion.initial=0.5"}},
        {"diffusion.spot[].center", {"diffusion.spot.0.center=[0.02, 0.0]"}},
        {"diffusion.spot[].radius", {"diffusion.spot.0.radius=0.07"}},
        {"diffusion.spot[].rate", {"diffusion.spot.0.rate=2"}},
        {"diffusion.spot[].start", {"diffusion.spot.0.start=0.01"}},
        {"diffusion.spot[].duration", {"diffusion.spot.0.duration=0.01"}},
        {"diffusion.scatter[].count", {"diffusion.scatter.0.count=5"}},
        {"diffusion.scatter[].radius", {"diffusion.scatter.0.radius=0.03"}},
        {"diffusion.scatter[].rate", {"diffusion.scatter.0.rate=2"}},
        {"diffusion.scatter[].start", {"diffusion.scatter.0.start=0.01"}},
        {"diffusion.scatter[].spread", {"diffusion.scatter.0.spread=0.05"}},
        {"diffusion.scatter[].duration", {"diffusion.scatter.0.duration=0.01"}},
        {"diffusion.scatter[].seed", {"diffusion.scatter.0.seed=5"}},
        {"diffusion.edge[].edge", {"diffusion.edge.0.edge=bottom"}},
        {"diffusion.edge[].depth", {"diffusion.edge.0.depth=0.04"}},
        {"diffusion.edge[].box.min", {"diffusion.edge.1.box.min=[-0.1, -0.08]"}},
        {"diffusion.edge[].box.max", {"diffusion.edge.1.box.max=[-0.02, -0.05]"}},
        {"diffusion.edge[].value", {"diffusion.edge.0.value=2"}},
        {"forces.gravity", {"forces.gravity=[0.0, 0.0, -5.0]"}},
        {"contact.ground", {"contact.ground=false"}, fall},
        {"contact.ground_friction", {"contact.ground_friction=0.0"}, fall},
        {"contact.ground_static_friction", {"contact.ground_static_friction=3.0"}, fall},
        {"contact.self", {"contact.self=true"}},
        {"contact.thickness", {"contact.thickness=0.004"}, fall},
        {"contact.friction", {"contact.friction=0.0", "contact.static_friction=0.0"}, touching},
        {"contact.static_friction", {"contact.static_friction=3.0"}, touching},
        {"collider[].shape",
         {"collider.0.shape=capsule", "collider.0.length=0.1"},
         {},
         collider(kSphere)},
        {"collider[].radius", {"collider.0.radius=0.06"}, {}, collider(kSphere)},
        {"material.map[].property", {"material.map.0.property=density"}, {}, map(kMapBox)},
        {"material.map[].shape",
         {"material.map.0.shape=box", "material.map.0.min=[-0.1, -0.1]",
          "material.map.0.max=[0.0, 0.1]", "material.map.0.factor=0.5"},
         {},
         map("shape = \"noise\"")},
        {"material.map[].factor", {"material.map.0.factor=0.3"}, {}, map(kMapBox)},
        {"material.map[].min", {"material.map.0.min=[-0.1, -0.05]"}, {}, map(kMapBox)},
        {"material.map[].max", {"material.map.0.max=[0.05, 0.1]"}, {}, map(kMapBox)},
        {"material.map[].center", {"material.map.0.center=[0.05, 0.0]"}, {}, map(kMapDisc)},
        {"material.map[].radius", {"material.map.0.radius=0.08"}, {}, map(kMapDisc)},
        {"material.map[].points",
         {"material.map.0.points=[[-0.1, -0.1], [0.1, -0.1], [0.1, 0.1]]"},
         {},
         map(kMapPolygon)},
        {"material.map[].scale", {"material.map.0.scale=[0.1, 0.02]"}, {}, map(kMapNoise)},
        {"material.map[].amplitude", {"material.map.0.amplitude=0.8"}, {}, map(kMapNoise)},
        {"material.map[].octaves", {"material.map.0.octaves=2"}, {}, map(kMapNoise)},
        {"material.map[].seed", {"material.map.0.seed=5"}, {}, map(kMapNoise)},
        {"material.map[].file",
         {"material.map.0.file=\"" REND_SOURCE_DIR "/tests/data/map_stripes.png\""},
         {},
         map(kMapImage)},
        {"material.map[].low", {"material.map.0.low=0.2"}, {}, map(kMapImage)},
        {"material.map[].high", {"material.map.0.high=3.0"}, {}, map(kMapImage)},
        {"collider[].size", {"collider.0.size=[0.1, 0.1, 0.11]"}, {}, collider(kBox)},
        {"collider[].length",
         {"collider.0.length=0.2"},
         {"collider.0.shape=capsule", "collider.0.length=0.1"},
         collider(kSphere)},
        {"collider[].file",
         {"collider.0.file=\"" REND_SOURCE_DIR "/tests/data/collider_octahedron.obj\""},
         {},
         collider(kCube)},
        {"collider[].scale", {"collider.0.scale=0.12"}, {}, collider(kCube)},
        {"collider[].position", {"collider.0.position=[0.01, 0.0, -0.052]"}, {}, collider(kSphere)},
        {"collider[].rotation", {"collider.0.rotation=[0.0, 0.0, 30.0]"}, {}, collider(kBox)},
        {"collider[].velocity", {"collider.0.velocity=[0.0, 0.0, 0.3]"}, {}, collider(kSphere)},
        {"collider[].spin", {"collider.0.spin=[0.0, 0.0, 200.0]"}, {}, collider(kBox)},
        {"collider[].keyframe[].time", {"collider.0.keyframe.1.time=0.08"}, {}, collider(kKeyed)},
        {"collider[].keyframe[].position",
         {"collider.0.keyframe.1.position=[0.0, 0.0, -0.04]"},
         {},
         collider(kKeyed)},
        {"collider[].keyframe[].rotation",
         {"collider.0.keyframe.1.rotation=[0.0, 0.0, 60.0]"},
         {"collider.0.shape=capsule", "collider.0.length=0.1"},
         collider(kKeyed)},
        {"collider[].friction", {"collider.0.friction=0.0"}, {}, collider(kSphere)},
        {"collider[].static_friction", {"collider.0.static_friction=3.0"}, {}, collider(kSphere)},
        {"collider[].color", {"collider.0.color=[0.9, 0.1, 0.1]"}, {}, collider(kSphere)},
        {"collider[].roughness",
         {"collider.0.roughness=0.1"},
         {"render.renderer=embree", "render.spp=2", "collider.0.metal=true"},
         collider(kSphere)},
        {"collider[].metal", {"collider.0.metal=true"}, {}, collider(kSphere)},
        {"forces.damping", {"forces.damping=1"}},
        {"forces.pressure", {"forces.pressure=10"}},
        {"time.dt", {"time.dt=1e-3"}},
        {"time.safety", {"time.safety=0.3"}},  // below the adaptive step's half bound
        // A weak sheet, so bonds near the notch are loaded towards breaking within two frames.
        {"time.max_stretch_increment",
         {"time.max_stretch_increment=1"},
         {"material.fracture_energy=1e-3"}},
        {"time.burst_bonds",
         {"time.burst_bonds=1"},
         {"material.fracture_energy=1e-3", "time.max_stretch_increment=1"}},
        {"time.duration", {"time.duration=0.125"}},
        {"time.fps", {"time.fps=30"}},
        {"time.allow_unstable", {"time.allow_unstable=true"}, {"time.dt=0.006"}},
        {"time.allow_slow", {"time.allow_slow=true"}, {"time.dt=1e-10"}, {}, true},
        {"time.integrator", {"time.integrator=velocity_verlet"}},
        {"camera.position", {"camera.position=[0.0, -0.5, 0.4]"}},
        {"camera.look_at", {"camera.look_at=[0.02, 0.0, 0.0]"}},
        {"camera.up", {"camera.up=[0.1, 0.0, 1.0]"}},
        {"camera.fov", {"camera.fov=30"}},
        {"light.direction", {"light.direction=[0.4, 0.5, 1.0]"}},
        {"light.color", {"light.color=[1.0, 0.5, 0.5]"}},
        {"light.intensity", {"light.intensity=0.5"}},
        {"light.ambient", {"light.ambient=0.5"}},
        {"render.renderer", {"render.renderer=none"}},
        {"render.width", {"render.width=48"}},
        {"render.height", {"render.height=40"}},
        {"render.supersample", {"render.supersample=2"}},
        {"render.color_by", {"render.color_by=speed"}},
        {"render.look", {"render.look=foil"}},
        {"render.theta_style", {"render.theta_style=paper_map"}, {"render.color_by=theta"}},
        {"render.tone_map", {"render.tone_map=clamp"}},
        {"render.exposure", {"render.exposure=1"}},
        {"render.color_range", {"render.color_range=[0.0, 0.01]"}, {"render.color_by=speed"}},
        {"render.albedo", {"render.albedo=[0.5, 0.5, 0.5]"}},
        {"render.background", {"render.background=[0.2, 0.2, 0.2]"}, {"render.ground=false"}},
        {"render.ground_color", {"render.ground_color=[0.2, 0.5, 0.2]"}},
        {"render.ground", {"render.ground=false"}},
        {"render.ground_height", {"render.ground_height=0.05"}},
        {"render.spp", {"render.spp=3"}, embree},
        {"render.max_depth", {"render.max_depth=1"}, embree},
        {"render.denoise", {"render.denoise=true"}, embree},
        {"render.material", {"render.material=conductor"}, embree},
        {"render.roughness",
         {"render.roughness=0.1"},
         {"render.renderer=embree", "render.spp=2", "render.material=conductor"}},
        {"render.transmission",
         {"render.transmission=0.5"},
         {"render.renderer=embree", "render.spp=2", "render.material=film"}},
        {"render.sky", {"render.sky=false"}, embree},
        {"render.sun_radius", {"render.sun_radius=10"}, embree},
        {"render.sky_zenith", {"render.sky_zenith=[0.1, 0.1, 0.9]"}, embree},
        {"render.sky_horizon", {"render.sky_horizon=[0.9, 0.1, 0.1]"}, embree},
        {"render.surface", {"render.surface=splat"}},
        {"render.thickness", {"render.thickness=0.01"}},
        {"render.vdb_voxel_size", {"render.vdb_voxel_size=0.005"}, vdb},
        {"render.vdb_particle_radius", {"render.vdb_particle_radius=0.02"}, vdb},
        {"render.vdb_smoothing", {"render.vdb_smoothing=3"}, vdb},
        {"render.vdb_adaptivity", {"render.vdb_adaptivity=0.5"}, vdb},
        {"output.stats", {"output.stats=false"}},
        {"output.exr", {"output.exr=true"}, embree},
        {"output.export", {"output.export=[\"ply\"]"}},
    };
}

/// Every key the README's table lists, by parsing schemaMarkdown()'s first column.
std::set<std::string> documentedKeys() {
    std::set<std::string> keys;
    std::istringstream table(scene::schemaMarkdown());
    for (std::string line; std::getline(table, line);) {
        if (line.rfind("| `", 0) != 0) continue;
        keys.insert(line.substr(3, line.find('`', 3) - 3));
    }
    return keys;
}

std::string readFile(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

/// run.json without what varies between identical runs (timings, threads) or merely echoes
/// the input (the scene's path, the resolved scene).
std::string runJsonWithoutTimings(const fs::path& file) {
    std::istringstream in(readFile(file));
    std::string kept;
    for (std::string line; std::getline(in, line);) {
        if (line.find("\"resolved_scene\"") != std::string::npos) break;
        if (line.find("wall_seconds") != std::string::npos ||
            line.find("ns_per_particle_step") != std::string::npos ||
            line.find("\"threads\"") != std::string::npos ||
            line.find("\"scene\"") != std::string::npos)
            continue;
        kept += line + "\n";
    }
    return kept;
}

/// What a run produced, or the error that stopped it.
std::string fingerprint(const std::string& text, const std::vector<std::string>& sets,
                        bool setUpOnly, const fs::path& dir) {
    fs::remove_all(dir);
    fs::create_directories(dir);
    std::ofstream(dir / "scene.toml") << text;
    try {
        const Scene scene = loadScene(dir / "scene.toml", sets);
        if (setUpOnly) {
            prepareMembrane(scene);
            return "set up";
        }
        RunOptions options;
        options.outDir = dir / "out";
        runScene(scene, options);
        std::string print = "name " + scene.sim.material.name + "\n";
        for (const auto& entry : fs::recursive_directory_iterator(options.outDir)) {
            if (!entry.is_regular_file()) continue;
            const std::string name = fs::relative(entry.path(), options.outDir).string();
            print +=
                name + "\n" +
                (name == "run.json" ? runJsonWithoutTimings(entry.path()) : readFile(entry.path()));
        }
        return print;
    } catch (const std::exception& e) {
        return std::string("error ") + e.what();
    }
}

}  // namespace

TEST(EveryKey, HasAVariationInThisTest) {
    std::set<std::string> covered;
    for (const Variation& v : variations()) covered.insert(v.key);
    for (const std::string& key : documentedKeys()) EXPECT_TRUE(covered.contains(key)) << key;
    for (const std::string& key : covered)
        EXPECT_TRUE(documentedKeys().contains(key)) << key << " is not in the schema";
}

TEST(EveryKey, ChangesTheRunOrItsOutput) {
    const fs::path root = test::scratchDir();
    // The control: the same scene twice gives the same fingerprint, frames included.
    const std::string base = fingerprint(kBase, {}, false, root);
    ASSERT_EQ(base, fingerprint(kBase, {}, false, root));
    ASSERT_NE(base.find("frames/frame_0002.png"), std::string::npos) << base.substr(0, 300);
    ASSERT_NE(base.find("stats.csv"), std::string::npos);
    for (const Variation& v : variations()) {
        std::string text = kBase;
        if (!v.edit.first.empty())
            text.replace(text.find(v.edit.first), v.edit.first.size(), v.edit.second);
        std::vector<std::string> variant = v.context;
        variant.insert(variant.end(), v.sets.begin(), v.sets.end());
        const std::string before = fingerprint(text, v.context, v.setUpOnly, root);
        const std::string after = fingerprint(text, variant, v.setUpOnly, root);
        EXPECT_NE(before, after) << v.key << " changed nothing";
        EXPECT_EQ(after.rfind("error", 0), std::string::npos) << v.key << ": " << after;
    }
}
