#pragma once
// The scene as a TOML document before validation: the file parsed, the --set overrides applied
// and the material preset merged. Every node keeps where it came from (scene file, preset file
// or --set), so validation can point at the exact source of a bad value.

#include <toml++/toml.h>

#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace rend::scene {

/// Parses a TOML file; a missing file, one past the limits of app/DocumentLimits.h or a syntax
/// error becomes a SceneError naming it. `what` names the file in the message ("scene file",
/// "material preset"); `baseDepth` counts the levels its values will sit under.
toml::table parseTomlFile(const std::filesystem::path& file, std::string_view what,
                          int baseDepth = 0);

/// Applies one "dotted.key=value" override. An integer segment indexes an array (0-based);
/// missing tables on the way are created, so unknown keys fail later like any other.
void applyOverride(toml::table& document, std::string_view override);

/// Fills [material] from assets/materials/<preset>.toml; keys already in [material] win.
void mergeMaterialPreset(toml::table& document, const std::filesystem::path& assets);

toml::table buildSceneDocument(const std::filesystem::path& file,
                               const std::vector<std::string>& overrides,
                               const std::filesystem::path& assets);

}  // namespace rend::scene
