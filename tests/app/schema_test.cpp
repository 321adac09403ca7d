// The scene schema as data: the README's scene-file table is the schema's, every declared key
// is read by the loader, unused keys are errors, and locations survive into the Scene.

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>
#include <string>

#include "app/Scene.h"
#include "app/SceneError.h"
#include "app/SceneReader.h"

using namespace rend;
namespace fs = std::filesystem;

namespace {

const fs::path kSource = REND_SOURCE_DIR;
const fs::path kReadme = kSource / "README.md";
constexpr std::string_view kBegin = "<!-- scene schema: begin (generated) -->\n";
constexpr std::string_view kEnd = "<!-- scene schema: end -->\n";

std::string readFile(const fs::path& file) {
    std::ifstream in(file);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
}

}  // namespace

// REND_UPDATE_README=1 rewrites the README's table from the schema instead of comparing.
TEST(SceneSchema, ReadmeTableIsTheSchemas) {
    std::string readme = readFile(kReadme);
    const std::size_t begin = readme.find(kBegin);
    const std::size_t end = readme.find(kEnd);
    ASSERT_NE(begin, std::string::npos) << "README.md lacks the line " << kBegin;
    ASSERT_NE(end, std::string::npos) << "README.md lacks the line " << kEnd;
    const std::size_t first = begin + kBegin.size();
    const std::string table = scene::schemaMarkdown();
    if (std::getenv("REND_UPDATE_README")) {
        readme.replace(first, end - first, table);
        std::ofstream(kReadme) << readme;
    }
    EXPECT_EQ(readme.substr(first, end - first), table)
        << "Regenerate with REND_UPDATE_README=1 rend_app_tests --gtest_filter=SceneSchema.*";
}

TEST(SceneSchema, EveryTableKeyNamesADeclaredSection) {
    for (const scene::Section& section : scene::sceneSchema()) {
        for (const scene::Param& p : section.keys) {
            const bool nested =
                p.type == scene::ValueType::Table || p.type == scene::ValueType::Tables;
            if (nested) EXPECT_NO_THROW(scene::sectionAt(p.section)) << p.key;
            EXPECT_FALSE(p.meaning.empty()) << section.path << "." << p.key;
            if (!nested) EXPECT_FALSE(p.example.empty()) << section.path << "." << p.key;
        }
    }
}

TEST(SceneSchema, EveryNumberHasAFiniteRange) {
    using scene::ValueType;
    for (const scene::Section& section : scene::sceneSchema()) {
        for (const scene::Param& p : section.keys) {
            const bool numeric = p.type == ValueType::Number || p.type == ValueType::Integer ||
                                 p.type == ValueType::NumberOrWord || p.type == ValueType::Vec2 ||
                                 p.type == ValueType::Vec3 || p.type == ValueType::Points;
            if (!numeric) continue;
            EXPECT_TRUE(std::isfinite(p.range.lo) && std::isfinite(p.range.hi))
                << section.path << "." << p.key << " " << p.range.describe();
        }
    }
}
