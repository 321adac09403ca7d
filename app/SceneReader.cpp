#include "app/SceneReader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <stdexcept>

#include "app/SceneError.h"

namespace rend::scene {
namespace {

std::size_t editDistance(std::string_view a, std::string_view b) {
    std::vector<std::size_t> row(b.size() + 1);
    for (std::size_t j = 0; j <= b.size(); ++j) row[j] = j;
    for (std::size_t i = 1; i <= a.size(); ++i) {
        std::size_t diagonal = row[0];
        row[0] = i;
        for (std::size_t j = 1; j <= b.size(); ++j) {
            const std::size_t substitute = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
            diagonal = row[j];
            row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitute});
        }
    }
    return row[b.size()];
}

std::string joined(std::span<const std::string_view> names, bool quote) {
    std::string out;
    for (std::string_view name : names) {
        if (!out.empty()) out += ", ";
        out += quote ? quoteText(name) : std::string(name);
    }
    return out;
}

std::optional<double> asNumber(const toml::node& node) {
    if (auto v = node.as_floating_point()) return v->get();
    if (auto v = node.as_integer()) return double(v->get());
    return std::nullopt;
}

std::string formatNumbers(const std::vector<double>& values) {
    std::string out = "[";
    for (std::size_t i = 0; i < values.size(); ++i) {
        out += (i ? ", " : "") + formatNumber(values[i]);
    }
    return out + "]";
}

std::string withMeaning(std::string expected, std::string_view meaning) {
    if (!meaning.empty()) expected += " (" + std::string(meaning) + ")";
    return expected;
}

bool isBefore(const toml::source_position& a, const toml::source_position& b) {
    return a.line != b.line ? a.line < b.line : a.column < b.column;
}

}  // namespace

std::string errorAt(std::string_view location, std::string_view message) {
    return std::string(location) + ": error: " + std::string(message);
}

std::string locationOf(const toml::source_region& source) {
    if (!source.path) return "<unknown location>";
    const std::string& path = *source.path;
    if (path.starts_with(kSetLabelPrefix)) return path;
    return path + ":" + std::to_string(source.begin.line) + ":" +
           std::to_string(source.begin.column);
}

std::string formatError(std::string_view location, std::string_view key, std::string_view expected,
                        std::string_view found, std::string_view fix) {
    // Appended piece by piece: GCC 12 warns falsely (-Wrestrict) on "literal" + std::string.
    std::string message;
    if (!key.empty()) message.append(key).append(": ");
    message.append("expected ").append(expected).append(", found ").append(found).append(".");
    if (!fix.empty()) message.append(" ").append(fix);
    return errorAt(location, message);
}

std::string formatNumber(double value) {
    char buffer[64];
    const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
    return std::string(buffer, result.ptr);
}

std::string tomlString(std::string_view text) {
    std::string out = "\"";
    for (const char c : text) {
        const unsigned char u = static_cast<unsigned char>(c);
        if (c == '"' || c == '\\') {
            out += '\\';
            out += c;
        } else if (u < 0x20 || u == 0x7f) {
            char escaped[8];
            std::snprintf(escaped, sizeof escaped, "\\u%04x", u);
            out += escaped;
        } else {
            out += c;
        }
    }
    return out + "\"";
}

std::string quoteText(std::string_view text) {
    // Long values would swamp the one-line message; the location already points at them.
    constexpr std::size_t kMaxShown = 60;
    if (text.size() <= kMaxShown) return tomlString(text);
    return tomlString(text.substr(0, kMaxShown)) + "...";
}

std::string oneOf(std::span<const std::string_view> names) {
    return "one of " + joined(names, true);
}

std::string describeType(const toml::node& node) {
    switch (node.type()) {
        case toml::node_type::string:
            return "a string " + quoteText(node.as_string()->get());
        case toml::node_type::integer:
        case toml::node_type::floating_point:
            return "the number " + formatNumber(*asNumber(node));
        case toml::node_type::boolean:
            return "a boolean";
        case toml::node_type::array: {
            const std::size_t n = node.as_array()->size();
            return "an array of " + std::to_string(n) + (n == 1 ? " element" : " elements");
        }
        case toml::node_type::table:
            return "a table";
        case toml::node_type::date:
            return "a date";
        case toml::node_type::time:
            return "a time";
        case toml::node_type::date_time:
            return "a date-time";
        default:
            return "nothing";
    }
}

std::optional<std::string_view> closestMatch(std::string_view word,
                                             std::span<const std::string_view> candidates) {
    constexpr std::size_t kMaxDistance = 2;
    std::optional<std::string_view> best;
    std::size_t bestDistance = kMaxDistance + 1;
    for (std::string_view candidate : candidates) {
        const std::size_t d = editDistance(word, candidate);
        if (d < bestDistance) {
            best = candidate;
            bestDistance = d;
        }
    }
    return best;
}

bool Range::contains(double v) const {
    // Written so that NaN fails every comparison and is rejected.
    const bool aboveLo = loOpen ? v > lo : v >= lo;
    const bool belowHi = hiOpen ? v < hi : v <= hi;
    return aboveLo && belowHi;
}

std::string Range::describe() const {
    const bool hasLo = std::isfinite(lo);
    const bool hasHi = std::isfinite(hi);
    if (hasLo && hasHi) {
        return std::string("in ") + (loOpen ? "(" : "[") + formatNumber(lo) + ", " +
               formatNumber(hi) + (hiOpen ? ")" : "]");
    }
    if (hasLo) return (loOpen ? "> " : ">= ") + formatNumber(lo);
    if (hasHi) return (hiOpen ? "< " : "<= ") + formatNumber(hi);
    return "";
}

const Param* Section::find(std::string_view key) const {
    const auto it =
        std::find_if(keys.begin(), keys.end(), [&](const Param& p) { return p.key == key; });
    return it == keys.end() ? nullptr : &*it;
}

const Section& sectionAt(std::string_view path) {
    for (const Section& s : sceneSchema())
        if (s.path == path) return s;
    throw std::logic_error("no scene schema section '" + std::string(path) + "'");
}

// ---- KeyLog ----------------------------------------------------------------------------------

std::size_t KeyLog::visit(const toml::table& table, const Section& section, std::string path,
                          std::string title, std::string location) {
    locations_.emplace(path, std::move(location));
    // A table read by two readers ([material]'s keys and its [[material.map]]) is one entry,
    // so neither reports the other's keys as unused.
    for (std::size_t k = 0; k < entries_.size(); ++k)
        if (entries_[k].table == &table && entries_[k].path == path) return k;
    entries_.push_back({&table, &section, std::move(path), std::move(title), {}});
    return entries_.size() - 1;
}

void KeyLog::use(std::size_t entry, std::string_view key, const toml::node& value) {
    Entry& e = entries_[entry];
    e.used.emplace(key);
    const std::string path = e.path.empty() ? std::string(key) : e.path + "." + std::string(key);
    locations_.emplace(path, locationOf(value.source()));
}

std::string KeyLog::unusedMessage(const Entry& entry, const toml::key& key,
                                  const toml::node& value) const {
    std::vector<std::string_view> names;
    for (const Param& p : entry.section->keys) names.push_back(p.key);
    const bool declared = entry.section->find(key.str()) != nullptr;
    std::string message = declared
                              ? "key '" + std::string(key.str()) + "' in " + entry.title +
                                    " is not used by this scene; remove it."
                              : "unknown key '" + std::string(key.str()) + "' in " + entry.title +
                                    "; expected one of: " + joined(names, false) + ".";
    if (!declared) {
        if (auto suggestion = closestMatch(key.str(), names))
            message += " Did you mean '" + std::string(*suggestion) + "'?";
    }
    const toml::source_region& where = key.source().path ? key.source() : value.source();
    return errorAt(locationOf(where), message);
}

std::optional<std::string> KeyLog::firstUnknown() const {
    for (const Entry& e : entries_) {
        const toml::key* first = nullptr;
        const toml::node* firstValue = nullptr;
        for (const auto& [key, value] : *e.table) {
            if (e.section->find(key.str())) continue;
            // The first typo in reading order, not the map's alphabetical order.
            if (!first || isBefore(value.source().begin, firstValue->source().begin)) {
                first = &key;
                firstValue = &value;
            }
        }
        if (first) return unusedMessage(e, *first, *firstValue);
    }
    return std::nullopt;
}

void KeyLog::reportUnused() const {
    // Reading order, not the map's alphabetical order; every unused key, one line each.
    std::vector<std::pair<toml::source_position, std::string>> unused;
    for (const Entry& e : entries_) {
        for (const auto& [key, value] : *e.table) {
            if (e.used.contains(key.str())) continue;
            unused.emplace_back(value.source().begin, unusedMessage(e, key, value));
        }
    }
    if (unused.empty()) return;
    std::stable_sort(unused.begin(), unused.end(),
                     [](const auto& a, const auto& b) { return isBefore(a.first, b.first); });
    std::string message;
    for (const auto& [position, line] : unused) message += (message.empty() ? "" : "\n") + line;
    throw SceneError(message);
}

// ---- TableReader -----------------------------------------------------------------------------

TableReader::TableReader(const toml::table& table, const Section& section, std::string path,
                         std::string title, KeyLog& log, std::string fallbackLocation)
    : table_(&table),
      section_(&section),
      path_(std::move(path)),
      title_(std::move(title)),
      log_(&log),
      fallbackLocation_(std::move(fallbackLocation)) {
    entry_ = log.visit(table, section, path_, title_, location());
}

const Param& TableReader::param(std::string_view key) const {
    if (const Param* p = section_->find(key)) return *p;
    throw std::logic_error("key '" + std::string(key) + "' is not declared in the schema of " +
                           title_);
}

const toml::node* TableReader::find(std::string_view key) const {
    param(key);
    const toml::node* node = table_->get(key);
    if (node) log_->use(entry_, key, *node);
    return node;
}

bool TableReader::has(std::string_view key) const {
    param(key);
    return table_->contains(key);
}

std::string TableReader::keyPath(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

std::string TableReader::location() const {
    return table_->source().path ? locationOf(table_->source()) : fallbackLocation_;
}

std::string TableReader::location(std::string_view key) const {
    const toml::node* node = table_->get(key);
    return node ? locationOf(node->source()) : location();
}

void TableReader::fail(std::string_view key, std::string_view expected, std::string_view found,
                       std::string_view fix) const {
    throw SceneError(formatError(location(key), keyPath(key), expected, found, fix));
}

void TableReader::missing(std::string_view key, std::string_view constraint) const {
    if (auto unknown = log_->firstUnknown()) throw SceneError(*unknown);
    const Param& p = param(key);
    std::string message = keyPath(p.key) + " is missing: expected " + std::string(p.meaning);
    if (!constraint.empty()) message += " (" + std::string(constraint) + ")";
    message += ". Add e.g. " + std::string(p.key) + " = " + std::string(p.example) + " under " +
               title_ + ".";
    throw SceneError(errorAt(location(), message));
}

std::string TableReader::useInstead(std::string_view key) const {
    const Param& p = param(key);
    return "Use e.g. " + std::string(p.key) + " = " + std::string(p.example) + ".";
}

std::string TableReader::expectedNumber(const Param& p, std::string_view what) const {
    std::string expected(what);
    if (const std::string bounds = p.range.describe(); !bounds.empty()) expected += " " + bounds;
    return expected;
}

std::optional<double> TableReader::number(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const Param& p = param(key);
    const std::string expected = withMeaning(expectedNumber(p, "a number"), p.meaning);
    const std::optional<double> value = asNumber(*node);
    if (!value) fail(key, expected, describeType(*node), useInstead(key));
    if (!std::isfinite(*value) || !p.range.contains(*value)) {
        fail(key, expected, formatNumber(*value), useInstead(key));
    }
    return value;
}

double TableReader::requiredNumber(std::string_view key) const {
    if (!has(key)) missing(key, param(key).range.describe());
    return *number(key);
}

std::optional<std::int64_t> TableReader::integer(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const Param& p = param(key);
    const std::string expected = withMeaning(expectedNumber(p, "an integer"), p.meaning);
    if (auto f = node->as_floating_point())
        fail(key, expected, formatNumber(f->get()), useInstead(key));
    const auto* value = node->as_integer();
    if (!value) fail(key, expected, describeType(*node), useInstead(key));
    if (!p.range.contains(double(value->get()))) {
        fail(key, expected, std::to_string(value->get()), useInstead(key));
    }
    return value->get();
}

std::optional<bool> TableReader::boolean(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const auto* value = node->as_boolean();
    if (!value) {
        fail(key, withMeaning("true or false", param(key).meaning), describeType(*node),
             useInstead(key));
    }
    return value->get();
}

std::optional<std::string> TableReader::string(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const auto* value = node->as_string();
    if (!value) {
        fail(key, withMeaning("a string", param(key).meaning), describeType(*node),
             useInstead(key));
    }
    return value->get();
}

std::optional<std::size_t> TableReader::choice(std::string_view key) const {
    return choice(key, param(key).names);
}

std::optional<std::size_t> TableReader::choice(std::string_view key,
                                               std::span<const std::string_view> names) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const std::string expected = oneOf(names);
    const auto* value = node->as_string();
    if (!value) fail(key, expected, describeType(*node), useInstead(key));
    const auto it = std::find(names.begin(), names.end(), value->get());
    if (it != names.end()) return std::size_t(it - names.begin());
    const auto suggestion = closestMatch(value->get(), names);
    fail(key, expected, quoteText(value->get()),
         suggestion ? "Did you mean " + quoteText(*suggestion) + "?" : useInstead(key));
}

std::optional<double> TableReader::numberOrWord(std::string_view key,
                                                std::optional<double> fallback) const {
    const toml::node* node = find(key);
    if (!node) return fallback;
    const Param& p = param(key);
    if (const auto* text = node->as_string();
        text && std::find(p.names.begin(), p.names.end(), text->get()) != p.names.end())
        return std::nullopt;
    if (node->is_number()) return number(key);
    std::string words;
    for (std::size_t k = 0; k < p.names.size(); ++k)
        words += (k == 0 ? "" : " or ") + quoteText(p.names[k]);
    const std::string orWord = " or " + std::string(p.key) + " = " + words + ".";
    fail(key, expectedNumber(p, "a number") + " (" + std::string(p.meaning) + ") or " + words,
         describeType(*node), useInstead(key).substr(0, useInstead(key).size() - 1) + orWord);
}

std::optional<std::vector<double>> TableReader::numbers(std::string_view key, std::size_t count,
                                                        bool nonZero) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const Param& p = param(key);
    std::string expected = expectedNumber(p, "an array of " + std::to_string(count) + " numbers");
    if (nonZero) expected += ", not all zero";
    expected = withMeaning(expected, p.meaning);

    const toml::array* array = node->as_array();
    if (!array || array->size() != count) fail(key, expected, describeType(*node), useInstead(key));
    std::vector<double> values;
    for (const toml::node& item : *array) {
        const std::optional<double> v = asNumber(item);
        if (!v) fail(key, expected, "an array containing " + describeType(item), useInstead(key));
        values.push_back(*v);
    }
    const bool inRange = std::all_of(values.begin(), values.end(), [&](double v) {
        return std::isfinite(v) && p.range.contains(v);
    });
    const bool allZero = std::all_of(values.begin(), values.end(), [](double v) { return v == 0; });
    if (!inRange || (nonZero && allZero))
        fail(key, expected, formatNumbers(values), useInstead(key));
    return values;
}

std::optional<Eigen::Vector2d> TableReader::vec2(std::string_view key) const {
    const auto v = numbers(key, 2, false);
    if (!v) return std::nullopt;
    return Eigen::Vector2d((*v)[0], (*v)[1]);
}

std::optional<Eigen::Vector3d> TableReader::vec3(std::string_view key, bool nonZero) const {
    const auto v = numbers(key, 3, nonZero);
    if (!v) return std::nullopt;
    return Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
}

std::optional<std::vector<Eigen::Vector2d>> TableReader::points(std::string_view key,
                                                                std::size_t minCount) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const Param& p = param(key);
    const std::string expected = withMeaning(
        "an array of at least " + std::to_string(minCount) + " points [x, y]", p.meaning);
    const toml::array* array = node->as_array();
    if (!array || array->size() < minCount)
        fail(key, expected, describeType(*node), useInstead(key));
    const std::string pointExpected =
        withMeaning(expectedNumber(p, "a point [x, y] of 2 numbers"), p.meaning);

    std::vector<Eigen::Vector2d> result;
    for (const toml::node& item : *array) {
        const std::string itemKey = keyPath(key) + "." + std::to_string(result.size());
        const auto failItem = [&](const std::string& found) {
            throw SceneError(formatError(locationOf(item.source()), itemKey, pointExpected, found,
                                         useInstead(key)));
        };
        const toml::array* point = item.as_array();
        if (!point || point->size() != 2) failItem(describeType(item));
        std::vector<double> values;
        for (const toml::node& coordinate : *point) {
            const std::optional<double> v = asNumber(coordinate);
            if (!v) failItem("an array containing " + describeType(coordinate));
            values.push_back(*v);
        }
        for (const double v : values) {
            if (!std::isfinite(v) || !p.range.contains(v)) failItem(formatNumbers(values));
        }
        result.emplace_back(values[0], values[1]);
    }
    return result;
}

std::optional<TableReader> TableReader::subtable(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return std::nullopt;
    const Param& p = param(key);
    const toml::table* child = node->as_table();
    if (!child) {
        fail(key, withMeaning("a table", p.meaning), describeType(*node),
             p.example.empty()
                 ? "Write it as a table: a [" + keyPath(key) + "] header followed by its keys."
                 : useInstead(key));
    }
    return childReader(*child, key);
}

TableReader TableReader::section(std::string_view key) const {
    if (auto child = subtable(key)) return *child;
    static const toml::table kEmpty;
    return childReader(kEmpty, key);
}

TableReader TableReader::childReader(const toml::table& table, std::string_view key) const {
    const Section& section = sectionAt(param(key).section);
    // "[sheet]" names a section; an inline table such as a box is named by its path.
    const std::string title =
        section.title.starts_with("[") ? std::string(section.title) : keyPath(key);
    return TableReader(table, section, keyPath(key), title, *log_, location());
}

std::vector<TableReader> TableReader::entries(std::string_view key) const {
    const toml::node* node = find(key);
    if (!node) return {};
    const Section& section = sectionAt(param(key).section);
    const std::string header = "[[" + keyPath(key) + "]]";
    const std::string expected = "an array of tables written as " + header;
    const std::string fix = "Give each entry its own " + header + " header.";
    const toml::array* array = node->as_array();
    if (!array) fail(key, expected, describeType(*node), fix);
    std::vector<TableReader> tables;
    for (const toml::node& item : *array) {
        const toml::table* table = item.as_table();
        if (!table) fail(key, expected, "an array containing " + describeType(item), fix);
        const std::string index = std::to_string(tables.size());
        tables.emplace_back(*table, section, keyPath(key) + "." + index, header + " entry " + index,
                            *log_, location());
    }
    return tables;
}

}  // namespace rend::scene
