#pragma once
// Typed, range-checked reads from one table of a scene document. Every failure becomes a
// SceneError of the form "LOCATION: error: KEY: expected WHAT, found FOUND. FIX", so the loader
// itself only declares keys, ranges and examples.

#include <toml++/toml.h>

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <map>
#include <optional>
#include <set>
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

    static constexpr Range any() { return {}; }
    static constexpr Range closed(double lo, double hi) { return {lo, hi, false, false}; }
    static constexpr Range open(double lo, double hi) { return {lo, hi, true, true}; }
    static constexpr Range openClosed(double lo, double hi) { return {lo, hi, true, false}; }

    bool contains(double v) const;
    std::string describe() const;  ///< empty when unbounded
};

/// What a key holds; the walker checks the value against it and the README table names it.
enum class ValueType {
    Number,
    Integer,
    Boolean,
    String,
    Choice,        ///< a string among Param::names
    NumberOrWord,  ///< a number in range, or the single word Param::names[0] ("auto", "none")
    Vec2,          ///< [x, y], each element in range
    Vec3,          ///< [x, y, z], each element in range
    Points,        ///< [[x, y], ...], each coordinate in range
    Table,         ///< a nested table described by the Section Param::section
    Tables,        ///< an array of tables [[...]], each described by Param::section
    ChoiceList,    ///< an array of strings, each among Param::names
};

/// One key of a table, declared once: its name, type, range, default, meaning and an example.
/// The loader reads by key name; the README's scene-file table is generated from these.
struct Param {
    std::string_view key;
    ValueType type = ValueType::Number;
    Range range{};
    std::string_view fallback;  ///< the default as documented: a value, "required", or a rule
    std::string_view meaning;   ///< with units
    std::string_view example;   ///< a valid TOML value to suggest
    std::span<const std::string_view> names{};
    std::string_view section{};  ///< Table and Tables: the path of the nested Section
};

/// The keys of one kind of table, by dotted path ("" the top level, "boundary" each
/// [[boundary]] entry, "boundary.box" its box).
struct Section {
    std::string_view path;
    std::string_view title;  ///< how messages name it: "[sheet]", "[[boundary]] entry"
    std::span<const Param> keys;

    /// The declared key, or nullptr.
    const Param* find(std::string_view key) const;
};

/// The whole scene schema: every Section, the top level first.
std::span<const Section> sceneSchema();
const Section& sectionAt(std::string_view path);
/// The README's scene-file table, one row per key that holds a value.
std::string schemaMarkdown();

/// What the readers of one document looked up: every table visited with its Section, every key
/// read and where its value came from. At the end, every key present but not read is an error
/// (pbrt-v4's ParameterDictionary::ReportUnused), so no list of allowed keys exists besides the
/// schema.
class KeyLog {
public:
    /// Returns the index of the table's entry (the same for a table visited again).
    std::size_t visit(const toml::table& table, const Section& section, std::string path,
                      std::string title, std::string location);
    void use(std::size_t entry, std::string_view key, const toml::node& value);
    /// Throws SceneError naming every key present but not read, each at its location with a
    /// did-you-mean among the keys its section declares.
    void reportUnused() const;
    /// The first undeclared key of the tables visited so far, as a message, if any: the likely
    /// cause of a missing required key ("materal" when material.E is missing).
    std::optional<std::string> firstUnknown() const;

    /// "file:line:column" of every value read and every table visited, by dotted key path.
    const std::map<std::string, std::string, std::less<>>& locations() const { return locations_; }

private:
    struct Entry {
        const toml::table* table;
        const Section* section;
        std::string path, title;
        std::set<std::string, std::less<>> used;
    };
    std::string unusedMessage(const Entry& entry, const toml::key& key,
                              const toml::node& value) const;

    std::vector<Entry> entries_;
    std::map<std::string, std::string, std::less<>> locations_;
};

class TableReader {
public:
    /// `path` is the dotted key of the table ("" for the root), `title` how messages name it
    /// ("[sheet]"); `section` declares its keys, `log` records what is read.
    TableReader(const toml::table& table, const Section& section, std::string path,
                std::string title, KeyLog& log, std::string fallbackLocation = {});

    /// The value of a declared key, recorded as used; nullptr when absent.
    const toml::node* find(std::string_view key) const;
    /// Whether the key is present, without using it.
    bool has(std::string_view key) const;
    const Param& param(std::string_view key) const;

    std::string keyPath(std::string_view key) const;
    std::string location() const;                      ///< of the table (its header)
    std::string location(std::string_view key) const;  ///< of the key's value

    std::optional<double> number(std::string_view key) const;
    double requiredNumber(std::string_view key) const;
    std::optional<std::int64_t> integer(std::string_view key) const;
    std::optional<bool> boolean(std::string_view key) const;
    std::optional<std::string> string(std::string_view key) const;
    /// Index into the Param's names of the value, which must be one of them.
    std::optional<std::size_t> choice(std::string_view key) const;
    /// Like choice, with names supplied by the caller (a registry).
    std::optional<std::size_t> choice(std::string_view key,
                                      std::span<const std::string_view> names) const;
    /// A number, or nullopt for the Param's word ("auto", "none"); `fallback` when absent.
    std::optional<double> numberOrWord(std::string_view key, std::optional<double> fallback) const;
    std::optional<Eigen::Vector2d> vec2(std::string_view key) const;
    std::optional<Eigen::Vector3d> vec3(std::string_view key, bool nonZero = false) const;
    /// An array of at least `minCount` points [x, y]; a malformed point is reported at its own
    /// location, keyed KEY.INDEX (counting from 0, like --set).
    std::optional<std::vector<Eigen::Vector2d>> points(std::string_view key,
                                                       std::size_t minCount) const;
    /// A nested table (inline or not) of a Table key.
    std::optional<TableReader> subtable(std::string_view key) const;
    /// Like subtable, but an absent table reads as empty so defaults apply, and its missing
    /// required keys are reported at this table's location.
    TableReader section(std::string_view key) const;
    /// Every entry of a Tables key ([[boundary]]); absent reads as none.
    std::vector<TableReader> entries(std::string_view key) const;

    [[noreturn]] void fail(std::string_view key, std::string_view expected, std::string_view found,
                           std::string_view fix) const;
    /// The required key is absent: reports an undeclared key of the table first (a typo of it).
    [[noreturn]] void missing(std::string_view key, std::string_view constraint = {}) const;
    /// "Use e.g. KEY = EXAMPLE."
    std::string useInstead(std::string_view key) const;

private:
    std::optional<std::vector<double>> numbers(std::string_view key, std::size_t count,
                                               bool nonZero) const;
    std::string expectedNumber(const Param& p, std::string_view what) const;
    TableReader childReader(const toml::table& table, std::string_view key) const;

    const toml::table* table_;
    const Section* section_;
    std::string path_;
    std::string title_;
    KeyLog* log_;
    std::size_t entry_;
    std::string fallbackLocation_;  ///< for tables that exist only as defaults
};

}  // namespace rend::scene
