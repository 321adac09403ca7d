#include "app/FrameSelection.h"

#include <algorithm>
#include <cstdio>
#include <string_view>

#include "app/SceneError.h"

namespace rend {

namespace {

[[noreturn]] void badList(const std::string& text, const std::string& part, int frameCount) {
    throw SceneError("--frames " + text + ": error: expected N, FIRST-LAST or FIRST-LAST:STEP " +
                     "within 1-" + std::to_string(frameCount) + ", separated by commas, found \"" +
                     part + "\" (the scene has " + std::to_string(frameCount) +
                     " frames). Use e.g. --frames 1-10,20,30-" + std::to_string(frameCount) +
                     ":2.");
}

/// One comma-separated part: N, FIRST-LAST or FIRST-LAST:STEP.
void addPart(const std::string& text, const std::string& part, int frameCount,
             std::vector<int>& frames) {
    int first = 0, last = 0, step = 1;
    char extra = 0;
    const bool single = std::sscanf(part.c_str(), "%d%c", &first, &extra) == 1;
    const bool range = std::sscanf(part.c_str(), "%d-%d%c", &first, &last, &extra) == 2;
    const bool stepped = std::sscanf(part.c_str(), "%d-%d:%d%c", &first, &last, &step, &extra) == 3;
    if (single) last = first;
    if ((!single && !range && !stepped) || first < 1 || last < first || last > frameCount ||
        step < 1)
        badList(text, part, frameCount);
    for (int frame = first; frame <= last; frame += step) frames.push_back(frame);
}

}  // namespace

std::vector<int> parseFrameList(const std::string& text, int frameCount) {
    std::vector<int> frames;
    std::size_t start = 0;
    while (start <= text.size()) {
        const std::size_t end = std::min(text.find(',', start), text.size());
        addPart(text, text.substr(start, end - start), frameCount, frames);
        start = end + 1;
    }
    std::sort(frames.begin(), frames.end());
    frames.erase(std::unique(frames.begin(), frames.end()), frames.end());
    return frames;
}

std::vector<int> chunkOf(const std::vector<int>& frames, const std::string& text) {
    int k = 0, n = 0;
    char extra = 0;
    if (std::sscanf(text.c_str(), "%d/%d%c", &k, &n, &extra) != 2 || n < 1 || k < 1 || k > n)
        throw SceneError("--chunk " + text + ": error: expected K/N with 1 <= K <= N, found \"" +
                         text + "\". Use e.g. --chunk 2/8 for the second of eight chunks.");
    const std::size_t size = frames.size(), begin = size * std::size_t(k - 1) / std::size_t(n),
                      end = size * std::size_t(k) / std::size_t(n);
    return {frames.begin() + std::ptrdiff_t(begin), frames.begin() + std::ptrdiff_t(end)};
}

}  // namespace rend
