// sim/Bonds.h: a particle's family is every other particle within the horizon, ascending, with
// its rest length and weight, whatever the grid the search goes through (dense on a sheet,
// hashed where the points lie far apart) and whatever the thread count.

#include "sim/Bonds.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <utility>
#include <vector>

#include "sim/DamageState.h"
#include "sim/Lattice.h"
#include "sim/Random.h"
#include "sim/StateArchive.h"

namespace rend::sim {
namespace {

// The definition: every pair tested.
BondFamilies everyPair(const std::vector<Eigen::Vector3d>& rest, double horizon) {
    const double reach = horizon * (1.0 + 1e-9);
    BondFamilies bonds;
    bonds.offsets.push_back(0);
    for (int i = 0; i < int(rest.size()); ++i) {
        for (int j = 0; j < int(rest.size()); ++j) {
            const double length = (rest[j] - rest[i]).norm();
            if (j == i || !(length <= reach)) continue;
            bonds.partners.push_back(j);
            bonds.restLength.push_back(length);
            bonds.weight.push_back(std::max(0.0, 1.0 - length / horizon));
        }
        bonds.offsets.push_back(int(bonds.partners.size()));
    }
    return bonds;
}

void expectSame(const BondFamilies& found, const BondFamilies& expected) {
    ASSERT_EQ(found.offsets, expected.offsets);
    ASSERT_EQ(found.partners, expected.partners);
    ASSERT_EQ(found.restLength, expected.restLength);  // the same expression: the same bits
    ASSERT_EQ(found.weight, expected.weight);
}

TEST(BondFamilies, AreEveryPairWithinTheHorizonOnASheet) {
    SheetParams sheet;
    sheet.size = {0.3, 0.2};
    sheet.dx = 0.01;
    const std::vector<Eigen::Vector3d> rest = generateLattice(sheet).positions;
    for (const double horizon : {1.0, 1.5, 3.0}) {  // 1.0: bonds at exactly R kept
        const BondFamilies expected = everyPair(rest, horizon * sheet.dx);
        for (const int threads : {1, 2, 3}) {
            omp_set_num_threads(threads);
            expectSame(buildBondFamilies(rest, horizon * sheet.dx), expected);
        }
    }
    omp_set_num_threads(omp_get_num_procs());
}

TEST(BondFamilies, AreEveryPairWithinTheHorizonAmongPointsFarApart) {
    // Three clouds a thousand horizons apart (a dense grid of their bounding cells would hold a
    // million cells per point), points stacked in z among them (the grid is in x and y).
    std::vector<Eigen::Vector3d> rest;
    const double horizon = 0.05;
    for (int k = 0; k < 600; ++k) {
        const Eigen::Vector3d centre(50.0 * (k % 3), -40.0 * (k % 3 == 1), 0.0);
        rest.push_back(centre + Eigen::Vector3d(0.3 * uniformFromHash(21, 3 * k),
                                                0.3 * uniformFromHash(21, 3 * k + 1),
                                                0.1 * uniformFromHash(21, 3 * k + 2)));
    }
    const BondFamilies expected = everyPair(rest, horizon);
    EXPECT_GT(expected.partners.size(), 3000u);
    for (const int threads : {1, 2}) {
        omp_set_num_threads(threads);
        expectSame(buildBondFamilies(rest, horizon), expected);
    }
    omp_set_num_threads(omp_get_num_procs());
    EXPECT_TRUE(buildBondFamilies({}, horizon).partners.empty());
}

// Breaking a bond breaks its copy at the other end, found by each family's bisection (findBond),
// and nothing else; a bond whose other end holds no copy (a family built by hand) breaks alone.
TEST(BondFamilies, ABrokenBondsCopyAtTheOtherEndBreaksWithIt) {
    SheetParams sheet;
    sheet.size = {0.1, 0.08};
    sheet.dx = 0.01;
    const Lattice lattice = generateLattice(sheet);
    BondFamilies bonds = buildBondFamilies(lattice.positions, 2.0 * sheet.dx);
    // Particle 5 loses its bond to its last partner: that partner's bond to 5 has no copy.
    const int lonely = bonds.partners[bonds.offsets[6] - 1];
    const int orphan = findBond(bonds, lonely, 5);
    ASSERT_GE(orphan, 0);
    bonds.partners.erase(bonds.partners.begin() + bonds.offsets[6] - 1);
    bonds.restLength.erase(bonds.restLength.begin() + bonds.offsets[6] - 1);
    bonds.weight.erase(bonds.weight.begin() + bonds.offsets[6] - 1);
    for (std::size_t i = 6; i < bonds.offsets.size(); ++i) --bonds.offsets[i];
    const int orphaned = orphan - (orphan >= bonds.offsets[6] ? 1 : 0);
    ASSERT_EQ(bonds.partners[orphaned], 5);
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; b += 3) {
            DamageState damage(bonds, lattice.triangles);
            damage.breakBond(b);
            const int copy = findBond(bonds, bonds.partners[b], i);
            EXPECT_EQ(copy < 0, b == orphaned);
            int broken = 0;
            for (int k = 0; k < int(bonds.directedCount()); ++k) broken += !damage.bondAlive()[k];
            ASSERT_EQ(broken, copy < 0 ? 1 : 2) << "bond " << b << " of particle " << i;
            EXPECT_FALSE(damage.bondAlive()[b]);
            if (copy >= 0) EXPECT_FALSE(damage.bondAlive()[copy]);
        }
    DamageState damage(bonds, lattice.triangles);
    damage.breakBond(orphaned);
    EXPECT_EQ(std::count(damage.bondAlive().begin(), damage.bondAlive().end(), 0), 1);
}

// Proposed breaks applied at once (eight flags at a time where none is set) give the bits and
// the order of breaking them one by one in index order; DamageState::breaksSince gives both
// copies of each bond broken since a version, and nothing once the state was loaded since.
TEST(DamageState, AppliedProposalsBreakInIndexOrderAndTheLogGivesEachBreak) {
    SheetParams sheet;
    sheet.size = {0.1, 0.08};
    sheet.dx = 0.01;
    const Lattice lattice = generateLattice(sheet);
    const BondFamilies bonds = buildBondFamilies(lattice.positions, 1.5 * sheet.dx);
    const int n = int(bonds.directedCount());
    DamageState proposed(bonds, lattice.triangles), oneByOne(bonds, lattice.triangles);
    // Ends, a word's every flag, neighbours across a word's edge and a scatter.
    std::vector<int> chosen = {0, 7, 8, 9, 15, 16, 17, 18, 19, 20, 21, 22, 23, n - 1};
    for (int b = 30; b < n - 1; b += 13) chosen.push_back(b);
    const std::uint64_t before = proposed.version();
    for (const int b : chosen) proposed.proposeBreak(b);
    proposed.applyProposals();
    std::sort(chosen.begin(), chosen.end());
    for (const int b : chosen) oneByOne.breakBond(b);
    EXPECT_EQ(proposed.bondAlive(), oneByOne.bondAlive());
    EXPECT_EQ(proposed.keptTriangles(), oneByOne.keptTriangles());
    EXPECT_EQ(proposed.brokenBondCount(), oneByOne.brokenBondCount());
    for (int b = 0; b < n; ++b) ASSERT_EQ(proposed.proposals()[b], 0) << b;
    const auto log = proposed.breaksSince(before);
    ASSERT_TRUE(log.has_value());
    ASSERT_EQ(log->size(), proposed.brokenBondCount());
    std::vector<std::uint8_t> alive(n, 1);
    for (const auto& [b, mirror] : *log) {
        ASSERT_EQ(mirror, proposed.mirror(b));
        EXPECT_TRUE(alive[b]) << "bond " << b << " broken twice";
        alive[b] = 0;
        if (mirror >= 0) alive[mirror] = 0;
    }
    EXPECT_EQ(alive, proposed.bondAlive());
    EXPECT_EQ(proposed.breaksSince(proposed.version())->size(), 0u);
    EXPECT_FALSE(proposed.breaksSince(proposed.version() + 1).has_value());
    // A loaded state's copy of the flags must be made again.
    StateWriter out;
    DamageState::visitState(std::as_const(proposed), out);
    const std::vector<std::byte> bytes = out.take();
    StateReader in(bytes);
    DamageState::visitState(oneByOne, in);
    EXPECT_FALSE(oneByOne.breaksSince(before).has_value());
    EXPECT_TRUE(oneByOne.breaksSince(oneByOne.version()).has_value());
}

}  // namespace
}  // namespace rend::sim
