#pragma once
// Which frames a command writes: the render farm's forms, as Houdini's and Deadline's frame
// lists read: "7", "1-120", "1-10,20,30-40:2" (every second frame of 30-40), and --chunk K/N,
// the K-th of N contiguous chunks of those, for a job array that splits one shot.

#include <string>
#include <vector>

namespace rend {

/// The frames of `text` within 1..frameCount, ascending, each once. Throws SceneError naming
/// the part that is wrong and the forms it takes.
std::vector<int> parseFrameList(const std::string& text, int frameCount);

/// The K-th (1-based) of N contiguous chunks of `frames` ("K/N"); the chunks' sizes differ by at
/// most one and together hold every frame once. Throws SceneError unless 1 <= K <= N.
std::vector<int> chunkOf(const std::vector<int>& frames, const std::string& text);

}  // namespace rend
