// Pipeline pieces that need no scene file: frame timing and the --frames option.

#include "app/Pipeline.h"

#include <gtest/gtest.h>

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

TEST(Pipeline, FrameRangeAcceptsOneFrameOrARangeWithinTheScene) {
    EXPECT_EQ(parseFrameRange("7", 120), (std::pair{7, 7}));
    EXPECT_EQ(parseFrameRange("1-120", 120), (std::pair{1, 120}));
    for (const char* bad : {"0", "5-4", "1-121", "abc", "3-x", "2-3-4"})
        EXPECT_THROW(parseFrameRange(bad, 120), SceneError) << bad;
}
