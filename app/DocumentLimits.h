#pragma once
// Limits checked before a scene file, a material preset or a --set value reaches the TOML
// parser, so that a hostile input is refused with its location instead of exhausting the stack
// or the memory.

#include <toml++/toml.h>

#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

namespace rend::scene {

/// Scenes are hand-written settings of a few kilobytes (the largest shipped one has 2.2 KB).
/// 16 MiB leaves room for generated point lists thousands of times longer, while bounding the
/// worst case: an array of 3.5 million numbers (14 MB) takes 9 s and 350 MB to parse and refuse
/// on the 2-core VM. A device or an endless pipe stops here instead of filling the memory.
inline constexpr std::size_t kMaxDocumentBytes = std::size_t{16} << 20;

/// Components of a value's dotted path (boundary.0.box.min.1 has five), counting table headers,
/// dotted keys, inline tables and array elements. The shipped scenes need at most five. toml++
/// caps nested arrays and inline tables (256) but not dotted keys or headers, and it recurses
/// once per level when it builds and frees the tree: some 10^5 levels overflow the stack.
inline constexpr int kMaxNesting = 32;

/// Bytes in one key. Scene keys are short names, so a longer key is a mistake, and it would
/// otherwise be echoed whole by the unknown-key message.
inline constexpr std::size_t kMaxKeyLength = 256;

/// The bytes of a regular file or a pipe, at most kMaxDocumentBytes. Directories, devices and
/// sockets are refused, and so is an empty document. `what` names the file in messages ("scene
/// file"). Throws SceneError.
std::string readDocument(const std::filesystem::path& file, std::string_view what);

/// Throws SceneError at the first place where `text` nests deeper than kMaxNesting, has a key
/// longer than kMaxKeyLength, or has a non-ASCII byte where toml++ 3.3 would reach undefined
/// behaviour on it (outside strings and comments, which TOML forbids anyway, and first after a
/// backslash in a """ string). `baseDepth` counts the levels the text will sit under (1 for a
/// preset, merged into [material]); `source` is the path the parser will report, a file or a
/// --set label. Strings and comments are skipped, so brackets and dots in them do not count.
void checkBeforeParsing(std::string_view text, const std::string& source, int baseDepth = 0);

/// checkBeforeParsing, then toml::parse. A document with non-ASCII text is parsed first with
/// each non-ASCII character replaced by '?' (invalid UTF-8 throws SceneError at its location),
/// and its own parse only when that one succeeds: toml++ 3.3 misreads non-ASCII characters
/// wherever it is not inside a string or a comment, including while it reads past an error.
/// Throws toml::parse_error like toml::parse, located in `source`.
toml::table parseDocument(std::string_view text, const std::string& source, int baseDepth = 0);

}  // namespace rend::scene
