// Contact (sim/Contact.h): the ground, kinematic colliders with Coulomb friction, and the sheet's
// self-contact, against closed forms and invariants.

#include <gtest/gtest.h>
#include <omp.h>

#include <cmath>
#include <cstring>
#include <random>

#include "sim/ColliderDistance.h"
#include "sim/Membrane.h"
#include "sim/SolverRegistry.h"

using namespace rend::sim;

namespace {

constexpr double kGravity = 9.81;

MembraneParams sheet(Eigen::Vector2d size, double dx) {
    MembraneParams p;
    p.sheet.size = size;
    p.sheet.dx = dx;
    p.material.youngsModulus = 2e4;
    p.material.density = 5000;
    p.gravity = {0, 0, -kGravity};
    return p;
}

/// A sheet lying on the ground plane z = 0 at the contact offset, every particle moving at v.
MembraneParams slidingSheet(double friction) {
    MembraneParams p = sheet({0.2, 0.2}, 0.02);
    p.contact.ground.enabled = true;
    p.contact.ground.friction = {friction, friction};
    p.sheet.center.z() = 0.5 * 0.5 * p.sheet.dx;  // d / 2, with d = dx / 2
    p.time.duration = 0.25;
    p.time.dt = 2e-4;  // a step's slide before friction acts is within 2% of the distance
    return p;
}

Eigen::Vector3d centroid(const Membrane& m) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3d& x : m.positions()) c += x;
    return c / m.particleCount();
}

double lowest(const Membrane& m) {
    double z = 1e300;
    for (const Eigen::Vector3d& x : m.positions()) z = std::min(z, x.z());
    return z;
}

void setVelocity(Membrane& m, const Eigen::Vector3d& v) {
    for (Eigen::Vector3d& u : m.velocities()) u = v;
}

/// The closest two particles that are not bonded at rest (farther apart than the horizon).
double closestUnbondedPair(const Membrane& m) {
    const auto& x = m.positions();
    const auto& rest = m.restPositions();
    const double reach2 = std::pow(m.horizon() * (1 + 1e-9), 2);
    double closest = 1e300;
    for (int i = 0; i < m.particleCount(); ++i)
        for (int j = i + 1; j < m.particleCount(); ++j)
            if ((rest[i] - rest[j]).squaredNorm() > reach2)
                closest = std::min(closest, (x[i] - x[j]).norm());
    return closest;
}

/// Two pieces: a sheet cut across y = 0, its upper half laid over its lower half `gap` above
/// it, on the ground.
MembraneParams stackedPieces(double width, double dx) {
    MembraneParams p = sheet({width, 2 * width}, dx);
    p.contact.ground.enabled = true;
    p.contact.self.enabled = true;
    p.sheet.center.z() = 0.25 * dx;
    p.notches.push_back(Notch{{{-width, 0.3 * dx}, {width, 0.3 * dx}}});
    p.damping = 2.0;
    return p;
}

void layUpperOverLower(Membrane& m, double width, double gap) {
    const double cut = m.params().notches.front().points.front().y();
    for (int i = 0; i < m.particleCount(); ++i) {
        if (m.restPositions()[i].y() < cut) continue;
        m.positions()[i] += Eigen::Vector3d(0.0, -width, gap);
    }
}

}  // namespace

TEST(Contact, ASheetSlidingOnAFrictionlessPlaneKeepsItsHorizontalMomentum) {
    MembraneParams p = slidingSheet(0.0);
    Membrane m(p);
    setVelocity(m, {0.3, 0.1, 0.0});
    const Eigen::Vector3d before = m.totalMomentum();
    m.advanceTo(p.time.duration);
    const Eigen::Vector3d after = m.totalMomentum();
    EXPECT_NEAR(after.x(), before.x(), 1e-12 * before.norm());
    EXPECT_NEAR(after.y(), before.y(), 1e-12 * before.norm());
    EXPECT_GE(lowest(m), 0.0) << "nothing below the ground";
    EXPECT_NEAR(centroid(m).x(), 0.3 * p.time.duration, 1e-6);
}

TEST(Contact, ASheetOnAHighFrictionPlaneStopsWhereCoulombSays) {
    for (const double mu : {0.5, 1.0}) {
        MembraneParams p = slidingSheet(mu);
        Membrane m(p);
        const double speed = 0.3;
        setVelocity(m, {speed, 0.0, 0.0});
        while (m.time() < p.time.duration)
            m.step();  // it stops after speed / (mu g) = 0.06 s at mu = 0.5
        EXPECT_LT(m.maxSpeed(), 1e-9) << "mu " << mu << ": static friction holds it";
        const double slide = speed * speed / (2 * mu * kGravity);
        EXPECT_NEAR(centroid(m).x(), slide, 0.05 * slide) << "mu " << mu;
        EXPECT_GE(lowest(m), 0.0);
    }
}

TEST(Contact, ASheetAtRestOnASphereFeelsNoNetForce) {
    MembraneParams p = sheet({0.2, 0.2}, 0.02);
    ColliderParams ball;
    ball.radius = 1.0;
    ball.position = {0, 0, -1.0};
    p.contact.colliders.push_back(ball);
    p.sheet.center.z() = 0.005;  // on top of the sphere at the offset d / 2
    p.damping = 20.0;
    p.time.control = StepControl::Auto;
    Membrane m(p);
    for (int k = 0; k < 20000 && m.time() < 1.0; ++k) m.step();
    EXPECT_LT(m.maxSpeed(), 1e-6) << "at rest";
    const Eigen::Vector3d support = m.contact()->lastImpulse() / m.timeStep();
    double mass = 0.0;
    for (double mi : m.masses()) mass += mi;
    const double weight = mass * kGravity;
    const Eigen::Vector3d net = support + mass * p.gravity;  // internal forces cancel
    EXPECT_LT(net.norm(), 1e-6 * weight) << "support " << support.transpose();
    for (const Eigen::Vector3d& x : m.positions())
        EXPECT_GE((x - ball.position).norm(), ball.radius) << "nothing inside the sphere";
}

TEST(Contact, StackedPiecesNeverComeCloserThanHalfTheContactThickness) {
    const double width = 0.2, dx = 0.02;
    Membrane m(stackedPieces(width, dx));
    layUpperOverLower(m, width, 0.04);
    const double d = m.contact()->thickness();
    EXPECT_DOUBLE_EQ(d, 0.5 * dx);
    double closest = 1e300;
    for (int frame = 1; frame <= 40; ++frame) {
        m.advanceTo(frame * 0.02);
        closest = std::min(closest, closestUnbondedPair(m));
        ASSERT_GE(lowest(m), 0.0) << "frame " << frame;
    }
    EXPECT_GE(closest, 0.5 * d);
    EXPECT_LT(closest, d) << "they touched";
    EXPECT_LT(m.maxSpeed(), 0.05) << "the upper piece landed on the lower one and stays";
    double upper = 0, lower = 0;
    int nu = 0, nl = 0;
    const double cut = m.params().notches.front().points.front().y();
    for (int i = 0; i < m.particleCount(); ++i) {
        const bool top = m.restPositions()[i].y() > cut;
        (top ? upper : lower) += m.positions()[i].z();
        (top ? nu : nl) += 1;
    }
    EXPECT_NEAR(upper / nu - lower / nl, d, 0.35 * d) << "one contact thickness apart";
}

TEST(Contact, SelfContactGivesIdenticalBitsWithOneAndTwoThreads) {
    const double width = 0.3, dx = 0.008;  // over the parallel threshold
    auto run = [&](int threads) {
        omp_set_num_threads(threads);
        Membrane m(stackedPieces(width, dx));
        EXPECT_GT(m.particleCount(), kParallelThreshold);
        layUpperOverLower(m, width, 0.01);
        m.advanceTo(0.06);
        EXPECT_GT(m.contact()->lastPairCount(), 0u) << "the pieces touch";
        return m.positions();
    };
    const std::vector<Eigen::Vector3d> one = run(1), two = run(2);
    omp_set_num_threads(2);
    ASSERT_EQ(one.size(), two.size());
    EXPECT_EQ(std::memcmp(one.data(), two.data(), one.size() * sizeof(one[0])), 0);
}

TEST(Contact, SelfContactForcesCancelInPairs) {
    MembraneParams p = stackedPieces(0.2, 0.02);
    p.contact.ground.friction = {0.0, 0.0};  // the ground's impulses are then along z only
    Membrane m(p);
    layUpperOverLower(m, 0.2, 0.004);  // closer than d: every overlapping pair pushes
    std::size_t touching = 0;
    for (int k = 0; k < 50; ++k) {
        m.step();
        touching = std::max(touching, m.contact()->lastPairCount());
    }
    ASSERT_GT(touching, 50u);
    EXPECT_NEAR(m.totalMomentum().x(), 0.0, 1e-14);
    EXPECT_NEAR(m.totalMomentum().y(), 0.0, 1e-14);
}

TEST(Contact, AMovingCapsuleLeavesNoParticleInside) {
    MembraneParams p = sheet({0.4, 0.4}, 0.02);
    p.gravity.setZero();
    BoundaryCondition edge;
    edge.kind = BoundaryKind::Pinned;
    edge.region.max.y() = -0.19;
    p.boundaries.push_back(edge);
    edge.region = Region{};
    edge.region.min.y() = 0.19;
    p.boundaries.push_back(edge);
    ColliderParams rod;
    rod.shape = ColliderShape::Capsule;
    rod.radius = 0.03;
    rod.length = 0.3;
    rod.rotation = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitY());  // along x
    rod.position = {0, 0, -0.05};
    rod.velocity = {0, 0, 0.5};
    p.contact.colliders.push_back(rod);
    Membrane m(p);
    const double offset = 0.5 * m.contact()->thickness();
    for (int frame = 1; frame <= 20; ++frame) {
        m.advanceTo(0.01 * frame);
        const ColliderPose pose = m.contact()->poses()[0];
        for (const Eigen::Vector3d& x : m.positions()) {
            const auto s = signedDistance(rod, nullptr, pose.toLocal(x));
            ASSERT_GE(s->distance, offset - 1e-12) << "frame " << frame;
        }
    }
    EXPECT_GT(centroid(m).z(), 0.02) << "the rod lifted the sheet";
}

TEST(Contact, AClosedMeshsSignedDistanceIsTheBoxsOwn) {
    TriangleMesh cube;
    for (int k = 0; k < 8; ++k)
        cube.vertices.emplace_back(k & 1 ? 0.5 : -0.5, k & 2 ? 0.5 : -0.5, k & 4 ? 0.5 : -0.5);
    cube.triangles = {{0, 2, 3}, {0, 3, 1}, {4, 5, 7}, {4, 7, 6}, {0, 1, 5}, {0, 5, 4},
                      {2, 6, 7}, {2, 7, 3}, {0, 4, 6}, {0, 6, 2}, {1, 3, 7}, {1, 7, 5}};
    const double reach = 0.2;
    const MeshDistance mesh(cube, reach);
    ColliderParams box;
    box.shape = ColliderShape::Box;
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> coordinate(-0.75, 0.75);
    int checked = 0;
    for (int k = 0; k < 20000; ++k) {
        const Eigen::Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
        const SurfaceDistance exact = *signedDistance(box, nullptr, p);
        const std::optional<SurfaceDistance> found = mesh.query(p);
        if (std::abs(exact.distance) >= reach) continue;
        ASSERT_TRUE(found) << p.transpose();
        EXPECT_NEAR(found->distance, exact.distance, 1e-12) << p.transpose();
        if (std::abs(exact.distance) > 1e-6 && exact.distance > 0) {
            EXPECT_LT((found->normal - exact.normal).norm(), 1e-9) << p.transpose();
        }
        ++checked;
    }
    EXPECT_GT(checked, 5000);
}

TEST(Contact, KeyframedPosesInterpolateAndTheirVelocitiesMatchTheMotion) {
    ColliderParams c;
    c.keyframes = {
        {0.0, {0, 0, 0}, Eigen::Quaterniond::Identity()},
        {1.0, {1, 2, 0}, Eigen::Quaterniond(Eigen::AngleAxisd(1.0, Eigen::Vector3d::UnitZ()))}};
    const ColliderPose mid = c.poseAt(0.5);
    EXPECT_LT((mid.position - Eigen::Vector3d(0.5, 1, 0)).norm(), 1e-12);
    const Eigen::Vector3d local(0.3, 0.1, 0.2);
    const double h = 1e-6;
    const Eigen::Vector3d moving =
        (c.poseAt(0.5 + h).toWorld(local) - c.poseAt(0.5 - h).toWorld(local)) / (2 * h);
    EXPECT_LT((moving - mid.velocityAt(mid.toWorld(local))).norm(), 1e-6);
    EXPECT_LT((c.poseAt(2.0).position - Eigen::Vector3d(1, 2, 0)).norm(), 1e-12) << "holds";
    EXPECT_EQ(c.poseAt(2.0).velocity.norm(), 0.0);
}

TEST(Contact, EverySolverGetsContactThroughTheMembrane) {
    for (const std::string_view name : solverNames()) {
        MembraneParams p = slidingSheet(0.5);
        p.solver = std::string(name);
        p.contact.self.enabled = true;
        Membrane m(p);
        const double speed = 0.3;
        setVelocity(m, {speed, 0.0, 0.0});
        while (m.time() < p.time.duration) m.step();
        EXPECT_LT(m.maxSpeed(), 1e-6) << name;
        const double slide = speed * speed / (2 * 0.5 * kGravity);
        EXPECT_NEAR(centroid(m).x(), slide, 0.05 * slide) << name;
        EXPECT_GE(lowest(m), 0.0) << name;
    }
}
