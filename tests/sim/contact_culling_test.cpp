// Self-contact's culling (sim/ContactCulling.h) and candidate list (sim/Contact.h) against brute
// force: whatever the sheet's shape, nothing within reach of a particle and not bonded to it at
// rest is left out, and a smooth sheet is left out of the search.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

#include "sim/ColliderDistance.h"
#include "sim/Contact.h"
#include "sim/ContactCulling.h"
#include "sim/Lattice.h"

using namespace rend::sim;

namespace {

constexpr double kDx = 0.01;
const double kBondReach = 1.5 * kDx * (1.0 + 1e-9);

struct Sheet {
    Lattice lattice;
    std::span<const Eigen::Vector3d> rest() const { return lattice.positions; }
};

Sheet makeSheet(LatticeKind kind, Eigen::Vector2d size) {
    SheetParams p;
    p.size = size;
    p.dx = kDx;
    p.lattice = kind;
    return {generateLattice(p)};
}

bool bonded(const Sheet& s, int i, int j) {
    return (s.rest()[std::size_t(i)] - s.rest()[std::size_t(j)]).squaredNorm() <=
           kBondReach * kBondReach;
}

/// Every particle pair and particle-triangle pair within reach and not bonded at rest involves
/// particles marked 1 and a triangle with a marked corner (ContactCulling::mark's contract).
void expectContract(const Sheet& s, std::span<const Eigen::Vector3d> x, double reach,
                    const std::vector<std::uint8_t>& active) {
    const int n = int(x.size());
    int missed = 0;
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j)
            if (j != i && !bonded(s, i, j) && (x[i] - x[j]).norm() < reach && active[i] != 1)
                ++missed;
        for (const auto& tri : s.lattice.triangles) {
            if (bonded(s, i, tri[0]) || bonded(s, i, tri[1]) || bonded(s, i, tri[2])) continue;
            const TrianglePoint c = closestOnTriangle(x[i], x[tri[0]], x[tri[1]], x[tri[2]]);
            if ((x[i] - c.at(x[tri[0]], x[tri[1]], x[tri[2]])).norm() >= reach) continue;
            if (active[i] != 1 || (!active[tri[0]] && !active[tri[1]] && !active[tri[2]])) ++missed;
        }
    }
    EXPECT_EQ(missed, 0);
}

/// Each particle's nearest triangle within d, and its particles within d, not bonded at rest:
/// what Contact::lastPairCount counts.
std::size_t contactsByBruteForce(const Sheet& s, std::span<const Eigen::Vector3d> x, double d) {
    std::size_t count = 0;
    const int n = int(x.size());
    for (int i = 0; i < n; ++i) {
        for (int j = 0; j < n; ++j)
            if (j != i && !bonded(s, i, j) && (x[i] - x[j]).squaredNorm() < d * d) ++count;
        for (const auto& tri : s.lattice.triangles) {
            if (bonded(s, i, tri[0]) || bonded(s, i, tri[1]) || bonded(s, i, tri[2])) continue;
            const TrianglePoint c = closestOnTriangle(x[i], x[tri[0]], x[tri[1]], x[tri[2]]);
            if ((x[i] - c.at(x[tri[0]], x[tri[1]], x[tri[2]])).squaredNorm() < d * d) {
                ++count;
                break;
            }
        }
    }
    return count;
}

/// Shapes marked at random: each keeps mark's contract, and over all of them some were searched
/// and some left quiet (so the shapes test both sides of the bounds).
struct MarkTally {
    int searched = 0, quiet = 0;
    void check(const Sheet& s, const ContactCulling& culling, std::span<const Eigen::Vector3d> x,
               double reach) {
        std::vector<std::uint8_t> active;
        const int marked = culling.mark(x, reach, s.lattice.triangles, {}, active);
        searched += marked > 0;
        quiet += marked < int(x.size());
        expectContract(s, x, reach, active);
    }
    void expectBoth() const {
        EXPECT_GT(searched, 0);
        EXPECT_GT(quiet, 0);
    }
};

using Deform = std::function<Eigen::Vector3d(const Eigen::Vector3d&)>;

std::vector<Eigen::Vector3d> deformed(const Sheet& s, const Deform& f) {
    std::vector<Eigen::Vector3d> x;
    for (const Eigen::Vector3d& p : s.rest()) x.push_back(f(p));
    return x;
}

/// A sheet with self-contact at d = dx / 2, unit masses and no velocities, whose kept list is
/// compared with one built afresh at each evaluation.
struct KeptAgainstFresh {
    Sheet s = makeSheet(LatticeKind::Hexagonal, {0.2, 0.12});
    ContactParams params = [] {
        ContactParams p;
        p.self.enabled = true;
        return p;
    }();
    double d = 0.5 * kDx;
    int n = int(s.rest().size());
    std::vector<double> mass = std::vector<double>(std::size_t(n), 1.0);
    std::vector<Eigen::Vector3d> v =
        std::vector<Eigen::Vector3d>(std::size_t(n), Eigen::Vector3d::Zero());
    Contact kept = make();

    Contact make() const {
        return Contact(params, d, 1.5 * kDx, 1.0, s.lattice.triangles, s.rest());
    }
    std::vector<Eigen::Vector3d> forces(Contact& c, std::span<const Eigen::Vector3d> x) const {
        std::vector<Eigen::Vector3d> f(std::size_t(n), Eigen::Vector3d::Zero());
        c.addSelfContactForces({x, v, s.rest(), mass, {}, 1e-3}, f);
        return f;
    }
    /// The kept list's forces at x against a fresh list's, to 1e-9 of the largest.
    void expectFreshForces(std::span<const Eigen::Vector3d> x, int frame) {
        const std::vector<Eigen::Vector3d> fromKept = forces(kept, x);
        Contact fresh = make();
        const std::vector<Eigen::Vector3d> fromFresh = forces(fresh, x);
        ASSERT_EQ(kept.lastPairCount(), fresh.lastPairCount()) << "frame " << frame;
        double largest = 0.0;
        for (const Eigen::Vector3d& f : fromFresh) largest = std::max(largest, f.norm());
        for (int i = 0; i < n; ++i)
            ASSERT_LE((fromKept[std::size_t(i)] - fromFresh[std::size_t(i)]).norm(), 1e-9 * largest)
                << "particle " << i << ", frame " << frame;
    }
};

}  // namespace

TEST(ContactCulling, RestClearanceIsTheNearestUnbondedParticleOrTriangle) {
    const Sheet hex = makeSheet(LatticeKind::Hexagonal, {0.2, 0.2});
    const ContactCulling h(hex.rest(), hex.lattice.triangles, kBondReach * kBondReach,
                           3 * kBondReach);
    EXPECT_NEAR(h.restClearance(), std::sqrt(3.0) * kDx, 1e-9);  // the second shell
    const Sheet square = makeSheet(LatticeKind::Square, {0.2, 0.2});
    const ContactCulling q(square.rest(), square.lattice.triangles, kBondReach * kBondReach,
                           3 * kBondReach);
    // Particles two apart along a row are the nearest unbonded ones (2 dx), but a diagonal of a
    // cell whose corners are all unbonded passes nearer.
    EXPECT_GT(q.restClearance(), kBondReach);
    EXPECT_LE(q.restClearance(), 2.0 * kDx + 1e-12);
}

TEST(ContactCulling, SmoothSheetsAreLeftOut) {
    const Sheet s = makeSheet(LatticeKind::Hexagonal, {0.3, 0.3});
    const ContactCulling culling(s.rest(), s.lattice.triangles, kBondReach * kBondReach,
                                 3 * kBondReach);
    const double reach = 0.8 * kDx;
    const std::vector<std::pair<const char*, Deform>> shapes = {
        {"flat", [](const Eigen::Vector3d& p) -> Eigen::Vector3d { return p; }},
        {"moved and turned",
         [](const Eigen::Vector3d& p) -> Eigen::Vector3d {
             return Eigen::Vector3d(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()) *
                                    p) +
                    Eigen::Vector3d(5, -3, 2);
         }},
        {"stretched 40% and drawn in 10%",
         [](const Eigen::Vector3d& p) -> Eigen::Vector3d {
             return Eigen::Vector3d(1.4 * p.x(), 0.9 * p.y(), p.z());
         }},
        {"rolled on a cylinder of 40 dx",
         [](const Eigen::Vector3d& p) -> Eigen::Vector3d {
             const double r = 40 * kDx, a = p.x() / r;
             return Eigen::Vector3d(r * std::sin(a), p.y(), r * (1 - std::cos(a)));
         }},
        {"wavy, 2 dx high over 30 dx",
         [](const Eigen::Vector3d& p) -> Eigen::Vector3d {
             return Eigen::Vector3d(p.x(), p.y(), 2 * kDx * std::sin(p.x() / (30 * kDx / 6.283)));
         }},
    };
    for (const auto& [name, shape] : shapes) {
        std::vector<std::uint8_t> active;
        const std::vector<Eigen::Vector3d> x = deformed(s, shape);
        EXPECT_EQ(culling.mark(x, reach, s.lattice.triangles, {}, active), 0) << name;
    }
}

// Folds, crumples and torn-off flaps laid back on the sheet: the contract holds, and the fold is
// found. Random crumples of several strengths look for a pair the tests miss.
TEST(ContactCulling, NothingWithinReachIsLeftOut) {
    for (const LatticeKind kind : {LatticeKind::Hexagonal, LatticeKind::Square}) {
        const Sheet s = makeSheet(kind, {0.24, 0.16});
        const ContactCulling culling(s.rest(), s.lattice.triangles, kBondReach * kBondReach,
                                     3 * kBondReach);
        const double reach = 0.9 * kDx;
        // Folded over at x = 0.03 onto itself, the layers 0.6 dx apart.
        const Deform fold = [](const Eigen::Vector3d& p) -> Eigen::Vector3d {
            if (p.x() < 0.03) return p;
            const double r = 0.3 * kDx, a = std::min((p.x() - 0.03) / r, M_PI);
            const double beyond = std::max(0.0, p.x() - 0.03 - M_PI * r);
            return Eigen::Vector3d(0.03 + r * std::sin(a) - beyond, p.y(), r * (1 - std::cos(a)));
        };
        std::vector<std::uint8_t> active;
        std::vector<Eigen::Vector3d> x = deformed(s, fold);
        EXPECT_GT(culling.mark(x, reach, s.lattice.triangles, {}, active), 0);
        expectContract(s, x, reach, active);
        std::mt19937 random(7);
        // A corner shattered: its particles thrown up to 12 dx about, some onto the sheet (tiles
        // torn far past their rest size go by their boxes).
        std::uniform_real_distribution<double> throwOf(-12 * kDx, 12 * kDx);
        x = deformed(s, [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
            if (p.x() < 0.06 || p.y() < 0.02) return p;
            return p + Eigen::Vector3d(throwOf(random), throwOf(random), 0.05 * throwOf(random));
        });
        culling.mark(x, reach, s.lattice.triangles, {}, active);
        expectContract(s, x, reach, active);
        for (const double strength : {0.2, 0.5, 1.0, 2.0}) {
            std::normal_distribution<double> noise(0.0, strength * kDx);
            const double k = 2 * M_PI / (6 * kDx);
            const Eigen::Vector3d phase(noise(random), noise(random), noise(random));
            const Deform crumple = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
                return Eigen::Vector3d(
                    p.x() + strength * kDx * std::sin(k * p.y() + phase.x()),
                    0.6 * p.y() + strength * kDx * std::sin(k * p.x() + phase.y()),
                    strength * 2 * kDx * std::sin(k * (p.x() + p.y()) + phase.z()) +
                        0.3 * noise(random));
            };
            x = deformed(s, crumple);
            culling.mark(x, reach, s.lattice.triangles, {}, active);
            expectContract(s, x, reach, active);
        }
    }
}

// Smooth in-plane squeezes that vary across a tile's neighbourhood (the shape the edge-path
// bound passes or fails), some bringing unbonded particles within reach, at random.
TEST(ContactCulling, UnevenSqueezesLeaveNothingOut) {
    const Sheet s = makeSheet(LatticeKind::Hexagonal, {0.2, 0.14});
    const ContactCulling culling(s.rest(), s.lattice.triangles, kBondReach * kBondReach,
                                 3 * kBondReach);
    std::mt19937 random(11);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    MarkTally tally;
    for (int trial = 0; trial < 40; ++trial) {
        const double k = 2 * M_PI / ((4 + 16 * uniform(random)) * kDx);
        const double depth = 0.3 + 0.6 * uniform(random), phase = 6.3 * uniform(random);
        const double reach = (0.6 + 0.4 * uniform(random)) * kDx;
        // x' = x - depth sin(k x + phase) / k: the stretch 1 - depth cos(k x + phase) runs from
        // 1 - depth to 1 + depth across a wavelength.
        const std::vector<Eigen::Vector3d> x =
            deformed(s, [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
                return {p.x() - depth * std::sin(k * p.x() + phase) / k, p.y(), p.z()};
            });
        tally.check(s, culling, x, reach);
    }
    tally.expectBoth();
}

// Shapes the tiles' own fits see differently from their neighbourhood's (the bound that spares
// a quiet neighbourhood its particle pass): strips slid past each other along the sheet by
// random offsets, as torn strips slide, and in-plane ripples shorter than a tile, at random.
TEST(ContactCulling, SlidingStripsAndShortRipplesLeaveNothingOut) {
    const Sheet s = makeSheet(LatticeKind::Hexagonal, {0.16, 0.12});
    const ContactCulling culling(s.rest(), s.lattice.triangles, kBondReach * kBondReach,
                                 3 * kBondReach);
    std::mt19937 random(5);
    std::uniform_real_distribution<double> uniform(0.0, 1.0);
    MarkTally tally;
    for (int trial = 0; trial < 30; ++trial) {
        const double reach = (0.6 + 0.4 * uniform(random)) * kDx;
        std::vector<double> cuts, offsets;  // strips along x, each slid by its own offset
        for (double y = -0.06; y < 0.06; y += (2 + 8 * uniform(random)) * kDx) {
            cuts.push_back(y);
            offsets.push_back((trial % 2 ? 1.5 : 0.2) * kDx * (2 * uniform(random) - 1));
        }
        const double k = 2 * M_PI / ((1.5 + 2.5 * uniform(random)) * kDx);
        const double depth = trial % 3 == 0 ? 0.3 + 0.6 * uniform(random) : 0.0;
        const std::vector<Eigen::Vector3d> x =
            deformed(s, [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
                const auto strip = std::upper_bound(cuts.begin(), cuts.end(), p.y());
                const double slide =
                    strip == cuts.begin() ? 0.0 : offsets[strip - cuts.begin() - 1];
                return {p.x() + slide - depth * std::sin(k * p.x()) / k, p.y(), p.z()};
            });
        tally.check(s, culling, x, reach);
    }
    tally.expectBoth();
}

// Rows of tiles slid across by turns, +a and -a, into and away from each other: each tile moved
// rigidly (its own fit exact), its neighbourhood's fit a plain translation (the rows' slides
// cancel by symmetry), so only the shift between each tile's fit and its neighbourhood's tells
// the rows' edges apart.
TEST(ContactCulling, RowsOfTilesSlidByTurnsLeaveNothingOut) {
    const Sheet s = makeSheet(LatticeKind::Hexagonal, {0.4, 0.3});
    const double tileSize = 3 * kBondReach;
    const ContactCulling culling(s.rest(), s.lattice.triangles, kBondReach * kBondReach, tileSize);
    const Eigen::Vector3d origin = s.rest()[0];  // the culling's tiles start from particle 0
    for (const double a : {0.3 * kDx, 0.4 * kDx, 0.5 * kDx, 0.6 * kDx}) {
        const std::vector<Eigen::Vector3d> x =
            deformed(s, [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
                const int row = int(std::floor((p.y() - origin.y()) / tileSize));
                return p + Eigen::Vector3d(0.0, row % 2 == 0 ? a : -a, 0.0);
            });
        std::vector<std::uint8_t> active;
        culling.mark(x, 0.9 * kDx, s.lattice.triangles, {}, active);
        expectContract(s, x, 0.9 * kDx, active);
        // From a = 0.5 dx on, the rows pushed into each other overlap.
        if (a >= 0.5 * kDx) EXPECT_GT(contactsByBruteForce(s, x, 0.9 * kDx), 0u);
    }
}

// The candidate list, kept across evaluations while the sheet stretches, bends and folds, finds
// every contact brute force finds: lastPairCount counts each particle's nearest triangle within
// d and its particles within d.
TEST(ContactCulling, TheListFindsEveryContactAsTheSheetMoves) {
    const Sheet s = makeSheet(LatticeKind::Hexagonal, {0.2, 0.12});
    ContactParams params;
    params.self.enabled = true;
    const double d = 0.5 * kDx;
    Contact contact(params, d, 1.5 * kDx, 1.0, s.lattice.triangles, s.rest());
    const int n = int(s.rest().size());
    const std::vector<double> mass(std::size_t(n), 1.0);
    const std::vector<Eigen::Vector3d> v(std::size_t(n), Eigen::Vector3d::Zero());
    for (int frame = 0; frame <= 60; ++frame) {
        const double t = frame / 60.0;
        // Stretched along x by up to 30%, then folded over at x = 0.02 by up to 180 degrees.
        const double stretch = 1.0 + 0.3 * std::min(1.0, 2 * t);
        const double angle = M_PI * std::max(0.0, 2 * t - 1.0);
        const std::vector<Eigen::Vector3d> x =
            deformed(s, [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
                Eigen::Vector3d q(stretch * p.x(), p.y(), p.z());
                if (q.x() <= 0.02) return q;
                const double r = 0.2 * kDx, a = std::min((q.x() - 0.02) / r, angle);
                const double beyond = q.x() - 0.02 - a * r;
                const Eigen::Vector3d bend(0.02 + r * std::sin(a), q.y(), r * (1 - std::cos(a)));
                return Eigen::Vector3d(bend +
                                       beyond * Eigen::Vector3d(std::cos(a), 0, std::sin(a)));
            });
        std::vector<Eigen::Vector3d> force(std::size_t(n), Eigen::Vector3d::Zero());
        contact.addSelfContactForces({x, v, s.rest(), mass, {}, 1e-3}, force);
        const std::size_t expected = contactsByBruteForce(s, x, d);
        ASSERT_EQ(contact.lastPairCount(), expected) << "frame " << frame;
    }
    EXPECT_GT(contact.lastPairCount(), 0u);  // the fold closed
    EXPECT_LT(contact.listBuilds(), 45);     // the stretch kept its list
}

// Triangles stretched threefold (a rubber flap) laid back over the sheet: they go into a hash of
// their own, and every contact is still found.
TEST(ContactCulling, StretchedTrianglesLaidOverTheSheetAreFound) {
    const Sheet s = makeSheet(LatticeKind::Hexagonal, {0.2, 0.12});
    ContactParams params;
    params.self.enabled = true;
    const double d = 0.5 * kDx;
    Contact contact(params, d, 1.5 * kDx, 1.0, s.lattice.triangles, s.rest());
    const int n = int(s.rest().size());
    const std::vector<double> mass(std::size_t(n), 1.0);
    const std::vector<Eigen::Vector3d> v(std::size_t(n), Eigen::Vector3d::Zero());
    // The part beyond x = 0.05 drawn out threefold along y and folded back at x = 0.05 onto the
    // rest, 0.3 dx above it.
    const std::vector<Eigen::Vector3d> x =
        deformed(s, [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
            if (p.x() <= 0.05) return p;
            const double r = 0.15 * kDx, a = std::min((p.x() - 0.05) / r, M_PI);
            const double beyond = std::max(0.0, p.x() - 0.05 - M_PI * r);
            return {0.05 + r * std::sin(a) - 3.0 * beyond, 3.0 * p.y(), r * (1 - std::cos(a))};
        });
    std::vector<Eigen::Vector3d> force(std::size_t(n), Eigen::Vector3d::Zero());
    contact.addSelfContactForces({x, v, s.rest(), mass, {}, 1e-3}, force);
    const std::size_t expected = contactsByBruteForce(s, x, d);
    EXPECT_GT(expected, 0u);
    EXPECT_EQ(contact.lastPairCount(), expected);
}

// Each step walks a particle's candidates nearest first at the build and stops at the first that
// cannot be nearer than the nearest so far, given how far anything drifted since: a list kept
// across evaluations gives the forces of a list built afresh at each one, while a folded layer
// slides and ripples over the other.
TEST(ContactCulling, AKeptListStopsAtTheSameNearestTriangleAsAFreshOne) {
    KeptAgainstFresh rig;
    const double d = rig.d;
    std::size_t touching = 0;
    for (int frame = 0; frame <= 40; ++frame) {
        // Folded over at x = 0, the upper layer 0.8 d above the lower, sliding along y and
        // rippling as it goes.
        const double slide = 0.03 * kDx * frame, phase = 0.3 * frame;
        const std::vector<Eigen::Vector3d> x =
            deformed(rig.s, [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
                if (p.x() <= 0.0) return p;
                const double r = 0.4 * d, a = std::min(p.x() / r, M_PI);
                const double beyond = std::max(0.0, p.x() - M_PI * r);
                const double ripple = 0.1 * d * std::sin(400.0 * p.x() + 300.0 * p.y() + phase);
                const double along = beyond > 0.0 ? slide : 0.0;
                return {r * std::sin(a) - beyond, p.y() + along,
                        r * (1 - std::cos(a)) + (beyond > 0.0 ? ripple : 0.0)};
            });
        ASSERT_NO_FATAL_FAILURE(rig.expectFreshForces(x, frame));
        touching = std::max(touching, rig.kept.lastPairCount());
    }
    EXPECT_GT(touching, 400u);             // the layers touch
    EXPECT_LT(rig.kept.listBuilds(), 20);  // and the list was kept across frames
}

// A patch of the upper layer of a fold slides fast over the lower one and a lone particle rises
// through both layers, while the rest of the sheet keeps still: the list is kept, the movers'
// contacts are found afresh, and the forces are those of a list built afresh at each evaluation.
TEST(ContactCulling, MoversFoundAfreshGiveTheForcesOfAFreshList) {
    KeptAgainstFresh rig;
    const double d = rig.d;
    const Eigen::Vector3d patch(0.06, 0.03, 0.0), lone(-0.07, -0.04, 0.0);
    int loneParticle = 0;
    for (int i = 0; i < rig.n; ++i)
        if ((rig.s.rest()[std::size_t(i)] - lone).norm() <
            (rig.s.rest()[std::size_t(loneParticle)] - lone).norm())
            loneParticle = i;
    std::size_t touching = 0;
    for (int frame = 0; frame <= 40; ++frame) {
        const Eigen::Vector3d moved(0.6 * d * std::sin(0.4 * frame), 0.3 * d * frame, 0.0);
        std::vector<Eigen::Vector3d> x =
            deformed(rig.s, [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
                if (p.x() <= 0.0) return p;
                const double r = 0.4 * d, a = std::min(p.x() / r, M_PI);
                const double beyond = std::max(0.0, p.x() - M_PI * r);
                const Eigen::Vector3d q(r * std::sin(a) - beyond, p.y(), r * (1 - std::cos(a)));
                return (p - patch).norm() < 1.2 * kDx ? Eigen::Vector3d(q + moved) : q;
            });
        // Through the lower layer at z = 0 and the upper at 0.8 d, and on above them.
        x[std::size_t(loneParticle)] = rig.s.rest()[std::size_t(loneParticle)] +
                                       Eigen::Vector3d(0.02, 0.0, -2.0 * d + 0.15 * d * frame);
        ASSERT_NO_FATAL_FAILURE(rig.expectFreshForces(x, frame));
        ASSERT_EQ(rig.kept.lastPairCount(), contactsByBruteForce(rig.s, x, d)) << "frame " << frame;
        touching = std::max(touching, rig.kept.lastPairCount());
    }
    EXPECT_GT(touching, 200u);                   // the layers touch
    EXPECT_GT(rig.kept.moverEvaluations(), 25);  // the movers were followed
    EXPECT_LT(rig.kept.listBuilds(), 8);         // and the list kept
}
