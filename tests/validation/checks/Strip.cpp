#include "tests/validation/checks/Strip.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <memory>
#include <vector>

namespace rend::checks {

using namespace rend::sim;

namespace {

constexpr double kE = kStripModulus;
constexpr double kStrain = 1e-6;

// Minus the internal force at displacement u (2 dofs per particle), zero on fixed dofs: K u.
class Stiffness {
public:
    Stiffness(Membrane& m, std::vector<bool> fixed) : m_(m), fixed_(std::move(fixed)) {}

    std::vector<double> apply(const std::vector<double>& u) const {
        double scale = 0.0;
        for (double v : u) scale = std::max(scale, std::abs(v));
        std::vector<double> out(u.size(), 0.0);
        if (scale == 0.0) return out;
        const double unit = kStrain * m_.horizon() / scale;  // keep the solve in the linear range
        for (int i = 0; i < m_.particleCount(); ++i) {
            m_.positions()[i] = m_.restPositions()[i];
            m_.positions()[i].x() += unit * u[2 * i];
            m_.positions()[i].y() += unit * u[2 * i + 1];
        }
        std::vector<Eigen::Vector3d> f;
        m_.computeForces(f);
        for (int i = 0; i < m_.particleCount(); ++i)
            for (int a = 0; a < 2; ++a) out[2 * i + a] = fixed_[2 * i + a] ? 0.0 : -f[i][a] / unit;
        return out;
    }
    bool fixed(int dof) const { return fixed_[dof]; }

private:
    Membrane& m_;
    std::vector<bool> fixed_;
};

double dot(const std::vector<double>& a, const std::vector<double>& b) {
    double s = 0.0;
    for (std::size_t k = 0; k < a.size(); ++k) s += a[k] * b[k];
    return s;
}

// Solves K_ff u_f = -K_fp u_p by conjugate gradients; returns u with u_p in place.
std::vector<double> relax(const Stiffness& K, std::vector<double> u) {
    std::vector<double> r = K.apply(u);
    for (double& v : r) v = -v;
    std::vector<double> p = r;
    double rr = dot(r, r);
    const double tolerance = 1e-24 * std::max(rr, 1e-300);
    for (int it = 0; it < 20000 && rr > tolerance; ++it) {
        const std::vector<double> Kp = K.apply(p);
        const double alpha = rr / dot(p, Kp);
        for (std::size_t k = 0; k < u.size(); ++k) {
            u[k] += alpha * p[k];
            r[k] -= alpha * Kp[k];
        }
        const double next = dot(r, r);
        for (std::size_t k = 0; k < u.size(); ++k) p[k] = r[k] + next / rr * p[k];
        rr = next;
    }
    return u;
}

}  // namespace

MembraneParams stripParams(const Strip& s) {
    MembraneParams p;
    p.sheet.dx = s.dx;
    p.sheet.horizonFactor = s.horizonFactor;
    const double row = p.sheet.dx * std::sqrt(3.0) / 2;
    const double width = s.alongX ? (s.cells - 1) * row : (s.cells - 1) * p.sheet.dx;
    const double length = std::max(12.0 * width, 40 * p.sheet.dx);
    p.sheet.size = s.alongX ? Eigen::Vector2d(length, width) : Eigen::Vector2d(width, length);
    p.material.youngsModulus = kE;
    p.material.density = 1000;
    p.material.surfaceCorrection = s.surfaceCorrection;
    return p;
}

namespace {

/// The strip relaxed under its grips: displacements, the far grip's reaction, and where it lies.
struct StripSolution {
    std::unique_ptr<Membrane> m;
    std::vector<double> u;
    double reaction = 0.0, lo = 1e9, hi = -1e9;
    int axis = 0;
};

StripSolution solveStrip(const Strip& s, const MembraneParams& params) {
    StripSolution out{std::make_unique<Membrane>(params)};
    Membrane& m = *out.m;
    const int n = m.particleCount();
    const int axis = out.axis = s.alongX ? 0 : 1;
    for (const auto& x : m.restPositions()) {
        out.lo = std::min(out.lo, x[axis]);
        out.hi = std::max(out.hi, x[axis]);
    }
    const double grip = std::max(m.horizon(), 2 * params.sheet.dx) + 1e-9;
    std::vector<bool> fixed(2 * n, false);
    std::vector<double> u(2 * n, 0.0);
    int centre = 0;
    for (int i = 0; i < n; ++i) {
        const Eigen::Vector3d& x = m.restPositions()[i];
        if (x[axis] < out.lo + grip || x[axis] > out.hi - grip) {
            fixed[2 * i + axis] = true;
            u[2 * i + axis] = kStrain * x[axis];
        }
        if (x.head<2>().norm() < m.restPositions()[centre].head<2>().norm()) centre = i;
    }
    fixed[2 * centre + 1 - axis] = true;  // no rigid sliding across the strip
    const Stiffness K(m, fixed);
    out.u = relax(K, u);
    std::vector<Eigen::Vector3d> f;
    for (int i = 0; i < n; ++i) {
        m.positions()[i] = m.restPositions()[i];
        m.positions()[i].x() += out.u[2 * i];
        m.positions()[i].y() += out.u[2 * i + 1];
    }
    m.computeForces(f);
    for (int i = 0; i < n; ++i)
        if (m.restPositions()[i][axis] > out.hi - grip) out.reaction -= f[i][axis];
    return out;
}

/// The strain along the strip fitted by least squares over [from, to] of the rest axis.
double fittedStrain(const StripSolution& s, double from, double to) {
    double sx = 0, sy = 0, sxx = 0, sxy = 0, count = 0;
    for (int i = 0; i < s.m->particleCount(); ++i) {
        const double x = s.m->restPositions()[i][s.axis];
        if (x < from || x > to) continue;
        const double v = s.u[2 * i + s.axis];
        sx += x, sy += v, sxx += x * x, sxy += x * v, count += 1;
    }
    return (count * sxy - sx * sy) / (count * sxx - sx * sx);
}

/// The strip's cross-section h W, W counted in cells over whole lattice periods (dx along x;
/// two rows along y).
double crossSection(const Strip& s, const MembraneParams& params, const StripSolution& sol) {
    const double period = s.alongX ? params.sheet.dx : params.sheet.dx * std::sqrt(3.0);
    const int periods = int((sol.hi - sol.lo) / period);
    int inside = 0;
    for (const auto& x : sol.m->restPositions())
        if (x[sol.axis] < sol.lo + periods * period - 1e-9 * period) ++inside;
    return params.sheet.thickness * inside * params.sheet.dx * params.sheet.dx * std::sqrt(3.0) /
           2 / (periods * period);
}

}  // namespace

double stripModulus(const Strip& s) {
    const MembraneParams params = stripParams(s);
    const StripSolution sol = solveStrip(s, params);
    const double mid = 0.5 * (sol.lo + sol.hi), quarter = 0.25 * (sol.hi - sol.lo);
    const double strainMid = fittedStrain(sol, mid - quarter, mid + quarter);
    return sol.reaction / (crossSection(s, params, sol) * strainMid) / kE;
}

BimaterialFigures bimaterialStrip(double softFactor, const std::string& solver) {
    // The FEM has no missing bonds at the edges, so no surface correction to take.
    const Strip s{true, 20, 1.5, solver == "peridynamic"};
    MembraneParams params = stripParams(s);
    params.solver = solver;
    MaterialMap soft;
    soft.property = MappedProperty::YoungsModulus;
    soft.shape = MapShape::Box;
    soft.min = {0.0, -1e3};
    soft.max = {1e3, 1e3};
    soft.factor = softFactor;
    params.materialMaps = {soft};
    const StripSolution sol = solveStrip(s, params);
    // Each half's strain away from its grip and from the interface (x = 0).
    const double half = 0.5 * (sol.hi - sol.lo), margin = 0.25 * half;
    const double stiff = fittedStrain(sol, sol.lo + margin, -margin);
    const double weak = fittedStrain(sol, margin, sol.hi - margin);
    const double stress = sol.reaction / crossSection(s, params, sol);
    return {stress / stiff / kE, stress / weak / (softFactor * kE)};
}

SkinFigures skin(bool alongX, double horizonFactor, bool corrected) {
    const int cells = int(std::lround(5 * horizonFactor));
    const double narrow = stripModulus({alongX, cells, horizonFactor, corrected});
    const double wide = stripModulus({alongX, 2 * cells, horizonFactor, corrected});
    const double interior = 2 * wide - narrow;  // E(N) = E_inf (1 - 2 d / N)
    return {narrow, 1 - (interior - narrow) * cells / 2 / interior, interior};
}

}  // namespace rend::checks
