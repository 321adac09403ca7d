#pragma once
// How one fuzz input is read: the scene text, then optionally a line "--set" followed by one
// --set override per line. The harness and the regression replay test share this split, so a
// saved crashing input replays exactly as it ran.

#include <string>
#include <string_view>
#include <vector>

namespace rend::fuzz {

struct FuzzInput {
    std::string scene;
    std::vector<std::string> sets;
};

inline constexpr std::string_view kSetSeparator = "\n--set\n";

inline FuzzInput splitFuzzInput(std::string_view data) {
    const std::size_t separator = data.find(kSetSeparator);
    FuzzInput input{std::string(data.substr(0, separator)), {}};
    if (separator == std::string_view::npos) return input;
    std::string_view rest = data.substr(separator + kSetSeparator.size());
    while (!rest.empty()) {
        const std::size_t end = rest.find('\n');
        input.sets.emplace_back(rest.substr(0, end));
        if (end == std::string_view::npos) break;
        rest.remove_prefix(end + 1);
    }
    return input;
}

}  // namespace rend::fuzz
