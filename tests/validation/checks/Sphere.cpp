#include "tests/validation/checks/Sphere.h"

#include <Eigen/Geometry>
#include <cmath>

#include "sim/Membrane.h"

namespace rend::checks {

using namespace rend::sim;

namespace {

double enclosedVolume(const Membrane& m) {
    double v = 0.0;
    const auto& x = m.positions();
    for (const auto& [a, b, c] : m.lattice().triangles) v += x[a].dot(x[b].cross(x[c])) / 6.0;
    return v;
}

double svkStretch(double k) { return 0.5 * (k + std::sqrt(k * k + 4)); }
double springStretch(double k) { return (1 - std::sqrt(1 - 2 * k)) / k; }

/// Van Gelder's eq. 1 per equilateral triangle, over E h.
double vanGelderTriangle() {
    return std::sqrt(3.0) / 4 / (1 + kNu) + kNu / (1 - kNu * kNu) / (2 * std::sqrt(3.0));
}

}  // namespace

SphereResult inflate(const std::string& solver, const Material& mat, double dx) {
    MembraneParams p;
    p.solver = solver;
    p.sheet.outline = Outline::Sphere;
    p.sheet.radius = kRadius;
    p.sheet.dx = dx;
    p.sheet.thickness = mat.h;
    p.material.youngsModulus = mat.E;
    p.material.poissonRatio = kNu;
    p.material.density = 1000;
    p.pressure = kPressure;
    // About critical for the breathing mode, omega^2 = 2 E / (rho R^2 (1 - nu)).
    const double omega =
        std::sqrt(2 * mat.E / (p.material.density * kRadius * kRadius * (1 - kNu)));
    p.damping = 2.0 * omega;
    Membrane m(p);
    const double v0 = enclosedVolume(m);
    double last = 0.0;
    for (int k = 0; k < 200000; ++k) {
        m.step();
        if (k % 200 == 0) {
            const double v = enclosedVolume(m);
            if (std::abs(v - last) < 1e-12 * v) break;
            last = v;
        }
    }
    SphereResult r{std::cbrt(enclosedVolume(m) / v0), 0, 0, m.particleCount()};
    for (int i = 0; i < m.particleCount(); ++i)
        (i < 12 ? r.fiveValent : r.sixValent) += m.positions()[i].norm() / kRadius;
    r.fiveValent /= 12;
    r.sixValent /= m.particleCount() - 12;
    return r;
}

double logStrainStretch(const Material& mat) {
    auto residual = [&](double l) {
        return mat.E / (1 - kNu) * std::log(l) * mat.h * std::pow(l, -2 * kNu / (1 - kNu)) -
               kPressure * kRadius * l / 2;
    };
    double lo = 1.0 + 1e-9, hi = 1.5;
    for (int k = 0; k < 200; ++k) {
        const double mid = 0.5 * (lo + hi);
        (residual(mid) > 0 ? hi : lo) = mid;
    }
    return 0.5 * (lo + hi);
}

double closedFormStretch(const std::string& solver, const Material& mat) {
    const double k = kPressure * kRadius * (1 - kNu) / (mat.E * mat.h);
    if (solver == "fem_cst" || solver == "mpm") return svkStretch(k);  // the FEM's forces
    if (solver == "mass_spring_vg")
        return springStretch(kPressure * kRadius /
                             (2 * std::sqrt(3.0) * vanGelderTriangle() * mat.E * mat.h));
    if (solver == "mass_spring_tp") return springStretch(k);
    return 0.0;
}

}  // namespace rend::checks
