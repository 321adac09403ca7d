#pragma once
// Typed, range-checked reads from one table of a scene document. Every failure becomes a
// SceneError of the form "LOCATION: error: KEY: expected WHAT, found FOUND. FIX", so the loader
// itself only declares keys, ranges and examples.

#include <toml++/toml.h>

#include <Eigen/Core>
#include <cstdint>
#include <initializer_list>
#include <limits>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace rend::scene {

/// Prefix of the source path given to values parsed from --set; such values have no useful
/// line:column, so their location is the --set text itself.
inline constexpr std::string_view kSetLabelPrefix = "--set '";

/// "file:line:column", or "--set '...'" for values that came from the command line.
std::string locationOf(const toml::source_region& source);

/// "LOCATION: error: MESSAGE".
std::string errorAt(std::string_view location, std::string_view message);

/// Builds the one-line message; `key` may be empty for messages that are not about one key.
std::string formatError(std::string_view location, std::string_view key, std::string_view expected,
                        std::string_view found, std::string_view fix);

/// How a node is described after "found" when its type is wrong: a string "abc", a boolean...
std::string describeType(const toml::node& node);
std::string formatNumber(double value);
/// `text` as a TOML basic string: quoted, with quotes, backslashes and controls escaped.
std::string tomlString(std::string_view text);
/// tomlString, shortened for messages.
std::string quoteText(std::string_view text);
/// `one of "a", "b"`.
std::string oneOf(std::span<const std::string_view> names);

/// The candidate within edit distance 2 of `word`, if any (the closest wins).
std::optional<std::string_view> closestMatch(std::string_view word,
                                             std::span<const std::string_view> candidates);

/// An interval of the reals as the messages quote it ("> 0", "in (-1, 0.5)").
struct Range {
    double lo = -std::numeric_limits<double>::infinity();
    double hi = std::numeric_limits<double>::infinity();
    bool loOpen = false;
    bool hiOpen = false;

    static Range any() { return {}; }
    static Range positive() { return {0.0, Range{}.hi, true, false}; }
    static Range nonNegative() { return {0.0, Range{}.hi, false, false}; }
    static Range closed(double lo, double hi) { return {lo, hi, false, false}; }
    static Range open(double lo, double hi) { return {lo, hi, true, true}; }
    static Range openClosed(double lo, double hi) { return {lo, hi, true, false}; }
    static Range above(double lo) { return {lo, Range{}.hi, true, false}; }
    static Range atMost(double hi) { return {Range{}.lo, hi, false, false}; }

    bool contains(double v) const;
    std::string describe() const;  ///< empty when unbounded
};

/// One key of a table: its name, what it means (with units) and a valid TOML value to suggest.
struct Param {
    std::string_view key;
    std::string_view meaning;
    std::string_view example;
};

class TableReader {
public:
    /// `path` is the dotted key of the table ("" for the root), `title` how messages name it
    /// ("[sheet]"). Keys outside `allowed` are rejected here, before any value is read.
    TableReader(const toml::table& table, std::string path, std::string title,
                std::initializer_list<std::string_view> allowed);

    const toml::table& table() const { return *table_; }
    const toml::node* find(std::string_view key) const;
    bool has(std::string_view key) const { return find(key) != nullptr; }

    std::string keyPath(std::string_view key) const;
    std::string location() const;                      ///< of the table (its header)
    std::string location(std::string_view key) const;  ///< of the key's value

    std::optional<double> number(const Param& p, Range range) const;
    double requiredNumber(const Param& p, Range range) const;
    std::optional<std::int64_t> integer(const Param& p, Range range) const;
    std::optional<bool> boolean(const Param& p) const;
    std::optional<std::string> string(const Param& p) const;
    /// Index into `names` of the value, which must be one of them.
    std::optional<std::size_t> choice(const Param& p,
                                      std::span<const std::string_view> names) const;
    std::optional<Eigen::Vector2d> vec2(const Param& p, Range element = Range::any()) const;
    std::optional<Eigen::Vector3d> vec3(const Param& p, Range element = Range::any(),
                                        bool nonZero = false) const;
    /// An array of at least `minCount` points [x, y]; a malformed point is reported at its own
    /// location, keyed KEY.INDEX (counting from 0, like --set).
    std::optional<std::vector<Eigen::Vector2d>> points(const Param& p, std::size_t minCount,
                                                       Range element = Range::any()) const;
    /// A nested table (inline or not) with its own allowed keys; `fix` is the advice when the
    /// value is not a table.
    std::optional<TableReader> subtable(const Param& p, std::string title,
                                        std::initializer_list<std::string_view> allowed,
                                        std::string_view fix) const;
    /// Like subtable, but an absent table reads as empty so defaults apply, and its missing
    /// required keys are reported at this table's location.
    TableReader section(const Param& p, std::string title,
                        std::initializer_list<std::string_view> allowed,
                        std::string_view fix) const;

    [[noreturn]] void fail(std::string_view key, std::string_view expected, std::string_view found,
                           std::string_view fix) const;
    [[noreturn]] void missing(const Param& p, std::string_view constraint) const;
    /// "Use e.g. KEY = EXAMPLE."
    static std::string useInstead(const Param& p);

private:
    std::optional<std::vector<double>> numbers(const Param& p, std::size_t count, Range element,
                                               bool nonZero) const;
    void rejectUnknownKeys(std::initializer_list<std::string_view> allowed) const;

    const toml::table* table_;
    std::string path_;
    std::string title_;
    std::string fallbackLocation_;  ///< for tables that exist only as defaults
};

}  // namespace rend::scene
