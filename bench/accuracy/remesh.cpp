// Seed 004's remeshing (sim/Remesh.h) against its frequency: the spinning disc's loss of
// angular momentum over 4000 steps (checks/Mpm.h's spinningSheet(disc)), from remeshing every
// step to every 1000th; and never, the floor. Error: |L - L0| / L0.

#include <string>

#include "bench/accuracy/Report.h"
#include "tests/validation/checks/Mpm.h"

namespace rend::bench {
namespace {

void remeshCase(Report& report) {
    for (const char* solver : {"sph", "peridynamic"}) {
        Family f{"remesh", std::string("spinning disc ") + solver, {}, ""};
        for (const int every : {1, 10, 100, 1000, 0}) {
            const auto start = Clock::now();
            const checks::SpinFigures s = checks::spinningSheet(solver, 4000, {}, true, every);
            const Point p{every ? "every=" + std::to_string(every) : std::string("never"),
                          secondsSince(start), s.angularMomentumDrift};
            f.points.push_back(p);
            report.row(f, p);
        }
        f.why = "never remeshed, the solver keeps the angular momentum to round-off";
        report.checkMonotone(f);
    }
}

const CaseRegistration kRemesh{95, "remesh", &remeshCase};

}  // namespace
}  // namespace rend::bench
