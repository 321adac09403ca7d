// Run time against error (../shared/VALIDATION.md, "Run time against error"): each check that
// has a closed-form answer is swept from coarse to fine (R/dx, dx, dt, integrator) and printed
// as CSV rows `case,setting,wall_seconds,error`, so a user can pick the cheapest setting that
// meets a tolerance. A setting is "family/label": scripts/plot_bench.py draws one line per
// family. Where the error does not fall monotonically within a family, a `# note:` line says why.
//
//   bench_accuracy [out.csv] [--only CASE]   (stdout always; the file too when given)

#include <omp.h>

#include <Eigen/Dense>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <numbers>
#include <string>
#include <vector>

#include "bench/accuracy/Report.h"
#include "sim/Membrane.h"
#include "tests/sim/Peridynamic.h"

using namespace rend::sim;
using namespace rend::bench;

namespace {

// ---- patch: interior E_eff at strain 1e-4 ---------------------------------------------------

/// In-plane stiffness (Voigt xx, yy, xy) of particle i from the virial stress under three
/// affine strains of size e, as the PatchTest suite measures it.
Eigen::Matrix3d voigtStiffness(Membrane& m, int i, double e) {
    Eigen::Matrix3d C;
    const Eigen::Vector3d strains[3] = {{e, 0, 0}, {0, e, 0}, {0, 0, e}};  // exx, eyy, 2exy
    for (int k = 0; k < 3; ++k) {
        Eigen::Matrix3d F = Eigen::Matrix3d::Identity();
        F(0, 0) += strains[k][0];
        F(1, 1) += strains[k][1];
        F(0, 1) += 0.5 * strains[k][2];
        F(1, 0) += 0.5 * strains[k][2];
        for (int p = 0; p < m.particleCount(); ++p) m.positions()[p] = F * m.restPositions()[p];
        const Eigen::Matrix3d s = rend::test::particleStress(m, i);
        C.col(k) = Eigen::Vector3d(s(0, 0), s(1, 1), s(0, 1)) / e;
    }
    return C;
}

/// Young's modulus for uniaxial stress along angle phi, from the compliance C^-1.
double directionalModulus(const Eigen::Matrix3d& C, double phi) {
    const double c = std::cos(phi), s = std::sin(phi);
    const Eigen::Vector3d stress(c * c, s * s, c * s);
    return 1.0 / stress.dot(C.inverse() * stress);
}

struct PatchResult {
    double seconds;
    double error;
};

/// Builds a 0.6 m sheet at dx = 0.02 and measures its centre particle: the worst |E(phi)/E - 1|
/// over directions 0..90 degrees, where anisotropy shows up away from the axes.
PatchResult patchRun(LatticeKind lattice, double factor, double strain) {
    const auto start = Clock::now();
    const double E = 2e4;
    MembraneParams p;
    p.sheet.size = {0.6, 0.6};
    p.sheet.dx = 0.02;
    p.sheet.lattice = lattice;
    p.sheet.horizonFactor = factor;
    p.material.youngsModulus = E;
    Membrane m(p);
    const int centre = m.nearestParticle({0, 0});
    Eigen::Matrix3d C = voigtStiffness(m, centre, strain);
    // The secant modulus at +strain differs from the tangent by O(strain); averaging with
    // -strain (a central difference) removes that, showing the lattice's own error.
    if (strain < 0.0) C = 0.5 * (C + voigtStiffness(m, centre, -strain));
    double worst = 0.0;
    for (int deg = 0; deg <= 90; deg += 5)
        worst = std::max(worst,
                         std::abs(directionalModulus(C, deg * std::numbers::pi / 180.0) / E - 1.0));
    return {secondsSince(start), worst};
}

void patchCase(Report& report) {
    for (LatticeKind lattice : {LatticeKind::Hexagonal, LatticeKind::Square}) {
        const bool hexagonal = lattice == LatticeKind::Hexagonal;
        Family f{"patch", hexagonal ? "hexagonal" : "square", {}, ""};
        std::string central;
        for (double factor : {1.5, 2.0, 3.0}) {
            const auto [seconds, error] = timed([&] { return patchRun(lattice, factor, 1e-4); });
            f.points.push_back({"R=" + fmt("%.1f", factor) + "dx", seconds, error});
            report.row(f, f.points.back());
            central += " " + fmt("%.1e", patchRun(lattice, factor, -1e-4).error);
        }
        f.why = hexagonal
                    ? "each shell of the hexagonal lattice has 6-fold symmetry, so its bond "
                      "tensor is isotropic at any R, and c is calibrated on the interior sum; "
                      "what is left is the O(strain) geometric nonlinearity of a secant modulus "
                      "at strain 1e-4 (measured at +-1e-4 the error is" +
                          central + " for R/dx = 1.5 2 3). Refining R/dx only costs time"
                    : "a square lattice's bond tensor has only cubic symmetry";
        report.checkMonotone(f);
    }
}

// ---- wave: P-wave speed sqrt(E / (rho (1 - nu^2))), nu = 1/3 --------------------------------

struct WaveSetup {
    double dx = 0.02;
    double dtFraction = 0.8;  ///< of the Silling-Askari bound
    Integrator integrator = Integrator::SymplecticEuler;
    std::string solver = "peridynamic";
    double poissonRatio = 1.0 / 3.0;  ///< the bonds' own; the other solvers take any
};

struct WaveResult {
    double seconds;
    double speed;
};

/// Time of the largest sample, refined by a parabola through the logarithms of the three samples
/// around it: exact for a Gaussian peak, so coarse time steps do not bias the arrival.
double peakTime(const std::vector<double>& u, double dt) {
    std::size_t k = 1;
    for (std::size_t s = 1; s + 1 < u.size(); ++s)
        if (u[s] > u[k]) k = s;
    const double a = std::log(u[k - 1]), b = std::log(u[k]), c = std::log(u[k + 1]);
    return (double(k) + 0.5 * (a - c) / (a - 2.0 * b + c)) * dt;
}

/// A Gaussian pulse of u_x, uniform in y, released at rest in a sheet wide enough (2 m) that the
/// free top and bottom edges' relief does not reach the centre line before the pulse has passed
/// both probes: there the sheet is laterally constrained, the plane-stress P-wave. The speed is
/// distance over time between the peaks at two probes, so the start-up split into two halves
/// cancels out.
WaveResult waveRun(const WaveSetup& w) {
    const auto start = Clock::now();
    const double E = 2e4, rho = 5000.0;
    MembraneParams p;
    p.sheet.size = {1.6, 2.0};
    p.sheet.dx = w.dx;
    p.material.youngsModulus = E;
    p.material.density = rho;
    p.time.integrator = w.integrator;
    p.solver = w.solver;
    p.material.poissonRatio = w.poissonRatio;
    Membrane probe(p);  // only for the stable bound, which depends on the lattice alone
    p.time.dt = w.dtFraction * probe.stableTimeStep();
    Membrane m(p);
    const double centre = -0.4, width = 0.06, amplitude = 1e-6;  // strain ~2e-5: linear
    for (int i = 0; i < m.particleCount(); ++i) {
        const double s = (m.restPositions()[i].x() - centre) / width;
        m.positions()[i].x() += amplitude * std::exp(-0.5 * s * s);
    }
    const int near = m.nearestParticle({-0.1, 0.0}), far = m.nearestParticle({0.4, 0.0});
    std::vector<double> uNear{0.0}, uFar{0.0};  // sample k is at t = k dt
    // The reflection off the left end reaches the near probe at ~0.52 s: stop before it.
    const long steps = long(std::ceil(0.45 / *p.time.dt));
    const Membrane& view = m;  // the writable positions() would make Verlet redo its forces
    for (long s = 0; s < steps; ++s) {
        m.step();
        uNear.push_back(view.positions()[near].x() - view.restPositions()[near].x());
        uFar.push_back(view.positions()[far].x() - view.restPositions()[far].x());
    }
    const double distance = m.restPositions()[far].x() - m.restPositions()[near].x();
    const double speed = distance / (peakTime(uFar, *p.time.dt) - peakTime(uNear, *p.time.dt));
    return {secondsSince(start), speed};
}

void waveCase(Report& report) {
    const double cp = std::sqrt(2e4 / (5000.0 * (1.0 - 1.0 / 9.0)));
    const std::pair<Integrator, const char*> integrators[] = {
        {Integrator::SymplecticEuler, "euler"}, {Integrator::VelocityVerlet, "verlet"}};
    for (const auto& [integrator, name] : integrators) {
        Family f{"wave", std::string("dx sweep ") + name + " dt=0.8dtc", {}, ""};
        for (double dx : {0.04, 0.02, 0.01, 0.005}) {
            const WaveResult r = timed([&] { return waveRun({dx, 0.8, integrator}); });
            f.points.push_back({"dx=" + fmt("%g", dx), r.seconds, std::abs(r.speed / cp - 1.0)});
            report.row(f, f.points.back());
        }
        f.why =
            "unexpected: the dispersion of the lattice and of the nonlocal bond both fall "
            "as (k dx)^2";
        report.checkMonotone(f);
    }
    for (const auto& [integrator, name] : integrators) {
        Family f{"wave", std::string("dt sweep ") + name + " dx=0.02", {}, ""};
        std::vector<double> speeds;
        for (double fraction : {0.8, 0.4, 0.2, 0.1}) {
            const WaveResult r = timed([&] { return waveRun({0.02, fraction, integrator}); });
            speeds.push_back(r.speed);
            f.points.push_back(
                {"dt=" + fmt("%g", fraction) + "dtc", r.seconds, std::abs(r.speed / cp - 1.0)});
            report.row(f, f.points.back());
        }
        // Both schemes advance positions by x+ - 2x + x- = dt^2 a (the central difference), whose
        // phase speed is sin(w dt / 2) / (dt / 2) = w_h(k): faster than the lattice's own w_h,
        // which is slower than c k. Shrinking dt removes the time error that was cancelling part
        // of the spatial one.
        f.why =
            "the pulse runs slower than c_p (the lattice and the nonlocal bond are "
            "dispersive) and the central-difference time error runs faster, so a large dt "
            "cancels part of the spatial error; as dt -> 0 the error rises to the spatial "
            "error at dx=0.02 (speed " +
            fmt("%.5f", speeds.front() / cp) + " c_p at 0.8 dtc, " +
            fmt("%.5f", speeds.back() / cp) + " c_p at 0.1 dtc). Refine dx, not dt";
        report.checkMonotone(f);
    }
    // Every solver against its own plane-stress P-wave speed sqrt(E / (rho (1 - nu^2))), nu = 0.3.
    const std::pair<std::string, const char*> solvers[] = {{"fem_cst", "fem_cst"},
                                                           {"mass_spring_vg", "mass_spring_vg"},
                                                           {"mass_spring_tp", "mass_spring_tp"},
                                                           {"sph", "sph"}};
    const double cp3 = std::sqrt(2e4 / (5000.0 * (1.0 - 0.09)));
    for (const auto& [solver, name] : solvers) {
        Family f{"wave", std::string("dx sweep ") + name + " nu=0.3", {}, ""};
        for (double dx : {0.04, 0.02, 0.01}) {
            const WaveResult r = timed([&] {
                return waveRun({dx, 0.8, Integrator::SymplecticEuler, solver, 0.3});
            });
            f.points.push_back({"dx=" + fmt("%g", dx), r.seconds, std::abs(r.speed / cp3 - 1.0)});
            report.row(f, f.points.back());
        }
        f.why = solver == "mass_spring_vg"
                    ? "a central-spring network has nu = 1/3 whatever k is: Van Gelder's k at "
                      "nu = 0.3 (0.8566 E h per spring) makes a network of modulus 0.9891 E "
                      "and nu = 1/3, whose P-wave is 0.63% faster than the continuum's at "
                      "0.3; the lattice's dispersion, slower and shrinking as dx^2, crosses it"
                    : "unexpected for a solver that carries nu = 0.3";
        report.checkMonotone(f);
    }
}

// ---- diffusion: 1D erfc profile from an edge held at theta = 1 ------------------------------

struct DiffusionResult {
    double seconds;
    double error;
};

/// A 0.8 m wide, 0.6 m long strip at theta = 0 whose bottom row is held at 1, compared at t =
/// 0.25 s with erfc(y / (2 sqrt(D t))), D = k / (rho C) = 0.01 m^2/s: the far end is 6 diffusion
/// lengths away, a semi-infinite domain. The bottom row is straight on both lattices (the
/// hexagonal one's left and right edges zig-zag), so theta = 1 sits exactly at y_min. The error
/// is the relative L2 norm over free particles with |x| <= 0.1: the insulated sides' missing
/// bonds slow diffusion along them, an O(dx) error that spreads inwards like theta itself and
/// would otherwise dominate (erfc(3) ~ 2e-5 of it reaches |x| = 0.1).
DiffusionResult diffusionRun(LatticeKind lattice, double dx, double dtFraction) {
    const auto start = Clock::now();
    MembraneParams p;
    p.sheet.size = {0.8, 0.6};
    p.sheet.dx = dx;
    p.sheet.lattice = lattice;
    // A soft, heavy sheet: the mechanics (idle here, nothing strains it) has a stable step far
    // above the diffusion's.
    p.material.youngsModulus = 1.0;
    p.material.density = 1000.0;
    p.material.capacity = 1e-3;
    p.material.conductivity = 1e-2;
    const double D = p.material.conductivity / (p.material.density * p.material.capacity);
    p.diffusion.initial = 1e-300;  // switches diffusion on for the probe below
    Membrane probe(p);
    double yMin = 0.0;
    for (const auto& x : probe.restPositions()) yMin = std::min(yMin, x.y());
    DiffusionEdge edge;
    edge.region.max.y() = yMin + 1e-9 * dx;
    p.diffusion.initial = 0.0;
    p.diffusion.edges = {edge};
    // The mechanics step is dtFraction of the diffusion bound, rounded down to divide the
    // duration; diffusion sub-steps only above 0.9 of its bound, so below that it takes this
    // step as is.
    const double duration = 0.25;
    const long steps =
        long(std::ceil(duration / (dtFraction * probe.diffusion()->stableTimeStep())));
    p.time.dt = duration / double(steps);
    Membrane m(p);
    for (long s = 0; s < steps; ++s) m.step();
    double diff2 = 0.0, ref2 = 0.0;
    for (int i = 0; i < m.particleCount(); ++i) {
        const Eigen::Vector3d& x = m.restPositions()[i];
        if (std::abs(x.x()) > 0.1 || edge.region.contains(x)) continue;
        const double exact = std::erfc((x.y() - yMin) / (2.0 * std::sqrt(D * m.time())));
        diff2 += std::pow(m.theta()[i] - exact, 2);
        ref2 += exact * exact;
    }
    return {secondsSince(start), std::sqrt(diff2 / ref2)};
}

void diffusionCase(Report& report) {
    for (LatticeKind lattice : {LatticeKind::Hexagonal, LatticeKind::Square}) {
        const char* name = lattice == LatticeKind::Square ? "square" : "hexagonal";
        Family f{"diffusion", std::string("dx sweep ") + name + " dt=0.9dtc", {}, ""};
        for (double dx : {0.04, 0.02, 0.01, 0.005}) {
            const auto [seconds, error] = timed([&] { return diffusionRun(lattice, dx, 0.9); });
            f.points.push_back({"dx=" + fmt("%g", dx), seconds, error});
            report.row(f, f.points.back());
        }
        f.why = "unexpected: the sweep refines dx and dt together (dt ~ dx^2 at the bound)";
        report.checkMonotone(f);
    }
    for (LatticeKind lattice : {LatticeKind::Hexagonal, LatticeKind::Square}) {
        const char* name = lattice == LatticeKind::Square ? "square" : "hexagonal";
        Family f{"diffusion", std::string("dt sweep ") + name + " dx=0.01", {}, ""};
        for (double fraction : {0.9, 0.45, 0.225, 0.1125}) {
            const auto [seconds, error] =
                timed([&] { return diffusionRun(lattice, 0.01, fraction); });
            f.points.push_back({"dt=" + fmt("%g", fraction) + "dtc", seconds, error});
            report.row(f, f.points.back());
        }
        // Forward Euler's time error (-D^2 dt/2 d4theta) and the spatial one (+D dx^2/12 d4theta
        // in 1D) have opposite signs, so shrinking dt alone only approaches this dx's error.
        f.why =
            "the time error of forward Euler vanishes and what is left is the spatial error "
            "of dx=0.01: refine dx, not dt";
        report.checkMonotone(f);
    }
}

}  // namespace

int main(int argc, char** argv) {
    std::string only, csv;  // bench_accuracy [out.csv] [--only CASE]
    for (int k = 1; k < argc; ++k) {
        if (std::string(argv[k]) == "--only" && k + 1 < argc)
            only = argv[++k];
        else
            csv = argv[k];
    }
    // One thread: wall times then compare settings fairly even on a shared machine, where
    // spinning OpenMP threads that lose their core make multi-threaded timings erratic.
    omp_set_num_threads(1);
    const auto start = Clock::now();
    Report report;
    report.line("case,setting,wall_seconds,error");
    // Wall times are only comparable on an idle machine: say how busy it was.
    report.line("# 1 thread; load average at start " + loadAverage());
    std::vector<CaseEntry> cases = {
        {10, "patch", &patchCase}, {20, "wave", &waveCase}, {30, "diffusion", &diffusionCase}};
    cases.insert(cases.end(), registeredCases().begin(), registeredCases().end());
    std::sort(cases.begin(), cases.end(),
              [](const CaseEntry& a, const CaseEntry& b) { return a.order < b.order; });
    for (const CaseEntry& c : cases)
        if (only.empty() || only == c.name) c.run(report);
    report.line("# total wall time " + fmt("%.1f", secondsSince(start)) +
                " s, load average at end " + loadAverage());
    if (!csv.empty()) {
        std::ofstream out(csv);
        out << report.text();
        if (!out) {
            std::fprintf(stderr, "error: cannot write %s\n", csv.c_str());
            return 1;
        }
    }
    return 0;
}
