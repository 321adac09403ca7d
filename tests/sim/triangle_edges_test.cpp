// sim/TriangleEdges.h: edges numbered in order of first use, found through the triangles at each
// corner, the same numbers as a map of every pair gives.

#include <gtest/gtest.h>

#include <array>
#include <cstdint>
#include <map>
#include <vector>

#include "sim/Lattice.h"
#include "sim/TriangleEdges.h"

namespace rend::sim {
namespace {

// The definition: sides in order, a pair's number the first time it is used.
TriangleEdges byMap(const std::vector<std::array<int, 3>>& triangles, int firstCorner) {
    TriangleEdges edges;
    std::map<std::array<int, 2>, int> index;
    for (const auto& t : triangles) {
        std::array<int, 3> sides{};
        for (int s = 0; s < 3; ++s) {
            const int a = t[(s + firstCorner) % 3], b = t[(s + firstCorner + 1) % 3];
            const std::array<int, 2> pair{std::min(a, b), std::max(a, b)};
            const auto [it, added] = index.try_emplace(pair, int(edges.ends.size()));
            if (added) edges.ends.push_back(pair);
            sides[s] = it->second;
        }
        edges.ofTriangle.push_back(sides);
    }
    return edges;
}

void expectSame(const std::vector<std::array<int, 3>>& triangles) {
    for (const int firstCorner : {0, 1, 2}) {
        const TriangleEdges fast = triangleEdges(triangles, firstCorner);
        const TriangleEdges reference = byMap(triangles, firstCorner);
        EXPECT_EQ(fast.ends, reference.ends) << "first corner " << firstCorner;
        EXPECT_EQ(fast.ofTriangle, reference.ofTriangle) << "first corner " << firstCorner;
    }
}

TEST(TriangleEdges, ALatticesEdgesAreNumberedAsAMapOfPairsNumbersThem) {
    SheetParams sheet;
    sheet.size = {0.3, 0.2};
    sheet.dx = 0.01;
    for (const LatticeKind kind : {LatticeKind::Hexagonal, LatticeKind::Square}) {
        sheet.lattice = kind;
        const Lattice lattice = generateLattice(sheet);
        ASSERT_GT(lattice.triangles.size(), 500u);
        expectSame(lattice.triangles);
    }
}

// Shuffled corners, triangles in any order, an edge on three triangles, a side used twice in
// one triangle and a corner repeated: the same numbers as the map.
TEST(TriangleEdges, AnyTriangleListIsNumberedAsAMapOfPairsNumbersIt) {
    std::vector<std::array<int, 3>> triangles{{0, 1, 2}, {2, 1, 3}, {1, 2, 4}, {5, 5, 6},
                                              {6, 5, 5}, {7, 8, 7}, {3, 9, 0}};
    std::uint32_t random = 7;
    for (int k = 0; k < 3000; ++k) {
        std::array<int, 3> t{};
        for (int& v : t) {
            random = random * 1664525u + 1013904223u;
            v = int(random >> 24) % 60;
        }
        triangles.push_back(t);
    }
    expectSame(triangles);
    expectSame({});
}

}  // namespace
}  // namespace rend::sim
