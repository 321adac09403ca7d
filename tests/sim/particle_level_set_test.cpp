// Seed 004's particle level set of the outline (sim/ParticleLevelSet.h): the ghost band, the
// zero level set on the scene's outline, carried through a spin and reinitialised, and a crack
// as a boundary.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <map>
#include <numbers>
#include <utility>

#include "sim/Lattice.h"
#include "sim/Membrane.h"

using namespace rend::sim;

namespace {

SheetParams disc() {
    SheetParams s;
    s.outline = Outline::Disc;
    s.radius = 0.1;
    s.dx = 0.01;
    return s;
}

SheetParams rectangle(LatticeKind kind) {
    SheetParams s;
    s.size = {0.2, 0.1};  // a hexagonal lattice's rows (0.866 dx apart) miss the top side
    s.dx = 0.01;
    s.lattice = kind;
    return s;
}

MembraneParams freeSheet(const SheetParams& sheet) {
    MembraneParams p;
    p.sheet = sheet;
    p.particleLevelSet = true;
    return p;
}

/// The zero level set's points: where Phi changes sign along the kept band's particle-ghost
/// edges, at the frame's positions.
std::vector<Eigen::Vector3d> zeroPoints(const FrameView& v) {
    std::vector<Eigen::Vector3d> points;
    const int n = int(v.particleCount());
    for (std::size_t t = 0; t < v.bandTriangles.size(); ++t) {
        if (!v.bandKept[t]) continue;
        for (int i : v.bandTriangles[t])
            for (int g : v.bandTriangles[t]) {
                if (i >= n || g < n) continue;
                const double s = v.levelSet[i] / (v.levelSet[i] - v.ghostLevelSet[g - n]);
                points.push_back(v.positions[i] + s * (v.ghostPositions[g - n] - v.positions[i]));
            }
    }
    return points;
}

/// Whether p is within 1.5 dx of a rectangle's corner, which a level set chamfers (the
/// distances to two sides meet there, and marching triangles interpolate them linearly).
bool nearCorner(const SheetParams& sheet, const Eigen::Vector3d& p) {
    if (sheet.outline != Outline::Rectangle) return false;
    const Eigen::Vector2d d = p.head<2>().cwiseAbs() - 0.5 * sheet.size;
    return d.x() > -1.5 * sheet.dx && d.y() > -1.5 * sheet.dx;
}

/// The largest distance, in the rest plane, of `points` from the sheet's outline, away from its
/// corners (first) and at them (second).
std::pair<double, double> largestOffOutline(const SheetParams& sheet,
                                            const std::vector<Eigen::Vector3d>& points) {
    std::pair<double, double> worst{0.0, 0.0};
    for (const Eigen::Vector3d& p : points) {
        double& w = nearCorner(sheet, p) ? worst.second : worst.first;
        w = std::max(w, std::abs(outlineDistance(sheet, p)));
    }
    return worst;
}

}  // namespace

// The band seals the outline: every lattice edge with one triangle has exactly one band
// triangle across it, every ghost lies outside the outline, and the band's triangles are
// counter-clockwise like the lattice's.
TEST(ParticleLevelSet, TheGhostBandContinuesTheLatticePastTheOutline) {
    for (const SheetParams& sheet :
         {disc(), rectangle(LatticeKind::Hexagonal), rectangle(LatticeKind::Square)}) {
        const Lattice lattice = generateLattice(sheet);
        const GhostBand band = ghostBand(sheet);
        const int n = int(lattice.positions.size());
        ASSERT_FALSE(band.sites.empty());
        for (const Eigen::Vector3d& g : band.sites) EXPECT_GT(outlineDistance(sheet, g), 0.0);
        std::map<std::pair<int, int>, int> uses;  // undirected edge -> triangles on it
        auto count = [&](const std::array<int, 3>& t) {
            for (int k = 0; k < 3; ++k) ++uses[std::minmax(t[k], t[(k + 1) % 3])];
        };
        for (const auto& t : lattice.triangles) count(t);
        std::map<std::pair<int, int>, int> latticeUses = uses;
        auto position = [&](int c) { return c < n ? lattice.positions[c] : band.sites[c - n]; };
        for (const auto& t : band.triangles) {
            int particles = 0;
            for (int c : t) particles += c < n;
            EXPECT_TRUE(particles == 1 || particles == 2);
            const Eigen::Vector3d a = position(t[0]);
            EXPECT_GT((position(t[1]) - a).cross(position(t[2]) - a).z(), 0.0);
            count(t);
        }
        int outlineEdges = 0;
        for (const auto& [edge, triangles] : latticeUses) {
            if (triangles != 1) continue;
            ++outlineEdges;
            EXPECT_EQ(uses[edge], 2) << edge.first << "-" << edge.second;
        }
        EXPECT_GT(outlineEdges, 20);
    }
    EXPECT_TRUE(ghostBand(SheetParams{.outline = Outline::Sphere}).sites.empty());
}

// At rest, and after a thousand steps of a sheet at rest (fifty reinitialisations), the zero
// level set lies on the scene's outline, not on the outermost particles: a hexagonal lattice's
// top row is 0.33 dx short of its rectangle's side, and a disc's outline particles up to 0.5 dx
// inside its circle.
TEST(ParticleLevelSet, TheZeroLevelSetIsTheScenesOutlineAndStaysThere) {
    for (const SheetParams& sheet :
         {disc(), rectangle(LatticeKind::Hexagonal), rectangle(LatticeKind::Square)}) {
        Membrane m(freeSheet(sheet));
        const FrameView rest = m.view(0);
        const std::vector<Eigen::Vector3d> atRest = zeroPoints(rest);
        ASSERT_GT(atRest.size(), 40u);
        double outermost = 0.0;  // the lattice's own outline: its outermost particles' distance
        for (int i = 0; i < m.particleCount(); ++i)
            if (rest.levelSet[i] > -0.75 * sheet.dx)
                outermost = std::max(outermost, -outlineDistance(sheet, m.restPositions()[i]));
        for (int s = 0; s < 1000; ++s) m.step();
        const auto start = largestOffOutline(sheet, atRest);
        const auto later = largestOffOutline(sheet, zeroPoints(m.view(1)));
        std::printf(
            "zero level set off the outline: %.2e dx at rest, %.2e dx after 1000 steps "
            "(at corners %.3f, %.3f dx); outermost particles up to %.3f dx inside\n",
            start.first / sheet.dx, later.first / sheet.dx, start.second / sheet.dx,
            later.second / sheet.dx, outermost / sheet.dx);
        EXPECT_LT(start.first, 0.02 * sheet.dx);
        EXPECT_LT(later.first, 0.02 * sheet.dx);
        EXPECT_LT(later.second, 0.25 * sheet.dx);
        if (sheet.outline == Outline::Disc || sheet.lattice == LatticeKind::Hexagonal)
            EXPECT_GT(outermost, 0.3 * sheet.dx);
    }
}

// A spinning free sheet: the ghosts move with their support's mean velocity (which lags in a
// spin) and are put back on their anchor's linear extrapolation every 20 steps, so the zero
// level set turns with the sheet. Each zero point's offset from its particle, turned back by the
// spin, is its rest offset: checked ten steps after a reinitialisation (carried) and on one.
TEST(ParticleLevelSet, TheZeroLevelSetTurnsWithASpinningSheet) {
    const SheetParams sheet = rectangle(LatticeKind::Hexagonal);
    Membrane m(freeSheet(sheet));
    const double omega = 2.0;  // rad/s about z through the centre
    for (int i = 0; i < m.particleCount(); ++i)
        m.velocities()[i] = omega * Eigen::Vector3d::UnitZ().cross(m.positions()[i]);
    for (const int steps : {410, 420}) {
        while (m.stepCount() < steps) m.step();
        const FrameView v = m.view(1);
        const Eigen::AngleAxisd back(-omega * v.time, Eigen::Vector3d::UnitZ());
        const int n = int(v.particleCount());
        double worst = 0.0;
        for (std::size_t t = 0; t < v.bandTriangles.size(); ++t)
            for (int i : v.bandTriangles[t])
                for (int g : v.bandTriangles[t]) {
                    if (!v.bandKept[t] || i >= n || g < n) continue;
                    const double s = v.levelSet[i] / (v.levelSet[i] - v.ghostLevelSet[g - n]);
                    const Eigen::Vector3d moved = s * (v.ghostPositions[g - n] - v.positions[i]);
                    const Eigen::Vector3d rest =
                        s * (v.ghostRestPositions[g - n] - v.restPositions[i]);
                    worst = std::max(worst, (back * moved - rest).norm());
                }
        std::printf(
            "spun by %.2f rad (%d steps): zero points off their turned rest offset by "
            "%.4f dx\n",
            omega * v.time, steps, worst / sheet.dx);
        EXPECT_GT(omega * v.time, 0.5);
        EXPECT_LT(worst, (steps % 20 == 0 ? 0.02 : 0.05) * sheet.dx);  // the mean velocity lags
    }
}

// A notch is a boundary: the particles beside it are within a spacing of it, and Phi does not
// leak across it (the particles on both sides measure their distance to their own lip).
TEST(ParticleLevelSet, ACrackIsABoundaryOfTheLevelSet) {
    MembraneParams p = freeSheet(rectangle(LatticeKind::Hexagonal));
    p.notches.push_back({{{0.0025, -0.06}, {0.0025, 0.0}}});  // from the bottom side up to y = 0
    Membrane m(p);
    const FrameView v = m.view(0);
    const double dx = p.sheet.dx;
    int beside = 0, far = 0;
    for (int i = 0; i < m.particleCount(); ++i) {
        const Eigen::Vector3d& X = m.restPositions()[i];
        const bool nearCrack = std::abs(X.x() - 0.0025) < 0.6 * dx && X.y() < -0.01;
        if (nearCrack) {
            ++beside;
            EXPECT_GT(v.levelSet[i], -0.6 * dx) << X.transpose();
            std::printf("beside the notch at (%.4f, %.4f): phi %.3f dx\n", X.x(), X.y(),
                        v.levelSet[i] / dx);
        }
        if (std::abs(X.x()) > 0.03 && std::abs(X.x()) < 0.06 && std::abs(X.y()) < 0.015) {
            ++far;
            EXPECT_DOUBLE_EQ(v.levelSet[i], -ParticleLevelSet::kBand * dx);
        }
    }
    EXPECT_GT(beside, 4);
    EXPECT_GT(far, 4);
}

// The level set is state: a checkpoint resumes it bit for bit. A run that does not draw it
// reads past it, and a run that draws it refuses a state without it.
TEST(ParticleLevelSet, ACheckpointCarriesItAndARunWithoutItReadsPast) {
    const MembraneParams p = freeSheet(disc());
    Membrane a(p);
    for (int i = 0; i < a.particleCount(); ++i) a.velocities()[i] = {0.0, 0.0, 0.01 * i};
    for (int s = 0; s < 30; ++s) a.step();
    const std::vector<std::byte> state = a.saveState();
    const std::vector<Eigen::Vector3d> saved = a.positions();
    Membrane b(p);
    b.loadState(state);
    for (int s = 0; s < 30; ++s) a.step(), b.step();
    const FrameView va = a.view(1), vb = b.view(1);
    ASSERT_EQ(va.ghostPositions.size(), vb.ghostPositions.size());
    for (std::size_t g = 0; g < va.ghostPositions.size(); ++g) {
        ASSERT_EQ(va.ghostPositions[g], vb.ghostPositions[g]);
        ASSERT_EQ(va.ghostLevelSet[g], vb.ghostLevelSet[g]);
    }
    for (int i = 0; i < a.particleCount(); ++i) ASSERT_EQ(va.levelSet[i], vb.levelSet[i]);
    MembraneParams plain = p;
    plain.particleLevelSet = false;
    Membrane c(plain);
    c.loadState(state);
    EXPECT_EQ(c.positions(), saved);
    EXPECT_TRUE(c.view(1).ghostPositions.empty());
    EXPECT_THROW(Membrane(p).loadState(c.saveState()), StateMismatch);
}
