#include "sim/Membrane.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "sim/FemCst.h"
#include "sim/Fracture.h"
#include "sim/MassSpring.h"
#include "sim/TotalLagrangianSph.h"

namespace rend::sim {

Membrane::Membrane(const MembraneParams& params)
    : params_(params), lattice_(generateLattice(params.sheet)) {
    const SheetParams& sheet = params.sheet;
    horizon_ = sheet.horizonFactor * sheet.dx;
    x0_ = lattice_.positions;
    const int n = int(x0_.size());
    if (n < 2) throw std::invalid_argument("the sheet holds fewer than two particles");
    volume_.assign(n, lattice_.particleArea * sheet.thickness);
    if (!lattice_.areas.empty())
        for (int i = 0; i < n; ++i) volume_[i] = lattice_.areas[i] * sheet.thickness;
    mass_.resize(n);
    for (int i = 0; i < n; ++i) mass_[i] = params.material.density * volume_[i];
    bonds_ = buildBondFamilies(x0_, horizon_);
    computeBondScales(params);
    if (params.solver != SolverKind::Peridynamic) useSolver(makeSolver(params, lattice_));
    setUpFracture(params);
    if (params.pressure != 0.0) {
        pressureEdgeBonds_.reserve(lattice_.triangles.size());
        for (const auto& t : lattice_.triangles)
            pressureEdgeBonds_.push_back({findBond(bonds_, t[0], t[1]),
                                          findBond(bonds_, t[1], t[2]),
                                          findBond(bonds_, t[2], t[0])});
    }
    assignBoundaries();
    x_ = x0_;
    perturb(sheet.perturbationAmplitude, sheet.perturbationSeed);
    v_.assign(n, Eigen::Vector3d::Zero());
    force_.assign(n, Eigen::Vector3d::Zero());
    if (Diffusion::needed(params)) {
        diffusion_.emplace(params, x0_, bonds_, volume_);
        theta_ = diffusion_->initialTheta();
    }
    dt_ = params.time.dt.value_or(params.time.safety * stableDt_);
    updateDamage();
}

void Membrane::computeBondScales(const MembraneParams& params) {
    const int n = particleCount();
    const bool paper = params.material.micromodulus == MicromodulusMode::Paper;
    bondScale_.resize(bonds_.directedCount());
    for (int i = 0; i < n; ++i)
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
            const int j = bonds_.partners[b];
            // Literal eq. 22 multiplies by the area A_j; the consistent form by V_i V_j.
            const double measure = paper ? lattice_.particleArea : volume_[i] * volume_[j];
            bondScale_[b] = bonds_.weight[b] * measure / bonds_.restLength[b];
        }
    const double interiorWeightedVolume = interiorFamilySum(
        bonds_, [&](int b) { return bonds_.weight[b] * volume_[bonds_.partners[b]]; });
    if (interiorWeightedVolume <= 0.0)
        throw std::invalid_argument(
            "no particle has a bond with non-zero weight: raise the horizon");
    if (params.material.surfaceCorrection) applySurfaceCorrection();
    const MaterialParams& m = params.material;
    const double c = paper ? paperMicromodulus(m.youngsModulus, m.poissonRatio, horizon_)
                           : calibratedMicromodulus(m.youngsModulus, interiorWeightedVolume);
    law_ = BondLaw::fromMaterial(m, c);

    double worstRatio = 0.0;  // max_i sum_j k_ij / m_i
    for (int i = 0; i < n; ++i) {
        double stiffness = 0.0;
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b)
            stiffness += bondScale_[b] * law_.stiffness() / bonds_.restLength[b];
        worstRatio = std::max(worstRatio, stiffness / mass_[i]);
    }
    setStableStep(worstRatio);
}

void Membrane::setStableStep(double worstRatio) {
    stableDt_ = std::sqrt(2.0 / worstRatio);
    // A runaway particle moves far faster than the fastest wave (~dx * omega_max), anything the
    // boundaries impose, or free fall over the whole run.
    double boundarySpeed = 0.0;
    for (const auto& bc : params_.boundaries)
        boundarySpeed = std::max(boundarySpeed, bc.velocity.norm());
    const double waveSpeed = params_.sheet.dx * std::sqrt(worstRatio);
    speedLimit_ = 100.0 * waveSpeed + 10.0 * boundarySpeed +
                  2.0 * params_.gravity.norm() * params_.time.duration + 1e-6;
}

namespace {

// Strain energy density of particle i under unit uniaxial stress along axis a, up to a constant
// common to all particles: sum_j W0 V_j |xi| s^2 (the linear law's micropotential c s^2 |xi| / 2),
// with the bond stretch s = n.eps.n of the plane-stress strain eps = a a - (1/3) a' a' (nu = 1/3)
// and W0 V_j |xi| written through the bond scale W0 V_i V_j / |xi| of equal particle volumes.
double uniaxialStressEnergy(const BondFamilies& bonds, const std::vector<double>& bondScale,
                            const std::vector<Eigen::Vector3d>& x0, int i, int a) {
    double sum = 0.0;
    for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
        const Eigen::Vector3d n = (x0[bonds.partners[b]] - x0[i]) / bonds.restLength[b];
        const double along = n[a] * n[a];
        const double s = along - (1.0 - along) / 3.0;
        sum += bondScale[b] * bonds.restLength[b] * bonds.restLength[b] * s * s;
    }
    return sum;
}

}  // namespace

void Membrane::applySurfaceCorrection() {
    const int n = particleCount();
    // Energy method (Madenci & Oterkus 2014, Sec. 4.2) with uniaxial stress, not strain, as the
    // loading: an edge is free of stress across it, so that is the state its particles meet.
    std::vector<Eigen::Vector2d> factor(n, Eigen::Vector2d::Ones());
    for (int a = 0; a < 2; ++a) {
        std::vector<double> energy(n);
        double interior = 0.0;
        for (int i = 0; i < n; ++i) {
            energy[i] = uniaxialStressEnergy(bonds_, bondScale_, x0_, i, a);
            interior = std::max(interior, energy[i]);
        }
        for (int i = 0; i < n; ++i)
            if (energy[i] > 0.0) factor[i][a] = interior / energy[i];
    }
    // The ends' mean keeps the bond symmetric (equal and opposite forces); the ellipse through
    // the x and y factors gives the factor along the bond's direction n.
    for (int i = 0; i < n; ++i)
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
            const int j = bonds_.partners[b];
            const Eigen::Vector3d d = (x0_[j] - x0_[i]) / bonds_.restLength[b];
            const Eigen::Vector2d g = 0.5 * (factor[i] + factor[j]);
            bondScale_[b] /= std::hypot(d.x() / g.x(), d.y() / g.y());
        }
}

double springCriticalStrain(const MembraneParams& params) {
    const MaterialParams& m = params.material;
    if (!m.fractureEnergy) return std::numeric_limits<double>::infinity();
    // The springs crossing a unit length of crack along a hexagonal row (2 / dx of them, each
    // sqrt(3)/2 E h at nu = 1/3) store G_f h at this strain: k eps^2 dx^2 / 2 * 2 / dx = G_f h.
    return std::sqrt(2.0 * *m.fractureEnergy /
                     (std::sqrt(3.0) * m.youngsModulus * params.sheet.dx));
}

std::unique_ptr<Solver> makeSolver(const MembraneParams& params, const Lattice& lattice) {
    const MaterialParams& m = params.material;
    const double h = params.sheet.thickness;
    const double critical = springCriticalStrain(params);
    switch (params.solver) {
        case SolverKind::FemCst:
            return std::make_unique<FemCst>(lattice, m, h, critical);
        case SolverKind::MassSpringVanGelder:
            return std::make_unique<MassSpring>(lattice, SpringModel::VanGelder, m, h, critical);
        case SolverKind::MassSpringTwoParameter:
            return std::make_unique<MassSpring>(lattice, SpringModel::TwoParameter, m, h, critical);
        case SolverKind::Sph:
            if (params.sheet.outline == Outline::Sphere)
                throw std::invalid_argument("the sph solver needs a flat rest sheet");
            return std::make_unique<TotalLagrangianSph>(
                lattice, params.sheet.dx, m, h, params.notches,
                m.fractureEnergy
                    ? sphCriticalStrain(*m.fractureEnergy, m.youngsModulus, params.sheet.dx)
                    : std::numeric_limits<double>::infinity());
        case SolverKind::Peridynamic:
            break;
    }
    return nullptr;
}

void Membrane::useSolver(std::unique_ptr<Solver> solver) {
    solver_ = std::move(solver);
    const std::vector<double> k = solver_->stiffnessRowSums(particleCount());
    double worstRatio = 0.0;
    for (int i = 0; i < particleCount(); ++i) worstRatio = std::max(worstRatio, k[i] / mass_[i]);
    setStableStep(worstRatio);
}

void Membrane::breakBond(int i, int j) {
    for (const auto& [a, b] : {std::pair{i, j}, std::pair{j, i}})
        if (const int bond = findBond(bonds_, a, b); bond >= 0) bonds_.alive[bond] = 0;
}

void Membrane::setUpFracture(const MembraneParams& params) {
    const MaterialParams& m = params.material;
    criticalStretch_ = std::numeric_limits<double>::infinity();
    if (m.fractureEnergy) {
        const double interiorMoment = interiorFamilySum(bonds_, [&](int b) {  // sum_j W0 |xi| V_j
            return bonds_.weight[b] * bonds_.restLength[b] * volume_[bonds_.partners[b]];
        });
        criticalStretch_ =
            m.criticalStretch == CriticalStretchMode::Paper
                ? paperCriticalStretch(*m.fractureEnergy, m.youngsModulus, horizon_)
                : calibratedCriticalStretch(*m.fractureEnergy, law_.c, interiorMoment);
    }
    if (m.law == BondLawKind::Elastoplastic) plastic_.assign(bonds_.directedCount(), {});
    notched_ = applyNotches(params.notches, x0_, bonds_);
    if (solver_ && notched_ > 0) {
        std::vector<std::array<int, 2>> edges;
        for (int i = 0; i < particleCount(); ++i)
            for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b)
                if (!bonds_.alive[b] && i < bonds_.partners[b])
                    edges.push_back({i, bonds_.partners[b]});
        if (!solver_->cut(edges))
            throw std::invalid_argument("this solver cannot represent notches");
    }
    canDamage_ = m.fractureEnergy.has_value() || !plastic_.empty() || notched_ > 0;
}

void Membrane::assignBoundaries() {
    constraint_.assign(x0_.size(), kFree);
    for (int k = 0; k < int(params_.boundaries.size()); ++k) {
        const BoundaryCondition& bc = params_.boundaries[k];
        const std::int16_t tag = bc.kind == BoundaryKind::Pinned ? kPinned : std::int16_t(k);
        for (int i = 0; i < particleCount(); ++i)
            if (bc.region.contains(x0_[i])) constraint_[i] = tag;
    }
}

int Membrane::nearestParticle(const Eigen::Vector2d& at) const {
    int best = 0;
    for (int i = 1; i < particleCount(); ++i)
        if ((x0_[i].head<2>() - at).squaredNorm() < (x0_[best].head<2>() - at).squaredNorm())
            best = i;
    return best;
}

std::vector<int> Membrane::boundaryParticleCounts() const {
    std::vector<int> counts(params_.boundaries.size(), 0);
    for (int k = 0; k < int(params_.boundaries.size()); ++k)
        for (int i = 0; i < particleCount(); ++i)
            if (params_.boundaries[k].region.contains(x0_[i])) ++counts[k];
    return counts;
}

void Membrane::perturb(double amplitude, std::uint64_t seed) {
    if (amplitude <= 0.0) return;
    for (int i = 0; i < particleCount(); ++i)
        x_[i].z() += amplitude * (2.0 * uniformFromHash(seed, std::uint64_t(i)) - 1.0);
}

double Membrane::mechanicalStrain(int i, int b, double length, double& thetaBar) const {
    const double eta = length / bonds_.restLength[b] - 1.0;  // eq. 10
    if (theta_.empty()) {
        thetaBar = 0.0;
        return eta;
    }
    // The printed eqs. 18-20 use theta_j alone; the mean is symmetric, so the pair forces stay
    // equal and opposite and momentum is conserved.
    thetaBar = 0.5 * (theta_[i] + theta_[bonds_.partners[b]]);
    return eta - params_.material.expansion * thetaBar;
}

// Writes only particle i's force and its own copies of its bonds, so the loop needs no atomics.
// Both copies of a bond see the same strain bit for bit, so they break and yield together.
template <bool kUpdateBonds, BondLawKind kLaw, bool kTheta, bool kBreak>
void Membrane::bondForcesFor(std::vector<Eigen::Vector3d>& force) {
    const int n = particleCount();
    force.resize(n);
    const auto& offsets = bonds_.offsets;
    const MaterialParams& m = params_.material;
    double lowest = 0.0;  // the most compressed bond's strain, for the power law's step
#pragma omp parallel for schedule(static) reduction(min : lowest) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        const Eigen::Vector3d xi = x_[i];
        for (int b = offsets[i]; b < offsets[i + 1]; ++b) {
            if (!bonds_.alive[b]) continue;
            const int j = bonds_.partners[b];
            const Eigen::Vector3d r = x_[j] - xi;
            const double length = r.norm();
            double eta = length / bonds_.restLength[b] - 1.0;  // eq. 10
            double thetaBar = 0.0;
            if constexpr (kTheta) {  // see mechanicalStrain()
                thetaBar = 0.5 * (theta_[i] + theta_[j]);
                eta -= m.expansion * thetaBar;
            }
            if constexpr (kBreak) {  // eq. 27/28
                double limit = criticalStretch_;
                if constexpr (kTheta) limit *= degradation(m.strengthLoss, thetaBar);
                if (eta > limit) {
                    if constexpr (kUpdateBonds) bonds_.alive[b] = 0;
                    continue;
                }
            }
            PlasticState state;
            if constexpr (kLaw == BondLawKind::Elastoplastic) {
                state = law_.yieldStep(eta, plastic_[b]);
                if constexpr (kUpdateBonds) plastic_[b] = state;
            }
            if constexpr (kLaw == BondLawKind::PowerLaw) {
                if (eta < 0.0) {  // where this compressed bond will be in dt, if it closes
                    const double rate = r.dot(v_[j] - v_[i]) / (length * bonds_.restLength[b]);
                    lowest = std::min(lowest, eta + std::min(0.0, dt_ * rate));
                }
            }
            double f = law_.forceAs<kLaw>(eta, state);
            if constexpr (kTheta) f *= degradation(m.stiffnessLoss, thetaBar);
            sum += (bondScale_[b] * f / length) * r;
        }
        force[i] = sum;
    }
    if constexpr (kUpdateBonds && kLaw == BondLawKind::PowerLaw)
        stiffening_ = std::max(1.0, law_.powerLawStiffening(std::max(lowest, -0.95)));
}

template <bool kUpdateBonds>
void Membrane::bondForces(std::vector<Eigen::Vector3d>& force) {
    const bool theta = !theta_.empty();
    const bool breakable = std::isfinite(criticalStretch_);
    auto forLaw = [&]<BondLawKind kLaw>() {
        if (theta && breakable) bondForcesFor<kUpdateBonds, kLaw, true, true>(force);
        if (theta && !breakable) bondForcesFor<kUpdateBonds, kLaw, true, false>(force);
        if (!theta && breakable) bondForcesFor<kUpdateBonds, kLaw, false, true>(force);
        if (!theta && !breakable) bondForcesFor<kUpdateBonds, kLaw, false, false>(force);
    };
    switch (law_.kind) {
        case BondLawKind::Linear:
            return forLaw.template operator()<BondLawKind::Linear>();
        case BondLawKind::PowerLaw:
            return forLaw.template operator()<BondLawKind::PowerLaw>();
        case BondLawKind::Elastoplastic:
            return forLaw.template operator()<BondLawKind::Elastoplastic>();
    }
}

void Membrane::computeForces(std::vector<Eigen::Vector3d>& force) const {
    if (solver_) {
        force.resize(x_.size());
        solver_->setTheta(theta_);
        solver_->forces(x_, force);
        return;
    }
    // With kUpdateBonds = false nothing of the membrane is written.
    const_cast<Membrane*>(this)->bondForces<false>(force);
}

Eigen::Vector3d Membrane::boundaryVelocity(int k, double t) const {
    const BoundaryCondition& bc = params_.boundaries[k];
    const double ramp = bc.rampTime > 0.0 ? std::min(1.0, t / bc.rampTime) : 1.0;
    return ramp * bc.velocity;
}

bool Membrane::isBad(int i) const {
    // Written so that NaN compares false and counts as bad.
    return !(v_[i].squaredNorm() <= speedLimit_ * speedLimit_) || !x_[i].allFinite();
}

void Membrane::kick(double h, double tNext) {
    const int n = particleCount();
    const Eigen::Vector3d gravity = params_.gravity;
    const double damping = params_.damping;
#pragma omp parallel for schedule(static) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i) {
        const std::int16_t c = constraint_[i];
        if (c == kFree)
            v_[i] += h * (force_[i] / mass_[i] + gravity - damping * v_[i]);
        else if (c == kPinned)
            v_[i].setZero();
        else
            v_[i] = boundaryVelocity(c, tNext);
    }
}

void Membrane::checkFinite() {
    const int n = particleCount();
    bool bad = false;
#pragma omp parallel for schedule(static) reduction(|| : bad) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i) bad = bad || isBad(i);
    if (!bad) return;
    time_ += dt_;
    ++steps_;
    reportBlowUp();
}

// Eq. 26 in one pass per particle: velocity, position and the blow-up check together.
void Membrane::integrate(double dt, double tNext) {
    const int n = particleCount();
    const Eigen::Vector3d gravity = params_.gravity;
    const double damping = params_.damping;
    bool bad = false;
#pragma omp parallel for schedule(static) reduction(|| : bad) if (n >= kParallelThreshold)
    for (int i = 0; i < n; ++i) {
        const std::int16_t c = constraint_[i];
        if (c == kFree)
            v_[i] += dt * (force_[i] / mass_[i] + gravity - damping * v_[i]);
        else if (c == kPinned)
            v_[i].setZero();
        else
            v_[i] = boundaryVelocity(c, tNext);
        x_[i] += dt * v_[i];
        bad = bad || isBad(i);
    }
    if (!bad) return;
    time_ = tNext;
    ++steps_;
    reportBlowUp();
}

void Membrane::accumulateForces() {
    if (solver_) {
        solver_->setTheta(theta_);
        for (const auto& [i, j] : solver_->advance(x_, v_, dt_, force_)) breakBond(i, j);
        stiffening_ = solver_->stiffening();
    } else
        bondForces<true>(force_);
    if (!pressureEdgeBonds_.empty()) addPressure(force_);
}

// Follower pressure: each intact triangle pushes its three corners along its current area
// vector, p A n / 3 each. A serial loop in triangle order keeps the sums identical for any
// thread count; it runs only when a scene sets a pressure.
void Membrane::addPressure(std::vector<Eigen::Vector3d>& force) const {
    const auto& triangles = lattice_.triangles;
    for (std::size_t t = 0; t < triangles.size(); ++t) {
        const auto& e = pressureEdgeBonds_[t];
        if ((e[0] >= 0 && !bonds_.alive[e[0]]) || (e[1] >= 0 && !bonds_.alive[e[1]]) ||
            (e[2] >= 0 && !bonds_.alive[e[2]]))
            continue;
        const auto& [a, b, c] = triangles[t];
        const Eigen::Vector3d area = 0.5 * (x_[b] - x_[a]).cross(x_[c] - x_[a]);
        const Eigen::Vector3d share = params_.pressure * area / 3.0;
        force[a] += share;
        force[b] += share;
        force[c] += share;
    }
}

int Membrane::piecesOfStep() {
    if (stiffening_ <= 1.0) return 1;
    // The bound scales as 1/sqrt(stiffness). Keep dt / bound within what was allowed at rest:
    // the safety factor, or the step's own ratio when it was set higher.
    const double allowed = std::max(params_.time.safety, dt_ / stableDt_) * stableDt_;
    const double needed = std::ceil(dt_ * std::sqrt(stiffening_) / allowed * (1.0 - 1e-12));
    const int pieces = int(std::clamp(needed, 1.0, double(kMaxPieces)));
    subSteps_ += pieces - 1;
    return pieces;
}

void Membrane::stepSymplecticEuler() {
    accumulateForces();  // at x^n
    const int pieces = piecesOfStep();
    double done = 0.0;
    for (int k = 0; k < pieces; ++k) {
        if (k > 0) accumulateForces();
        const double h = (dt_ - done) / (pieces - k);
        integrate(h, time_ + done + h);
        done += h;
    }
    forcesCurrent_ = false;
}

void Membrane::stepVelocityVerlet() {
    const int n = particleCount();
    if (!forcesCurrent_) accumulateForces();  // at x^n, unless the last step left them
    const int pieces = piecesOfStep();
    double done = 0.0;
    for (int k = 0; k < pieces; ++k) {
        const double h = (dt_ - done) / (pieces - k);
        kick(0.5 * h, time_ + done + h);
#pragma omp parallel for schedule(static) if (n >= kParallelThreshold)
        for (int i = 0; i < n; ++i) x_[i] += h * v_[i];
        accumulateForces();  // at x^n+1
        kick(0.5 * h, time_ + done + h);
        done += h;
    }
    forcesCurrent_ = true;
    checkFinite();
}

void Membrane::step() {
    if (params_.time.integrator == Integrator::VelocityVerlet)
        stepVelocityVerlet();
    else
        stepSymplecticEuler();
    if (diffusion_) {
        diffusion_->advance(theta_, bonds_, time_, dt_);  // theta^n -> theta^n+1
        forcesCurrent_ = false;
    }
    time_ += dt_;
    ++steps_;
}

void Membrane::reportBlowUp() const {
    int culprit = 0;
    while (culprit < particleCount() && !isBad(culprit)) ++culprit;
    const double suggested = 0.5 * std::min(dt_, stableDt_);
    std::ostringstream out;
    out << "numerical blow-up at step " << steps_ << " (t = " << time_ << " s): particle "
        << culprit << " (rest position " << x0_[culprit].x() << ", " << x0_[culprit].y()
        << ") has speed " << v_[culprit].norm() << " m/s, beyond the plausible limit "
        << speedLimit_ << " m/s. The time step " << dt_ << " s against the stable limit "
        << stableDt_ << " s is the usual cause; use dt <= " << suggested
        << " (or dt = \"auto\"), or slow the boundary velocities.";
    throw NumericalBlowUp(out.str(), steps_, culprit, suggested);
}

void Membrane::updateDamage() {
    if (!canDamage_) return;
    damage_.resize(particleCount());
    for (int i = 0; i < particleCount(); ++i) {
        double total = 0.0, intact = 0.0;
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
            total += bonds_.weight[b];
            if (!bonds_.alive[b]) continue;
            const double left = solver_            ? solver_->bondStrengthLeft(b)
                                : plastic_.empty() ? 1.0
                                                   : law_.strengthLeft(plastic_[b]);  // eq. 27
            intact += bonds_.weight[b] * left;
        }
        damage_[i] = total > 0.0 ? 1.0 - intact / total : 0.0;
    }
}

double Membrane::kineticEnergy() const {
    double sum = 0.0;
    for (int i = 0; i < particleCount(); ++i) sum += 0.5 * mass_[i] * v_[i].squaredNorm();
    return sum;
}

double Membrane::strainEnergy() const {
    if (solver_) {
        solver_->setTheta(theta_);
        return solver_->strainEnergy(x_);
    }
    const MaterialParams& m = params_.material;
    double sum = 0.0;
    for (int i = 0; i < particleCount(); ++i)
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
            if (!bonds_.alive[b]) continue;
            double thetaBar;
            const double length = (x_[bonds_.partners[b]] - x_[i]).norm();
            const double eta = mechanicalStrain(i, b, length, thetaBar);
            const PlasticState state = plastic_.empty() ? PlasticState{} : plastic_[b];
            // Each bond is stored from both ends: half of U_ij from each.
            sum += 0.5 * bondScale_[b] * bonds_.restLength[b] *
                   degradation(m.stiffnessLoss, thetaBar) * law_.energy(eta, state);
        }
    return sum;
}

double Membrane::maxSpeed() const {
    double m = 0.0;
    for (const auto& v : v_) m = std::max(m, v.norm());
    return m;
}

double Membrane::maxTheta() const {
    return theta_.empty() ? 0.0 : *std::max_element(theta_.begin(), theta_.end());
}

std::size_t Membrane::brokenBondCount() const {
    return std::size_t(std::count(bonds_.alive.begin(), bonds_.alive.end(), 0)) / 2;
}

Eigen::Vector3d Membrane::totalMomentum() const {
    Eigen::Vector3d p = Eigen::Vector3d::Zero();
    for (int i = 0; i < particleCount(); ++i) p += mass_[i] * v_[i];
    return p;
}

Eigen::Matrix3d Membrane::particleStress(int i) const {
    const MaterialParams& m = params_.material;
    Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
    for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
        if (!bonds_.alive[b]) continue;
        const Eigen::Vector3d r = x_[bonds_.partners[b]] - x_[i];
        const double length = r.norm();
        double thetaBar;
        const double eta = mechanicalStrain(i, b, length, thetaBar);
        const PlasticState state = plastic_.empty() ? PlasticState{} : plastic_[b];
        const double f = degradation(m.stiffnessLoss, thetaBar) * law_.force(eta, state);
        sigma += (bondScale_[b] * f / length) * r * r.transpose();
    }
    return sigma / (2.0 * volume_[i]);
}

FrameView Membrane::view(int frame) const {
    FrameView v;
    v.frame = frame;
    v.time = time_;
    v.positions = x_;
    v.velocities = v_;
    v.restPositions = x0_;
    v.theta = theta_;
    v.damage = damage_;
    v.restTriangles = lattice_.triangles;
    v.bondOffsets = bonds_.offsets;
    v.bondPartners = bonds_.partners;
    v.bondRestLength = bonds_.restLength;
    v.bondAlive = bonds_.alive;
    if (solver_) v.triangleAlive = solver_->triangleAlive();
    return v;
}

template void Membrane::bondForces<true>(std::vector<Eigen::Vector3d>&);
template void Membrane::bondForces<false>(std::vector<Eigen::Vector3d>&);

}  // namespace rend::sim
