// app/AlignedNew.cpp: the programs that link rend_app start every allocation of 4 KiB or more on
// a 64-byte line, so the kernels' 512-bit loads of the particle and pair arrays never span two,
// and from 4 MiB on a 2 MiB huge page.

#include <gtest/gtest.h>
#include <malloc.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
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

// The kB of transparent huge pages in the mapping (/proc/self/smaps) that holds p, or -1.
long hugeKilobytesAt(const void* p) {
    const auto at = reinterpret_cast<std::uintptr_t>(p);
    std::ifstream smaps("/proc/self/smaps");
    std::string line;
    bool inside = false;
    while (std::getline(smaps, line)) {
        std::uintptr_t from = 0, to = 0;
        char dash = 0;
        std::istringstream head(line);
        if (head >> std::hex >> from >> dash >> to && dash == '-') {
            inside = from <= at && at < to;
        } else if (inside && line.rfind("AnonHugePages:", 0) == 0) {
            return std::stol(line.substr(14));
        }
    }
    return -1;
}

bool hugePagesOnRequest() {
    std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
    std::string modes;
    std::getline(file, modes);
    return modes.find("[always]") != std::string::npos ||
           modes.find("[madvise]") != std::string::npos;
}

// A large block that malloc carves from memory it used before (small pages already there, as
// after a set-up's freed maps) gets huge pages all the same. Without giving the old pages back
// first, the block kept them small: 2.2 of a 10^7 sheet's 11 GB.
TEST(AlignedNew, ALargeBlockInReusedMemoryGetsHugePages) {
    if (!hugePagesOnRequest()) GTEST_SKIP() << "transparent huge pages are off on this system";
    constexpr std::size_t kBlock = std::size_t(8) << 20;
    // A fresh block first: where the system has no huge page to give now, there is nothing to
    // check.
    auto fresh = std::make_unique<std::vector<char>>(kBlock, 1);
    if (hugeKilobytesAt(fresh->data() + kBlock / 2) <= 0)
        GTEST_SKIP() << "the system gave no huge page to a fresh block";
    fresh.reset();
    // Touched small blocks, freed (a small one kept after them, so the heap is not trimmed).
    std::vector<void*> small;
    for (int k = 0; k < 400000; ++k) {
        small.push_back(std::malloc(96));
        static_cast<char*>(small.back())[0] = 1;
    }
    void* keep = std::malloc(96);
    for (void* q : small) std::free(q);
    std::vector<char> block(std::size_t(12) << 20, 2);
    EXPECT_EQ(block[block.size() / 2], 2);
    EXPECT_GE(hugeKilobytesAt(block.data() + (std::size_t(4) << 20)), 2048);
    std::free(keep);
}

// A large block freed and taken again keeps its pages: they were given back once, when first
// taken, and not again (the frame's meshes and buffers, every frame). Given back, they would read
// as zeros.
TEST(AlignedNew, ALargeBlockTakenAgainKeepsItsPages) {
    constexpr std::size_t kBlock = std::size_t(12) << 20;
    // Kept in the heap, as malloc's dynamic thresholds keep a run's frame blocks once it has
    // freed one (a block mapped on its own is unmapped when freed, a trimmed top given back:
    // memory taken again there is zeros whatever this file does).
    mallopt(M_MMAP_THRESHOLD, 32 << 20);
    mallopt(M_TRIM_THRESHOLD, 64 << 20);
    auto* first = static_cast<unsigned char*>(::operator new(kBlock));
    for (std::size_t k = 0; k < kBlock; k += 4096) first[k] = 7;
    void* const firstAddress = first;
    ::operator delete(first);
    auto* again = static_cast<unsigned char*>(::operator new(kBlock));
    if (static_cast<void*>(again) != firstAddress) {
        ::operator delete(again);
        GTEST_SKIP() << "malloc placed the second block elsewhere";
    }
    int kept = 0;
    for (std::size_t k = std::size_t(4) << 20; k < kBlock; k += 4096) kept += again[k] == 7;
    EXPECT_EQ(kept, int((kBlock - (std::size_t(4) << 20)) / 4096));
    ::operator delete(again);
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
