// VALIDATION.md, "rigid translation + rotation: zero internal force, <= 1e-12 relative", for every
// bond law, with diffusion strain and the surface correction on.

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "sim/Membrane.h"
#include "tests/sim/Peridynamic.h"

using namespace rend::sim;

TEST(Validation, RigidMotionGivesZeroForceForEveryLaw) {
    for (BondLawKind law :
         {BondLawKind::Linear, BondLawKind::PowerLaw, BondLawKind::Elastoplastic}) {
        MembraneParams p;
        p.sheet.size = {0.4, 0.4};
        p.sheet.dx = 0.02;
        p.material.law = law;
        p.material.surfaceCorrection = true;
        p.material.expansion = 0.1;
        p.diffusion.initial = 0.3;  // uniform theta: a uniform free expansion, then a rigid motion
        Membrane m(p);
        const Eigen::Matrix3d R =
            Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -1.0, 0.5).normalized()).toRotationMatrix();
        for (int i = 0; i < m.particleCount(); ++i)
            m.positions()[i] = R * (1.03 * m.restPositions()[i]) + Eigen::Vector3d(1, 2, 3);
        std::vector<Eigen::Vector3d> f;
        m.computeForces(f);
        double worst = 0.0;
        for (const auto& fi : f) worst = std::max(worst, fi.norm());
        const double unit = rend::test::micromodulus(m) * m.volumes()[0] * m.volumes()[0] / 0.03;
        EXPECT_LE(worst / unit, 1e-12) << "law " << int(law);
    }
}
