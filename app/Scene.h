#pragma once
// A validated scene: everything `rend run` needs, with every value range-checked at load.

#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "render/RenderSettings.h"
#include "sim/Params.h"

namespace rend {

enum class RendererKind { Osmesa, None, Embree };

/// The resolution a scene runs at: preview at [sheet] dx, final at dx_final (names::kQualities).
enum class Quality { Preview, Final };

/// Particles per sheet that quality = "final" asks for at least.
inline constexpr std::size_t kFinalParticles = 250000;

/// Per-frame files besides the PNG: meshes through assimp, level sets through OpenVDB.
enum class ExportFormat { Ply, Obj, Glb, Vdb };

struct Scene {
    std::filesystem::path file;          ///< the scene file as given
    std::vector<std::string> overrides;  ///< the --set values (and --quality) it was loaded with
    sim::MembraneParams sim;
    render::RenderSettings render;
    RendererKind renderer = RendererKind::Osmesa;
    bool writeStats = true;
    bool writeExr = false;  ///< [output] exr: frames/frame_N.exr beside each PNG (Embree only)
    std::vector<ExportFormat> exports;  ///< [output] export, in the order given

    Quality quality = Quality::Preview;
    /// [sheet] dx, the preview spacing [m]: the default width of edge strips, and the spacing
    /// seeded draws refer to, so both stay put in metres at every quality.
    double previewDx = 0.0;

    /// Whether a run estimated beyond the cost limit may start ([time] allow_slow).
    bool allowSlow = false;

    /// "file:line:column" (or "--set '...'") of every value and table read, by dotted key
    /// path ("time.dt", "boundary.1.box", "boundary.1"), so checks made after set-up can point
    /// at what caused them.
    std::map<std::string, std::string, std::less<>> locations;

    /// The resolved scene (preset merged, --set applied) as JSON, for run.json.
    std::string resolvedJson;
    /// A hash of what the simulation depends on: the resolved scene without [render],
    /// [camera], [light] and [output]. A cache is resumed or rendered only under the same one.
    std::uint64_t simulationFingerprint = 0;

    int frameCount() const;  ///< round(duration * fps), at least 1

    /// Where `key` was given; else where its nearest enclosing table was; else the file.
    std::string locationOf(std::string_view key) const;
};

/// What a sheet will cost in memory before it is built: the particle count from the outline's
/// area, the bonds per particle from the horizon (lattice points within R = horizon * dx).
struct SheetEstimate {
    /// Positions, velocities, rest positions, forces, masses, theta and the solvers'
    /// per-particle arrays; measured at about 170 B, rounded up.
    static constexpr double kBytesPerParticle = 400;
    /// Partner, rest length, weight, alive, strength and the solver's per-bond state, each bond
    /// stored from both ends; measured at about 32 B per end, rounded up.
    static constexpr double kBytesPerBondEnd = 40;

    double particles = 0;
    double bondsPerParticle = 0;  ///< bond ends per particle
    double bytes = 0;
};
SheetEstimate estimateSheet(const sim::SheetParams& sheet);

/// Parses and validates a scene file; `overrides` are "key.path=value" strings from --set,
/// applied before validation with the same checks. Throws SceneError.
Scene loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

/// Directory holding materials/*.toml: $REND_ASSETS if set, else the source tree's assets/.
std::filesystem::path assetsDirectory();

}  // namespace rend
