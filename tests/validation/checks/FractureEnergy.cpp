#include "tests/validation/checks/FractureEnergy.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <vector>

#include "tests/sim/Peridynamic.h"

namespace rend::checks {

using namespace rend::sim;

namespace {

/// The heights of the lattice rows, bottom to top.
std::vector<double> rowHeights(const MembraneParams& p) {
    const Membrane probe(p);
    std::vector<double> rows;
    for (const auto& x : probe.restPositions()) rows.push_back(x.y());
    std::sort(rows.begin(), rows.end());
    rows.erase(std::unique(rows.begin(), rows.end(),
                           [&](double a, double b) { return b - a < 1e-6 * p.sheet.dx; }),
               rows.end());
    return rows;
}

/// Holds every row of the far end (one horizon deep) at x = rest and y stretched with the grips:
/// the uniform plane-strain state of the uncracked strip, so the grips' corners there carry no
/// stress concentration.
void holdFarEnd(MembraneParams& p, const std::vector<double>& rows, double strainRate) {
    const double horizon = p.sheet.horizonFactor * p.sheet.dx;
    for (double y : rows) {
        BoundaryCondition row;
        row.kind = BoundaryKind::Velocity;
        row.region.min = {0.5 * p.sheet.size.x() - horizon - 0.25 * p.sheet.dx,
                          y - 0.25 * p.sheet.dx};
        row.region.max.y() = y + 0.25 * p.sheet.dx;
        row.velocity = {0, strainRate * y, 0};
        p.boundaries.push_back(row);
    }
}

}  // namespace

double stripGriffithStrain(const NotchedStrip& s, const MembraneParams& p) {
    const double height = 2.0 * p.boundaries[0].region.min.y();  // between the grip rows
    return std::sqrt(2.0 * s.fractureEnergy / (s.youngsModulus / (1.0 - 1.0 / 9.0) * height));
}

MembraneParams pulledStrip(const NotchedStrip& s) {
    MembraneParams p;
    p.solver = s.solver;
    if (s.solver != "peridynamic") p.material.poissonRatio = 1.0 / 3.0;
    p.sheet.size = {s.width, s.height};
    p.sheet.dx = s.dx;
    p.sheet.horizonFactor = s.horizonFactor;
    p.sheet.thickness = s.thickness;
    p.material.youngsModulus = s.youngsModulus;
    p.material.density = s.density;
    p.material.fractureEnergy = s.fractureEnergy * s.criticalStrainScale * s.criticalStrainScale;
    p.material.criticalStretch = s.mode;
    const std::vector<double> rows = rowHeights(p);
    const auto above = std::upper_bound(rows.begin(), rows.end(), 0.0);
    const double y = 0.5 * (*std::prev(above) + *above);  // between the rows next to y = 0
    const double topRow = rows.back();
    p.notches = {Notch{{{-0.5 * s.width - s.dx, y}, {s.notchTip, y}}}};
    BoundaryCondition top, bottom;
    top.kind = bottom.kind = BoundaryKind::Velocity;
    top.region.min.y() = topRow - 0.25 * s.dx;  // the lattice is mirror-symmetric
    bottom.region.max.y() = -topRow + 0.25 * s.dx;
    top.velocity = {0, s.strainRate * topRow, 0};
    bottom.velocity = {0, -s.strainRate * topRow, 0};
    p.boundaries = {top, bottom};
    if (s.holdFarEnd) holdFarEnd(p, rows, s.strainRate);
    p.damping = s.damping;
    p.time.safety = s.timeStepSafety;
    return p;
}

CrackRecord runCrack(const NotchedStrip& s, double windowStart, double windowEnd) {
    const MembraneParams p = pulledStrip(s);
    const double y = p.notches[0].points[0].y();
    const double height = 2.0 * p.boundaries[0].region.min.y();  // between the grip rows
    const double griffith = stripGriffithStrain(s, p);
    Membrane m(p);
    const double prestretch = 0.8 * griffith;
    for (auto& x : m.positions()) x.y() *= 1.0 + prestretch;
    const BondFamilies& bonds = m.bonds();
    const std::vector<std::uint8_t>& bondAlive = m.damageState().bondAlive();
    const double etaC = rend::test::criticalStretch(m);
    const double c = rend::test::micromodulus(m);
    const double halfReach = 0.5 * m.horizon() + 1e-9;  // a bond crossing the line has its
                                                        // midpoint this close to it
    CrackRecord r;
    r.etaC = etaC;
    r.rowShare = rowCrackShare(m);
    auto midpoint = [&](int i, int b) {
        return 0.5 * (m.restPositions()[i] + m.restPositions()[bonds.partners[b]]);
    };
    for (int i = 0; i < m.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
            if (!bondAlive[b]) r.notchFront = std::max(r.notchFront, midpoint(i, b).x());
    std::vector<std::uint8_t> before = bondAlive;
    std::size_t brokenBefore = m.brokenBondCount();
    const long maxSteps = long(s.duration / m.timeStep());
    for (long step = 0; step < maxSteps && !r.reached; ++step) {
        m.step();
        const std::size_t broken = m.brokenBondCount();
        if (broken == brokenBefore) continue;
        if (r.broken == 0 && r.elsewhere == 0)
            r.strainAtStart = (prestretch + s.strainRate * m.time()) / griffith;
        brokenBefore = broken;
        for (int i = 0; i < m.particleCount(); ++i)
            for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
                const int j = bonds.partners[b];
                if (j < i || bondAlive[b] == before[b]) continue;  // each bond once
                const double u =
                    bonds.weight[b] * m.volumes()[i] * m.volumes()[j] * c * etaC * etaC / 2.0;
                const Eigen::Vector3d mid = midpoint(i, b);
                const double offset = std::abs(mid.y() - y);
                if (offset > 0.25 * height) {
                    ++r.elsewhere;
                    continue;
                }
                r.energy += u;
                ++r.broken;
                const double yi = m.restPositions()[i].y(), yj = m.restPositions()[j].y();
                if ((yi < y) != (yj < y)) r.crossingEnergy += u;
                if (offset > halfReach)
                    ++r.offLine;
                else
                    r.front = std::max(r.front, mid.x());
                if (mid.x() >= windowStart && mid.x() < windowEnd) r.windowEnergy += u;
            }
        before = bondAlive;
        if (r.front >= windowEnd) {
            r.reached = true;
            r.seconds = m.time();
        }
    }
    return r;
}

double energyPerLength(const NotchedStrip& s, const CrackRecord& r, bool crossingOnly) {
    const double energy = crossingOnly ? r.crossingEnergy : r.energy;
    return energy / ((r.front - r.notchFront) * s.thickness) / s.fractureEnergy;
}

double rowCrackShare(const Membrane& m) {
    const BondFamilies& bonds = m.bonds();
    // The interior particle is the one whose family sum is largest, as the calibration takes it.
    int interior = 0;
    double best = -1.0;
    for (int i = 0; i < m.particleCount(); ++i) {
        double all = 0.0;
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
            all += bonds.weight[b] * bonds.restLength[b] * m.volumes()[bonds.partners[b]];
        if (all > best) best = all, interior = i;
    }
    double across = 0.0;
    for (int b = bonds.offsets[interior]; b < bonds.offsets[interior + 1]; ++b) {
        const int j = bonds.partners[b];
        const double xiY = m.restPositions()[j].y() - m.restPositions()[interior].y();
        across += bonds.weight[b] * std::abs(xiY) * m.volumes()[j];
    }
    return across / (2.0 / std::numbers::pi * best);
}

}  // namespace rend::checks
