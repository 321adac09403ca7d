// app/AlignedNew.cpp: the programs that link rend_app start every allocation of 4 KiB or more on
// a 64-byte line, so the kernels' 512-bit loads of the particle and pair arrays never span two,
// and from 4 MiB on a 2 MiB huge page.

#include <gtest/gtest.h>

#include <cstdint>
#include <memory>
#include <vector>

#include "app/Scene.h"
#include "sim/Membrane.h"

namespace rend {
namespace {

bool onALine(const void* p) { return reinterpret_cast<std::uintptr_t>(p) % 64 == 0; }

TEST(AlignedNew, LargeAllocationsStartOnACacheLine) {
    int aligned = 0;
    std::vector<std::unique_ptr<std::vector<double>>> kept;  // kept, so no block is reused
    for (int k = 0; k < 20; ++k) {
        kept.push_back(std::make_unique<std::vector<double>>(512 + 37 * k));
        aligned += onALine(kept.back()->data());
    }
    EXPECT_EQ(aligned, 20);
}

// From 4 MiB, on a 2 MiB boundary (whole huge pages for madvise), and the memory is usable.
TEST(AlignedNew, AllocationsFromFourMebibytesStartOnAHugePage) {
    std::vector<std::unique_ptr<std::vector<double>>> kept;
    int aligned = 0;
    for (int k = 0; k < 4; ++k) {
        const std::size_t count = (std::size_t(4) << 20) / sizeof(double) + 1000 * k;
        kept.push_back(std::make_unique<std::vector<double>>(count, double(k)));
        aligned += reinterpret_cast<std::uintptr_t>(kept.back()->data()) % (2u << 20) == 0;
        EXPECT_EQ(kept.back()->back(), double(k));
    }
    EXPECT_EQ(aligned, 4);
    std::vector<double> small(1000);
    EXPECT_TRUE(onALine(small.data()));
}

TEST(AlignedNew, AMembranesParticleArraysStartOnACacheLine) {
    sim::MembraneParams p;
    p.sheet.size = {0.5, 0.5};
    p.sheet.dx = 0.01;
    const sim::Membrane m(p);
    ASSERT_GT(m.particleCount(), 1000);
    EXPECT_TRUE(onALine(m.positions().data()));
    EXPECT_TRUE(onALine(m.velocities().data()));
    EXPECT_TRUE(onALine(m.masses().data()));
}

}  // namespace
}  // namespace rend
