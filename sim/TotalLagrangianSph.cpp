#include "sim/TotalLagrangianSph.h"

#include <Eigen/LU>
#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "sim/Fracture.h"
#include "sim/Parallel.h"
#include "sim/SolverRegistry.h"

namespace rend::sim {
namespace {

constexpr double kSupport = 2.0;  ///< neighbours within this many dx

/// Wendland C2 in 2D, up to its constant (the correction A_i^-T absorbs any scale).
double kernel(double r, double support) {
    const double q = r / support;
    return q >= 1.0 ? 0.0 : std::pow(1.0 - q, 4) * (4.0 * q + 1.0);
}

/// G / (E h dx e^2) of a straight crack on the hexagonal lattice, e the Green strain normal to it:
/// 0.942 along a row, 1.002 across the rows (1.055 on the square lattice either way), measured
/// by SphFracture.AStraightCrackReleasesTheFractureEnergy; the mean of the hexagonal two.
constexpr double kCrackEnergyFactor = 0.97;

/// A pair longer than this many times its rest length breaks whatever F says: F hardly sees a
/// pair near the kernel's edge (weight ~ 0), which would otherwise tether a particle that tore
/// away. Far above the pair lengths' zero-energy noise (< 2 e_c next to the grips).
constexpr double kTetherStretch = 2.0;

}  // namespace

double sphCriticalStrain(double fractureEnergy, double youngsModulus, double dx) {
    const double green = std::sqrt(fractureEnergy / (kCrackEnergyFactor * youngsModulus * dx));
    return std::sqrt(1.0 + 2.0 * green) - 1.0;
}

TotalLagrangianSph::TotalLagrangianSph(const Lattice& lattice, double dx, const Material& material,
                                       double thickness, std::span<const Notch> notches,
                                       double criticalStrain)
    : rest_(lattice.positions),
      support_(kSupport * dx),
      material_(material),
      expansion_(material.expansion()),
      thickness_(thickness),
      criticalStrain_(criticalStrain) {
    lambda_ = material.lambda();
    mu_ = material.mu();
    const int n = int(rest_.size());
    pairs_ = buildBondFamilies(rest_, support_);
    pairAlive_.assign(pairs_.directedCount(), 1);
    for (const int k : notchedBonds(notches, rest_, pairs_)) pairAlive_[k] = 0;
    offsets_ = pairs_.offsets;
    neighbours_ = pairs_.partners;
    volume_.assign(n, lattice.particleArea);
    if (!lattice.areas.empty()) volume_ = lattice.areas;
    gradient_.resize(neighbours_.size());
    for (int i = 0; i < n; ++i) correctGradients(i);
    mirror_.resize(neighbours_.size());
    for (int i = 0; i < n; ++i)
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
            mirror_[k] = findBond(pairs_, neighbours_[k], i);
    restMetric_.assign(n, -1);
    breaking_.assign(neighbours_.size(), 0);
    bindOwn({}, n, lattice.triangles);
}

std::unique_ptr<Solver> TotalLagrangianSph::make(const SolverSetUp& s) {
    if (s.params.sheet.outline == Outline::Sphere)
        throw std::invalid_argument("the sph solver needs a flat rest sheet");
    const MaterialParams& m = s.params.material;
    auto sph = std::make_unique<TotalLagrangianSph>(
        s.lattice, s.params.sheet.dx, s.material, s.params.sheet.thickness, s.params.notches,
        m.fractureEnergy ? sphCriticalStrain(*m.fractureEnergy, m.youngsModulus, s.params.sheet.dx)
                         : std::numeric_limits<double>::infinity());
    sph->applyMaterialMaps(s.params.materialMaps);
    return sph;
}

void TotalLagrangianSph::applyMaterialMaps(std::span<const MaterialMap> maps) {
    if (!mapsProperty(maps, MappedProperty::YoungsModulus) &&
        !mapsProperty(maps, MappedProperty::FractureEnergy))
        return;
    stiffness_ = materialFactors(MappedProperty::YoungsModulus, maps, rest_);
    const std::vector<double> g = materialFactors(MappedProperty::FractureEnergy, maps, rest_);
    pairStrength_.resize(neighbours_.size());
    for (int i = 0; i < int(rest_.size()); ++i)
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
            const int j = neighbours_[k];
            pairStrength_[k] = std::sqrt((g[i] + g[j]) / (stiffness_[i] + stiffness_[j]));
        }
}

void TotalLagrangianSph::onBind() {
    // The pairs that are also sides of rest triangles (the FrameView's cracks); set-up only.
    pairEdge_.assign(neighbours_.size(), -1);
    const auto& edges = damage_->edges();
    for (int e = 0; e < int(edges.size()); ++e)
        if (const int k = findBond(pairs_, edges[e][0], edges[e][1]); k >= 0)
            pairEdge_[k] = pairEdge_[mirror_[k]] = e;
}

bool TotalLagrangianSph::pairAlive(int i, int j) const {
    const int k = findBond(pairs_, i, j);
    return k >= 0 && pairAlive_[k];
}

std::unique_ptr<Workspace> TotalLagrangianSph::makeWorkspace() const {
    return std::make_unique<SphWorkspace>();
}

void TotalLagrangianSph::fracture(const StepState& s, Workspace& work) {
    if (!std::isfinite(criticalStrain_)) return;
    const auto& x = s.x;
    const auto& theta = s.theta;
    const int n = int(x.size());
    std::vector<Eigen::Matrix<double, 3, 2>>& deformation =
        static_cast<SphWorkspace&>(work).deformation;
    deformations(s, deformation);
    // The pair's stretch seen through the mean of its ends' mechanical F, not its own length:
    // F filters the particle-scale (zero-energy) noise that the pair lengths carry, twice the
    // continuum's strain next to the grips (see the top). Both copies of a pair see the same
    // strain bit for bit, so they break together; each particle writes only its own copies.
    int count = 0;
#pragma omp parallel for schedule(static) reduction(+ : count) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i) {
        const double si = 1.0 + expansion_ * thetaAt(theta, i);
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
            breaking_[k] = 0;
            if (!pairAlive_[k]) continue;
            const int j = neighbours_[k];
            const double thetaBar = 0.5 * (thetaAt(theta, i) + thetaAt(theta, j));
            const Eigen::Vector2d d = (rest_[j] - rest_[i]).head<2>() / pairs_.restLength[k];
            const double sj = 1.0 + expansion_ * thetaAt(theta, j);
            const double eta = (0.5 * (deformation[i] / si + deformation[j] / sj) * d).norm() - 1.0;
            const double limit = criticalStrain_ * material_.strengthFactor(thetaBar) *
                                 (pairStrength_.empty() ? 1.0 : pairStrength_[k]);
            const double length = (x[j] - x[i]).norm() / pairs_.restLength[k];
            breaking_[k] = eta > limit || length > kTetherStretch;
            count += breaking_[k];
        }
    }
    if (count == 0) return;
    std::vector<int> touched;
    for (int i = 0; i < n; ++i)
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
            if (breaking_[k]) {
                breakPair(k, touched);
                if (pairEdge_[k] >= 0) damage_->breakEdge(pairEdge_[k]);  // in index order
            }
    settle(touched);
    for (int i : touched) deformation[i] = deformationGradient(i, x);
}

void TotalLagrangianSph::cut(const std::vector<std::array<int, 2>>& edges) {
    // Without fracture the notches did it all at set-up, with their pairs re-corrected.
    if (!std::isfinite(criticalStrain_)) return;
    std::vector<int> touched;
    for (const auto& [i, j] : edges)
        if (const int k = findBond(pairs_, i, j); k >= 0 && pairAlive_[k]) {
            breakPair(k, touched);
            breakPair(mirror_[k], touched);
        }
    settle(touched);
}

void TotalLagrangianSph::breakPair(int k, std::vector<int>& touched) {
    pairAlive_[k] = 0;
    gradient_[k].setZero();
    const int i = int(std::upper_bound(offsets_.begin(), offsets_.end(), k) - offsets_.begin()) - 1;
    touched.push_back(i);
    if (i < neighbours_[k]) ++brokenPairs_;
}

void TotalLagrangianSph::settle(std::vector<int>& touched) {
    std::sort(touched.begin(), touched.end());
    touched.erase(std::unique(touched.begin(), touched.end()), touched.end());
    for (int i : touched) {
        // The rest correction A_i^-T stays; i now measures strain against its rest metric
        // C0 = B^T B, B = sum over its living pairs of d g^T, so the rest state holds no stress.
        Eigen::Matrix2d B = Eigen::Matrix2d::Zero();
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
            B += (rest_[neighbours_[k]] - rest_[i]).head<2>() * gradient_[k].transpose();
        if (restMetric_[i] < 0) {
            restMetric_[i] = int(metric_.size());
            metric_.emplace_back();
        }
        metric_[restMetric_[i]] = B.transpose() * B;
    }
}

void TotalLagrangianSph::advance(const StepState& s, Workspace& work,
                                 std::vector<Eigen::Vector3d>& force) {
    if (!std::isfinite(criticalStrain_)) return forces(s, work, force);
    fracture(s, work);  // leaves the deformation gradients at s.x in the workspace
    forcesFrom(s, static_cast<SphWorkspace&>(work), force);
}

void TotalLagrangianSph::deformations(const StepState& s,
                                      std::vector<Eigen::Matrix<double, 3, 2>>& deformation) const {
    const int n = int(s.x.size());
    deformation.resize(n);
    forEachIndex(n >= kParallelThreshold, 0, n,
                 [&](int i) { deformation[i] = deformationGradient(i, s.x); });
}

void TotalLagrangianSph::correctGradients(int i) {
    Eigen::Matrix2d A = Eigen::Matrix2d::Zero();
    for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
        const Eigen::Vector2d d = (rest_[neighbours_[k]] - rest_[i]).head<2>();
        gradient_[k] =
            pairAlive_[k]
                ? Eigen::Vector2d(volume_[neighbours_[k]] * kernel(d.norm(), support_) * d)
                : Eigen::Vector2d::Zero();
        A += d * gradient_[k].transpose();
    }
    const double size = A.norm();
    const bool spans = size > 0.0 && std::abs(A.determinant()) > 1e-6 * size * size;
    Eigen::Matrix2d correction = Eigen::Matrix2d::Zero();
    if (spans) correction = A.inverse().transpose();
    for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) gradient_[k] = correction * gradient_[k];
}

Eigen::Matrix<double, 3, 2> TotalLagrangianSph::deformationGradient(
    int i, std::span<const Eigen::Vector3d> x) const {
    Eigen::Matrix<double, 3, 2> F = Eigen::Matrix<double, 3, 2>::Zero();
    for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
        F += (x[neighbours_[k]] - x[i]) * gradient_[k].transpose();
    return F;
}

Eigen::Matrix2d TotalLagrangianSph::greenStrain(int i, const Eigen::Matrix<double, 3, 2>& F) const {
    if (restMetric_[i] < 0) return 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
    return 0.5 * (F.transpose() * F - metric_[restMetric_[i]]);
}

Eigen::Matrix<double, 3, 2> TotalLagrangianSph::firstPiola(
    int i, const Eigen::Matrix<double, 3, 2>& F) const {
    const Eigen::Matrix2d E = greenStrain(i, F);
    return F * (lambda_ * E.trace() * Eigen::Matrix2d::Identity() + 2.0 * mu_ * E);
}

void TotalLagrangianSph::forces(const StepState& s, Workspace& work,
                                std::vector<Eigen::Vector3d>& force) const {
    SphWorkspace& sph = static_cast<SphWorkspace&>(work);
    deformations(s, sph.deformation);
    forcesFrom(s, sph, force);
}

void TotalLagrangianSph::forcesFrom(const StepState& s, SphWorkspace& work,
                                    std::vector<Eigen::Vector3d>& force) const {
    const std::vector<Eigen::Matrix<double, 3, 2>>& deformation = work.deformation;
    std::vector<Eigen::Matrix<double, 3, 2>>& stress = work.stress;
    const int n = int(deformation.size());
    stress.resize(n);
    force.resize(n);
    forEachIndex(n >= kParallelThreshold, 0, n, [&](int i) {
        // Psi(F / s) with s = 1 + alpha theta: its derivative is P(F / s) / s.
        const double stretch = 1.0 + expansion_ * thetaAt(s.theta, i);
        stress[i] = stiffnessOf(i) * volume_[i] * thickness_ *
                    material_.stiffnessFactor(thetaAt(s.theta, i)) / stretch *
                    firstPiola(i, deformation[i] / stretch);
    });
    forEachIndex(n >= kParallelThreshold, 0, n, [&](int i) {
        Eigen::Vector2d own = Eigen::Vector2d::Zero();
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
            own += gradient_[k];
            sum -= stress[neighbours_[k]] * gradient_[mirror_[k]];  // - V_j h P_j g_ji
        }
        force[i] = sum + stress[i] * own;
    });
}

std::vector<double> TotalLagrangianSph::stiffnessRowSums(int particleCount) const {
    // As for the FEM: particle i's energy term is an "element" over i and its neighbours with
    // gradients g_ij and -sum_j g_ij; each adds sqrt(2)/2 V_i h (lambda* + 2 mu) |G_a| sum_b |G_b|
    // to its nodes' half row sums.
    std::vector<double> sums(particleCount, 0.0);
    for (int i = 0; i < particleCount; ++i) {
        Eigen::Vector2d own = Eigen::Vector2d::Zero();
        double total = 0.0;
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k) {
            own += gradient_[k];
            total += gradient_[k].norm();
        }
        total += own.norm();
        const double scale =
            std::sqrt(0.5) * stiffnessOf(i) * volume_[i] * thickness_ * (lambda_ + 2.0 * mu_);
        sums[i] += scale * own.norm() * total;
        for (int k = offsets_[i]; k < offsets_[i + 1]; ++k)
            sums[neighbours_[k]] += scale * gradient_[k].norm() * total;
    }
    return sums;
}

double TotalLagrangianSph::strainEnergy(const StepState& s, Workspace&) const {
    const auto& x = s.x;
    double sum = 0.0;
    for (int i = 0; i < int(x.size()); ++i) {
        const Eigen::Matrix<double, 3, 2> F =
            deformationGradient(i, x) / (1.0 + expansion_ * thetaAt(s.theta, i));
        const Eigen::Matrix2d E = greenStrain(i, F);
        sum += stiffnessOf(i) * volume_[i] * thickness_ *
               material_.stiffnessFactor(thetaAt(s.theta, i)) *
               (0.5 * lambda_ * E.trace() * E.trace() + mu_ * (E.array() * E.array()).sum());
    }
    return sum;
}

}  // namespace rend::sim
