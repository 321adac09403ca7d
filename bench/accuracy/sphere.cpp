// Every solver against its own closed form on the pressurised sphere (checks/Sphere.h, the
// mass-spring paper's first case: E = 50 MPa, h = 1 mm): a dx sweep of the geodesic sphere.

#include "tests/validation/checks/Sphere.h"

#include <cmath>
#include <string>

#include "bench/accuracy/Report.h"

namespace rend::bench {
namespace {

void sphereCase(Report& report) {
    const std::pair<std::string, const char*> solvers[] = {{"fem_cst", "fem_cst"},
                                                           {"mass_spring_vg", "mass_spring_vg"},
                                                           {"mass_spring_tp", "mass_spring_tp"}};
    const checks::Material& mat = checks::kCases[0];
    for (const auto& [solver, name] : solvers) {
        Family f{"sphere", std::string(name) + " dx sweep", {}, ""};
        const double closed = checks::closedFormStretch(solver, mat);
        for (double dx : {0.2, 0.1, 0.05}) {
            const auto start = Clock::now();
            const checks::SphereResult r = checks::inflate(solver, mat, dx);
            f.points.push_back(
                {"dx=" + fmt("%g", dx), secondsSince(start), std::abs(r.stretch / closed - 1.0)});
            report.row(f, f.points.back());
        }
        // The FEM and the two-parameter springs are exact for any triangle shape and fall at
        // second order; Van Gelder's k is exact only for equilateral ones.
        f.why =
            "Van Gelder's springs reproduce the closed form only on equilateral triangles; the "
            "geodesic sphere's edges span a ratio of 1.19 at every resolution (0.1383..0.1646 "
            "at dx = 0.2, 0.0346..0.0413 at 0.05), so its error is the law's sensitivity to "
            "the mesh (the paper's Table 2), which refinement does not remove";
        report.checkMonotone(f);
    }
}

const CaseRegistration kSphere{90, "sphere", &sphereCase};

}  // namespace
}  // namespace rend::bench
