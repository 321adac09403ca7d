// The scene schema: every key of every table, declared once with its type, range, default,
// meaning and an example. SceneLoader.cpp reads by key name through TableReader, which refuses
// any key not declared here; the README's scene-file table is schemaMarkdown()'s output.
//
// Ranges are physical sanity bounds, upper ones included, so that no product of accepted values
// (substeps, frames, particle counts, blow-up limits) can overflow: speeds stay below 1 km/s,
// accelerations below 1000 g, lengths within 10 km, times within 1e6 s.

#include <string>

#include "app/SceneNames.h"
#include "app/SceneReader.h"
#include "sim/SolverRegistry.h"

namespace rend::scene {
namespace {

using T = ValueType;
constexpr Range closed(double lo, double hi) { return Range::closed(lo, hi); }
constexpr Range positive(double hi) { return Range::openClosed(0.0, hi); }

constexpr Range kLength = closed(-1e4, 1e4);  ///< coordinates in metres
constexpr Range kUnit = closed(0.0, 1.0);
constexpr Range kTime = closed(0.0, 1e6);  ///< seconds
constexpr Range kTheta = closed(-1e6, 1e6);
constexpr Range kRate = closed(-1e9, 1e9);
constexpr Range kSeed = closed(0.0, 9e18);  ///< below 2^63

// Not constexpr: the solver names are the registry's (sim/SolverRegistry.h).
const Param kRoot[] = {
    {"solver",
     T::Choice,
     {},
     "\"peridynamic\"",
     "the discretisation of the membrane (see Solvers)",
     "\"fem_cst\"",
     sim::solverNames()},
    {"sheet", T::Table, {}, "", "the membrane's outline and lattice", "", {}, "sheet"},
    {"material", T::Table, {}, "", "the membrane's material", "", {}, "material"},
    {"boundary", T::Tables, {}, "", "a boundary condition", "", {}, "boundary"},
    {"notch", T::Tables, {}, "", "a pre-cut crack", "", {}, "notch"},
    {"diffusion",
     T::Table,
     {},
     "",
     "the diffusive quantity theta (acid, heat, moisture)",
     "",
     {},
     "diffusion"},
    {"forces", T::Table, {}, "", "external forces", "", {}, "forces"},
    {"mpm", T::Table, {}, "", "the MPM solver's background grid", "", {}, "mpm"},
    {"remesh",
     T::Table,
     {},
     "",
     "seed 004's remeshing of the particle solvers (peridynamic, sph)",
     "",
     {},
     "remesh"},
    {"contact", T::Table, {}, "", "the ground and self-contact", "", {}, "contact"},
    {"collider", T::Tables, {}, "", "a kinematic collider", "", {}, "collider"},
    {"time", T::Table, {}, "", "time stepping", "", {}, "time"},
    {"camera", T::Table, {}, "", "the camera", "", {}, "camera"},
    {"light", T::Table, {}, "", "the lighting", "", {}, "light"},
    {"render", T::Table, {}, "", "image settings", "", {}, "render"},
    {"output", T::Table, {}, "", "output options", "", {}, "output"},
};

constexpr Param kSheet[] = {
    {"shape",
     T::Choice,
     {},
     "\"rectangle\"",
     "the sheet's outline (sphere: closed, for inflation)",
     "\"rectangle\"",
     names::kShapes},
    {"size", T::Vec2, positive(1e4), "required for a rectangle",
     "the rectangle's extent [x, y] in metres", "[2.0, 2.0]"},
    {"radius", T::Number, positive(1e4), "required for a disc or sphere",
     "the disc or sphere radius in metres", "1.0"},
    {"center", T::Vec3, kLength, "[0, 0, 0]",
     "the sheet's centre [x, y, z] in metres; at rest it lies in the plane z = center.z",
     "[0.0, 0.0, 0.0]"},
    {"lattice",
     T::Choice,
     {},
     "\"hexagonal\"",
     "the particle arrangement",
     "\"hexagonal\"",
     names::kLattices},
    {"dx", T::Number, closed(1e-6, 1e3), "required",
     "the particle spacing in metres at quality = \"preview\"", "0.02"},
    {"quality",
     T::Choice,
     {},
     "\"preview\"",
     "the resolution: preview runs at dx, final at dx_final (rend run --quality wins)",
     "\"final\"",
     names::kQualities},
    {"dx_final", T::Number, closed(1e-6, 1e3), "the coarsest giving 250,000 particles",
     "the particle spacing in metres at quality = \"final\"", "0.004"},
    {"horizon", T::Number, Range::openClosed(1.0, 6.0), "1.5",
     "the bond cutoff R in units of dx (the paper's is 1.5)", "1.5"},
    {"thickness", T::Number, closed(1e-9, 10.0), "0.001", "the membrane thickness h in metres",
     "0.001"},
    {"perturbation", T::Number, closed(0.0, 1e4), "0",
     "the amplitude of a seeded out-of-plane jitter at rest in metres", "1e-4"},
    {"seed", T::Integer, kSeed, "1", "the jitter's random seed", "7"},
};

constexpr Param kMaterialMap[] = {
    {"property",
     T::Choice,
     {},
     "required",
     "what the map multiplies",
     "\"E\"",
     names::kMappedProperties},
    {"shape",
     T::Choice,
     {},
     "required",
     "where: a region (factor inside, 1 outside), a noise field, or an image",
     "\"disc\"",
     names::kMapShapes},
    {"factor", T::Number, positive(1e6), "required for a box, disc or polygon",
     "the factor inside the region", "0.2"},
    {"min", T::Vec2, kLength, "required for a box", "the box's lower corner [x, y] in metres",
     "[-1.0, -1.0]"},
    {"max", T::Vec2, kLength, "required for a box", "the box's upper corner [x, y] in metres",
     "[0.0, 1.0]"},
    {"center", T::Vec2, kLength, "required for a disc", "the disc's centre [x, y] in metres",
     "[0.0, 0.0]"},
    {"radius", T::Number, positive(1e4), "required for a disc", "the disc's radius in metres",
     "0.3"},
    {"points", T::Points, kLength, "required for a polygon",
     "the polygon's corners [[x, y], ...] in rest coordinates, metres",
     "[[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]"},
    // At least a micrometre: the noise's lattice index (coordinate / scale, 2^7 times finer at
    // the last octave) must stay a 64-bit integer.
    {"scale", T::Vec2, closed(1e-6, 1e4), "[0.1, 0.1]",
     "the noise's cell size along x and y in metres (unequal: fibres)", "[0.2, 0.02]"},
    {"amplitude", T::Number, closed(0.0, 0.99), "0.5", "the noise's factor spans 1 +- amplitude",
     "0.6"},
    {"octaves", T::Integer, closed(1, 8), "4", "noise octaves, each half the cell and amplitude",
     "4"},
    {"seed", T::Integer, kSeed, "1", "the noise's random seed", "7"},
    {"file",
     T::String,
     {},
     "required for an image",
     "a greyscale PNG spread over the sheet's rest bounds, relative to the scene file",
     "\"fibres.png\""},
    {"low", T::Number, positive(1e6), "0.5", "the image's factor where black", "0.5"},
    {"high", T::Number, positive(1e6), "1.5", "the image's factor where white", "1.5"},
};

constexpr Param kMaterial[] = {
    {"preset",
     T::String,
     {},
     "none",
     "a file assets/materials/NAME.toml whose keys apply unless given here",
     "\"stretch_sheet\""},
    {"name", T::String, {}, "the preset, else \"custom\"", "the material's name", "\"rubber\""},
    {"E", T::Number, closed(1e-3, 1e13), "required", "Young's modulus in Pa", "2e4"},
    {"poisson", T::Number, Range::open(-1.0, 0.5), "0.3",
     "Poisson's ratio (bond-based peridynamics fixes 1/3 unless micromodulus = \"paper\")", "0.3"},
    {"density", T::Number, closed(1e-3, 1e6), "required", "the density in kg/m^3", "5000"},
    {"micromodulus",
     T::Choice,
     {},
     "\"calibrated\"",
     "how the bond stiffness is derived",
     "\"calibrated\"",
     names::kMicromoduli},
    {"law",
     T::Choice,
     {},
     "\"linear\"",
     "the bond law: eq. 18, 19 or 20 of the membrane paper",
     "\"linear\"",
     names::kLaws},
    {"power_ratio", T::Number, closed(-1e6, 0.0), "0", "c*/c of the power law, eq. 19", "-0.1"},
    {"power_exponent", T::Number, Range::openClosed(1.0, 100.0), "4",
     "the exponent n of the power law, eq. 19", "4"},
    {"yield_strain", T::Number, positive(10.0), "1e-4", "the elastic limit eta0 of eqs. 20 and 27",
     "1e-4"},
    {"softening", T::Number, positive(1e6), "1",
     "beta of eqs. 20 and 27, the post-yield decay, at the preview spacing (a crack band scales it "
     "with dx / dx_preview at final quality)",
     "1.0"},
    {"fracture_energy", T::NumberOrWord, positive(1e9), "\"none\" (unbreakable)",
     "the fracture energy G_f in J/m^2", "11.3", names::kNone},
    {"critical_stretch",
     T::Choice,
     {},
     "\"calibrated\"",
     "how the critical stretch follows from G_f (\"paper\": eq. 28 as printed; \"preview\": the "
     "preview spacing's at every quality; \"midway\": the geometric mean of the two)",
     "\"calibrated\"",
     names::kCriticalStretches},
    {"strength_loss", T::Number, closed(0.0, 1e6), "0",
     "the critical stretch lost per unit theta (acid, moisture)", "0.6"},
    {"surface_correction",
     T::Boolean,
     {},
     "false",
     "whether edge particles are stiffened to the interior's",
     "true"},
    {"capacity", T::Number, closed(1e-9, 1e9), "1", "the diffusive capacity C of eq. 25", "1.0"},
    {"conductivity", T::Number, closed(0.0, 1e9), "0 (no diffusion)",
     "the coefficient of diffusion k of eq. 25", "0.01"},
    {"expansion", T::Number, closed(-10.0, 10.0), "0", "alpha, the strain per unit theta", "0.3"},
    {"stiffness_loss", T::Number, closed(0.0, 1e6), "0", "the stiffness lost per unit theta",
     "0.5"},
    {"map",
     T::Tables,
     {},
     "",
     "a factor over the sheet for E, fracture_energy or density",
     "",
     {},
     "material.map"},
};

// The region keys of [[boundary]] and [[diffusion.edge]].
constexpr Param kEdge{"edge",
                      T::Choice,
                      {},
                      "required unless box",
                      "a strip along a side of the sheet's rest bounding box",
                      "\"left\"",
                      names::kEdges};
constexpr Param kDepth{"depth",
                       T::Number,
                       positive(1e4),
                       "the sheet's dx (its preview spacing)",
                       "the strip width in metres",
                       "0.02"};
constexpr Param kBoundaryBox{"box",
                             T::Table,
                             {},
                             "instead of edge",
                             "a region's corners in rest coordinates",
                             "{ min = [-1.0, -1.0], max = [-0.9, 1.0] }",
                             {},
                             "boundary.box"};

constexpr Param kBoundary[] = {
    {"type",
     T::Choice,
     {},
     "required",
     "the kind of condition",
     "\"velocity\"",
     names::kBoundaryTypes},
    kEdge,
    kDepth,
    kBoundaryBox,
    {"velocity", T::Vec3, closed(-1e3, 1e3), "required for type = \"velocity\"",
     "the prescribed velocity [x, y, z] in m/s", "[0.15, 0.0, 0.0]"},
    {"ramp", T::Number, kTime, "0", "seconds to reach full speed from rest", "0.5"},
};

constexpr Param kBox[] = {
    {"min", T::Vec2, kLength, "required", "the box's lower corner [x, y] in metres",
     "[-1.0, -1.0]"},
    {"max", T::Vec2, kLength, "required", "the box's upper corner [x, y] in metres", "[-0.9, 1.0]"},
};

constexpr Param kNotch[] = {
    {"points", T::Points, kLength, "required",
     "the notch polyline in rest coordinates, metres; bonds crossing it break at set-up",
     "[[-1.0, 0.0], [-0.6, 0.0]]"},
};

constexpr Param kDiffusion[] = {
    {"initial", T::Number, kTheta, "0", "theta everywhere at t = 0", "0.0"},
    {"spot", T::Tables, {}, "", "a source of theta", "", {}, "diffusion.spot"},
    {"scatter",
     T::Tables,
     {},
     "",
     "seeded spots or a spray of droplets",
     "",
     {},
     "diffusion.scatter"},
    {"edge", T::Tables, {}, "", "theta held on a region", "", {}, "diffusion.edge"},
};

// The source keys of [[diffusion.spot]] and [[diffusion.scatter]].
constexpr Param kSourceRadius{
    "radius", T::Number, positive(1e4), "required", "the source's radius in metres", "0.05"};
constexpr Param kSourceRate{
    "rate", T::Number, kRate, "required", "theta added per second inside it (negative: a sink)",
    "1.0"};
constexpr Param kSourceStart{"start", T::Number, kTime, "0", "the time in seconds it switches on",
                             "0.0"};
constexpr Param kSourceDuration{
    "duration", T::Number, positive(1e6), "forever", "how many seconds it stays on", "2.0"};

constexpr Param kSpot[] = {
    {"center", T::Vec2, kLength, "required", "the spot's centre [x, y] in rest coordinates, metres",
     "[0.0, 0.0]"},
    kSourceRadius,
    kSourceRate,
    kSourceStart,
    kSourceDuration,
};

constexpr Param kScatter[] = {
    {"count", T::Integer, closed(1, 1e4), "required", "how many spots or droplets", "20"},
    kSourceRadius,
    kSourceRate,
    kSourceStart,
    {"spread", T::Number, kTime, "0", "seconds over which droplets are emitted; 0: all at once",
     "3.0"},
    kSourceDuration,
    {"seed", T::Integer, kSeed, "1", "the placement's random seed", "1"},
};

constexpr Param kDiffusionEdge[] = {
    kEdge,
    kDepth,
    {"box",
     T::Table,
     {},
     "instead of edge",
     "a region's corners in rest coordinates",
     "{ min = [-1.0, -1.0], max = [-0.9, 1.0] }",
     {},
     "diffusion.edge.box"},
    {"value", T::Number, kTheta, "required", "the theta held on the region", "1.0"},
};

constexpr Param kForces[] = {
    {"gravity", T::Vec3, closed(-1e4, 1e4), "[0, 0, 0]",
     "the gravitational acceleration [x, y, z] in m/s^2", "[0.0, 0.0, -9.81]"},
    {"damping", T::Number, closed(0.0, 1e6), "0", "the mass-proportional velocity damping in 1/s",
     "0.1"},
    {"pressure", T::Number, kRate, "0", "a uniform follower pressure on the +z side in Pa",
     "100.0"},
};

constexpr Param kMpm[] = {
    {"grid", T::Number, closed(0.25, 8.0), "0.5",
     "the background grid's spacing over `sheet.dx` (read by `solver = \"mpm\"` only); at 1 "
     "or more the grid has fewer nodes than the sheet has particles and locks part of the "
     "motion",
     "1.0"},
    {"enrich",
     T::Boolean,
     {},
     "true",
     "seed 002's enrichment: particles in the grid cells of a material boundary or a crack "
     "are solved on their own domains, not averaged by the grid",
     "false"},
};

constexpr Param kRemesh[] = {
    {"every", T::Integer, closed(1.0, 1e6), "never",
     "steps between remeshes: positions and velocities refitted with the M4' kernel over each "
     "particle's intact bonds in rest coordinates",
     "10"},
};

constexpr Range kFriction = closed(0.0, 10.0);

constexpr Param kContact[] = {
    {"ground",
     T::Boolean,
     {},
     "as `render.ground`",
     "whether the ground plane at `render.ground_height` stops the sheet",
     "true"},
    {"ground_friction", T::Number, kFriction, "0.5",
     "the ground's kinetic Coulomb friction coefficient", "0.8"},
    {"ground_static_friction", T::Number, kFriction, "ground_friction",
     "the ground's static friction coefficient", "1.0"},
    {"self",
     T::Boolean,
     {},
     "false",
     "whether the sheet collides with itself (torn pieces, folds)",
     "true"},
    {"thickness", T::Number, positive(1e4), "dx / 2, at least the sheet's thickness",
     "the contact thickness d in metres: particles and triangles of the sheet keep d apart, "
     "and d / 2 off colliders and the ground",
     "0.005"},
    {"friction", T::Number, kFriction, "0.3", "the self-contact's kinetic friction coefficient",
     "0.5"},
    {"static_friction", T::Number, kFriction, "friction",
     "the self-contact's static friction coefficient", "0.6"},
};

constexpr Param kCollider[] = {
    {"shape",
     T::Choice,
     {},
     "required",
     "the collider's shape",
     "\"sphere\"",
     names::kColliderShapes},
    {"radius", T::Number, positive(1e4), "required for a sphere or capsule",
     "the sphere's or capsule's radius in metres", "0.3"},
    {"size", T::Vec3, positive(1e4), "required for a box",
     "the box's full extents [x, y, z] in metres", "[1.0, 1.0, 0.2]"},
    {"length", T::Number, positive(1e4), "required for a capsule",
     "the capsule's segment length along its local z in metres", "0.5"},
    {"file",
     T::String,
     {},
     "required for a mesh",
     "a closed triangle mesh (OBJ, PLY, glTF, GLB), relative to the scene file",
     "\"rock.obj\""},
    {"scale", T::Number, positive(1e4), "1", "the mesh's scale", "0.01"},
    {"position", T::Vec3, kLength, "[0, 0, 0]",
     "the collider's origin at t = 0 [x, y, z] in metres", "[0.0, 0.0, -0.3]"},
    {"rotation", T::Vec3, closed(-36000, 36000), "[0, 0, 0]",
     "the rotation at t = 0 in degrees about x, then y, then z (world axes)", "[90.0, 0.0, 0.0]"},
    {"velocity", T::Vec3, closed(-1e3, 1e3), "[0, 0, 0]",
     "a constant velocity [x, y, z] in m/s (without keyframes)", "[0.0, 0.0, 0.5]"},
    {"spin", T::Vec3, closed(-36000, 36000), "[0, 0, 0]",
     "a constant angular velocity about the world axes through the origin, in degrees per second "
     "(without keyframes)",
     "[0.0, 0.0, 90.0]"},
    {"keyframe",
     T::Tables,
     {},
     "",
     "a keyed pose; between keys the collider moves linearly",
     "",
     {},
     "collider.keyframe"},
    {"friction", T::Number, kFriction, "0.5", "the kinetic Coulomb friction coefficient", "0.3"},
    {"static_friction", T::Number, kFriction, "friction", "the static friction coefficient", "0.4"},
    {"color", T::Vec3, kUnit, "[0.62, 0.60, 0.56]", "the colour the renderers draw it in, linear",
     "[0.3, 0.35, 0.4]"},
    {"roughness", T::Number, kUnit, "0.6", "a metal collider's roughness in the path tracer",
     "0.3"},
    {"metal",
     T::Boolean,
     {},
     "false",
     "a metal (rough conductor) instead of a diffuse surface",
     "true"},
};

constexpr Param kKeyframe[] = {
    {"time", T::Number, kTime, "required", "the key's time in seconds", "1.0"},
    {"position", T::Vec3, kLength, "the collider's position", "the origin at that time",
     "[0.0, 0.0, 0.2]"},
    {"rotation", T::Vec3, closed(-36000, 36000), "the collider's rotation",
     "the rotation at that time in degrees about x, then y, then z", "[0.0, 0.0, 45.0]"},
};

constexpr Param kTimeKeys[] = {
    {"dt", T::NumberOrWord, positive(10.0), "\"adaptive\" (see the README's time step)",
     "the time step in seconds (fixed); \"auto\": safety x the stable bound, fixed; "
     "\"adaptive\": min(safety, 0.5) x the current bound, cut where bonds stretch fast or break "
     "in bursts",
     "3e-4", names::kStepWords},
    {"safety", T::Number, Range::openClosed(0.0, 1.0), "0.8",
     "the fraction of the stable time step used by dt = \"auto\"; \"adaptive\" takes at most "
     "0.5 of it, lower when set lower",
     "0.8"},
    {"max_stretch_increment", T::Number, Range::openClosed(0.0, 1.0), "0.02",
     "adaptive dt: near breaking, the most one step may stretch a loaded bond, as a fraction of "
     "its critical stretch (farther away, a step may close half the bond's way to breaking)",
     "0.05"},
    {"burst_bonds", T::Integer, closed(1, 1e6), "8",
     "adaptive dt: a step that breaks more bonds shrinks the next (by the excess, regrowing "
     "1.25x per step)",
     "4"},
    {"duration", T::Number, positive(1e6), "5", "the simulated time in seconds", "5.0"},
    {"fps", T::Number, closed(1e-3, 1e4), "24", "the output frames per simulated second", "24"},
    {"allow_unstable",
     T::Boolean,
     {},
     "false",
     "expert: accept a dt above the stable bound (the blow-up guard still runs)",
     "false"},
    {"allow_slow",
     T::Boolean,
     {},
     "false",
     "run even when the estimated cost is beyond the limit",
     "true"},
    {"integrator",
     T::Choice,
     {},
     "\"symplectic_euler\"",
     "the explicit scheme (eq. 26)",
     "\"velocity_verlet\"",
     names::kIntegrators},
};

constexpr Param kCamera[] = {
    {"position", T::Vec3, kLength, "frames the sheet from the front and above",
     "the camera position [x, y, z] in metres", "[0.0, -4.0, 3.0]"},
    {"look_at", T::Vec3, kLength, "the sheet's centre",
     "the point the camera aims at [x, y, z] in metres", "[0.0, 0.0, 0.0]"},
    {"up", T::Vec3, kLength, "[0, 0, 1]", "the camera's up direction [x, y, z]", "[0.0, 0.0, 1.0]"},
    {"fov", T::Number, Range::open(1.0, 170.0), "40", "the vertical field of view in degrees",
     "40"},
};

constexpr Param kLight[] = {
    {"direction", T::Vec3, kLength, "[-0.4, -0.5, 1]", "from the surface towards the sun [x, y, z]",
     "[-0.4, -0.5, 1.0]"},
    {"color", T::Vec3, closed(0.0, 1e3), "[1, 1, 1]", "the sun's colour [r, g, b]",
     "[1.0, 1.0, 1.0]"},
    {"intensity", T::Number, closed(0.0, 1e3), "0.85", "the sun's strength", "0.85"},
    {"ambient", T::Number, kUnit, "0.25", "the ambient light level", "0.25"},
};

constexpr Param kRender[] = {
    {"renderer", T::Choice, {}, "\"osmesa\"", "the renderer", "\"osmesa\"", names::kRenderers},
    {"width", T::Integer, closed(16, 8192), "960", "the image width in pixels", "960"},
    {"height", T::Integer, closed(16, 8192), "540", "the image height in pixels", "540"},
    {"supersample", T::Integer, closed(1, 4), "2", "samples per pixel along each axis", "2"},
    {"look",
     T::Choice,
     {},
     "\"plain\"",
     "the material preset (foil: aluminium; film: amber rubber; seaweed: nori; paper: paper "
     "towel); material, albedo, roughness and transmission default to it",
     "\"foil\"",
     names::kLooks},
    {"color_by",
     T::Choice,
     {},
     "\"none\"",
     "what the surface colour shows (theta: see theta_style; strain: mean bond strain; speed, "
     "strain and damage replace the look's colour)",
     "\"theta\"",
     names::kColorModes},
    {"theta_style",
     T::Choice,
     {},
     "\"layer\"",
     "how color_by = \"theta\" shows: a layer on the look (heat tint, damp, etch, wet) or the "
     "paper's light-to-dark-red map replacing the colour",
     "\"paper_map\"",
     names::kThetaStyles},
    {"tone_map",
     T::Choice,
     {},
     "\"filmic\"",
     "linear light to display: an ACES-like filmic curve that rolls highlights off, or a clamp",
     "\"filmic\"",
     names::kToneMaps},
    {"exposure", T::Number, closed(-16.0, 16.0), "0",
     "the exposure in stops (light is scaled by 2^exposure before the tone curve)", "0.5"},
    {"color_range", T::Vec2, closed(-1e9, 1e9), "0 .. each frame's maximum",
     "the values mapped to the ends of the colour map", "[0.0, 0.6]"},
    {"albedo", T::Vec3, kUnit, "[0.78, 0.80, 0.85]", "the surface colour [r, g, b], linear",
     "[0.78, 0.80, 0.85]"},
    {"background", T::Vec3, kUnit, "[0.80, 0.84, 0.90]", "the sky colour [r, g, b], linear",
     "[0.80, 0.84, 0.90]"},
    {"ground_color", T::Vec3, kUnit, "[0.55, 0.55, 0.52]", "the ground colour [r, g, b], linear",
     "[0.55, 0.55, 0.52]"},
    {"ground", T::Boolean, {}, "true", "whether to draw the ground plane", "true"},
    {"ground_height", T::Number, kLength, "half the sheet's size below it",
     "the ground plane's z in metres", "-0.5"},
    {"spp", T::Integer, closed(1, 4096), "16", "path-traced samples per pixel (embree)", "16"},
    {"max_depth", T::Integer, closed(1, 64), "4", "the longest light path in bounces (embree)",
     "4"},
    {"denoise",
     T::Boolean,
     {},
     "false",
     "filter the path-traced noise, keeping edges by each pixel's normal, depth and colour "
     "(embree; few samples then look like many)",
     "true"},
    {"material",
     T::Choice,
     {},
     "\"diffuse\"",
     "how the path tracer shades the sheet",
     "\"conductor\"",
     names::kMaterials},
    {"roughness", T::Number, closed(0.01, 1.0), "0.35",
     "the surface roughness (GGX alpha = roughness^2)", "0.35"},
    {"transmission", T::Number, kUnit, "0", "the fraction of light passing through", "0.3"},
    {"sky", T::Boolean, {}, "true", "a sky gradient instead of the constant background", "true"},
    {"sun_radius", T::Number, closed(0.0, 30.0), "2", "the sun's angular radius in degrees", "2.0"},
    {"sky_zenith", T::Vec3, closed(0.0, 10.0), "[0.35, 0.50, 0.80]",
     "the sky colour overhead [r, g, b]", "[0.35, 0.50, 0.80]"},
    {"sky_horizon", T::Vec3, closed(0.0, 10.0), "[0.85, 0.88, 0.92]",
     "the sky colour at the horizon [r, g, b]", "[0.85, 0.88, 0.92]"},
    {"surface",
     T::Choice,
     {},
     "\"lattice\"",
     "how each frame becomes a surface",
     "\"lattice\"",
     names::kSurfaces},
    {"thickness", T::Number, closed(0.0, 100.0), "0",
     "the lattice surface's extruded thickness in metres", "0.002"},
    {"vdb_voxel_size", T::Number, closed(0.0, 1e3), "0 (dx / 2)",
     "the level set's voxel size in metres (the vdb surface's, and the --export vdb volume's: "
     "it holds the sheet's thickness down to 2 voxels)",
     "0.01"},
    {"vdb_particle_radius", T::Number, closed(0.0, 1e3), "0 (0.75 dx)",
     "the particle radius in metres", "0.015"},
    {"vdb_smoothing", T::Integer, closed(0, 20), "1", "level-set smoothing iterations", "1"},
    {"vdb_adaptivity", T::Number, kUnit, "0.1", "volumeToMesh adaptivity", "0.1"},
};

constexpr Param kOutput[] = {
    {"stats", T::Boolean, {}, "true", "whether to write stats.csv", "true"},
    {"exr",
     T::Boolean,
     {},
     "false",
     "whether to write frames/frame_N.exr beside each PNG: linear half-float R, G, B before the "
     "tone curve, and Z (camera distance, float), N.X, N.Y, N.Z (world normal) and theta of the "
     "first hit; path tracer only",
     "true"},
    {"export",
     T::ChoiceList,
     {},
     "[]",
     "per-frame files besides the PNG",
     "[\"ply\", \"vdb\"]",
     names::kExportFormats},
};

const Section kSchema[] = {
    {"", "the top-level table", kRoot},
    {"sheet", "[sheet]", kSheet},
    {"material", "[material]", kMaterial},
    {"material.map", "[[material.map]]", kMaterialMap},
    {"boundary", "[[boundary]]", kBoundary},
    {"boundary.box", "box", kBox},
    {"notch", "[[notch]]", kNotch},
    {"diffusion", "[diffusion]", kDiffusion},
    {"diffusion.spot", "[[diffusion.spot]]", kSpot},
    {"diffusion.scatter", "[[diffusion.scatter]]", kScatter},
    {"diffusion.edge", "[[diffusion.edge]]", kDiffusionEdge},
    {"diffusion.edge.box", "box", kBox},
    {"forces", "[forces]", kForces},
    {"mpm", "[mpm]", kMpm},
    {"remesh", "[remesh]", kRemesh},
    {"contact", "[contact]", kContact},
    {"collider", "[[collider]]", kCollider},
    {"collider.keyframe", "[[collider.keyframe]]", kKeyframe},
    {"time", "[time]", kTimeKeys},
    {"camera", "[camera]", kCamera},
    {"light", "[light]", kLight},
    {"render", "[render]", kRender},
    {"output", "[output]", kOutput},
};

std::string quotedNames(std::span<const std::string_view> names) {
    std::string out;
    for (std::size_t k = 0; k < names.size(); ++k) {
        out += (k == 0 ? "" : k + 1 == names.size() ? " or " : ", ");
        out += "`\"" + std::string(names[k]) + "\"`";
    }
    return out;
}

std::string typeText(const Param& p) {
    const std::string bounds = p.range.describe();
    const std::string within = bounds.empty() ? "" : " " + bounds;
    switch (p.type) {
        case T::Number:
            return "number" + within;
        case T::Integer:
            return "integer" + within;
        case T::Boolean:
            return "`true` or `false`";
        case T::String:
            return "string";
        case T::Choice:
            return quotedNames(p.names);
        case T::NumberOrWord:
            return "number" + within + " or " + quotedNames(p.names);
        case T::Vec2:
            return "[x, y]" + within;
        case T::Vec3:
            return "[x, y, z]" + within;
        case T::Points:
            return "[[x, y], ...]" + within;
        case T::ChoiceList:
            return "array of " + quotedNames(p.names);
        case T::Table:
        case T::Tables:
            break;
    }
    return "table";
}

void appendRows(const Section& section, const std::string& prefix, std::string& out) {
    for (const Param& p : section.keys) {
        const std::string key = prefix + std::string(p.key);
        if (p.type == T::Table) {
            appendRows(sectionAt(p.section), key + ".", out);
        } else if (p.type == T::Tables) {
            appendRows(sectionAt(p.section), key + "[].", out);
        } else {
            out += "| `" + key + "` | " + typeText(p) + " | " + std::string(p.fallback) + " | " +
                   std::string(p.meaning) + " |\n";
        }
    }
}

}  // namespace

std::span<const Section> sceneSchema() { return kSchema; }

std::string schemaMarkdown() {
    std::string out = "| key | value | default | meaning |\n|---|---|---|---|\n";
    appendRows(kSchema[0], "", out);
    return out;
}

}  // namespace rend::scene
