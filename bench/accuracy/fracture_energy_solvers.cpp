// Fracture energy for every solver: the pulled, long-notched strip of checks/FractureEnergy.h at
// dx = 0.01, R = 1.5 dx, far end held, booked by the energy each step's breaking releases
// (checks/CrackRelease.h). Error |released per unit new crack length / G_f - 1|, swept in the
// time step (dt = 0.8, 0.4, 0.2 x the stable bound): a bond breaks at the first step that finds
// it past its critical strain, so the booking overshoots the calibration at first order in dt.
// A table gives, per solver and dt, G booked / G_f, over the window only, the onset strain over
// the strip's Griffith strain, the bonds broken off the line and at the grips, and the wall time.
// The FEM and the two-parameter springs break at bandCriticalStrain (sim/Membrane.h).

#include <cmath>
#include <string>

#include "bench/accuracy/Report.h"
#include "tests/validation/checks/CrackRelease.h"

namespace rend::bench {
namespace {

struct ReleasePoint {
    double seconds;
    checks::ReleaseRecord record;
    double ratio, window;
};

ReleasePoint releaseRun(std::string solver, double safety, double scale) {
    const auto start = Clock::now();
    checks::NotchedStrip s;
    s.solver = solver;
    s.holdFarEnd = true;
    s.timeStepSafety = safety;
    s.criticalStrainScale = scale;
    const double windowStart = s.notchTip + 5 * s.dx, windowEnd = 0.5 * s.width - 15 * s.dx;
    const checks::ReleaseRecord r = checks::runCrackRelease(s, windowStart, windowEnd);
    return {secondsSince(start), r, checks::releasedPerLength(s, r),
            r.reached ? checks::releasedPerLength(s, r, true) : NAN};
}

std::string tableRow(const std::string& label, double safety, const ReleasePoint& p) {
    const checks::ReleaseRecord& r = p.record;
    char line[200];
    std::snprintf(line, sizeof line, "# %-18s %5.1f %8.4f %8.4f %8.3f %6zu %6zu %6zu %8.2f %s",
                  label.c_str(), safety, p.ratio, p.window, r.strainAtStart, r.broken, r.offLine,
                  r.elsewhere, p.seconds, r.reached ? "" : "(did not run through)");
    return line;
}

void fractureEnergySolversCase(Report& report) {
    report.line("# solver              dt  G/G_f   window  onset/Gr  broken   off  grips  seconds");
    const double safeties[] = {0.8, 0.4, 0.2};
    for (std::string solver :
         {"peridynamic", "fem_cst", "mass_spring_vg", "mass_spring_tp", "sph"}) {
        Family f{"fracture_energy_solvers", std::string(solver.c_str()) + " dt sweep", {}, ""};
        std::string measured;
        // SPH gives no single crack at any dt and takes 40 s at 0.2 x the bound.
        const int count = solver == "sph" ? 1 : 3;
        for (int k = 0; k < count; ++k) {
            const ReleasePoint p = releaseRun(solver, safeties[k], 1.0);
            f.points.push_back(
                {"dt=" + fmt("%.1f", safeties[k]), p.seconds, std::abs(p.ratio - 1.0)});
            report.row(f, f.points.back());
            report.line(tableRow(solver.c_str(), safeties[k], p));
            measured += (measured.empty() ? "" : ", ") + fmt("%.4f", p.ratio);
        }
        f.why =
            "the booking tends to the solver's own calibration as dt falls, not to G_f: the "
            "bonds store their row share 0.907, the others about 1 (measured " +
            measured + " G_f)";
        report.checkMonotone(f);
    }
}

const CaseRegistration kFractureEnergySolvers{75, "fracture_energy_solvers",
                                              &fractureEnergySolversCase};

}  // namespace
}  // namespace rend::bench
