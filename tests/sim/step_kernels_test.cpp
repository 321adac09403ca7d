// The one-pass kick and drift (sim/StepKernels.h) gives the bits of eq. 26 written with Eigen as
// Membrane::updateVelocity writes it, for free, pinned and driven particles, from any start.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "sim/Random.h"
#include "sim/StepKernels.h"

using namespace rend::sim;

namespace {

struct Particles {
    std::vector<Eigen::Vector3d> x, v, force;
    std::vector<double> mass;
    std::vector<std::int16_t> constraint;
};

/// n particles with values of every size; every 37th pinned, every 41st driven (most blocks of
/// eight are all free, and take the vector path).
Particles someParticles(int n) {
    Particles p;
    const auto r = [](int i, int k) { return uniformFromHash(77, 8 * std::uint64_t(i) + k); };
    for (int i = 0; i < n; ++i) {
        p.x.emplace_back(r(i, 0), r(i, 1), r(i, 2) - 0.5);
        p.v.emplace_back(r(i, 3) - 0.5, 1e-3 * r(i, 4), -r(i, 5));
        p.force.emplace_back(1e6 * (r(i, 6) - 0.5), 3.0 * r(i, 7), -1e-9 * r(i, 0));
        p.mass.push_back(1e-6 + r(i, 1) * 1e-3);
        p.constraint.push_back(i % 37 == 3 ? -2 : i % 41 == 5 ? std::int16_t(i % 2) : -1);
    }
    return p;
}

/// The kernel's view of `p`, stepping h and dt, with `boundary`'s velocities.
KickDrift viewOf(Particles& p, const std::vector<double>& boundary, double h, double dt) {
    return {p.x.data()->data(),
            p.v.data()->data(),
            p.force.data()->data(),
            p.mass.data(),
            p.constraint.data(),
            boundary,
            h,
            dt};
}

bool sameBits(const std::vector<Eigen::Vector3d>& a, const std::vector<Eigen::Vector3d>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof a[0]) == 0;
}

TEST(KickDrift, GivesTheBitsOfTheEigenStepForEveryConstraint) {
    const Particles start = someParticles(203);  // blocks of four and a tail
    const double h = 1.3e-4, dt = 1.1e-4, damping = 0.7;
    const Eigen::Vector3d gravity(0.1, -0.2, -9.81);
    const std::vector<double> boundary = {0.5, 0.0, -0.25, 0.0, 1e-3, 2.0};  // two boundaries

    Particles expected = start;
    for (std::size_t i = 0; i < start.x.size(); ++i) {
        const std::int16_t c = start.constraint[i];
        Eigen::Vector3d& v = expected.v[i];
        if (c == -1)
            v += h * (start.force[i] / start.mass[i] + gravity - damping * v);
        else if (c == -2)
            v.setZero();
        else
            v = Eigen::Vector3d(boundary[3 * c], boundary[3 * c + 1], boundary[3 * c + 2]);
        expected.x[i] += dt * v;
    }
    // Whole, and split at a point that is not a multiple of four (a thread's range).
    for (const int split : {0, 1, 6, 101}) {
        Particles p = start;
        KickDrift k = viewOf(p, boundary, h, dt);
        k.damping = damping;
        for (int a = 0; a < 3; ++a) k.gravity[a] = gravity[a];
        EXPECT_FALSE(kickDrift(k, 0, split) || kickDrift(k, split, int(p.x.size())))
            << "no floor: nothing is below it";
        EXPECT_TRUE(sameBits(p.v, expected.v)) << "split at " << split;
        EXPECT_TRUE(sameBits(p.x, expected.x)) << "split at " << split;
    }
}

// With one mass for the sheet (KickDrift::oneMass) the mass array is not read: the same bits as
// every particle's own mass of that value, at every width and in every block.
TEST(KickDrift, OneMassGivesTheBitsOfEveryParticleHavingIt) {
    Particles start = someParticles(203);
    const double mass = 3.7e-4;
    start.mass.assign(start.mass.size(), mass);
    const std::vector<double> boundary = {0.5, 0.0, -0.25, 0.0, 1e-3, 2.0};
    Particles each = start, one = start;
    KickDrift k = viewOf(each, boundary, 1.3e-4, 1.1e-4);
    k.damping = 0.7, k.gravity[2] = -9.81;
    kickDrift(k, 0, int(each.x.size()));
    std::vector<double> wrong(one.mass.size(), 2.0 * mass);  // read, they would show
    KickDrift o = viewOf(one, boundary, 1.3e-4, 1.1e-4);
    o.damping = 0.7, o.gravity[2] = -9.81, o.mass = wrong.data(), o.oneMass = mass;
    kickDrift(o, 0, 101), kickDrift(o, 101, int(one.x.size()));
    EXPECT_TRUE(sameBits(one.v, each.v));
    EXPECT_TRUE(sameBits(one.x, each.x));
    EXPECT_FALSE(sameBits(one.v, start.v)) << "the kick moved them";
}

// Forces from a block of their own (KickDrift::forceFirst, where a solver's pass kept a block's
// forces): the bits of the whole array's, and the particles that are not free have theirs
// copied into the array (keptForce), the free ones' left as they were.
TEST(KickDrift, ABlocksForcesGiveTheBitsOfTheWholeArray) {
    const Particles start = someParticles(203);
    const std::vector<double> boundary = {0.5, 0.0, -0.25, 0.0, 1e-3, 2.0};
    Particles whole = start;
    KickDrift k = viewOf(whole, boundary, 1.3e-4, 1.1e-4);
    k.damping = 0.7, k.gravity[2] = -9.81;
    kickDrift(k, 0, int(whole.x.size()));
    Particles blocked = start;
    const Eigen::Vector3d stale(7.0, -7.0, 7.0);
    std::vector<Eigen::Vector3d> array(start.force.size(), stale);
    KickDrift b = viewOf(blocked, boundary, 1.3e-4, 1.1e-4);
    b.damping = 0.7, b.gravity[2] = -9.81, b.keptForce = array.data()->data();
    for (const auto& [first, end] : {std::pair{0, 40}, {40, 45}, {45, 160}, {160, 203}}) {
        std::vector<Eigen::Vector3d> block(start.force.begin() + first, start.force.begin() + end);
        b.force = block.data()->data(), b.forceFirst = first;
        kickDrift(b, first, end);
    }
    EXPECT_TRUE(sameBits(blocked.v, whole.v));
    EXPECT_TRUE(sameBits(blocked.x, whole.x));
    int copied = 0;
    for (std::size_t i = 0; i < array.size(); ++i) {
        const bool free = start.constraint[i] == -1;
        EXPECT_EQ(array[i], free ? stale : start.force[i]) << "particle " << i;
        copied += !free;
    }
    EXPECT_GT(copied, 5);
}

// The floor test counts exactly the free particles whose new z is not >= the floor, whichever
// block of four or eight they sit in; pinned and driven ones never count, and NaN does.
TEST(KickDrift, FindsAFreeParticleThatEndsBelowTheFloor) {
    const Particles start = someParticles(203);
    const double floor = 10.0;  // every start z is below 0.5
    for (int i = 0; i < int(start.x.size()); ++i) {
        Particles p = start;
        for (int j = 0; j < int(p.x.size()); ++j)
            if (j != i) p.x[j].z() = 20.0;  // all above but i
        p.v.assign(p.v.size(), Eigen::Vector3d::Zero());
        p.force.assign(p.force.size(), Eigen::Vector3d::Zero());
        const std::vector<double> boundary = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
        KickDrift k = viewOf(p, boundary, 1e-4, 1e-4);
        k.floor = floor;
        const bool below = kickDrift(k, 0, 100) || kickDrift(k, 100, int(p.x.size()));
        EXPECT_EQ(below, start.constraint[i] == -1) << "particle " << i;
    }
    Particles p = start;
    for (Eigen::Vector3d& x : p.x) x.z() = 20.0;
    p.x[150].z() = std::numeric_limits<double>::quiet_NaN();
    p.constraint[150] = -1;
    const std::vector<double> boundary(6, 0.0);
    KickDrift k = viewOf(p, boundary, 1e-4, 1e-4);
    k.floor = floor;
    EXPECT_TRUE(kickDrift(k, 0, int(p.x.size()))) << "a NaN height is not above the floor";
}

}  // namespace

namespace {

/// The guard's sums one particle at a time, in index order.
GuardSums naiveGuard(const GuardInput& g, int n) {
    GuardSums s;
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d v(g.v[3 * i], g.v[3 * i + 1], g.v[3 * i + 2]);
        const double speed = v.squaredNorm();
        const bool badTheta = g.theta && !std::isfinite(g.theta[i]);
        if ((!(speed <= g.limitSquared) || badTheta) && s.firstBad < 0) s.firstBad = i;
        if (g.theta && !std::isnan(g.theta[i]))  // inf counts, NaN is skipped
            s.maxAbsTheta = std::max(s.maxAbsTheta, std::abs(g.theta[i]));
        if (g.constraint[i] >= 0) {
            const Eigen::Vector3d f(g.force[3 * i], g.force[3 * i + 1], g.force[3 * i + 2]);
            s.boundaryPower += std::abs(f.dot(v));
        }
        if (g.constraint[i] != -1) continue;
        s.kinetic += 0.5 * g.mass[i] * speed;
        s.gravityPower += g.mass[i] * std::abs(Eigen::Vector3d(g.gravity).dot(v));
        if (speed > s.maxSpeedSquared) s.maxSpeedSquared = speed, s.fastest = i;
    }
    return s;
}

// The guard's sums at this width (ctest's kernels.* run it at each): the largest speed, its
// lowest index, the largest |theta| and the first bad index exactly, the sums to rounding; with
// pinned and driven particles among the free (two of them faster than any free one), two free
// particles tied at the top speed, one too fast, and an infinite and a NaN theta.
TEST(GuardSums, MatchTheSumsOneParticleAtATime) {
    for (const int n : {5, 64, 203}) {
        Particles p = someParticles(n);
        std::vector<double> theta(n);
        for (int i = 0; i < n; ++i) theta[i] = uniformFromHash(9, i) - 0.7;
        const int top = n - 3, twin = n / 2;  // twin < top, both free
        p.constraint[top] = p.constraint[twin] = -1;
        p.v[top] = Eigen::Vector3d(3.0, 4.0, 0.0), p.v[twin] = Eigen::Vector3d(0.0, 4.0, 3.0);
        // A pinned and a driven particle faster than any free one, within the limit: neither
        // is the fastest.
        for (const int held : {3, 5})
            if (held < n && p.constraint[held] != -1) p.v[held] = Eigen::Vector3d(0.0, 5.2, 0.0);
        GuardInput g{p.v.data()->data(), p.force.data()->data(),
                     p.mass.data(),      p.constraint.data(),
                     theta.data(),       30.0,
                     {0.0, 0.0, -9.81},  true};
        for (const int bad : {-1, 0, 1, 2}) {
            if (bad == 1) p.v[n - 1] = Eigen::Vector3d(0.0, 0.0, 6.0);  // past the limit
            if (bad == 2)
                theta[1] = std::numeric_limits<double>::infinity(),
                theta[n - 2] = std::numeric_limits<double>::quiet_NaN();
            const GuardSums got = guardSums(g, 0, n), want = naiveGuard(g, n);
            EXPECT_EQ(got.maxSpeedSquared, want.maxSpeedSquared) << n << " " << bad;
            EXPECT_EQ(got.fastest, want.fastest) << n << " " << bad;
            EXPECT_EQ(got.fastest, n >= 64 && bad < 1 ? twin : got.fastest);
            EXPECT_EQ(got.firstBad, want.firstBad) << n << " " << bad;
            EXPECT_EQ(got.maxAbsTheta, want.maxAbsTheta) << n << " " << bad;
            EXPECT_NEAR(got.kinetic, want.kinetic, 1e-14 * want.kinetic);
            EXPECT_NEAR(got.gravityPower, want.gravityPower, 1e-14 * want.gravityPower);
            EXPECT_NEAR(got.boundaryPower, want.boundaryPower, 1e-14 * want.boundaryPower);
        }
    }
}

/// The scalar loop's sums: four chains, particle begin + 4 q + k in chain k, the tail in chain
/// 0, the chains added (0 + 1) + (2 + 3).
GuardSums fourChainGuard(const GuardInput& g, int begin, int end) {
    double kinetic[4] = {}, gravity[4] = {}, boundary[4] = {};
    const int whole = begin + (end - begin) / 4 * 4;
    for (int i = begin; i < end; ++i) {
        const int k = i < whole ? (i - begin) % 4 : 0;
        const double* v = g.v + 3 * i;
        const double speed = (v[0] * v[0] + v[1] * v[1]) + v[2] * v[2];
        if (g.constraint[i] >= 0) {
            const double* f = g.force + 3 * i;
            boundary[k] += std::abs((f[0] * v[0] + f[1] * v[1]) + f[2] * v[2]);
        }
        if (g.constraint[i] != -1) continue;
        kinetic[k] += 0.5 * g.mass[i] * speed;
        const double* a = g.gravity;
        gravity[k] += g.mass[i] * std::abs((a[0] * v[0] + a[1] * v[1]) + a[2] * v[2]);
    }
    GuardSums s;
    s.kinetic = (kinetic[0] + kinetic[1]) + (kinetic[2] + kinetic[3]);
    s.gravityPower = (gravity[0] + gravity[1]) + (gravity[2] + gravity[3]);
    s.boundaryPower = (boundary[0] + boundary[1]) + (boundary[2] + boundary[3]);
    return s;
}

// The scalar loop and AVX2 (ctest's kernels.scalar, kernels.avx2 and an AVX2 CPU) add in the
// same four chains: the same bits, from a start that is not a multiple of four, with pinned and
// driven particles in some quads.
TEST(GuardSums, TheScalarLoopAndAvx2AddInTheSameFourChains) {
    if (simdWidth() > 4) GTEST_SKIP() << "AVX-512 adds in eight chains";
    for (const int n : {5, 64, 203}) {
        Particles p = someParticles(n);
        GuardInput g{p.v.data()->data(),
                     p.force.data()->data(),
                     p.mass.data(),
                     p.constraint.data(),
                     nullptr,
                     30.0,
                     {0.3, -0.2, -9.81},
                     true};
        // With and without gravity (the four-lane loop's two forms); without, its power is 0.
        for (const bool gravity : {true, false}) {
            g.hasGravity = gravity;
            if (!gravity) g.gravity[0] = g.gravity[1] = g.gravity[2] = 0.0;
            for (const int begin : {0, 3}) {
                const GuardSums got = guardSums(g, begin, n), want = fourChainGuard(g, begin, n);
                EXPECT_GT(got.kinetic, 0.0);
                EXPECT_EQ(got.kinetic, want.kinetic) << n << " " << begin;
                EXPECT_EQ(got.gravityPower, want.gravityPower) << n << " " << begin;
                EXPECT_EQ(got.boundaryPower, want.boundaryPower) << n << " " << begin;
                const GuardSums naive = naiveGuard(g, n);
                if (begin == 0) {
                    EXPECT_EQ(got.fastest, naive.fastest) << n << " " << gravity;
                }
            }
        }
    }
}

// GuardInput::oneMass: the sums of every particle having that mass, to the bit, the mass array
// unread.
TEST(GuardSums, OneMassGivesTheSumsOfEveryParticleHavingIt) {
    for (const int n : {5, 64, 203}) {
        Particles p = someParticles(n);
        const double mass = 2.9e-4;
        p.mass.assign(n, mass);
        GuardInput each{p.v.data()->data(),
                        p.force.data()->data(),
                        p.mass.data(),
                        p.constraint.data(),
                        nullptr,
                        30.0,
                        {0.0, 0.0, -9.81},
                        true};
        const std::vector<double> wrong(n, 5.0 * mass);
        GuardInput one = each;
        one.mass = wrong.data(), one.oneMass = mass;
        const GuardSums a = guardSums(each, 0, n), b = guardSums(one, 0, n);
        EXPECT_GT(a.kinetic, 0.0);
        EXPECT_EQ(b.kinetic, a.kinetic) << n;
        EXPECT_EQ(b.gravityPower, a.gravityPower) << n;
        EXPECT_EQ(b.boundaryPower, a.boundaryPower) << n;
        EXPECT_EQ(b.maxSpeedSquared, a.maxSpeedSquared) << n;
        EXPECT_EQ(b.fastest, a.fastest) << n;
    }
}

}  // namespace

namespace {

bool sameSums(const GuardSums& a, const GuardSums& b) {
    return std::memcmp(&a.kinetic, &b.kinetic, sizeof(double)) == 0 &&
           std::memcmp(&a.boundaryPower, &b.boundaryPower, sizeof(double)) == 0 &&
           std::memcmp(&a.gravityPower, &b.gravityPower, sizeof(double)) == 0 &&
           a.maxSpeedSquared == b.maxSpeedSquared && a.fastest == b.fastest &&
           a.firstBad == b.firstBad && a.maxAbsTheta == b.maxAbsTheta;
}

// The kick with the guard's sums in its loop (kickDriftSampled, adaptive steps' blocks): the
// bits of kickDrift and then guardMotionSums, at every width, from starts that are not multiples
// of four, with pinned and driven particles, with and without one mass, gravity and a floor, and
// with a particle past the speed limit.
TEST(KickDrift, SampledGivesTheBitsOfTheKickAndThenTheGuard) {
    const std::vector<double> boundary = {0.5, 0.0, -0.25, 0.0, 1e-3, 2.0};
    int cases = 0;
    for (const bool one : {false, true})
        for (const bool gravity : {false, true})
            for (const bool floor : {false, true})
                for (const bool fast : {false, true}) {
                    Particles start = someParticles(203);
                    if (one) start.mass.assign(start.mass.size(), 3.7e-4);
                    if (fast) start.v[150] = Eigen::Vector3d(0.0, 1e20, 0.0);  // past the limit
                    for (const auto& [first, end] : {std::pair{0, 203}, {3, 101}, {101, 203}}) {
                        Particles a = start, b = start;
                        const auto setUp = [&](Particles& p) {
                            KickDrift k = viewOf(p, boundary, 1.3e-4, 1.1e-4);
                            k.damping = 0.7, k.oneMass = one ? 3.7e-4 : 0.0;
                            if (gravity) k.gravity[0] = 0.3, k.gravity[2] = -9.81;
                            if (floor) k.floor = 0.2;
                            return k;
                        };
                        const auto guardOf = [&](Particles& p, const KickDrift& k) {
                            GuardInput g{p.v.data()->data(),
                                         p.force.data()->data(),
                                         p.mass.data(),
                                         p.constraint.data(),
                                         nullptr,
                                         1e30,
                                         {},
                                         gravity};
                            for (int c = 0; c < 3; ++c) g.gravity[c] = k.gravity[c];
                            g.oneMass = k.oneMass;
                            return g;
                        };
                        const KickDrift ka = setUp(a), kb = setUp(b);
                        const bool belowA = kickDrift(ka, first, end);
                        const GuardSums want = guardMotionSums(guardOf(a, ka), first, end);
                        bool belowB = !belowA;
                        const GuardSums got =
                            kickDriftSampled(kb, guardOf(b, kb), first, end, belowB);
                        EXPECT_TRUE(sameBits(b.v, a.v)) << one << gravity << floor << first;
                        EXPECT_TRUE(sameBits(b.x, a.x)) << one << gravity << floor << first;
                        EXPECT_EQ(belowB, belowA) << one << gravity << floor << first;
                        EXPECT_TRUE(sameSums(got, want)) << one << gravity << floor << first;
                        EXPECT_GT(got.kinetic, 0.0);
                        const bool bad = fast && first <= 150 && end > 150;
                        EXPECT_EQ(got.firstBad, bad ? 150 : -1) << one << gravity << floor;
                        ++cases;
                    }
                }
    EXPECT_EQ(cases, 48);
}

}  // namespace
