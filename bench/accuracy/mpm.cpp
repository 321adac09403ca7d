// The MPM solver (issue 15, checks/Mpm.h) against refinement, beside the FEM whose lattice
// forces it uses: the P wave's speed over c_p at nu = 0.3 (dx = 0.04, 0.02, 0.01), and the
// jerked bimaterial strip's largest displacement difference from the FEM's run (dx = 0.04,
// 0.02, 0.01). Errors: |speed / c_p - 1| and max |u - u_fem| / max |u_fem|.

#include "tests/validation/checks/Mpm.h"

#include <cmath>
#include <string>

#include "bench/accuracy/Report.h"

namespace rend::bench {
namespace {

void mpmCase(Report& report) {
    for (const char* solver : {"mpm", "fem_cst"}) {
        Family f{"mpm", std::string("wave ") + solver, {}, ""};
        for (const double dx : {0.04, 0.02, 0.01}) {
            const auto start = Clock::now();
            const checks::WaveFigures w = checks::planeWave(solver, dx, 0.3);
            const Point p{"dx=" + fmt("%g", dx), secondsSince(start),
                          std::abs(w.speedOverCp - 1.0)};
            f.points.push_back(p);
            report.row(f, p);
        }
        f.why =
            "the arrival is read at half the driving velocity on a front ramped over 10 "
            "horizons: its dispersion shifts the measured speed by about 1% either way";
        report.checkMonotone(f);
    }
    for (const bool enrich : {true, false}) {
        Family f{"mpm", std::string("bimaterial jerk vs fem") + (enrich ? "" : " plain"), {}, ""};
        sim::MpmParams mpm;
        mpm.enrich = enrich;
        for (const double dx : {0.04, 0.02, 0.01}) {
            const auto start = Clock::now();
            const checks::PullFigures pull = checks::pulledBimaterial("mpm", dx, mpm, true);
            const Point p{"dx=" + fmt("%g", dx), secondsSince(start), pull.worstDifference};
            f.points.push_back(p);
            report.row(f, p);
        }
        f.why = "the grid's smoothing of the waves crossing the strip shrinks with its spacing";
        report.checkMonotone(f);
    }
}

const CaseRegistration kMpm{90, "mpm", &mpmCase};

}  // namespace
}  // namespace rend::bench
