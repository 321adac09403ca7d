// Pipeline pieces that need no scene file: frame timing and the --frames option.

#include "app/Pipeline.h"

#include <gtest/gtest.h>

#include "app/FrameSelection.h"
#include "app/SceneError.h"

using namespace rend;

TEST(Pipeline, SubstepsLandFramesExactlyAndNeverExceedTheRequestedStep) {
    const auto [substeps, dt] = substepsPerFrame(1e-4, 24.0);
    EXPECT_EQ(substeps, 417);
    EXPECT_LE(dt, 1e-4);
    EXPECT_DOUBLE_EQ(substeps * dt, 1.0 / 24.0);
    EXPECT_EQ(substepsPerFrame(0.25, 24.0).first, 1) << "a step longer than a frame is one step";
    EXPECT_EQ(substepsPerFrame(1.0 / 240.0, 24.0).first, 10) << "no extra step from rounding";
}

TEST(Pipeline, FrameListsTakeTheRenderFarmsForms) {
    EXPECT_EQ(parseFrameList("7", 120), std::vector<int>{7});
    EXPECT_EQ(parseFrameList("1-120", 120).size(), 120u);
    EXPECT_EQ(parseFrameList("1-3,20,30-36:2", 120),
              (std::vector<int>{1, 2, 3, 20, 30, 32, 34, 36}));
    EXPECT_EQ(parseFrameList("5,1-3,2", 120), (std::vector<int>{1, 2, 3, 5})) << "sorted, once";
    for (const char* bad :
         {"0", "5-4", "1-121", "abc", "3-x", "2-3-4", "1-10:0", "1,,2", "", "1-10:", " 1-3 x"})
        EXPECT_THROW(parseFrameList(bad, 120), SceneError) << bad;
}

TEST(Pipeline, ChunksSplitTheFramesIntoContiguousPartsThatCoverThemOnce) {
    const std::vector<int> frames = parseFrameList("1-10,20,30-40:2", 120);
    for (const int n : {1, 2, 3, 7, 17}) {
        std::vector<int> joined;
        std::size_t smallest = frames.size(), largest = 0;
        for (int k = 1; k <= n; ++k) {
            const std::vector<int> part =
                chunkOf(frames, std::to_string(k) + "/" + std::to_string(n));
            joined.insert(joined.end(), part.begin(), part.end());
            smallest = std::min(smallest, part.size());
            largest = std::max(largest, part.size());
        }
        EXPECT_EQ(joined, frames) << n << " chunks";
        EXPECT_LE(largest - smallest, 1u) << n << " chunks";
    }
    for (const char* bad : {"0/3", "4/3", "1/0", "a/b", "1/3x", "1-3"})
        EXPECT_THROW(chunkOf(frames, bad), SceneError) << bad;
}
