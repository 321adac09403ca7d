#pragma once
// A validated scene: everything `rend run` needs, with every value range-checked at load.

#include <filesystem>
#include <string>
#include <vector>

#include "render/RenderSettings.h"
#include "sim/Params.h"

namespace rend {

enum class RendererKind { Osmesa, None, Embree };

/// Per-frame files besides the PNG: meshes through assimp, level sets through OpenVDB.
enum class ExportFormat { Ply, Obj, Glb, Vdb };

struct Scene {
    std::filesystem::path file;  ///< the scene file as given
    sim::MembraneParams sim;
    render::RenderSettings render;
    RendererKind renderer = RendererKind::Osmesa;
    bool writeStats = true;
    std::vector<ExportFormat> exports;  ///< [output] export, in the order given

    /// "file:line:column" of the time.dt value (or of [time] when dt is "auto"), so the
    /// pipeline can point at it when dt exceeds the stable bound.
    std::string dtLocation;

    /// The resolved scene (preset merged, --set applied) as JSON, for run.json.
    std::string resolvedJson;

    int frameCount() const;  ///< round(duration * fps), at least 1
};

/// Parses and validates a scene file; `overrides` are "key.path=value" strings from --set,
/// applied before validation with the same checks. Throws SceneError.
Scene loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

/// Directory holding materials/*.toml: $REND_ASSETS if set, else the source tree's assets/.
std::filesystem::path assetsDirectory();

}  // namespace rend
