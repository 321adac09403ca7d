// Issue 15's material maps (sim/MaterialMap.h): each shape's factor field, and a map that
// changes only the property it names.

#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "sim/Diffusion.h"
#include "sim/Fracture.h"
#include "sim/MaterialMap.h"
#include "sim/Membrane.h"
#include "sim/SolverRegistry.h"
#include "sim/TotalLagrangianSph.h"
#include "tests/sim/Peridynamic.h"

using namespace rend::sim;

namespace {

std::vector<Eigen::Vector3d> grid(int n, double spacing) {
    std::vector<Eigen::Vector3d> points;
    for (int i = 0; i < n; ++i)
        for (int j = 0; j < n; ++j) points.emplace_back(i * spacing, j * spacing, 0.0);
    return points;
}

MaterialMap region(MapShape shape, double factor) {
    MaterialMap m;
    m.shape = shape;
    m.factor = factor;
    return m;
}

MembraneParams sheet() {
    MembraneParams p;
    p.sheet.size = {0.4, 0.2};
    p.sheet.dx = 0.02;
    p.material.fractureEnergy = 1.0;
    return p;
}

}  // namespace

TEST(MaterialMap, RegionsScaleInsideAndLeaveOutsideAlone) {
    const std::vector<Eigen::Vector3d> points{{0.1, 0.1, 0}, {0.5, 0.5, 0}, {0.9, 0.2, 0}};
    MaterialMap box = region(MapShape::Box, 3.0);
    box.min = {0.0, 0.0}, box.max = {0.6, 0.6};
    MaterialMap disc = region(MapShape::Disc, 0.5);
    disc.center = {0.9, 0.2}, disc.radius = 0.05;
    MaterialMap triangle = region(MapShape::Polygon, 2.0);
    triangle.polygon = {{0.0, 0.0}, {0.3, 0.0}, {0.0, 0.3}};
    const std::vector<MaterialMap> maps{box, disc, triangle};
    EXPECT_EQ(materialFactors(MappedProperty::YoungsModulus, maps, points),
              (std::vector<double>{6.0, 3.0, 0.5}))
        << "maps of one property multiply";
    EXPECT_EQ(materialFactors(MappedProperty::Density, maps, points), (std::vector<double>(3, 1.0)))
        << "no map of density";
}

TEST(MaterialMap, NoiseIsSeededBoundedAndStretchedAlongItsLongCells) {
    const std::vector<Eigen::Vector3d> points = grid(40, 0.01);
    MaterialMap noise;
    noise.shape = MapShape::Noise;
    noise.amplitude = 0.6;
    noise.scale = {0.2, 0.02};  // fibres along x
    const std::vector<MaterialMap> maps{noise};
    const std::vector<double> a = materialFactors(MappedProperty::YoungsModulus, maps, points);
    EXPECT_EQ(a, materialFactors(MappedProperty::YoungsModulus, maps, points)) << "seeded";
    const auto [low, high] = std::minmax_element(a.begin(), a.end());
    EXPECT_GE(*low, 0.4);
    EXPECT_LE(*high, 1.6);
    EXPECT_GT(*high - *low, 0.4) << "it varies";
    // Neighbours along the fibres differ far less than across them.
    double along = 0, across = 0;
    for (int i = 0; i + 1 < 40; ++i)
        for (int j = 0; j + 1 < 40; ++j) {
            along += std::abs(a[(i + 1) * 40 + j] - a[i * 40 + j]);
            across += std::abs(a[i * 40 + j + 1] - a[i * 40 + j]);
        }
    EXPECT_LT(3 * along, across);
    std::vector<MaterialMap> reseeded = maps;
    reseeded[0].seed = 2;
    EXPECT_NE(a, materialFactors(MappedProperty::YoungsModulus, reseeded, points));
}

TEST(MaterialMap, AnImageSpansTheRestBoundsLowInBlackHighInWhite) {
    MaterialMap image;
    image.property = MappedProperty::Density;
    image.shape = MapShape::Image;
    image.low = 0.5, image.high = 2.0;
    image.image = {2, 2, {0.0f, 1.0f, 1.0f, 1.0f}};  // top-left black
    const std::vector<Eigen::Vector3d> points{{0, 1, 0}, {1, 1, 0}, {0, 0, 0}, {1, 0, 0}};
    EXPECT_EQ(materialFactors(MappedProperty::Density, std::vector<MaterialMap>{image}, points),
              (std::vector<double>{0.5, 2.0, 2.0, 2.0}));
}

// A density map changes the masses and nothing of the bonds; an E map the bonds' stiffness
// and critical stretch (as sqrt(G_f / E)) and not the masses; a fracture-energy map only the
// critical stretch.
TEST(MaterialMap, AMapChangesOnlyWhatItNames) {
    const Membrane plain(sheet());
    const auto withMap = [](MappedProperty property) {
        MembraneParams p = sheet();
        MaterialMap m = region(MapShape::Box, 4.0);
        m.property = property;
        m.min = {0.0, -1.0}, m.max = {1.0, 1.0};  // x >= 0
        p.materialMaps = {m};
        return p;
    };
    const Membrane dense(withMap(MappedProperty::Density)),
        stiff(withMap(MappedProperty::YoungsModulus)),
        tough(withMap(MappedProperty::FractureEnergy));
    std::vector<Eigen::Vector3d> f0, f;
    Membrane pulled(sheet()), pulledStiff(withMap(MappedProperty::YoungsModulus)),
        pulledDense(withMap(MappedProperty::Density));
    for (Membrane* m : {&pulled, &pulledStiff, &pulledDense})
        for (int i = 0; i < m->particleCount(); ++i)
            m->positions()[i].x() = 1.001 * m->restPositions()[i].x();
    pulled.computeForces(f0);
    pulledDense.computeForces(f);
    EXPECT_EQ(f, f0) << "density leaves the forces";
    pulledStiff.computeForces(f);
    for (int i = 0; i < plain.particleCount(); ++i) {
        const double x = plain.restPositions()[i].x();
        const double ratio = dense.masses()[i] / plain.masses()[i];
        EXPECT_DOUBLE_EQ(ratio, x >= 0 ? 4.0 : 1.0) << i;
        EXPECT_EQ(stiff.masses()[i], plain.masses()[i]);
        EXPECT_EQ(tough.masses()[i], plain.masses()[i]);
        if (x > 0.05) EXPECT_NEAR(f[i].norm(), 4.0 * f0[i].norm(), 1e-9 * f0[i].norm() + 1e-18);
        if (x < -0.05) EXPECT_NEAR(f[i].norm(), f0[i].norm(), 1e-12 + 1e-9 * f0[i].norm());
    }
    EXPECT_LT(stiff.stableTimeStep(), plain.stableTimeStep());
    EXPECT_NEAR(dense.stableTimeStep(), plain.stableTimeStep(), 1e-9 * plain.stableTimeStep())
        << "heavier particles on one side: the lighter side still sets the step";
    EXPECT_EQ(rend::test::criticalStretch(tough), rend::test::criticalStretch(plain))
        << "the reference is the material's; the map scales each bond";
}

// A fracture-energy map scales each bond's critical stretch by sqrt(G_f): stretched to 1.5 times
// the material's, the plain side breaks and the side four times as tough (twice the stretch)
// holds.
namespace {

/// Bonds broken on each side of x = 0 after one step of the sheet stretched isotropically to
/// `stretch` with the right half four times as tough.
std::pair<int, int> brokenEachSide(MembraneParams p, double stretch) {
    p.time.dt = 1e-9;
    MaterialMap tough = region(MapShape::Box, 4.0);
    tough.property = MappedProperty::FractureEnergy;
    tough.min = {0.0, -1.0}, tough.max = {1.0, 1.0};
    p.materialMaps = {tough};
    Membrane m(p);
    for (int i = 0; i < m.particleCount(); ++i)
        m.positions()[i] = (1.0 + stretch) * m.restPositions()[i];
    m.step();
    const BondFamilies& bonds = m.bonds();
    std::pair<int, int> broken{0, 0};
    for (int i = 0; i < m.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const int j = bonds.partners[b];
            const bool gone = !m.damageState().bondAlive()[std::size_t(b)];
            const double xi = m.restPositions()[i].x(), xj = m.restPositions()[j].x();
            if (xi < -0.03 && xj < -0.03) broken.first += gone;
            if (xi > 0.03 && xj > 0.03) broken.second += gone;
        }
    return broken;
}

}  // namespace

// The FEM's elements take the map too: each element's critical strain by its corners'.
TEST(MaterialMap, TheFemsToughSideHoldsWhereThePlainSideBreaks) {
    MembraneParams p = sheet();
    p.solver = "fem_cst";
    const auto [left, right] = brokenEachSide(p, 1.5 * bandCriticalStrain(p));
    EXPECT_GT(left, 0);
    EXPECT_EQ(right, 0);
}

// And the SPH's pairs, each by its two ends.
TEST(MaterialMap, TheSphsToughSideHoldsWhereThePlainSideBreaks) {
    MembraneParams p = sheet();
    p.solver = "sph";
    const double strain =
        sphCriticalStrain(*p.material.fractureEnergy, p.material.youngsModulus, p.sheet.dx);
    const auto [left, right] = brokenEachSide(p, 1.5 * strain);
    EXPECT_GT(left, 0);
    EXPECT_EQ(right, 0);
}

// And the springs of both mass-spring models, each by its two ends.
TEST(MaterialMap, TheSpringsToughSideHoldsWhereThePlainSideBreaks) {
    for (const char* solver : {"mass_spring_vg", "mass_spring_tp"}) {
        MembraneParams p = sheet();
        p.solver = solver;
        const double strain = std::string(solver) == "mass_spring_vg" ? springCriticalStrain(p)
                                                                      : bandCriticalStrain(p);
        const auto [left, right] = brokenEachSide(p, 1.5 * strain);
        EXPECT_GT(left, 0) << solver;
        EXPECT_EQ(right, 0) << solver;
    }
}

// An E map stiffens the springs' side: the two-parameter model's triangles and Van Gelder's
// springs both pull four times as hard where E is four times the material's.
TEST(MaterialMap, TheSpringsTakeAnEMap) {
    for (const char* solver : {"mass_spring_vg", "mass_spring_tp"}) {
        MembraneParams plainParams = sheet();
        plainParams.solver = solver;
        MembraneParams stiffParams = plainParams;
        MaterialMap stiff = region(MapShape::Box, 4.0);
        stiff.min = {0.0, -1.0}, stiff.max = {1.0, 1.0};
        stiffParams.materialMaps = {stiff};
        Membrane plain(plainParams), stiffened(stiffParams);
        std::vector<Eigen::Vector3d> f0, f;
        for (Membrane* m : {&plain, &stiffened})
            for (int i = 0; i < m->particleCount(); ++i)
                m->positions()[i].x() = 1.001 * m->restPositions()[i].x();
        plain.computeForces(f0);
        stiffened.computeForces(f);
        for (int i = 0; i < plain.particleCount(); ++i) {
            const double x = plain.restPositions()[i].x();
            if (x > 0.05)
                EXPECT_NEAR(f[i].norm(), 4.0 * f0[i].norm(), 1e-6 * f0[i].norm()) << solver;
            if (x < -0.05) EXPECT_NEAR(f[i].norm(), f0[i].norm(), 1e-6 * f0[i].norm()) << solver;
        }
    }
}

TEST(MaterialMap, AToughSideHoldsWhereThePlainSideBreaks) {
    const Membrane plain(sheet());
    const auto [left, right] = brokenEachSide(sheet(), 1.5 * rend::test::criticalStretch(plain));
    EXPECT_GT(left, 0);
    EXPECT_EQ(right, 0);
}

// The kick and the guard take one mass for the sheet only where every particle has it to the
// bit (Membrane::oneMass): a density map, or particles of different areas, read their own.
TEST(MaterialMap, OneMassOnlyWhereEveryParticleHasIt) {
    const auto oneMassHolds = [](const Membrane& m) {
        const std::vector<double>& mass = m.masses();
        const bool same = std::all_of(mass.begin(), mass.end(),
                                      [&](double value) { return value == mass.front(); });
        return m.oneMass() == (same ? mass.front() : 0.0);
    };
    MembraneParams square = sheet();
    square.sheet.lattice = LatticeKind::Square;
    const Membrane plain(square), hexagonal(sheet());
    EXPECT_GT(plain.oneMass(), 0.0) << "a square sheet's particles all have one area";
    EXPECT_TRUE(oneMassHolds(plain));
    EXPECT_TRUE(oneMassHolds(hexagonal));
    MaterialMap heavy = region(MapShape::Box, 4.0);
    heavy.property = MappedProperty::Density;
    heavy.min = {0.0, -1.0}, heavy.max = {1.0, 1.0};
    square.materialMaps = {heavy};
    const Membrane dense(square);
    EXPECT_EQ(dense.oneMass(), 0.0) << "half the sheet four times as heavy";
    EXPECT_TRUE(oneMassHolds(dense));
}

// The density is the diffusion's too: four times the density is four times the thermal mass
// rho C, so theta spreads four times slower and its explicit step may be four times longer.
TEST(MaterialMap, ADensityMapIsTheDiffusionsThermalMassToo) {
    MembraneParams p = sheet();
    p.material.conductivity = 0.01;
    p.diffusion.initial = 1.0;
    const Membrane plain(p);
    MaterialMap dense = region(MapShape::Box, 4.0);
    dense.property = MappedProperty::Density;
    dense.min = {-1.0, -1.0}, dense.max = {1.0, 1.0};  // the whole sheet
    p.materialMaps = {dense};
    const Membrane heavy(p);
    ASSERT_NE(plain.diffusion(), nullptr);
    ASSERT_NE(heavy.diffusion(), nullptr);
    EXPECT_NEAR(heavy.diffusion()->stableTimeStep(), 4.0 * plain.diffusion()->stableTimeStep(),
                1e-12 * plain.diffusion()->stableTimeStep());
}

// A yield_strain map halves eta0 on x > 0: stretched to 0.8 eta0 everywhere, only that half
// yields and softens (eq. 27's gamma < 1); the other stays whole. Without the map nothing yields.
TEST(MaterialMap, AYieldStrainMapYieldsOnlyWhereItLowersTheYield) {
    for (const char* solver : {"peridynamic", "fem_cst", "mpm", "mass_spring_vg", "mass_spring_tp"})
        for (const bool mapped : {true, false}) {
            SCOPED_TRACE(solver);
            MembraneParams p = sheet();
            p.solver = solver;
            p.material.fractureEnergy.reset();
            p.material.law = BondLawKind::Elastoplastic;
            p.material.yieldStrain = 0.01;
            p.material.softening = 2.0;
            if (mapped) {
                MaterialMap weak = region(MapShape::Box, 0.5);
                weak.property = MappedProperty::YieldStrain;
                weak.min = {0.0, -1.0};
                weak.max = {1.0, 1.0};
                p.materialMaps = {weak};
            }
            Membrane m(p);
            for (int i = 0; i < m.particleCount(); ++i)
                m.positions()[i] = (1.0 + 0.8 * 0.01) * m.restPositions()[i];
            m.step();
            m.updateDamage();
            const BondFamilies& bonds = m.bonds();
            int weakened = 0, weakenedLeft = 0;
            for (int i = 0; i < m.particleCount(); ++i)
                for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
                    const double xi = m.restPositions()[i].x();
                    const double xj = m.restPositions()[bonds.partners[b]].x();
                    if (m.damageState().strength()[b] >= 1.0) continue;
                    ++weakened;
                    if (xi < -0.02 && xj < -0.02) ++weakenedLeft;
                }
            EXPECT_EQ(weakenedLeft, 0) << "x < 0 keeps its yield strain";
            if (mapped)
                EXPECT_GT(weakened, 100) << "x > 0 yields at half of it";
            else
                EXPECT_EQ(weakened, 0);
        }
    MembraneParams fem = sheet();
    fem.material.law = BondLawKind::Elastoplastic;
    MaterialMap weak = region(MapShape::Box, 0.5);
    weak.property = MappedProperty::YieldStrain;
    fem.materialMaps = {weak};
    EXPECT_EQ(unsupportedFeatures(solverEntry("sph"), fem),
              "a bond law other than linear and a material map of the bond law (yield_strain, "
              "softening, power_ratio, power_exponent)");
    EXPECT_EQ(unsupportedFeatures(solverEntry("mass_spring_tp"), fem), "");
    EXPECT_EQ(unsupportedFeatures(solverEntry("fem_cst"), fem), "");
    EXPECT_EQ(unsupportedFeatures(solverEntry("peridynamic"), fem), "");
}

// A softening map makes eq. 20 decay four times as fast on x > 0: stretched to 2 eta0, the
// bonds (or elements) there keep exp(-4) of their strength against exp(-1) on x < 0.
TEST(MaterialMap, ASofteningMapSoftensOnlyWhereItNames) {
    for (const char* solver :
         {"peridynamic", "fem_cst", "mpm", "mass_spring_vg", "mass_spring_tp"}) {
        SCOPED_TRACE(solver);
        MembraneParams p = sheet();
        p.solver = solver;
        p.material.fractureEnergy.reset();
        p.material.law = BondLawKind::Elastoplastic;
        p.material.yieldStrain = 0.01;
        p.material.softening = 1.0;
        MaterialMap brittle = region(MapShape::Box, 4.0);
        brittle.property = MappedProperty::Softening;
        brittle.min = {0.0, -1.0};
        brittle.max = {1.0, 1.0};
        p.materialMaps = {brittle};
        Membrane m(p);
        for (int i = 0; i < m.particleCount(); ++i)
            m.positions()[i] = (1.0 + 2.0 * 0.01) * m.restPositions()[i];
        m.step();
        m.updateDamage();
        const BondFamilies& bonds = m.bonds();
        double left = 1.0, right = 0.0;  // the weakest on the left, the strongest on the right
        for (int i = 0; i < m.particleCount(); ++i)
            for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
                const double xi = m.restPositions()[i].x();
                const double xj = m.restPositions()[bonds.partners[b]].x();
                const double gamma = m.damageState().strength()[b];
                if (xi < -0.04 && xj < -0.04) left = std::min(left, gamma);
                if (xi > 0.04 && xj > 0.04) right = std::max(right, gamma);
            }
        std::printf("%s: strength left at 2 eta0, beta 1: >= %.3f; beta 4: <= %.3f\n", solver, left,
                    right);
        EXPECT_GT(left, 0.2);
        EXPECT_LT(right, 0.1);
    }
}

// A power-law map changes the law's shape only: eq. 19 keeps its small-strain stiffness c, so
// the mapped sheet stores the plain one's energy at a small stretch and not at a large one, and
// a map over half the sheet changes about half as much as one over all of it.
TEST(MaterialMap, APowerLawMapChangesOnlyTheLargeStrainShape) {
    for (const MappedProperty property :
         {MappedProperty::PowerRatio, MappedProperty::PowerExponent})
        for (const char* solver :
             {"peridynamic", "fem_cst", "mpm", "mass_spring_vg", "mass_spring_tp"}) {
            SCOPED_TRACE(std::string(solver) + " " + mappedPropertyName(property));
            auto energyAt = [&](double strain, double xMax) {
                MembraneParams p = sheet();
                p.solver = solver;
                p.material.fractureEnergy.reset();
                p.material.law = BondLawKind::PowerLaw;
                p.material.powerLawRatio = -0.05;
                p.material.powerLawExponent = 4.0;
                if (xMax > -1.0) {
                    MaterialMap map = region(MapShape::Box, 1.5);
                    map.property = property;
                    map.min = {-1.0, -1.0};
                    map.max = {xMax, 1.0};
                    p.materialMaps = {map};
                }
                Membrane m(p);
                for (int i = 0; i < m.particleCount(); ++i)
                    m.positions()[i] = (1.0 + strain) * m.restPositions()[i];
                return m.strainEnergy();
            };
            const double small = 1e-5, large = 0.2;
            EXPECT_NEAR(energyAt(small, 1.0) / energyAt(small, -2.0), 1.0, 1e-3);
            const double plain = energyAt(large, -2.0), all = energyAt(large, 1.0);
            const double half = energyAt(large, 0.0);
            std::printf("%s %s at 20%%: all mapped / plain %.4f, half share %.3f\n", solver,
                        mappedPropertyName(property).c_str(), all / plain,
                        (half - plain) / (all - plain));
            EXPECT_GT(std::abs(all / plain - 1.0), 0.05);
            EXPECT_NEAR((half - plain) / (all - plain), 0.5, 0.1);
        }
}
