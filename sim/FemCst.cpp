#include "sim/FemCst.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <utility>

#include "sim/Fracture.h"
#include "sim/Parallel.h"
#include "sim/SolverRegistry.h"

namespace rend::sim {

void triangleIncidence(const std::vector<std::array<int, 3>>& triangles, int particleCount,
                       std::vector<int>& offsets, std::vector<int>& corners) {
    offsets.assign(particleCount + 1, 0);
    for (const auto& t : triangles)
        for (int v : t) ++offsets[v + 1];
    for (int i = 0; i < particleCount; ++i) offsets[i + 1] += offsets[i];
    corners.assign(offsets.back(), 0);
    std::vector<int> fill(offsets.begin(), offsets.end() - 1);
    for (int t = 0; t < int(triangles.size()); ++t)
        for (int c = 0; c < 3; ++c) corners[fill[triangles[t][c]]++] = 3 * t + c;
}

namespace {

/// A guard, not physics: a principal stretch below this (an element squashed to 5%) is held
/// there, as the power-law look-ahead holds the strain (sim/Material.h, clampCompression).
constexpr double kMinStretch = 0.05;

/// Eigen-decomposition of a symmetric 2x2 matrix in closed form: values largest first, unit
/// eigenvectors as the columns of a rotation (the identity when the values are equal).
struct Principal {
    Eigen::Vector2d value;
    Eigen::Matrix2d vectors;
};

Principal principal(const Eigen::Matrix2d& a) {
    const double offDiagonal = 0.5 * (a(0, 1) + a(1, 0));
    const double mean = 0.5 * (a(0, 0) + a(1, 1)), half = 0.5 * (a(0, 0) - a(1, 1));
    const double radius =
        std::sqrt(half * half + offDiagonal * offDiagonal);  // strains: no overflow
    Principal p{{mean + radius, mean - radius}, Eigen::Matrix2d::Identity()};
    if (radius > 0.0) {  // (a - value_0 I) v = 0, from whichever row keeps v far from zero
        Eigen::Vector2d v = half >= 0.0 ? Eigen::Vector2d(half + radius, offDiagonal)
                                        : Eigen::Vector2d(offDiagonal, radius - half);
        v.normalize();
        p.vectors << v.x(), -v.y(), v.y(), v.x();
    }
    return p;
}

/// Principal stretches l_k and Biot strains e_k = l_k - 1 from the principal Green strains
/// g_k = (l_k^2 - 1) / 2; e_k = 2 g_k / (1 + l_k) keeps the digits of a small strain.
void stretchesOf(const Eigen::Vector2d& green, Eigen::Vector2d& stretch, Eigen::Vector2d& strain) {
    for (int k = 0; k < 2; ++k) {
        const double square = 1.0 + 2.0 * green[k];
        if (square > kMinStretch * kMinStretch) {
            stretch[k] = std::sqrt(square);
            strain[k] = 2.0 * green[k] / (1.0 + stretch[k]);
        } else {
            stretch[k] = kMinStretch;
            strain[k] = kMinStretch - 1.0;
        }
    }
}

/// s^n - 1 - n e with s = 1 + e, by the binomial series where the closed form would cancel
/// (small e), and exactly for a whole n (the series ends).
double powerExcess(double e, double n) {
    const bool whole = n == std::floor(n) && n <= 16.0;
    if (!whole && std::abs(e) >= 0.1) return std::expm1(n * std::log1p(e)) - n * e;
    double term = 0.5 * n * (n - 1.0) * e * e, sum = term;
    for (int k = 2; k < 64 && term != 0.0; ++k) {
        term *= (n - k) / (k + 1) * e;
        sum += term;
        if (!whole && std::abs(term) <= 1e-17 * std::abs(sum)) break;
    }
    return sum;
}

/// The power law's shape at unit stiffness (eq. 19 with c = 1): its energy Phi(e) and the
/// strain measure q(e) = sign(e) sqrt(2 Phi(e)) with its derivative q' = Phi'/q (1 at rest).
struct PowerShape {
    double q, slope, energy;
};

PowerShape powerShape(const BondLaw& law, double e) {
    const double s = 1.0 + e, n = law.powerN;
    const double w = e * (2.0 + e) / s;  // s - 1/s without cancellation
    const double energy = law.powerC * w * w + law.powerCStar * powerExcess(e, n);
    const double force =
        2.0 * law.powerC * w * (1.0 + 1.0 / (s * s)) +
        law.powerCStar * n * (n == 2.0 ? e : std::expm1((n - 1.0) * std::log1p(e)));
    // Past the peak of a softening law (c* < 0, large n) Phi can fall to 0: nothing is stored.
    if (!(energy > 0.0)) return {0.0, e == 0.0 ? 1.0 : 0.0, 0.0};
    const double q = std::copysign(std::sqrt(2.0 * energy), e);
    return {q, force / q, energy};
}

}  // namespace

FemCst::FemCst(const Lattice& lattice, const Material& material, double thickness,
               double criticalStrain)
    : material_(material),
      lambda_(material.lambda()),
      mu_(material.mu()),
      thickness_(thickness),
      criticalStrain_(criticalStrain),
      expansion_(material.expansion()),
      law_(material.law(1.0)) {
    const auto& p = lattice.positions;
    for (int index = 0; index < int(lattice.triangles.size()); ++index) {
        const auto& t = lattice.triangles[index];
        // Rest edges in the triangle's own plane (u along edge 01), so curved rest shapes such
        // as the sphere work; St. Venant-Kirchhoff is isotropic, so the frame is free.
        const Eigen::Vector3d e1 = p[t[1]] - p[t[0]], e2 = p[t[2]] - p[t[0]];
        const Eigen::Vector3d u = e1.normalized();
        const Eigen::Vector3d w = e1.cross(e2).cross(e1).normalized();
        Eigen::Matrix2d Dm;
        Dm << e1.dot(u), e2.dot(u), e1.dot(w), e2.dot(w);
        const double area = 0.5 * std::abs(Dm.determinant());
        if (area <= 0.0) continue;  // a degenerate rest triangle carries nothing
        elements_.push_back({t, Dm.inverse(), area, index, {-1, -1, -1}});
    }
    findNeighbours();
    elementOf_.assign(lattice.triangles.size(), -1);
    for (int t = 0; t < int(elements_.size()); ++t) elementOf_[elements_[t].triangle] = t;
    std::vector<std::array<int, 3>> kept;
    for (const Element& e : elements_) kept.push_back(e.v);
    triangleIncidence(kept, int(p.size()), cornerOffsets_, corners_);
    eroding_.assign(elements_.size(), 0);
    if (law_.kind == BondLawKind::Elastoplastic) {
        plasticStrain_.assign(elements_.size(), Eigen::Matrix2d::Zero());
        maxStrain_.assign(elements_.size(), 0.0);
    }
    bindOwn({}, int(p.size()), lattice.triangles);
}

std::unique_ptr<Solver> FemCst::make(const SolverSetUp& s) {
    auto fem = std::make_unique<FemCst>(s.lattice, s.material, s.params.sheet.thickness,
                                        bandCriticalStrain(s.params));
    fem->applyMaterialMaps(s.params.materialMaps, s.rest);
    return fem;
}

void FemCst::applyMaterialMaps(std::span<const MaterialMap> maps,
                               std::span<const Eigen::Vector3d> rest) {
    double Element::*factors[] = {&Element::yield, &Element::softening, &Element::powerRatio,
                                  &Element::powerExponent};  // in kLawProperties' order
    for (int k = 0; k < 4; ++k) {
        if (!mapsProperty(maps, kLawProperties[k])) continue;
        const std::vector<double> f = materialFactors(kLawProperties[k], maps, rest);
        for (Element& element : elements_)
            element.*factors[k] = (f[element.v[0]] + f[element.v[1]] + f[element.v[2]]) / 3.0;
    }
    ownPowerLaws_ = mapsProperty(maps, MappedProperty::PowerRatio) ||
                    mapsProperty(maps, MappedProperty::PowerExponent);
    if (!mapsProperty(maps, MappedProperty::YoungsModulus) &&
        !mapsProperty(maps, MappedProperty::FractureEnergy))
        return;
    const std::vector<double> e = materialFactors(MappedProperty::YoungsModulus, maps, rest);
    const std::vector<double> g = materialFactors(MappedProperty::FractureEnergy, maps, rest);
    for (Element& element : elements_) {
        double sumE = 0.0, sumG = 0.0;
        for (const int v : element.v) sumE += e[v], sumG += g[v];
        element.stiffness = sumE / 3.0;
        element.strength = std::sqrt(sumG / sumE);
    }
}

void FemCst::findNeighbours() {
    std::map<std::pair<int, int>, std::pair<int, int>> side;  // edge -> (element, side)
    for (int e = 0; e < int(elements_.size()); ++e)
        for (int s = 0; s < 3; ++s) {
            const auto key = std::minmax(elements_[e].v[(s + 1) % 3], elements_[e].v[(s + 2) % 3]);
            const auto [it, added] = side.try_emplace(key, e, s);
            if (added) continue;
            elements_[e].across[s] = it->second.first;
            elements_[it->second.first].across[it->second.second] = e;
        }
}

Eigen::Matrix<double, 3, 2> FemCst::deformationGradient(const Element& e,
                                                        std::span<const Eigen::Vector3d> x) const {
    Eigen::Matrix<double, 3, 2> Ds;
    Ds.col(0) = x[e.v[1]] - x[e.v[0]];
    Ds.col(1) = x[e.v[2]] - x[e.v[0]];
    return Ds * e.restInverse;
}

Eigen::Matrix2d FemCst::greenStrain(int t, std::span<const Eigen::Vector3d> x) const {
    const Eigen::Matrix<double, 3, 2> F = deformationGradient(elements_[t], x);
    return 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
}

std::unique_ptr<Workspace> FemCst::makeWorkspace() const {
    auto work = std::make_unique<FemWorkspace>();
    work->cornerForce.resize(3 * elements_.size());
    return work;
}

// One parallel pass over the elements into per-corner forces, then the gather: each particle
// sums its own corners, so the loop needs no atomics and no ordering by thread.
void FemCst::forces(const StepState& s, Workspace& work,
                    std::vector<Eigen::Vector3d>& force) const {
    std::vector<Eigen::Vector3d>& cornerForce = static_cast<FemWorkspace&>(work).cornerForce;
    const std::span<const Eigen::Vector3d> x = s.x;
    const bool ahead = !s.v.empty() && law_.kind == BondLawKind::PowerLaw;
    const int elements = int(elements_.size());
    double lowest = 0.0;
#pragma omp parallel for schedule(static) reduction(min \
                                                    : lowest) if (elements >= kParallelThreshold)
    for (int t = 0; t < elements; ++t) {
        const Element& e = elements_[t];
        if (!elementAlive(t)) {
            cornerForce[3 * t] = cornerForce[3 * t + 1] = cornerForce[3 * t + 2] =
                Eigen::Vector3d::Zero();
            continue;
        }
        // The thermal strain stretches the rest state isotropically by s = 1 + alpha theta:
        // Psi(F / s), whose derivative is P(F / s) / s.
        const double theta = thetaOf(e, s.theta), stretch = 1.0 + expansion_ * theta;
        const Eigen::Matrix<double, 3, 2> F = deformationGradient(e, x) / stretch;
        const bool linear = law_.kind == BondLawKind::Linear;
        Eigen::Matrix2d S;
        if (linear) {
            const Eigen::Matrix2d E = 0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity());
            S = e.stiffness * material_.stiffnessFactor(theta) *
                (lambda_ * E.trace() * Eigen::Matrix2d::Identity() + 2.0 * mu_ * E);
        } else {
            Eigen::Matrix<double, 3, 2> rate;
            if (ahead) rate = deformationGradient(e, s.v) / stretch;
            S = e.stiffness * material_.stiffnessFactor(theta) *
                nonlinearStress(t, F, stretchesOf(F), nullptr, ahead ? &rate : nullptr, s.dt,
                                ahead ? &lowest : nullptr);
        }
        const Eigen::Matrix<double, 3, 2> H =
            -e.restArea * thickness_ / stretch * F * S * e.restInverse.transpose();
        cornerForce[3 * t + 1] = H.col(0);
        cornerForce[3 * t + 2] = H.col(1);
        cornerForce[3 * t] = -H.col(0) - H.col(1);
    }
    const int n = int(x.size());
    force.resize(n);
    forEachIndex(n >= kParallelThreshold, 0, n, [&](int i) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int k = cornerOffsets_[i]; k < cornerOffsets_[i + 1]; ++k)
            sum += cornerForce[corners_[k]];
        force[i] = sum;
    });
    static_cast<FemWorkspace&>(work).lowest = lowest;
}

std::vector<double> FemCst::stiffnessRowSums(int particleCount) const {
    // At rest the element stiffness is K_ab = A0 h B_a^T C B_b with B_a the gradient of vertex
    // a's shape function; |C| <= lambda* + 2 mu bounds each 2x2 block's norm by
    // A0 h (lambda* + 2 mu) |g_a| |g_b|, a row of the block by sqrt(2) times that; half of the
    // row sum over b is the k_i of Solver::stiffnessRowSums.
    std::vector<double> sums(particleCount, 0.0);
    for (const Element& e : elements_) {
        const Eigen::Vector2d g1 = e.restInverse.row(0).transpose();
        const Eigen::Vector2d g2 = e.restInverse.row(1).transpose();
        const Eigen::Vector2d g[3] = {-g1 - g2, g1, g2};
        const double total = g[0].norm() + g[1].norm() + g[2].norm();
        for (int a = 0; a < 3; ++a)
            sums[e.v[a]] += e.stiffness * e.restArea * thickness_ * (lambda_ + 2.0 * mu_) *
                            g[a].norm() * total * std::sqrt(2.0) / 2.0;
    }
    return sums;
}

double FemCst::thetaOf(const Element& e, std::span<const double> theta) {
    if (theta.empty()) return 0.0;
    return (theta[e.v[0]] + theta[e.v[1]] + theta[e.v[2]]) / 3.0;
}

void FemCst::erode(int t, bool breakSides) {
    const int triangle = elements_[t].triangle;
    damage_->removeTriangle(triangle);
    if (!breakSides) return;
    for (int s = 0; s < 3; ++s) {  // a side comes apart once no living element holds it
        const int other = elements_[t].across[s];
        if (other >= 0 && elementAlive(other)) continue;
        damage_->breakEdge(damage_->triangleEdges(triangle)[s]);
    }
}

FemCst::Stretches FemCst::stretchesOf(const Eigen::Matrix<double, 3, 2>& F) {
    const Principal c = principal(0.5 * (F.transpose() * F - Eigen::Matrix2d::Identity()));
    Stretches p{c.vectors, {}, {}};
    rend::sim::stretchesOf(c.value, p.stretch, p.strain);
    return p;
}

Eigen::Matrix2d FemCst::nonlinearStress(int t, const Eigen::Matrix<double, 3, 2>& F,
                                        const Stretches& principal, double* energy,
                                        const Eigen::Matrix<double, 3, 2>* rate, double dt,
                                        double* lowest) const {
    const Eigen::Vector2d& l = principal.stretch;
    const Eigen::Vector2d& e = principal.strain;
    const Eigen::Matrix2d& V = principal.directions;
    if (lowest) {  // where each principal strain will be in dt if it keeps closing
        for (int k = 0; k < 2; ++k) {
            // dl/dt = (F n) . (dF/dt n) / l along the principal direction n.
            const double closing = rate ? (F * V.col(k)).dot(*rate * V.col(k)) / l[k] : 0.0;
            *lowest = std::min(*lowest, e[k] + std::min(0.0, dt * closing));
        }
    }
    Eigen::Matrix2d biot;  // Biot stress in U's eigenbasis
    if (law_.kind == BondLawKind::PowerLaw) {
        // W = 1/2 q^T D q with D = [[lambda* + 2 mu, lambda*], [lambda*, lambda* + 2 mu]].
        const BondLaw law = ownPowerLaws_ ? lawOf(t) : law_;
        const PowerShape a = powerShape(law, e[0]), b = powerShape(law, e[1]);
        const double da = (lambda_ + 2.0 * mu_) * a.q + lambda_ * b.q;
        const double db = lambda_ * a.q + (lambda_ + 2.0 * mu_) * b.q;
        biot << da * a.slope, 0.0, 0.0, db * b.slope;
        if (energy) *energy = 0.5 * (a.q * da + b.q * db);
    } else {
        const Eigen::Matrix2d elastic =
            V * e.asDiagonal() * V.transpose() - plasticStrain_[t];  // (U - I) - Ep
        const Eigen::Matrix2d hooke =
            lambda_ * elastic.trace() * Eigen::Matrix2d::Identity() + 2.0 * mu_ * elastic;
        biot = V.transpose() * hooke * V;
        if (energy)
            *energy = 0.5 * lambda_ * elastic.trace() * elastic.trace() +
                      mu_ * (elastic.array() * elastic.array()).sum();
    }
    Eigen::Matrix2d S;  // 2 T_ij / (l_i + l_j): the chain rule through U dU + dU U = dC
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j) S(i, j) = 2.0 * biot(i, j) / (l[i] + l[j]);
    return V * S * V.transpose();
}

void FemCst::yieldElement(int t, const Stretches& p) {
    const Principal elastic = principal(
        p.directions * p.strain.asDiagonal() * p.directions.transpose() - plasticStrain_[t]);
    // The total strain along the most stretched elastic direction, the bond's eta of eq. 20.
    // With a yield map's factor k the law is k f(eta / k), whose plastic strain is
    // k kappa(T / k) (T kept in real units).
    const double k = elements_[t].yield;
    const BondLaw law = lawOf(t);
    const double before = k * law.plasticStrain({maxStrain_[t] / k});
    const double trial = elastic.value[0] + before;
    if (!(trial > maxStrain_[t])) return;
    maxStrain_[t] = trial;
    const double flow = k * law.plasticStrain({trial / k}) - before;
    if (flow != 0.0) {
        const Eigen::Vector2d n = elastic.vectors.col(0);
        plasticStrain_[t] += flow * n * n.transpose();
    }
}

bool FemCst::pastCriticalStrain(int t, std::span<const Eigen::Vector3d> x,
                                std::span<const double> thetas) const {
    // Largest principal Green strain of the mechanical part against the critical stretch's,
    // (l^2 - 1) / 2, with l = 1 + eps_c weakened by theta.
    const double theta = thetaOf(elements_[t], thetas);
    const double limit = criticalStrain_ * elements_[t].strength * material_.strengthFactor(theta);
    const double stretch = 1.0 + expansion_ * theta;
    const Eigen::Matrix2d E =
        0.5 * ((greenStrain(t, x) * 2.0 + Eigen::Matrix2d::Identity()) / (stretch * stretch) -
               Eigen::Matrix2d::Identity());
    const double centre = 0.5 * E.trace();
    const double radius = std::hypot(0.5 * (E(0, 0) - E(1, 1)), E(0, 1));
    return centre + radius > 0.5 * ((1 + limit) * (1 + limit) - 1);
}

void FemCst::erodeFlagged(bool breakSides) {
    for (int t = 0; t < int(elements_.size()); ++t)
        if (eroding_[t]) {
            eroding_[t] = 0;
            erode(t, breakSides);
        }
}

void FemCst::fracture(const StepState& s, Workspace&) {
    const std::span<const Eigen::Vector3d> x = s.x;
    const bool breakable = std::isfinite(criticalStrain_);
    if (maxStrain_.empty() && !breakable) return;
    const int elements = int(elements_.size());
    forEachIndex(elements >= kParallelThreshold, 0, elements,
                 [&](int t) {  // each element's own history and flag
                     if (!elementAlive(t)) return;
                     const double stretch = 1.0 + expansion_ * thetaOf(elements_[t], s.theta);
                     if (!maxStrain_.empty())
                         yieldElement(t,
                                      stretchesOf(deformationGradient(elements_[t], x) / stretch));
                     if (breakable && pastCriticalStrain(t, x, s.theta)) eroding_[t] = 1;
                 });
    erodeFlagged(true);
}

void FemCst::cut(const std::vector<std::array<int, 2>>&) {
    // The notches broke their edges in the DamageState; an element with one of them as a side
    // goes, its other sides stay whole (the bonds along them still diffuse). Flag first, so the
    // elements removed do not depend on the order.
    for (int t = 0; t < int(elements_.size()); ++t)
        for (const int e : damage_->triangleEdges(elements_[t].triangle))
            if (!damage_->edgeIntact(e)) eroding_[t] = 1;
    erodeFlagged(false);
}

double FemCst::strainEnergy(const StepState& s, Workspace&) const {
    const std::span<const Eigen::Vector3d> x = s.x;
    double sum = 0.0;
    for (int t = 0; t < int(elements_.size()); ++t) {
        if (!elementAlive(t)) continue;
        const double theta = thetaOf(elements_[t], s.theta), stretch = 1.0 + expansion_ * theta;
        const Eigen::Matrix2d E =
            0.5 * ((greenStrain(t, x) * 2.0 + Eigen::Matrix2d::Identity()) / (stretch * stretch) -
                   Eigen::Matrix2d::Identity());
        double density;
        if (law_.kind == BondLawKind::Linear) {
            density = 0.5 * lambda_ * E.trace() * E.trace() + mu_ * (E.array() * E.array()).sum();
        } else {
            const Eigen::Matrix<double, 3, 2> F = deformationGradient(elements_[t], x) / stretch;
            nonlinearStress(t, F, stretchesOf(F), &density);
        }
        sum += elements_[t].stiffness * elements_[t].restArea * thickness_ *
               material_.stiffnessFactor(theta) * density;
    }
    return sum;
}

void FemCst::advance(const StepState& s, Workspace& work, std::vector<Eigen::Vector3d>& force) {
    fracture(s, work);
    forces(s, work, force);
    // The power law's tangent grows as s^-4 in compression (eq. 19); the others do not stiffen.
    const double lowest = static_cast<FemWorkspace&>(work).lowest;
    stiffening_ = law_.kind == BondLawKind::PowerLaw ? stiffestAt(clampCompression(lowest)) : 1.0;
}

double FemCst::stiffestAt(double strain) const {
    if (!(strain < 0.0)) return 1.0;
    if (!ownPowerLaws_) return std::max(1.0, law_.powerLawStiffening(strain));
    // With power-law maps, every element's law at the most compressed strain anywhere: a bound,
    // since each tangent only grows as the element closes.
    double stiffest = 1.0;
    for (int t = 0; t < int(elements_.size()); ++t)
        stiffest = std::max(stiffest, lawOf(t).powerLawStiffening(strain));
    return stiffest;
}

double FemCst::strengthLeft(int t) const {
    return maxStrain_.empty() ? 1.0 : lawOf(t).strengthLeft({maxStrain_[t] / elements_[t].yield});
}

void FemCst::reportStrength(DamageState& damage) const {
    if (maxStrain_.empty()) return;  // only the elastoplastic law loses strength
    const BondFamilies& bonds = *sharedBonds_;
    for (int i = 0; i < bonds.particleCount(); ++i)
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
            damage.weaken(b, bondStrength(b, i, bonds.partners[b]));
}

double FemCst::bondStrength(int b, int i, int j) const {
    double sum = 0.0;
    int count = 0;
    if (const int edge = damage_->bondEdge(b); edge >= 0)
        for (int triangle : damage_->edgeTriangles(edge))
            if (const int t = triangle >= 0 ? elementOf_[triangle] : -1; t >= 0 && elementAlive(t))
                sum += strengthLeft(t), ++count;
    if (count > 0) return sum / count;
    double ends = 0.0;
    for (int end : {i, j}) {  // a bond no element side carries: its ends' mean
        double own = 0.0;
        int held = 0;
        for (int k = cornerOffsets_[end]; k < cornerOffsets_[end + 1]; ++k)
            if (const int t = corners_[k] / 3; elementAlive(t)) own += strengthLeft(t), ++held;
        ends += held > 0 ? own / held : 1.0;
    }
    return 0.5 * ends;
}

}  // namespace rend::sim
