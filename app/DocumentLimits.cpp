#include "app/DocumentLimits.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <toml++/toml.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <vector>

#include "app/SceneError.h"
#include "app/SceneReader.h"

namespace rend::scene {
namespace {

/// Closes the descriptor on every way out, thrown or not.
struct Descriptor {
    int fd;
    ~Descriptor() {
        if (fd >= 0) ::close(fd);
    }
};

std::string fileKind(mode_t mode) {
    if (S_ISDIR(mode)) return "a directory";
    if (S_ISCHR(mode)) return "a character device";
    if (S_ISBLK(mode)) return "a block device";
    if (S_ISSOCK(mode)) return "a socket";
    return "a special file";
}

std::string cannotRead(const std::string& name, std::string_view what, std::string_view verb) {
    return name + ": error: cannot " + std::string(verb) + " " + std::string(what) + " (" +
           std::strerror(errno) + ")";
}

/// Reads at most `limit` bytes (a pipe delivers them in pieces).
std::string readUpTo(int fd, std::size_t limit, const std::string& name, std::string_view what) {
    std::string text;
    char buffer[1 << 16];
    while (text.size() < limit) {
        const ssize_t got = ::read(fd, buffer, std::min(sizeof buffer, limit - text.size()));
        if (got == 0) break;
        if (got < 0) {
            if (errno == EINTR) continue;
            throw SceneError(cannotRead(name, what, "read"));
        }
        text.append(buffer, std::size_t(got));
    }
    return text;
}

}  // namespace

std::string readDocument(const std::filesystem::path& file, std::string_view what) {
    const std::string name = file.string();
    const std::string expected = "a " + std::string(what);
    const std::string limit = std::to_string(kMaxDocumentBytes >> 20) + " MiB limit";
    const auto refuse = [&](const std::string& found, std::string_view fix) {
        throw SceneError(formatError(name, "", expected, found, fix));
    };
    // O_NONBLOCK: opening a FIFO that no process writes would otherwise wait forever.
    const Descriptor in{::open(name.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC)};
    struct stat info {};
    if (in.fd < 0) throw SceneError(cannotRead(name, what, "open"));
    if (::fstat(in.fd, &info) != 0) throw SceneError(cannotRead(name, what, "open"));
    const bool regular = S_ISREG(info.st_mode);
    if (!regular && !S_ISFIFO(info.st_mode)) {
        refuse(fileKind(info.st_mode), "Give the path of a .toml file (or a pipe).");
    }
    if (regular && std::size_t(info.st_size) > kMaxDocumentBytes) {
        refuse(std::to_string(info.st_size) + " bytes, over the " + limit,
               "Scenes are a few kilobytes; check that this is the scene file.");
    }
    // Back to blocking reads, so a pipe is read until its writer closes it.
    ::fcntl(in.fd, F_SETFL, ::fcntl(in.fd, F_GETFL) & ~O_NONBLOCK);
    std::string text = readUpTo(in.fd, kMaxDocumentBytes + 1, name, what);
    if (text.size() > kMaxDocumentBytes) {
        refuse("more than the " + limit + " (reading stopped there)",
               "Check that this is the scene file; a device or an endless pipe never ends.");
    }
    if (text.empty() && !regular) {
        refuse("nothing (an empty pipe, or one that no process writes)",
               "Start the writer first, or save the scene to a file and give its path.");
    }
    return text;
}

namespace {

/// A small TOML tokenizer that knows only what changes the depth: table headers, keys (dotted
/// or not), arrays and inline tables, and where strings and comments begin and end. Everything
/// else (numbers, dates, booleans) is stepped over, and what toml++ would reject is left for it
/// to report; the scan only has to never count less than toml++ will build.
class PreParseScan {
public:
    PreParseScan(std::string_view text, const std::string& source, int baseDepth)
        : text_(text), source_(source), base_(baseDepth) {}

    void run() {
        // toml++ skips a UTF-8 byte order mark and does not count it as a column.
        if (text_.starts_with("\xef\xbb\xbf")) pos_ = 3;
        while (pos_ < text_.size()) step(text_[pos_]);
    }

private:
    /// What an open array or inline table adds to the depth: 1 for an array (the index), the
    /// segments of the current key for an inline table.
    struct Frame {
        bool table;
        int levels;
    };

    void step(char c) {
        // TOML allows other characters only in strings and comments; refusing them here also
        // keeps toml++ 3.3 from classifying them, which reaches undefined behaviour for many
        // (marzer/tomlplusplus#295).
        if (!isAscii(c)) notAscii("ASCII outside strings and comments");
        if (c == ' ' || c == '\t' || c == '\r') return advance();
        if (c == '\n') {
            lineStart_ = frames_.empty();
            return advance();
        }
        if (c == '#') return skipComment();
        if (lineStart_) {
            lineStart_ = false;
            topKey_ = 0;
            if (c == '[') return header();
            topKey_ = key(depth());
            return;
        }
        if (expectKey_) {
            expectKey_ = false;
            if (c != '}') {
                frames_.back().levels = key(depth() - frames_.back().levels);
                return;
            }
        }
        value(c);
    }

    void value(char c) {
        switch (c) {
            case '"':
            case '\'':
                return skipString(c);
            case '[':
                require(depth() + 1, "an array");
                frames_.push_back({false, 1});
                break;
            case '{':
                frames_.push_back({true, 0});
                expectKey_ = true;
                break;
            case ']':
            case '}':
                if (!frames_.empty()) frames_.pop_back();
                break;
            case ',':
                expectKey_ = !frames_.empty() && frames_.back().table;
                break;
            default:
                break;
        }
        advance();
    }

    /// [a.b] or [[a.b]]: every later key sits under the header's segments, plus the element
    /// index of an array of tables.
    void header() {
        advance();
        const bool arrayOfTables = pos_ < text_.size() && text_[pos_] == '[';
        if (arrayOfTables) advance();
        header_ = 0;
        header_ = key(base_) + (arrayOfTables ? 1 : 0);
        require(base_ + header_, "an array of tables");
    }

    /// Reads a possibly dotted key, checking each segment; returns its number of segments.
    int key(int depthBefore) {
        int segments = 0;
        while (true) {
            skipSpaces();
            if (pos_ >= text_.size()) break;
            const std::size_t start = pos_;
            const Position at = position_;
            const char c = text_[pos_];
            if (c == '"' || c == '\'') {
                skipString(c);
            } else {
                while (pos_ < text_.size() && isBare(text_[pos_])) advance();
            }
            if (pos_ == start) break;
            ++segments;
            checkSegment(at, pos_ - start, depthBefore + segments);
            skipSpaces();
            if (pos_ >= text_.size() || text_[pos_] != '.') break;
            advance();
        }
        return segments;
    }

    static bool isBare(char c) {
        return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
               c == '_' || c == '-';
    }

    /// Steps over a basic or literal string, single- or multi-line, from its opening quote.
    void skipString(char quote) {
        const std::string triple(3, quote);
        const bool multiLine = text_.substr(pos_, 3) == triple;
        advance(multiLine ? 3 : 1);
        while (pos_ < text_.size()) {
            const char c = text_[pos_];
            if (c == '\\' && quote == '"') {
                skipEscape(multiLine);
            } else if (multiLine && text_.substr(pos_, 3) == triple) {
                advance(3);
                // Up to two more quotes belong to the content: """a"""" ends with a quote.
                for (int extra = 0; extra < 2 && pos_ < text_.size() && text_[pos_] == quote;
                     ++extra)
                    advance();
                return;
            } else if (!multiLine && (c == quote || c == '\n')) {
                if (c == quote) advance();
                return;
            } else {
                advance();
            }
        }
    }

    /// Steps over a backslash in a basic string and what it escapes. Every TOML escape is ASCII,
    /// and toml++ 3.3 classifies the character after a backslash (or, after a line-ending
    /// backslash in a """ string, the first one that is not whitespace) in ways that reach
    /// undefined behaviour for many non-ASCII ones (marzer/tomlplusplus#190, #295), so those
    /// are refused here. A line-ending backslash escapes only the whitespace after it: what
    /// follows is content again (another backslash, or the closing quotes), for the caller.
    void skipEscape(bool multiLine) {
        advance();
        bool lineEnding = false;
        while (multiLine && pos_ < text_.size() && isWhitespace(text_[pos_])) {
            advance();
            lineEnding = true;
        }
        if (pos_ < text_.size() && !isAscii(text_[pos_])) {
            notAscii(
                "an ASCII character first after a backslash in a string (every escape is "
                "ASCII; toml++ 3.3 misreads others, marzer/tomlplusplus#190)");
        }
        if (!lineEnding) advance();
    }

    static bool isAscii(char c) { return static_cast<unsigned char>(c) < 0x80; }
    static bool isWhitespace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; }

    [[noreturn]] void notAscii(std::string_view expected) const {
        char found[32];
        std::snprintf(found, sizeof found, "the byte 0x%02X",
                      static_cast<unsigned char>(text_[pos_]));
        throw SceneError(formatError(location(position_), "", expected, found,
                                     "Quote the text, write the character as an escape such as "
                                     "\\u00e9 inside a string, or remove it."));
    }

    void skipComment() {
        while (pos_ < text_.size() && text_[pos_] != '\n') advance();
    }

    void skipSpaces() {
        while (pos_ < text_.size() && (text_[pos_] == ' ' || text_[pos_] == '\t')) advance();
    }

    /// Line and column as toml++ counts them: columns in code points, from 1.
    struct Position {
        std::uint32_t line = 1;
        std::uint32_t column = 1;
    };

    void advance(std::size_t count = 1) {
        for (; count > 0 && pos_ < text_.size(); --count, ++pos_) {
            const unsigned char c = static_cast<unsigned char>(text_[pos_]);
            if (c == '\n') {
                ++position_.line;
                position_.column = 1;
            } else if ((c & 0xC0) != 0x80) {
                ++position_.column;
            }
        }
    }

    int depth() const {
        int total = base_ + header_ + topKey_;
        for (const Frame& frame : frames_) total += frame.levels;
        return total;
    }

    std::string location(Position at) const {
        toml::source_region region;
        region.begin = {at.line, at.column};
        region.end = region.begin;
        region.path = std::make_shared<const std::string>(source_);
        return locationOf(region);
    }

    void checkSegment(Position at, std::size_t length, int depthHere) const {
        if (length > kMaxKeyLength) {
            throw SceneError(formatError(
                location(at), "", "a key of at most " + std::to_string(kMaxKeyLength) + " bytes",
                "one of " + std::to_string(length) + " bytes",
                "Scene keys are short names such as fracture_energy (README \"Scene files\")."));
        }
        if (depthHere > kMaxNesting) tooDeep(at, depthHere, "a key");
    }

    void require(int depthHere, std::string_view what) const {
        if (depthHere > kMaxNesting) tooDeep(position_, depthHere, what);
    }

    [[noreturn]] void tooDeep(Position at, int depthHere, std::string_view what) const {
        throw SceneError(formatError(
            location(at), "",
            "at most " + std::to_string(kMaxNesting) +
                " levels of nested tables, keys and arrays (the shipped scenes need five)",
            std::string(what) + " at level " + std::to_string(depthHere),
            "Flatten the nesting: a scene's values sit at most five levels deep, as in "
            "boundary.0.box.min.1."));
    }

    std::string_view text_;
    const std::string& source_;
    std::size_t pos_ = 0;
    Position position_;
    int base_;
    int header_ = 0;  ///< levels of the current [table] or [[array of tables]]
    int topKey_ = 0;  ///< segments of the current top-level key
    std::vector<Frame> frames_;
    bool lineStart_ = true;
    bool expectKey_ = false;
};

}  // namespace

void checkBeforeParsing(std::string_view text, const std::string& source, int baseDepth) {
    PreParseScan(text, source, baseDepth).run();
}

namespace {

/// Bytes in the UTF-8 sequence that `lead` starts; 0 for a byte no sequence starts with.
int utf8Length(unsigned char lead) {
    if (lead < 0x80) return 1;
    if (lead >= 0xC2 && lead <= 0xDF) return 2;
    if (lead >= 0xE0 && lead <= 0xEF) return 3;
    if (lead >= 0xF0 && lead <= 0xF4) return 4;
    return 0;
}

/// `text` with each non-ASCII character replaced by '?', so lines and columns (counted in code
/// points) stay where they were. '?' is valid in strings and comments and nowhere else, so the
/// stand-in parses only where every non-ASCII character sits in a string or a comment.
std::string asciiStandIn(std::string_view text, const std::string& source) {
    std::string standIn;
    standIn.reserve(text.size());
    toml::source_position at{1, 1};
    // toml++ skips a byte order mark and does not count it as a column.
    const std::size_t start = text.starts_with("\xef\xbb\xbf") ? 3 : 0;
    standIn.append(text.substr(0, start));
    for (std::size_t i = start; i < text.size();) {
        const auto lead = static_cast<unsigned char>(text[i]);
        const int length = utf8Length(lead);
        bool valid = length > 0 && i + std::size_t(length) <= text.size();
        for (int k = 1; valid && k < length; ++k)
            valid = (static_cast<unsigned char>(text[i + k]) & 0xC0) == 0x80;
        if (!valid) {
            char found[32];
            std::snprintf(found, sizeof found, "the byte 0x%02X", lead);
            toml::source_region region{at, at, std::make_shared<const std::string>(source)};
            throw SceneError(formatError(locationOf(region), "", "text in UTF-8", found,
                                         "Save the file as UTF-8."));
        }
        standIn.push_back(length == 1 ? text[i] : '?');
        at = lead == '\n' ? toml::source_position{at.line + 1, 1}
                          : toml::source_position{at.line, at.column + 1};
        i += std::size_t(length);
    }
    return standIn;
}

}  // namespace

toml::table parseDocument(std::string_view text, const std::string& source, int baseDepth) {
    checkBeforeParsing(text, source, baseDepth);
    const bool ascii = std::all_of(text.begin(), text.end(),
                                   [](char c) { return static_cast<unsigned char>(c) < 0x80; });
    // toml++ 3.3 reaches undefined behaviour when it classifies some non-ASCII characters
    // (marzer/tomlplusplus#190, #295), which it does while reading past an error as well as
    // outside strings. The stand-in has none: where the document is wrong, its error is the
    // one reported, and the original is parsed only when every non-ASCII character is in a
    // string or a comment of a well-formed document.
    if (!ascii) (void)toml::parse(asciiStandIn(text, source), source);
    return toml::parse(text, source);
}

}  // namespace rend::scene
