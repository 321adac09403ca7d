// The force loop over each bond once (sim/Bonds.h's BondPairs, sim/PairKernels.h) gives the
// bits of the loop over both copies of every bond, for every law, with theta and breaking.

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <optional>
#include <vector>

#include "sim/Domain.h"
#include "sim/Material.h"
#include "sim/PairKernels.h"
#include "sim/PeridynamicBonds.h"
#include "sim/Random.h"

using namespace rend::sim;

namespace {

/// The bonds of a hexagonal sheet of `width` x `height` at dx = 0.01 within `horizon` dx.
BondFamilies sheetBonds(double width, double height, double horizon) {
    SheetParams sheet;
    sheet.size = {width, height};
    sheet.dx = 0.01;
    return buildBondFamilies(generateLattice(sheet).positions, horizon * sheet.dx);
}

TEST(BondPairs, NumberEachBondOnceThroughItsUpperCopy) {
    const BondFamilies bonds = sheetBonds(0.2, 0.1, 2.5);
    const BondPairs pairs = buildBondPairs(bonds);
    ASSERT_EQ(std::size_t(pairs.pairCount()), bonds.bondCount());
    std::vector<int> seen(pairs.pairCount(), 0);
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const int j = bonds.partners[b], u = pairs.pairOf[b];
            ++seen[u];
            EXPECT_EQ(pairs.isUpper(i, b), j > i);
            if (j > i) {
                EXPECT_EQ(u, pairs.pairBegin[i] + b - pairs.upperBegin[i]);
                EXPECT_EQ(bonds.partners[pairs.twin[u]], i);
            } else {
                EXPECT_EQ(pairs.twin[u], b);
            }
        }
    for (int u = 0; u < pairs.pairCount(); ++u) EXPECT_EQ(seen[u], 2) << u;
}

struct Case {
    BondLawKind law;
    bool theta, breakable;
    /// A sheet of 1 x 0.5 m: ~5,800 particles, over the threads' threshold, and more pairs
    /// than a thread's ring of slots holds (sim/PeridynamicBonds.h), so that it wraps.
    bool large = false;
    /// A square lattice within 1.5 dx: eight bonds each, the tile sums' groups of lanes
    /// (sim/PairSums.h); else hexagonal within 2 dx (18 bonds: one particle at a time).
    bool square = false;
    /// The sheet 40 m from the origin: its coordinates' rounding gives the bonds of one
    /// direction rest lengths a few hundred last bits apart (rows of a class plus steps).
    bool far = false;
    /// A sheet of 4 x 4 m: 160,801 particles, whose step streams from memory
    /// (streamsForces()): the tile sums' stores go around the caches.
    bool huge = false;
    /// The power law's n (eq. 19): each whole exponent is its own SIMD loop.
    double exponent = 4.0;
};

/// Particle i's force summed over both copies of its bonds, one at a time: the loop as the
/// paper writes it (eqs. 10, 18-20, 27-28).
std::vector<Eigen::Vector3d> bothCopies(const PeridynamicBonds& solver, const BondFamilies& bonds,
                                        const DamageState& damage, const MaterialParams& m,
                                        const std::vector<Eigen::Vector3d>& x,
                                        const std::vector<double>& theta) {
    const Material material(m);
    std::vector<Eigen::Vector3d> force(x.size(), Eigen::Vector3d::Zero());
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            if (!damage.bondAlive()[b]) continue;
            const int j = bonds.partners[b];
            const Eigen::Vector3d r = x[j] - x[i];
            const double length = r.norm(), rest = bonds.restLength[b];
            const BondLaw& law = solver.law();
            // The linear and power laws' strain times rest (no division), their limit times
            // rest, their force over the length divided once (BondLaw::powerLawByRest).
            const bool power = law.kind == BondLawKind::PowerLaw;
            const bool byRest = law.kind == BondLawKind::Linear || power;
            double eta = byRest ? length - rest : length / rest - 1.0;
            const double thetaBar = theta.empty() ? 0.0 : 0.5 * (theta[i] + theta[j]);
            const double swelling = material.expansion() * thetaBar;
            if (!theta.empty()) eta -= byRest ? rest * swelling : swelling;
            const double limit = solver.criticalStretch() * material.strengthFactor(thetaBar);
            if (eta > (byRest ? rest * limit : limit)) continue;
            const BondLaw::PowerLawByRest parts = law.powerLawByRest(eta, rest);
            double f = power ? parts.numerator : law.force(eta, law.yieldStep(eta, {}));
            if (!theta.empty()) f *= material.stiffnessFactor(thetaBar);
            const double over = power    ? parts.denominator * length
                                : byRest ? rest * length
                                         : length;
            force[i] += (solver.bondScale(b) * f / over) * r;
        }
    return force;
}

class PairLoop : public ::testing::TestWithParam<Case> {};

TEST_P(PairLoop, HasTheBitsOfTheLoopOverBothCopies) {
    const Case c = GetParam();
    MembraneParams p;
    p.sheet.size = c.huge    ? Eigen::Vector2d(4.0, 4.0)
                   : c.large ? Eigen::Vector2d(1.0, 0.5)
                             : Eigen::Vector2d(0.2, 0.1);
    p.sheet.dx = 0.01;
    if (c.square) p.sheet.lattice = LatticeKind::Square;
    p.material.youngsModulus = 1e5;
    p.material.law = c.law;
    p.material.yieldStrain = 0.002;
    p.material.powerLawExponent = c.exponent;
    if (c.breakable) p.material.fractureEnergy = 0.02;
    if (c.theta)
        p.material.expansion = 0.01, p.material.stiffnessLoss = 0.4, p.material.strengthLoss = 0.3;
    Lattice lattice = generateLattice(p.sheet);
    if (c.far)
        for (Eigen::Vector3d& x : lattice.positions) x += Eigen::Vector3d(40.3, -23.7, 0.0);
    const double horizon = c.square ? 1.5 : 2.0;
    const BondFamilies bonds = buildBondFamilies(lattice.positions, horizon * p.sheet.dx);
    p.sheet.horizonFactor = horizon;
    const std::vector<double> volumes(lattice.positions.size(),
                                      lattice.particleArea * p.sheet.thickness);
    PeridynamicBonds solver(p, lattice, bonds, lattice.positions, volumes);
    DamageState damage(bonds, lattice.triangles);
    solver.bind(bonds, damage);
    for (int b = 0; b < int(bonds.directedCount()); b += 37) damage.breakBond(b);  // some dead
    const PeridynamicBonds::RowClasses rows = solver.rowClasses();
    if (c.far) {
        EXPECT_GT(rows.stepped, std::max(40, rows.exact))
            << "rows in steps: " << rows.exact << " exact, " << rows.stepped << " stepped, "
            << rows.perPair << " per pair";
        // Rounding steps the rest lengths and scales; eta_c is one value (read without steps).
        EXPECT_EQ(rows.steppedLimits, 0);
    }

    const int n = int(lattice.positions.size());
    std::vector<Eigen::Vector3d> x = lattice.positions, v(n, Eigen::Vector3d::Zero());
    std::vector<double> theta;
    const double etaC = std::isfinite(solver.criticalStretch()) ? solver.criticalStretch() : 0.01;
    for (int i = 0; i < n; ++i) {  // strains up to twice eta_c either way
        for (int a = 0; a < 3; ++a)
            x[i][a] += 2.0 * etaC * p.sheet.dx * (2.0 * uniformFromHash(7, 3 * i + a) - 1.0);
        if (c.theta) theta.push_back(2.0 * uniformFromHash(8, i));
    }
    const std::vector<Eigen::Vector3d> expected =
        bothCopies(solver, bonds, damage, p.material, x, theta);
    const int before = omp_get_max_threads();
    for (const int threads : {1, 3}) {
        omp_set_num_threads(threads);
        std::vector<Eigen::Vector3d> force;
        solver.forces({x, v, theta, 1e-4}, *solver.makeWorkspace(), force);
        ASSERT_EQ(force.size(), expected.size());
        EXPECT_EQ(std::memcmp(force.data(), expected.data(), n * sizeof(Eigen::Vector3d)), 0);
        int differ = 0;
        for (int i = 0; i < n; ++i) differ += force[i] != expected[i];
        EXPECT_EQ(differ, 0) << "of " << n << " particles, " << threads << " threads";
    }
    omp_set_num_threads(before);
}

/// A 0.2 x 0.1 m sheet at dx 0.01 with bonds within 1.5 dx, and its solver and damage bound.
struct SmallSheet {
    explicit SmallSheet(const MembraneParams& params)
        : p(params),
          lattice(generateLattice(p.sheet)),
          bonds(buildBondFamilies(lattice.positions, 1.5 * p.sheet.dx)),
          volumes(lattice.positions.size(), lattice.particleArea * p.sheet.thickness),
          solver(p, lattice, bonds, lattice.positions, volumes),
          damage(bonds, lattice.triangles) {
        solver.bind(bonds, damage);
    }
    static MembraneParams params(BondLawKind law) {
        MembraneParams p;
        p.sheet.size = {0.2, 0.1};
        p.sheet.dx = 0.01;
        p.material.youngsModulus = 1e5;
        p.material.law = law;
        p.material.yieldStrain = 0.002;
        return p;
    }
    MembraneParams p;
    Lattice lattice;
    BondFamilies bonds;
    std::vector<double> volumes;
    PeridynamicBonds solver;
    DamageState damage;
};

/// The largest look-ahead tangent over the living compressed bonds of `bonds` at x, v and dt,
/// as the loop over bonds computes it; its bond in `stiffestBond`.
double lookAheadOverBonds(const PeridynamicBonds& solver, const BondFamilies& bonds,
                          const DamageState& damage, const std::vector<Eigen::Vector3d>& x,
                          const std::vector<Eigen::Vector3d>& v, double dt, int& stiffestBond) {
    double expected = 1.0;
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            if (!damage.bondAlive()[b]) continue;
            const int j = bonds.partners[b];
            const Eigen::Vector3d r = x[j] - x[i];
            // The strain as the kernels take it where they look ahead: (length - rest) / rest.
            const double eta = (r.norm() - bonds.restLength[b]) / bonds.restLength[b];
            if (!(eta < 0.0)) continue;
            const double rate = r.dot(v[j] - v[i]) / (r.norm() * bonds.restLength[b]);
            const double t =
                solver.law().powerLawStiffening(clampCompression(eta + std::min(0.0, dt * rate)));
            if (t > expected) expected = t, stiffestBond = b;
        }
    return expected;
}

// On the small sheet (one block) and on one of 1 x 0.5 m (blocks of 512 particles, each
// starting from the largest tangent of the blocks before it, on 1 and 3 threads). Particles
// moved by `jitter` dx: much, so that one bond stands out, or little, so that many compete.
// One row of eight pairs (lists, not runs) whose rest lengths, scales and limits are stepped
// (LinearPairInput::uniform) in every combination, its code saying whether the limits are: the
// forces and breaking flags are those of the same row read per pair.
TEST(PairLoop, AStepsRowReadsItsLimitsStepsWhereItSaysSo) {
    MaterialParams m;
    const BondLaw law = BondLaw::fromMaterial(m, 3.0e9);
    constexpr int kPairs = kPairTile;
    std::vector<double> x(3 * 2 * kPairs);
    std::vector<int> first(kPairs), second(kPairs), upper(kPairs);
    for (int k = 0; k < kPairs; ++k) {
        first[k] = 2 * k, second[k] = 2 * k + 1, upper[k] = k;
        x[6 * k] = 40.3 + 0.01 * k, x[6 * k + 1] = -23.7;
        // Stretched by 0.9-1.6 times eta_c: the flags differ between a limit and its steps.
        x[6 * k + 3] = x[6 * k] + 0.01 * (1.0 + 0.01 * (0.9 + 0.1 * k)), x[6 * k + 4] = -23.7;
    }
    const double classRest = 0.01, classScale = 2.5e-9, classLimit = 0.01;
    const double restUnit = std::ldexp(1.0, std::ilogb(classRest) - 52);
    const double scaleUnit = std::ldexp(1.0, std::ilogb(classScale) - 52);
    const double limitUnit = std::ldexp(1.0, std::ilogb(classLimit) - 40);  // steps of 2^-12 %
    const std::uint8_t alive[kPairs] = {1, 1, 1, 1, 1, 1, 1, 1};
    constexpr int kStepsRest = 1, kStepsScale = 2, kStepsLimits = 4;
    for (int which = 1; which < 8; ++which) {
        std::vector<std::uint16_t> restSteps(kPairs, 0), scaleSteps(kPairs, 0),
            limitSteps(kPairs, 0);
        std::vector<double> rest(kPairs), scale(kPairs), limit(kPairs);
        for (int k = 0; k < kPairs; ++k) {
            if (which & kStepsRest) restSteps[k] = std::uint16_t(300 * k);
            if (which & kStepsScale) scaleSteps[k] = std::uint16_t(7 * k + 1);
            if (which & kStepsLimits) limitSteps[k] = std::uint16_t(9000 * k);
            rest[k] = classRest + restSteps[k] * restUnit;
            scale[k] = classScale + scaleSteps[k] * scaleUnit;
            limit[k] = classLimit + limitSteps[k] * limitUnit;
        }
        LinearPairInput in{first.data(), second.data(), rest.data(), scale.data(),
                           limit.data(), x.data(),      nullptr,     law.c};
        in.law = &law, in.alive = alive, in.allAlive = true, in.upper = upper.data();
        in.twin = upper.data(), in.particles = 2 * kPairs, in.pairs = kPairs;
        const int noRun = -1;
        in.runFirst = &noRun, in.runSecond = &noRun;
        in.classRest = &classRest, in.classScale = &classScale, in.classLimit = &classLimit;
        in.classRestUnit = &restUnit, in.classScaleUnit = &scaleUnit;
        in.classLimitUnit = &limitUnit;
        in.restSteps = restSteps.data(), in.scaleSteps = scaleSteps.data();
        in.limitSteps = limitSteps.data();
        const auto forces = [&](int uniform, std::uint8_t& over) {
            in.uniform = &uniform;
            alignas(64) double slots[4 * kPairs] = {};
            LinearPairOutput out;
            out.force = slots, out.over = &over, out.rows = slotRows();
            linearPairForces(in, out, 0, kPairs);
            std::vector<double> f;
            for (int k = 0; k < kPairs; ++k)
                for (int a = 0; a < 3; ++a) f.push_back(out.slot(k)[a * out.slotStep()]);
            return f;
        };
        std::uint8_t perPairOver = 0, steppedOver = 0;
        const std::vector<double> perPair = forces(-1, perPairOver);
        const std::vector<double> stepped =
            forces(steppedClass(0, (which & kStepsLimits) != 0), steppedOver);
        EXPECT_EQ(steppedOver, perPairOver) << "stepped constants " << which;
        for (int k = 0; k < 3 * kPairs; ++k)
            EXPECT_EQ(std::bit_cast<std::uint64_t>(stepped[k]),
                      std::bit_cast<std::uint64_t>(perPair[k]))
                << "stepped constants " << which << ", component " << k;
        if (which == kStepsLimits) {
            EXPECT_NE(perPairOver, 0);  // some pairs past their limits, some not
            EXPECT_NE(perPairOver, 0xff);
        }
    }
}

TEST(PairLoop, ThePowerLawsLookAheadIsTheStiffestCompressedLivingBonds) {
    const int before = omp_get_max_threads();
    for (const bool large : {false, true})
        for (const double jitter : {0.2, 0.002}) {
            MembraneParams params = SmallSheet::params(BondLawKind::PowerLaw);
            if (large) params.sheet.size = {1.0, 0.5};
            SmallSheet sheet(params);
            auto& [p, lattice, bonds, volumes, solver, damage] = sheet;
            const int n = int(lattice.positions.size());
            std::vector<Eigen::Vector3d> x = lattice.positions, v(n);
            for (int i = 0; i < n; ++i)
                for (int a = 0; a < 3; ++a) {
                    x[i][a] += jitter * p.sheet.dx * (2.0 * uniformFromHash(3, 3 * i + a) - 1.0);
                    v[i][a] = 2.0 * uniformFromHash(4, 3 * i + a) - 1.0;
                }
            const double dt = 1e-3;
            // The stiffest bond, broken: the look-ahead must pass over it.
            for (int pass = 0; pass < 2; ++pass) {
                int stiffestBond = -1;
                const double expected =
                    lookAheadOverBonds(solver, bonds, damage, x, v, dt, stiffestBond);
                EXPECT_GT(expected, 1.0);
                for (const int threads : {1, 3}) {
                    omp_set_num_threads(threads);
                    const std::vector<Eigen::Vector3d> force = solver.advanceAt(x, v, dt);
                    EXPECT_EQ(solver.stiffening(), expected)
                        << (large ? "large" : "small") << ", jitter " << jitter << ", pass " << pass
                        << ", " << threads << " threads";
                    // With the least the step needs known (StepState::stiffeningNeeded): the
                    // largest where it lies above, else that least; the same forces.
                    for (const double needed : {0.5 * (1.0 + expected), 2.0 * expected}) {
                        std::vector<Eigen::Vector3d> floored;
                        StepState s{x, v, {}, dt};
                        s.stiffeningNeeded = needed;
                        solver.advance(s, *solver.makeWorkspace(), floored);
                        EXPECT_EQ(solver.stiffening(), std::max(expected, needed)) << needed;
                        EXPECT_EQ(std::memcmp(floored.data(), force.data(),
                                              force.size() * sizeof(Eigen::Vector3d)),
                                  0);
                    }
                    // With a bound on every speed given (StepState::speedBound, as the membrane
                    // gives after a step) rather than read from v: the same largest and forces.
                    double fastest = 0.0;
                    for (const Eigen::Vector3d& u : v) fastest = std::max(fastest, u.norm());
                    std::vector<Eigen::Vector3d> bounded;
                    StepState s{x, v, {}, dt};
                    s.speedBound = fastest;
                    solver.advance(s, *solver.makeWorkspace(), bounded);
                    EXPECT_EQ(solver.stiffening(), expected) << "speed bound " << fastest;
                    EXPECT_EQ(std::memcmp(bounded.data(), force.data(),
                                          force.size() * sizeof(Eigen::Vector3d)),
                              0);
                }
                ASSERT_GT(stiffestBond, 0);
                damage.breakBond(stiffestBond);
            }
        }
    omp_set_num_threads(before);
}

// The look-ahead's slack (LinearPairInput::lookAheadSlack): at least dt |v_j - v_i| for any two
// of the particles it was taken over, the largest |component| at every width and length (the
// lanes and the rest), infinity for an infinite velocity, and positive for a sheet at rest.
TEST(PairLoop, TheLookAheadSlackBoundsEveryPairsRelativeVelocity) {
    for (const int n : {1, 7, 8, 9, 100, 333}) {
        std::vector<double> v(3 * n);
        double largest = 0.0;
        for (int k = 0; k < 3 * n; ++k) {
            v[k] = 4.0 * uniformFromHash(31, k) - 2.0;
            largest = std::max(largest, std::abs(v[k]));
        }
        ASSERT_EQ(largestMagnitude(v.data(), v.size()), largest) << n;
        const double dt = 1e-3, slack = lookAheadSlack(largestMagnitude(v.data(), v.size()), dt);
        for (int i = 0; i < n; ++i)
            for (int j = 0; j < n; ++j) {
                const double dx = v[3 * j] - v[3 * i], dy = v[3 * j + 1] - v[3 * i + 1],
                             dz = v[3 * j + 2] - v[3 * i + 2];
                EXPECT_LT(dt * std::sqrt(dx * dx + dy * dy + dz * dz), slack) << n;
            }
        v[3 * n / 2] = std::numeric_limits<double>::infinity();
        EXPECT_EQ(lookAheadSlack(largestMagnitude(v.data(), v.size()), dt),
                  std::numeric_limits<double>::infinity());
    }
    EXPECT_GT(lookAheadSlack(0.0, 1e-4), 0.0);
}

/// Counts the particles a pass asks it to move, and moves none.
struct CountingMotion final : BlockMotion {
    int moved = 0;
    void move(int begin, int end, const double*, int) override { moved += end - begin; }
};

// The power law's pass moves the particles (StepState::motion) only where the last pass's gap
// to the look-ahead's reach outlasts what moved since and this step's own slack
// (PeridynamicBonds::lookAheadClear): the largest speed bound at which it moves them halves
// where a drift as long as the step came before, falls further with theta's change times the
// expansion, and nothing moves where the drift, the speeds or theta's change are unknown, or
// the stiffening asked for is not the last pass's.
TEST(PairLoop, ThePowerLawsPassMovesOnlyWhereItsLastGapOutlastsTheMotionSince) {
    MembraneParams params = SmallSheet::params(BondLawKind::PowerLaw);
    params.material.expansion = 0.5;
    SmallSheet sheet(params);
    std::vector<Eigen::Vector3d> x = sheet.lattice.positions;
    for (Eigen::Vector3d& p : x) p *= 0.99;  // every bond compressed by 1%
    const std::vector<Eigen::Vector3d> v(x.size(), Eigen::Vector3d::Zero());
    const std::vector<double> theta(x.size(), 0.0);
    const double dt = 1e-4, needed = 50.0;
    const auto work = sheet.solver.makeWorkspace();
    std::vector<Eigen::Vector3d> force;
    const auto pass = [&](double speed, StepState::SinceLastPass since, double asked) {
        CountingMotion motion;
        StepState s{x, v, theta, dt};
        s.stiffeningNeeded = asked, s.speedBound = speed, s.sinceLastPass = since;
        s.motion = &motion;
        sheet.solver.advance(s, *work, force);
        EXPECT_EQ(sheet.solver.stiffening(), asked) << "nothing stiffens";
        EXPECT_TRUE(motion.moved == 0 || motion.moved == int(x.size()));
        return motion.moved > 0;
    };
    pass(-1.0, {}, needed);  // the first pass: its gap only
    // The largest speed bound (to 1e-9) at which the pass moves them.
    const auto largest = [&](StepState::SinceLastPass since) {
        double low = 0.0, high = 1e6;
        for (int k = 0; k < 80 && high - low > 1e-9 * high; ++k) {
            const double mid = 0.5 * (low + high);
            (pass(mid, since, needed) ? low : high) = mid;
        }
        return low;
    };
    const double still = largest({0.0, 0.0, 1.0}), drifted = largest({dt, 0.0, 1.0});
    ASSERT_GT(still, 1.0) << "a sheet compressed by 1% lies far from the reach of 50";
    EXPECT_NEAR(drifted, 0.5 * still, 1e-4 * still);
    const double swollen = largest({dt, 0.2, 1.0});
    EXPECT_LT(swollen, 0.95 * drifted);
    EXPECT_GT(swollen, 0.0);
    EXPECT_EQ(largest({dt, 1e3, 1.0}), 0.0) << "theta's change alone closes the gap";
    EXPECT_FALSE(pass(0.0, {-1.0, 0.0, 1.0}, needed)) << "the drift unknown";
    EXPECT_FALSE(pass(-1.0, {0.0, 0.0, 1.0}, needed)) << "the speeds unknown";
    EXPECT_FALSE(pass(0.0, {0.0, -1.0, 1.0}, needed)) << "theta's change unknown";
    pass(0.0, {0.0, 0.0, 1.0}, needed);
    EXPECT_FALSE(pass(0.0, {0.0, 0.0, 1.0}, 2.0 * needed)) << "another stiffening asked for";
}

// largestChange: the largest |after - before| of n values at every width and length (the lanes
// and the rest).
TEST(PairLoop, TheLargestChangeIsTheLargestDifference) {
    for (const int n : {0, 1, 3, 4, 9, 100, 333}) {
        std::vector<double> before(n), after(n);
        double largest = 0.0;
        for (int k = 0; k < n; ++k) {
            before[k] = uniformFromHash(41, k), after[k] = uniformFromHash(42, k);
            largest = std::max(largest, std::abs(after[k] - before[k]));
        }
        EXPECT_EQ(largestChange(before.data(), after.data(), n), largest) << n;
        if (n > 0) after[n - 1] = before[n - 1] - 3.0;
        if (n > 0) EXPECT_EQ(largestChange(before.data(), after.data(), n), 3.0) << n;
    }
}

// advance() moves the elastoplastic history on in the kernel: both copies of every living,
// unbroken bond hold the largest strain it has seen, and a dead bond's history stays put.
TEST(PairLoop, TheElastoplasticHistoryHoldsEachLivingBondsLargestStrain) {
    SmallSheet sheet(SmallSheet::params(BondLawKind::Elastoplastic));
    auto& [p, lattice, bonds, volumes, solver, damage] = sheet;
    for (int b = 0; b < int(bonds.directedCount()); b += 29) damage.breakBond(b);
    const int n = int(lattice.positions.size());
    std::vector<double> largest(bonds.directedCount(), 0.0);
    std::vector<Eigen::Vector3d> v(n, Eigen::Vector3d::Zero());
    for (const double amplitude : {0.004, 0.001, 0.006}) {  // strains of up to ~2 amplitudes
        std::vector<Eigen::Vector3d> x = lattice.positions;
        for (int i = 0; i < n; ++i)
            for (int a = 0; a < 2; ++a)
                x[i][a] += amplitude * p.sheet.dx * (2.0 * uniformFromHash(11, 3 * i + a) - 1.0);
        for (int i = 0; i < n; ++i)
            for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
                if (damage.bondAlive()[b]) {
                    const double eta =
                        (x[bonds.partners[b]] - x[i]).norm() / bonds.restLength[b] - 1.0;
                    largest[b] = std::max(largest[b], eta);
                }
        solver.advanceAt(x, v, 1e-5);
        int differ = 0, grew = 0;
        for (std::size_t b = 0; b < largest.size(); ++b) {
            differ += solver.plasticState()[b].maxStrain != largest[b];
            grew += largest[b] > p.material.yieldStrain;
        }
        EXPECT_EQ(differ, 0) << "amplitude " << amplitude;
        EXPECT_GT(grew, 100) << "the test yields bonds";
        // More bonds break between the passes: their history stays where it was (the
        // kernels' copy of which bonds live follows DamageState::version()).
        for (int b = int(amplitude * 1e4); b < int(bonds.directedCount()); b += 17)
            if (damage.bondAlive()[b]) damage.breakBond(b);
    }
}

// A checkpoint holds the elastoplastic history once per bond, both its ends holding the same
// bits, and per end when they differ; either reads back bit for bit.
TEST(PairLoop, ACheckpointHoldsTheHistoryOncePerBondUnlessItsEndsDiffer) {
    const MembraneParams params = SmallSheet::params(BondLawKind::Elastoplastic);
    SmallSheet sheet(params);
    auto& [p, lattice, bonds, volumes, solver, damage] = sheet;
    const int n = int(lattice.positions.size());
    std::vector<Eigen::Vector3d> x = lattice.positions, v(n, Eigen::Vector3d::Zero());
    for (int i = 0; i < n; ++i)
        for (int a = 0; a < 2; ++a)
            x[i][a] += 0.006 * p.sheet.dx * (2.0 * uniformFromHash(5, 3 * i + a) - 1.0);
    solver.advanceAt(x, v, 1e-5);
    auto saved = [](const PeridynamicBonds& s) {
        StateWriter out;
        s.saveState(out);
        return out.take();
    };
    auto historyAfterLoading = [&](const std::vector<std::byte>& state) {
        SmallSheet other(params);
        StateReader in(state);
        other.solver.loadState(in);
        in.finish();
        return other.solver.plasticState();
    };
    auto sameBits = [](const std::vector<PlasticState>& a, const std::vector<PlasticState>& b) {
        return a.size() == b.size() &&
               std::memcmp(a.data(), b.data(), a.size() * sizeof(PlasticState)) == 0;
    };
    const std::vector<std::byte> once = saved(solver);
    const std::vector<PlasticState> history = solver.plasticState();
    EXPECT_GT(
        std::count_if(history.begin(), history.end(),
                      [&](const PlasticState& s) { return s.maxStrain > p.material.yieldStrain; }),
        100)
        << "the test yields bonds";
    EXPECT_TRUE(sameBits(historyAfterLoading(once), history));

    solver.plasticState()[7].maxStrain = std::nextafter(history[7].maxStrain, 1.0);  // one end
    const std::vector<std::byte> perEnd = saved(solver);
    EXPECT_EQ(perEnd.size(), once.size() + bonds.directedCount() / 2 * sizeof(PlasticState));
    EXPECT_TRUE(sameBits(historyAfterLoading(perEnd), solver.plasticState()));
    EXPECT_FALSE(sameBits(historyAfterLoading(perEnd), history));
}

/// Membrane::failureApproachRate's loop over bonds, as written there.
double approachOverBonds(const BondFamilies& bonds, const DamageState& damage,
                         const FailureApproach& f, const std::vector<Eigen::Vector3d>& x,
                         const std::vector<Eigen::Vector3d>& v, const std::vector<double>& theta) {
    double fastest = 0.0;
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const int j = bonds.partners[b];
            if (j < i || !damage.bondAlive()[b]) continue;
            const Eigen::Vector3d xi = x[j] - x[i];
            const double rest = bonds.restLength[b];
            const double thetaBar = theta.empty() ? 0.0 : 0.5 * (theta[i] + theta[j]);
            const double critical = f.criticalStretch * degradation(f.strengthLoss, thetaBar);
            const double unstretched = 1.0 + f.expansion * thetaBar;
            const double loaded = rest * (unstretched + 0.5 * critical);
            if (!(critical > 0.0 && xi.squaredNorm() > loaded * loaded)) continue;
            const double length = xi.norm();
            const double rate = xi.dot(v[j] - v[i]) / (length * rest);
            if (!(rate > 0.0)) continue;
            const double margin = critical - (length / rest - unstretched);
            fastest =
                std::max(fastest, rate / std::max(0.5 * margin, f.maxStretchIncrement * critical));
        }
    return fastest;
}

// The solver's pairs give Membrane's failure approach rate bit for bit (the adaptive step's
// measure), on both lattices, with theta, dead bonds and 1 or 3 threads.
TEST(PairLoop, TheFailureApproachRateIsMembranesLoopOverBonds) {
    for (const LatticeKind kind : {LatticeKind::Square, LatticeKind::Hexagonal}) {
        MembraneParams p = SmallSheet::params(BondLawKind::Linear);
        p.sheet.lattice = kind;
        p.sheet.size = {1.0, 0.5};  // over the threads' threshold
        SmallSheet sheet(p);
        auto& [params, lattice, bonds, volumes, solver, damage] = sheet;
        for (int b = 0; b < int(bonds.directedCount()); b += 31) damage.breakBond(b);
        const int n = int(lattice.positions.size());
        std::vector<Eigen::Vector3d> x = lattice.positions, v(n);
        std::vector<double> theta(n);
        FailureApproach f{0.01, 0.02, 0.3, 0.05};
        for (int i = 0; i < n; ++i) {  // strains up to 2 eta_c, some bonds opening fast
            for (int a = 0; a < 3; ++a) {
                x[i][a] += 0.02 * p.sheet.dx * (2.0 * uniformFromHash(31, 3 * i + a) - 1.0);
                v[i][a] = 2.0 * uniformFromHash(32, 3 * i + a) - 1.0;
            }
            theta[i] = 1.5 * uniformFromHash(33, i);
        }
        const int before = omp_get_max_threads();
        // The margin's floor: what most lanes take, what the fastest takes, what all take.
        for (const double delta : {0.05, 1e-4, 10.0})
            for (const bool heated : {false, true}) {
                f.maxStretchIncrement = delta;
                const std::vector<double> t = heated ? theta : std::vector<double>{};
                const double expected = approachOverBonds(bonds, damage, f, x, v, t);
                EXPECT_GT(expected, 0.0);
                for (const int threads : {1, 3}) {
                    omp_set_num_threads(threads);
                    const std::optional<double> got =
                        solver.failureApproachRate({x, v, t, 1e-5}, f);
                    ASSERT_TRUE(got.has_value());
                    EXPECT_EQ(std::bit_cast<std::uint64_t>(*got),
                              std::bit_cast<std::uint64_t>(expected))
                        << *got << " against " << expected << ", " << threads << " threads";
                }
            }
        omp_set_num_threads(before);
    }
}

// advance() breaks the bonds past their limit, both copies, each once: the pairs are computed in
// tiles of eight particles whose short lanes repeat a pair (sim/PeridynamicBonds.h), and a
// repeat is never proposed. A 1 x 0.5 m sheet on 1 and 3 threads, some bonds already dead.
TEST(PairLoop, AdvanceBreaksEachBondPastItsLimitOnce) {
    MembraneParams p = SmallSheet::params(BondLawKind::Linear);
    p.sheet.size = {1.0, 0.5};
    p.material.fractureEnergy = 0.02;
    const int before = omp_get_max_threads();
    for (const int threads : {1, 3}) {
        omp_set_num_threads(threads);
        SmallSheet sheet(p);
        auto& [params, lattice, bonds, volumes, solver, damage] = sheet;
        for (int b = 0; b < int(bonds.directedCount()); b += 31) damage.breakBond(b);
        const int n = int(lattice.positions.size());
        std::vector<Eigen::Vector3d> x = lattice.positions, v(n, Eigen::Vector3d::Zero());
        const double etaC = solver.criticalStretch();
        for (int i = 0; i < n; ++i)
            for (int a = 0; a < 2; ++a)
                x[i][a] += 1.5 * etaC * p.sheet.dx * (2.0 * uniformFromHash(5, 3 * i + a) - 1.0);
        std::vector<std::uint8_t> expected = damage.bondAlive();
        std::size_t breaking = 0;  // directed copies
        for (int i = 0; i < n; ++i)
            for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
                const double eta = (x[bonds.partners[b]] - x[i]).norm() / bonds.restLength[b] - 1.0;
                if (expected[b] && eta > etaC) expected[b] = 0, ++breaking;
            }
        ASSERT_GT(breaking, 1000u) << "the test breaks bonds";
        const std::size_t broken = damage.brokenBondCount();
        solver.advanceAt(x, v, 1e-5);
        EXPECT_EQ(damage.bondAlive(), expected) << threads << " threads";
        EXPECT_EQ(damage.brokenBondCount(), broken + breaking / 2) << threads << " threads";
    }
    omp_set_num_threads(before);
}

INSTANTIATE_TEST_SUITE_P(
    EveryLaw, PairLoop,
    ::testing::Values(
        Case{BondLawKind::Linear, false, false}, Case{BondLawKind::Linear, true, true},
        Case{BondLawKind::Linear, false, true}, Case{BondLawKind::Linear, true, false},
        Case{BondLawKind::PowerLaw, false, false}, Case{BondLawKind::PowerLaw, true, true},
        Case{BondLawKind::Elastoplastic, false, true}, Case{BondLawKind::Elastoplastic, true, true},
        Case{BondLawKind::Linear, true, true, true}, Case{BondLawKind::PowerLaw, true, true, true},
        Case{BondLawKind::Elastoplastic, true, true, true},
        Case{BondLawKind::Linear, true, true, false, true},
        Case{BondLawKind::PowerLaw, true, true, false, true},
        Case{BondLawKind::Elastoplastic, true, true, true, true},
        Case{BondLawKind::Linear, false, false, true, true},
        Case{BondLawKind::Linear, true, true, false, true, true},
        Case{BondLawKind::PowerLaw, true, true, false, false, true},
        Case{BondLawKind::Elastoplastic, false, true, true, true, true},
        Case{BondLawKind::Linear, true, true, false, true, false, true},
        Case{BondLawKind::PowerLaw, true, true, false, true, true, false, 2.0},
        Case{BondLawKind::PowerLaw, false, true, false, true, false, false, 3.0}));

TEST(PartitionSlabs, OwnEveryParticleOnceAndHoldEveryPairTheyCompute) {
    const BondFamilies bonds = sheetBonds(0.3, 0.2, 1.5);
    const int n = bonds.particleCount();
    for (const int count : {1, 2, 3, 7}) {
        const std::vector<Slab> slabs = partitionSlabs(bonds, count);
        ASSERT_EQ(int(slabs.size()), count);
        EXPECT_EQ(slabs.front().begin, 0);
        EXPECT_EQ(slabs.back().end, n);
        for (int r = 0; r < count; ++r) {
            const Slab& s = slabs[r];
            if (r > 0) {
                EXPECT_EQ(s.begin, slabs[r - 1].end);
            }
            // Every pair from [ghostBegin, end) and every owned particle's partner is held.
            for (int i = s.ghostBegin; i < s.end; ++i)
                for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
                    const int j = bonds.partners[b];
                    if (i >= s.begin || j > i) {
                        EXPECT_GE(j, s.ghostBegin);
                        EXPECT_LT(j, s.ghostEnd);
                    }
                }
            if (r > 0) {
                EXPECT_GE(s.ghostBegin, slabs[r - 1].begin) << "only the next slab";
            }
        }
    }
    EXPECT_THROW(partitionSlabs(bonds, n / 10), std::invalid_argument) << "slabs of 10";
}

}  // namespace
