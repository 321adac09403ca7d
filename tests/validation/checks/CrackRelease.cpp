#include "tests/validation/checks/CrackRelease.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

#include "tests/sim/Peridynamic.h"

namespace rend::checks {

using namespace rend::sim;

ReleaseRecord runCrackRelease(const NotchedStrip& s, double windowStart, double windowEnd) {
    const MembraneParams p = pulledStrip(s);
    const double y = p.notches[0].points[0].y();
    const double height = 2.0 * p.boundaries[0].region.min.y();  // between the grip rows
    const double griffith = stripGriffithStrain(s, p);
    Membrane m(p);
    const double prestretch = 0.8 * griffith;
    for (auto& x : m.positions()) x.y() *= 1.0 + prestretch;
    const BondFamilies& bonds = m.bonds();
    const std::vector<std::uint8_t>& bondAlive = m.damageState().bondAlive();
    const auto& rest = m.restPositions();
    const double halfReach = 0.5 * m.horizon() + 1e-9;  // see runCrack
    ReleaseRecord r;
    if (s.solver == "peridynamic")
        r.critical = rend::test::criticalStretch(m);
    else if (s.solver != "fem_cst" && s.solver != "sph")
        r.critical = springCriticalStrain(p);  // a spring is the bond along it
    auto midpoint = [&](int i, int b) { return 0.5 * (rest[i] + rest[bonds.partners[b]]); };
    for (int i = 0; i < m.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
            if (!bondAlive[b]) r.notchFront = std::max(r.notchFront, midpoint(i, b).x());
    std::vector<std::uint8_t> before = bondAlive;
    std::vector<Eigen::Vector3d> xn;
    bool inWindow = false;
    double overshoot = 0.0;
    const long maxSteps = long(s.duration / m.timeStep());
    for (long step = 0; step < maxSteps && !r.reached; ++step) {
        const double strain = prestretch + s.strainRate * m.time();  // at x_n
        const double u0 = m.strainEnergy();
        xn = std::as_const(m).positions();
        m.step();
        // U(x_n) with the state the step left; the swaps put x_n in and x_n+1 back, bit for bit.
        m.positions().swap(xn);
        const double u1 = m.strainEnergy();
        m.positions().swap(xn);
        const double release = u0 - u1;
        if (release == 0.0 && bondAlive == before) continue;
        if (r.breakingSteps++ == 0) r.strainAtStart = strain / griffith;
        bool atGrips = false;
        for (int i = 0; i < m.particleCount(); ++i)
            for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
                const int j = bonds.partners[b];
                if (j < i || bondAlive[b] == before[b]) continue;  // each bond once
                const Eigen::Vector3d mid = midpoint(i, b);
                const double offset = std::abs(mid.y() - y);
                if (offset > 0.25 * height) {
                    ++r.elsewhere;
                    atGrips = true;
                    continue;
                }
                ++r.broken;
                if (std::isfinite(r.critical)) {
                    const double stretch = (xn[j] - xn[i]).norm() / bonds.restLength[b] - 1.0;
                    r.minBreakStretch = std::min(r.minBreakStretch, stretch / r.critical);
                    overshoot += (stretch / r.critical) * (stretch / r.critical);
                }
                if (offset > halfReach)
                    ++r.offLine;
                else
                    r.front = std::max(r.front, mid.x());
            }
        before = bondAlive;
        if (release < 0.0) r.negativeReleased += release;
        if (atGrips) {
            r.elsewhereReleased += release;
            continue;
        }
        r.released += release;
        if (inWindow) r.windowReleased += release;
        if (!inWindow && r.front >= windowStart) {
            inWindow = true;
            r.windowFrom = r.front;
        }
        r.windowTo = r.front;
        if (r.front >= windowEnd) {
            r.reached = true;
            r.seconds = m.time();
        }
    }
    if (r.broken > 0) r.overshoot = overshoot / double(r.broken);
    return r;
}

double releasedPerLength(const NotchedStrip& s, const ReleaseRecord& r, bool window) {
    const double energy = window ? r.windowReleased : r.released;
    const double length = window ? r.windowTo - r.windowFrom : r.front - r.notchFront;
    return energy / (length * s.thickness) / s.fractureEnergy;
}

}  // namespace rend::checks
