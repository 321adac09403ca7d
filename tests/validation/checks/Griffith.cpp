#include "tests/validation/checks/Griffith.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <vector>

#include "sim/Membrane.h"
#include "tests/sim/Peridynamic.h"

namespace rend::checks {

using namespace rend::sim;

double halfLength(const CentreCrack& k) { return k.horizons * k.factor * k.dx; }

double griffithStress(const CentreCrack& k) {
    return std::sqrt(k.youngsModulus * k.fractureEnergy / (std::numbers::pi * halfLength(k)));
}

double feddersenStress(const CentreCrack& k) {
    return griffithStress(k) * std::sqrt(std::cos(std::numbers::pi / k.widthOverA));
}

namespace {

struct Plate {
    MembraneParams params;
    double width = 0.0, height = 0.0;
    double notchY = 0.0;    ///< the notch's line
    double duration = 0.0;  ///< ramp and loading time
};

Plate centreCrackedPlate(const CentreCrack& k) {
    const double a = halfLength(k);
    Plate plate;
    plate.width = k.widthOverA * a;
    plate.height = k.heightOverA * a;
    MembraneParams& p = plate.params;
    p.sheet.size = {plate.width, plate.height};
    p.sheet.dx = k.dx;
    p.sheet.horizonFactor = k.factor;
    p.sheet.thickness = k.thickness;
    p.material.youngsModulus = k.youngsModulus;
    p.material.density = k.density;
    p.material.fractureEnergy = k.fractureEnergy;
    double below = -1e9, above = 1e9;  // the notch lies halfway between the rows next to y = 0
    double top = 0.0;                  // the top row
    const Membrane probe(p);
    for (const auto& x : probe.restPositions()) {
        if (x.y() <= 0.0) below = std::max(below, x.y());
        if (x.y() > 0.0) above = std::min(above, x.y());
        top = std::max(top, x.y());
    }
    plate.notchY = 0.5 * (below + above);
    p.notches = {Notch{{{-a, plate.notchY}, {a, plate.notchY}}}};
    // Griffith's strain sqrt(G_f / (pi E a)) reached after `transits` transits of the height.
    const double waveSpeed = std::sqrt(k.youngsModulus / (k.density * (1.0 - 1.0 / 9.0)));
    const double rampTime = 2.0 * plate.height / waveSpeed;
    const double loadTime = k.transits * plate.height / waveSpeed;
    plate.duration = rampTime + loadTime;
    const double strainC = std::sqrt(k.fractureEnergy / (std::numbers::pi * k.youngsModulus * a));
    const double speed = 0.5 * strainC * plate.height / loadTime;
    BoundaryCondition upper, lower;  // the top and bottom rows (the lattice is symmetric)
    upper.kind = lower.kind = BoundaryKind::Velocity;
    upper.region.min.y() = top - 0.25 * k.dx;
    lower.region.max.y() = -top + 0.25 * k.dx;
    upper.velocity = {0, speed, 0};
    lower.velocity = {0, -speed, 0};
    upper.rampTime = lower.rampTime = rampTime;
    p.boundaries = {upper, lower};
    p.damping = 0.5;  // 1/s
    return plate;
}

/// The far-field stresses of the plate now: the bands' mean sigma_yy and the grip's reaction.
class FarField {
public:
    FarField(const Membrane& m, const Plate& plate) : width_(plate.width) {
        const Region& grip = plate.params.boundaries[0].region;
        for (int i = 0; i < m.particleCount(); ++i) {
            const Eigen::Vector3d& x = m.restPositions()[i];
            const double h = plate.height;  // full-width rows between the crack and the grips
            if (std::abs(x.y()) >= 0.3 * h && std::abs(x.y()) <= 0.4 * h) band_.push_back(i);
            if (grip.contains(x)) grip_.push_back(i);
        }
    }
    double bandStress(const Membrane& m) const {
        double sum = 0.0;
        for (int i : band_) sum += rend::test::particleStress(m, i)(1, 1);
        return sum / double(band_.size());
    }
    double reactionStress(const Membrane& m, double thickness) const {
        std::vector<Eigen::Vector3d> f;
        m.computeForces(f);
        double reaction = 0.0;  // the sheet pulls the top grip down
        for (int i : grip_) reaction -= f[i].y();
        return reaction / (width_ * thickness);
    }

private:
    double width_;
    std::vector<int> band_, grip_;
};

struct NewBreaks {
    double farthest = 0.0;                                      ///< largest |x| of their midpoints
    double shortest = std::numeric_limits<double>::infinity();  ///< rest length
};

/// The bonds that broke since `before` near the notch's line.
NewBreaks newBreaks(const Membrane& m, const std::vector<std::uint8_t>& before, double y) {
    const BondFamilies& bonds = m.bonds();
    const std::vector<std::uint8_t>& bondAlive = m.damageState().bondAlive();
    NewBreaks r;
    for (int i = 0; i < m.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            if (bondAlive[b] == before[b]) continue;
            const Eigen::Vector3d mid =
                0.5 * (m.restPositions()[i] + m.restPositions()[bonds.partners[b]]);
            if (std::abs(mid.y() - y) > m.horizon()) continue;
            r.farthest = std::max(r.farthest, std::abs(mid.x()));
            r.shortest = std::min(r.shortest, bonds.restLength[b]);
        }
    return r;
}

/// Steps until a bond beyond the notch breaks, and measures the far field then.
Onset firstBreak(Membrane& m, const FarField& farField, long maxSteps, double thickness) {
    Onset o;
    o.particles = m.particleCount();
    const std::size_t notched = m.notchedBondCount();
    for (long s = 0; s < maxSteps; ++s) {
        m.step();
        if (m.brokenBondCount() == notched) continue;
        o.grew = true;
        o.seconds = m.time();
        o.steps = m.stepCount();
        o.bandStress = farField.bandStress(m);
        o.reactionStress = farField.reactionStress(m, thickness);
        o.kineticShare = m.kineticEnergy() / m.strainEnergy();
        break;
    }
    return o;
}

/// Keeps pulling until a bond breaks at |x| >= `reach` near the notch's line, sampling the far
/// field every 20 steps (the band's stress costs a fifth of a step) for its peak.
void growCrack(Membrane& m, const FarField& farField, long maxSteps, double reach, double tip,
               double y, Onset& o) {
    std::vector<std::uint8_t> before = m.damageState().bondAlive();
    std::size_t brokenBefore = m.brokenBondCount();
    o.peakBandStress = o.bandStress;
    while (m.stepCount() < maxSteps && tip < reach) {
        m.step();
        if (m.stepCount() % 20 == 0)
            o.peakBandStress = std::max(o.peakBandStress, farField.bandStress(m));
        if (m.brokenBondCount() == brokenBefore) continue;
        brokenBefore = m.brokenBondCount();
        tip = std::max(tip, newBreaks(m, before, y).farthest);
        before = m.damageState().bondAlive();
    }
    if (tip < reach) return;
    o.grown = true;
    o.grownSeconds = m.time();
    o.grownBandStress = farField.bandStress(m);
}

}  // namespace

Onset pullCentreCrack(const CentreCrack& k) {
    const Plate plate = centreCrackedPlate(k);
    Membrane m(plate.params);
    const FarField farField(m, plate);
    const std::vector<std::uint8_t> notchedOnly = m.damageState().bondAlive();
    const long maxSteps = long(3.0 * plate.duration / m.timeStep());
    Onset o = firstBreak(m, farField, maxSteps, k.thickness);
    if (!o.grew || k.growth <= 0.0) return o;
    const NewBreaks first = newBreaks(m, notchedOnly, plate.notchY);
    o.firstBondLength = first.shortest / k.dx;
    growCrack(m, farField, maxSteps, halfLength(k) + k.growth, first.farthest, plate.notchY, o);
    return o;
}

}  // namespace rend::checks
