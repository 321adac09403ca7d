#include "app/SceneReader.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <cstdio>

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

TableReader::TableReader(const toml::table& table, std::string path, std::string title,
                         std::initializer_list<std::string_view> allowed)
    : table_(&table), path_(std::move(path)), title_(std::move(title)) {
    rejectUnknownKeys(allowed);
}

void TableReader::rejectUnknownKeys(std::initializer_list<std::string_view> allowed) const {
    const toml::key* first = nullptr;
    const toml::node* firstValue = nullptr;
    for (const auto& [key, value] : *table_) {
        if (std::find(allowed.begin(), allowed.end(), key.str()) != allowed.end()) continue;
        // Report the first typo in reading order, not the map's alphabetical order.
        if (!first || isBefore(value.source().begin, firstValue->source().begin)) {
            first = &key;
            firstValue = &value;
        }
    }
    if (!first) return;
    const std::span<const std::string_view> names(allowed.begin(), allowed.size());
    std::string message = "unknown key '" + std::string(first->str()) + "' in " + title_ +
                          "; expected one of: " + joined(names, false) + ".";
    if (auto suggestion = closestMatch(first->str(), names)) {
        message += " Did you mean '" + std::string(*suggestion) + "'?";
    }
    const toml::source_region& where =
        first->source().path ? first->source() : firstValue->source();
    throw SceneError(errorAt(locationOf(where), message));
}

const toml::node* TableReader::find(std::string_view key) const { return table_->get(key); }

std::string TableReader::keyPath(std::string_view key) const {
    return path_.empty() ? std::string(key) : path_ + "." + std::string(key);
}

std::string TableReader::location() const {
    return table_->source().path ? locationOf(table_->source()) : fallbackLocation_;
}

std::string TableReader::location(std::string_view key) const {
    const toml::node* node = find(key);
    return node ? locationOf(node->source()) : location();
}

void TableReader::fail(std::string_view key, std::string_view expected, std::string_view found,
                       std::string_view fix) const {
    throw SceneError(formatError(location(key), keyPath(key), expected, found, fix));
}

void TableReader::missing(const Param& p, std::string_view constraint) const {
    std::string message = keyPath(p.key) + " is missing: expected " + std::string(p.meaning);
    if (!constraint.empty()) message += " (" + std::string(constraint) + ")";
    message += ". Add e.g. " + std::string(p.key) + " = " + std::string(p.example) + " under " +
               title_ + ".";
    throw SceneError(errorAt(location(), message));
}

std::string TableReader::useInstead(const Param& p) {
    return "Use e.g. " + std::string(p.key) + " = " + std::string(p.example) + ".";
}

std::optional<double> TableReader::number(const Param& p, Range range) const {
    const toml::node* node = find(p.key);
    if (!node) return std::nullopt;
    std::string expected = "a number";
    if (const std::string bounds = range.describe(); !bounds.empty()) expected += " " + bounds;
    expected = withMeaning(expected, p.meaning);
    const std::optional<double> value = asNumber(*node);
    if (!value) fail(p.key, expected, describeType(*node), useInstead(p));
    if (!std::isfinite(*value) || !range.contains(*value)) {
        fail(p.key, expected, formatNumber(*value), useInstead(p));
    }
    return value;
}

double TableReader::requiredNumber(const Param& p, Range range) const {
    if (!has(p.key)) missing(p, range.describe());
    return *number(p, range);
}

std::optional<std::int64_t> TableReader::integer(const Param& p, Range range) const {
    const toml::node* node = find(p.key);
    if (!node) return std::nullopt;
    std::string expected = "an integer";
    if (const std::string bounds = range.describe(); !bounds.empty()) expected += " " + bounds;
    expected = withMeaning(expected, p.meaning);
    if (auto f = node->as_floating_point())
        fail(p.key, expected, formatNumber(f->get()), useInstead(p));
    const auto* value = node->as_integer();
    if (!value) fail(p.key, expected, describeType(*node), useInstead(p));
    if (!range.contains(double(value->get()))) {
        fail(p.key, expected, std::to_string(value->get()), useInstead(p));
    }
    return value->get();
}

std::optional<bool> TableReader::boolean(const Param& p) const {
    const toml::node* node = find(p.key);
    if (!node) return std::nullopt;
    const auto* value = node->as_boolean();
    if (!value)
        fail(p.key, withMeaning("true or false", p.meaning), describeType(*node), useInstead(p));
    return value->get();
}

std::optional<std::string> TableReader::string(const Param& p) const {
    const toml::node* node = find(p.key);
    if (!node) return std::nullopt;
    const auto* value = node->as_string();
    if (!value) fail(p.key, withMeaning("a string", p.meaning), describeType(*node), useInstead(p));
    return value->get();
}

std::optional<std::size_t> TableReader::choice(const Param& p,
                                               std::span<const std::string_view> names) const {
    const toml::node* node = find(p.key);
    if (!node) return std::nullopt;
    const std::string expected = oneOf(names);
    const auto* value = node->as_string();
    if (!value) fail(p.key, expected, describeType(*node), useInstead(p));
    const auto it = std::find(names.begin(), names.end(), value->get());
    if (it != names.end()) return std::size_t(it - names.begin());
    const auto suggestion = closestMatch(value->get(), names);
    fail(p.key, expected, quoteText(value->get()),
         suggestion ? "Did you mean " + quoteText(*suggestion) + "?" : useInstead(p));
}

std::optional<std::vector<double>> TableReader::numbers(const Param& p, std::size_t count,
                                                        Range element, bool nonZero) const {
    const toml::node* node = find(p.key);
    if (!node) return std::nullopt;
    std::string expected = "an array of " + std::to_string(count) + " numbers";
    if (const std::string bounds = element.describe(); !bounds.empty()) expected += " " + bounds;
    if (nonZero) expected += ", not all zero";
    expected = withMeaning(expected, p.meaning);

    const toml::array* array = node->as_array();
    if (!array || array->size() != count) fail(p.key, expected, describeType(*node), useInstead(p));
    std::vector<double> values;
    for (const toml::node& item : *array) {
        const std::optional<double> v = asNumber(item);
        if (!v) fail(p.key, expected, "an array containing " + describeType(item), useInstead(p));
        values.push_back(*v);
    }
    const bool inRange = std::all_of(values.begin(), values.end(), [&](double v) {
        return std::isfinite(v) && element.contains(v);
    });
    const bool allZero = std::all_of(values.begin(), values.end(), [](double v) { return v == 0; });
    if (!inRange || (nonZero && allZero)) {
        fail(p.key, expected, formatNumbers(values), useInstead(p));
    }
    return values;
}

std::optional<Eigen::Vector2d> TableReader::vec2(const Param& p, Range element) const {
    const auto v = numbers(p, 2, element, false);
    if (!v) return std::nullopt;
    return Eigen::Vector2d((*v)[0], (*v)[1]);
}

std::optional<Eigen::Vector3d> TableReader::vec3(const Param& p, Range element,
                                                 bool nonZero) const {
    const auto v = numbers(p, 3, element, nonZero);
    if (!v) return std::nullopt;
    return Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
}

std::optional<std::vector<Eigen::Vector2d>> TableReader::points(const Param& p,
                                                                std::size_t minCount,
                                                                Range element) const {
    const toml::node* node = find(p.key);
    if (!node) return std::nullopt;
    const std::string expected = withMeaning(
        "an array of at least " + std::to_string(minCount) + " points [x, y]", p.meaning);
    const toml::array* array = node->as_array();
    if (!array || array->size() < minCount) {
        fail(p.key, expected, describeType(*node), useInstead(p));
    }
    std::string pointExpected = "a point [x, y] of 2 numbers";
    if (const std::string bounds = element.describe(); !bounds.empty()) {
        pointExpected += " " + bounds;
    }
    pointExpected = withMeaning(pointExpected, p.meaning);

    std::vector<Eigen::Vector2d> result;
    for (const toml::node& item : *array) {
        const std::string itemKey = keyPath(p.key) + "." + std::to_string(result.size());
        const auto failItem = [&](const std::string& found) {
            throw SceneError(formatError(locationOf(item.source()), itemKey, pointExpected, found,
                                         useInstead(p)));
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
            if (!std::isfinite(v) || !element.contains(v)) failItem(formatNumbers(values));
        }
        result.emplace_back(values[0], values[1]);
    }
    return result;
}

std::optional<TableReader> TableReader::subtable(const Param& p, std::string title,
                                                 std::initializer_list<std::string_view> allowed,
                                                 std::string_view fix) const {
    const toml::node* node = find(p.key);
    if (!node) return std::nullopt;
    const toml::table* child = node->as_table();
    if (!child) fail(p.key, withMeaning("a table", p.meaning), describeType(*node), fix);
    TableReader reader(*child, keyPath(p.key), std::move(title), allowed);
    reader.fallbackLocation_ = location();
    return reader;
}

TableReader TableReader::section(const Param& p, std::string title,
                                 std::initializer_list<std::string_view> allowed,
                                 std::string_view fix) const {
    if (auto child = subtable(p, title, allowed, fix)) return *child;
    static const toml::table kEmpty;
    TableReader empty(kEmpty, keyPath(p.key), std::move(title), allowed);
    empty.fallbackLocation_ = location();
    return empty;
}

}  // namespace rend::scene
