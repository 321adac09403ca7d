#include "tests/validation/checks/Hencky.h"

#include <cmath>
#include <vector>

#include "sim/Membrane.h"

namespace rend::checks {

using namespace rend::sim;

namespace {

struct Disc {
    MembraneParams params;
    double clamp;   ///< a_c
    double omega1;  ///< fundamental frequency of the tensioned membrane
};

Disc discParams(const DiscSpec& s) {
    Disc d;
    d.clamp = s.radius - 2.0 * s.dx;  // a ring 2 dx > delta = 1.5 dx thick is held
    const double kE = s.youngsModulus, kH = s.thickness, kRho = s.density;
    // Pressure for w0 / a_c = sag in Hencky's formula.
    const double load = s.load > 0 ? s.load : std::pow(s.sag / kHenckyC, 3) * kE * kH / d.clamp;
    MembraneParams& p = d.params;
    p.solver = s.solver;
    p.sheet.outline = Outline::Disc;
    p.sheet.radius = s.radius;
    p.sheet.dx = s.dx;
    p.sheet.thickness = kH;
    p.material.youngsModulus = kE;
    p.material.poissonRatio = s.poissonRatio;
    p.material.density = kRho;
    p.pressure = load;
    p.gravity = {0, 0, 0};
    const double n0 = 0.435 * std::cbrt(kE * kH * load * load * d.clamp * d.clamp);
    d.omega1 = 2.405 * std::sqrt(n0 / (kRho * kH)) / d.clamp;
    p.damping = 2.0 * d.omega1;
    p.time.duration = 1e9;
    return d;
}

double restRadius(const Membrane& m, int i) { return m.restPositions()[i].head<2>().norm(); }

/// Steps until the centre deflection moves by less than 1e-5 of itself over 1 / omega1 (the
/// slowest mode is about critically damped, so what is left is of the same order), holding the
/// particles outside a_c at rest after every step; returns the centre particle.
int settle(Membrane& m, const Disc& d) {
    std::vector<int> ring;
    int centre = 0;
    for (int i = 0; i < m.particleCount(); ++i) {
        if (restRadius(m, i) > d.clamp) ring.push_back(i);
        if (restRadius(m, i) < restRadius(m, centre)) centre = i;
    }
    const double check = 1.0 / d.omega1;
    double last = 0.0, nextCheck = check;
    while (m.time() < 200 * check) {
        m.step();
        for (int i : ring) {
            m.positions()[i] = m.restPositions()[i];
            m.velocities()[i].setZero();
        }
        if (m.time() >= nextCheck) {
            const double w = std::abs(m.positions()[centre].z());
            if (std::abs(w - last) < 1e-5 * w) break;
            last = w;
            nextCheck += check;
        }
    }
    return centre;
}

/// Fills `attached` and `lastFree` from the rest bonds that cross a_c.
void clampRadii(const Membrane& m, double clamp, Result& r) {
    double attached = 0.0, lastFree = 0.0;
    int nAttached = 0, nLastFree = 0;
    const auto& b = m.bonds();
    for (int i = 0; i < m.particleCount(); ++i) {
        const double ri = restRadius(m, i);
        bool across = false;
        for (int k = b.offsets[i]; k < b.offsets[i + 1]; ++k)
            across = across || (restRadius(m, b.partners[k]) > clamp) != (ri > clamp);
        if (!across) continue;
        if (ri > clamp)
            attached += ri, ++nAttached;
        else
            lastFree += ri, ++nLastFree;
    }
    r.attached = attached / nAttached;
    r.lastFree = lastFree / nLastFree;
}

}  // namespace

double henckyDeflection(double a, double load, double Eh) {
    return kHenckyC * a * std::cbrt(load * a / Eh);
}

Result clampedDisc(double radius, double dx, double sag) {
    DiscSpec spec;
    spec.radius = radius;
    spec.dx = dx;
    spec.sag = sag;
    return clampedDisc(spec);
}

Result clampedDisc(const DiscSpec& spec) {
    const Disc d = discParams(spec);
    Membrane m(d.params);
    const int centre = settle(m, d);
    Result r{};
    r.w0 = std::abs(m.positions()[centre].z() - m.restPositions()[centre].z());
    r.load = d.params.pressure;
    r.threshold = d.clamp;
    clampRadii(m, d.clamp, r);
    r.particles = m.particleCount();
    for (int i = 0; i < m.particleCount(); ++i) r.free += restRadius(m, i) <= d.clamp;
    r.settleTime = m.time();
    return r;
}

}  // namespace rend::checks
