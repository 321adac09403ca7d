#include "app/SceneDocument.h"

#include <algorithm>
#include <cctype>
#include <charconv>

#include "app/DocumentLimits.h"
#include "app/SceneError.h"
#include "app/SceneReader.h"

namespace fs = std::filesystem;

namespace rend::scene {
namespace {

constexpr std::string_view kSetExample = "KEY=VALUE, e.g. --set material.E=3e4";

/// Parses TOML text whose nodes will report `sourcePath` as their location, after the checks of
/// app/DocumentLimits.h (`baseDepth` levels above it).
toml::table parseText(std::string_view text, std::string sourcePath, int baseDepth = 0) {
    try {
        return parseDocument(text, sourcePath, baseDepth);
    } catch (const toml::parse_error& e) {
        throw SceneError(locationOf(e.source()) +
                         ": error: TOML syntax: " + std::string(e.description()));
    }
}

/// The location of a --set value: its text, shortened like other quoted input.
std::string overrideLabel(std::string_view override) {
    constexpr std::size_t kMaxShown = 80;
    std::string label(kSetLabelPrefix);
    if (override.size() <= kMaxShown) return label.append(override).append("'");
    return label.append(override.substr(0, kMaxShown)).append("...'");
}

[[noreturn]] void badOverride(const std::string& label, std::string_view key,
                              std::string_view expected, std::string_view found,
                              std::string_view fix = "") {
    throw SceneError(formatError(label, key, expected, found, fix));
}

/// Parses the value as TOML ("3e4", "[0,0,1]", "\"disc\""); text that is not a single TOML
/// value (a bare word such as disc or auto) is taken as a string, so users need not quote it
/// through their shell. Parsing under the --set label gives every node that location.
toml::table parseOverrideValue(std::string_view value, const std::string& label) {
    try {
        toml::table parsed = parseDocument("v = " + std::string(value), label);
        if (parsed.size() == 1 && parsed.contains("v")) return parsed;
    } catch (const toml::parse_error&) {
    }
    return parseText("v = " + tomlString(value), label);
}

bool isBareKey(std::string_view segment) {
    return !segment.empty() && std::all_of(segment.begin(), segment.end(), [](char c) {
        return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
    });
}

std::string singleQuoted(std::string_view text) {
    // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "'" + std::string.
    std::string out = "'";
    return out.append(text).append("'");
}

std::vector<std::string> splitKey(std::string_view key, const std::string& label) {
    std::vector<std::string> segments;
    std::size_t start = 0;
    while (true) {
        const std::size_t dot = key.find('.', start);
        const std::string_view segment = key.substr(start, dot - start);
        if (!isBareKey(segment)) {
            badOverride(label, "", "a dotted key of letters, digits, '_' and '-' such as time.dt",
                        singleQuoted(key));
        }
        segments.emplace_back(segment);
        if (dot == std::string_view::npos) return segments;
        start = dot + 1;
    }
}

std::optional<std::size_t> parseIndex(std::string_view segment) {
    std::size_t index = 0;
    const auto [end, ec] = std::from_chars(segment.data(), segment.data() + segment.size(), index);
    if (ec != std::errc() || end != segment.data() + segment.size()) return std::nullopt;
    return index;
}

std::size_t arrayIndex(const toml::array& array, std::string_view segment,
                       const std::string& parentPath, const std::string& label) {
    const std::optional<std::size_t> index = parseIndex(segment);
    if (index && *index < array.size()) return *index;
    const std::string expected =
        array.empty() ? "no index (" + parentPath + " is an empty array)"
                      : "an index in 0.." + std::to_string(array.size() - 1) + " (" + parentPath +
                            " has " + std::to_string(array.size()) + " entries)";
    badOverride(label, parentPath, expected, singleQuoted(segment));
}

/// The child `segment` of `parent`, creating a table when a table lacks it.
toml::node& descend(toml::node& parent, std::string_view segment, const std::string& parentPath,
                    const std::string& label) {
    if (toml::array* array = parent.as_array()) {
        return (*array)[arrayIndex(*array, segment, parentPath, label)];
    }
    toml::table* table = parent.as_table();
    if (!table) badOverride(label, parentPath, "a table to set keys in", describeType(parent));
    if (toml::node* child = table->get(segment)) return *child;
    toml::table created = parseText("v = {}", label);
    return table->insert_or_assign(segment, std::move(*created.get("v"))).first->second;
}

/// Only table keys are assigned: replacing one element of an array would leave the array's
/// location pointing at the file while its bad value came from --set.
void assign(toml::node& parent, std::string_view segment, toml::node&& value,
            const std::string& parentPath, const std::string& label) {
    toml::table* table = parent.as_table();
    if (!table) {
        badOverride(label, parentPath,
                    "a table to set a key in (arrays are set whole, e.g. --set sheet.size=[1, 2])",
                    describeType(parent));
    }
    table->insert_or_assign(segment, std::move(value));
}

std::vector<std::string> presetNames(const fs::path& directory) {
    std::vector<std::string> names;
    std::error_code ec;
    for (const auto& entry : fs::directory_iterator(directory, ec)) {
        if (entry.path().extension() == ".toml") names.push_back(entry.path().stem().string());
    }
    std::sort(names.begin(), names.end());
    return names;
}

[[noreturn]] void unknownPreset(const toml::node& preset, const std::string& name,
                                const fs::path& directory) {
    const std::vector<std::string> names = presetNames(directory);
    const std::vector<std::string_view> views(names.begin(), names.end());
    if (names.empty()) {
        throw SceneError(formatError(locationOf(preset.source()), "material.preset",
                                     "the name of a preset in " + directory.string(),
                                     quoteText(name) + ", and that directory has no presets",
                                     "Set REND_ASSETS to the assets directory."));
    }
    const std::string expected = oneOf(views) + " (the presets in " + directory.string() + ")";
    const auto suggestion = closestMatch(name, views);
    const std::string fix = suggestion ? "Did you mean " + quoteText(*suggestion) + "?"
                                       : "Use e.g. preset = " + quoteText(views.front()) + ".";
    throw SceneError(formatError(locationOf(preset.source()), "material.preset", expected,
                                 quoteText(name), fix));
}

}  // namespace

toml::table parseTomlFile(const fs::path& file, std::string_view what, int baseDepth) {
    return parseText(readDocument(file, what), file.string(), baseDepth);
}

void applyOverride(toml::table& document, std::string_view override) {
    const std::string label = overrideLabel(override);
    const std::size_t equals = override.find('=');
    if (equals == std::string_view::npos) badOverride(label, "", kSetExample, "no '='");
    const auto trim = [](std::string_view s) {
        const auto first = s.find_first_not_of(" \t");
        if (first == std::string_view::npos) return std::string_view();
        return s.substr(first, s.find_last_not_of(" \t") - first + 1);
    };
    const std::string_view key = trim(override.substr(0, equals));
    if (key.empty()) badOverride(label, "", kSetExample, "an empty key");
    const std::vector<std::string> segments = splitKey(key, label);
    checkBeforeParsing(key, label);
    const std::string_view text = trim(override.substr(equals + 1));
    if (text.empty()) {
        badOverride(label, key, "a value after '='", "nothing",
                    "Give one, e.g. --set material.E=3e4, or leave out this --set.");
    }
    checkBeforeParsing("v = " + std::string(text), label, int(segments.size()) - 1);

    toml::table value = parseOverrideValue(text, label);
    toml::node* parent = &document;
    std::string parentPath;
    for (std::size_t i = 0; i + 1 < segments.size(); ++i) {
        parent = &descend(*parent, segments[i], parentPath, label);
        parentPath += (i ? "." : "") + segments[i];
    }
    assign(*parent, segments.back(), std::move(*value.get("v")), parentPath, label);
}

void mergeMaterialPreset(toml::table& document, const fs::path& assets) {
    toml::table* material = document["material"].as_table();
    if (!material) return;
    const toml::node* preset = material->get("preset");
    // A non-string preset is left for validation to report with the usual wording.
    if (!preset || !preset->is_string()) return;
    const std::string name = preset->as_string()->get();
    const fs::path directory = assets / "materials";
    const std::vector<std::string> names = presetNames(directory);
    if (std::find(names.begin(), names.end(), name) == names.end()) {
        unknownPreset(*preset, name, directory);
    }

    toml::table values = parseTomlFile(directory / (name + ".toml"), "material preset", 1);
    if (const toml::node* nested = values.get("preset")) {
        throw SceneError(formatError(locationOf(nested->source()), "preset", "material values only",
                                     "another preset",
                                     "Presets cannot name presets; copy its values instead."));
    }
    for (auto&& [key, node] : values) {
        // Moving (not copying) keeps the preset file's location on each value.
        if (!material->contains(key.str())) material->insert(key, std::move(node));
    }
}

toml::table buildSceneDocument(const fs::path& file, const std::vector<std::string>& overrides,
                               const fs::path& assets) {
    toml::table document = parseTomlFile(file, "scene file");
    for (const std::string& override : overrides) applyOverride(document, override);
    mergeMaterialPreset(document, assets);
    return document;
}

}  // namespace rend::scene
