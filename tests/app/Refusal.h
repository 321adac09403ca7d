#pragma once
// What the scene loader refuses a file with, for the tests of its keys.

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "app/Scene.h"
#include "app/SceneError.h"

namespace rend::test {

/// The message loading `scene` with `sets` fails with ("" when it loads).
inline std::string refusalOf(const std::filesystem::path& scene,
                             const std::vector<std::string>& sets = {}) {
    try {
        loadScene(scene, sets);
    } catch (const SceneError& e) {
        return e.what();
    }
    return "";
}

/// The message names scene.toml at `line` and says `fragment`.
inline void expectRefusedAt(const std::string& message, int line, const std::string& fragment) {
    EXPECT_NE(message.find("scene.toml:" + std::to_string(line) + ":"), std::string::npos)
        << message;
    EXPECT_NE(message.find(fragment), std::string::npos) << message;
}

}  // namespace rend::test
