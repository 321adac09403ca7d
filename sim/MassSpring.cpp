#include "sim/MassSpring.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "sim/Fracture.h"
#include "sim/Parallel.h"
#include "sim/SolverRegistry.h"

namespace rend::sim {

MassSpring::MassSpring(const Lattice& lattice, SpringModel model, const Material& material,
                       double thickness, double criticalStrain, std::span<const MaterialMap> maps)
    : model_(model),
      material_(material),
      poisson_(material.poissonRatio()),
      law_(material.law(1.0)),
      expansion_(material.expansion()),
      criticalStrain_(criticalStrain) {
    const double t = thickness, nu = poisson_;
    const auto& p = lattice.positions;
    const std::vector<double> eFactor = materialFactors(MappedProperty::YoungsModulus, maps, p);
    std::map<std::pair<int, int>, int> index;
    auto springOf = [&](int a, int b) {
        const auto key = std::minmax(a, b);
        const auto [it, added] = index.try_emplace(key, int(springs_.size()));
        if (added) springs_.push_back({key.first, key.second, (p[a] - p[b]).norm(), 0.0});
        return it->second;
    };
    for (const auto& v : lattice.triangles) {
        Triangle tri{v, {}, {}, 0.0, 0.0, int(&v - lattice.triangles.data())};
        for (int s = 0; s < 3; ++s) {
            const int a = v[(s + 1) % 3], b = v[(s + 2) % 3];
            tri.side[s] = springOf(a, b);
            tri.restLength[s] = (p[a] - p[b]).norm();
        }
        tri.restArea = 0.5 * (p[v[1]] - p[v[0]]).cross(p[v[2]] - p[v[0]]).norm();
        if (tri.restArea <= 0.0) continue;
        const double E =
            material.youngsModulus() * (eFactor[v[0]] + eFactor[v[1]] + eFactor[v[2]]) / 3.0;
        tri.fixedPart = E * t / (8.0 * (1.0 - nu * nu) * tri.restArea);  // eq. 12
        for (int s = 0; s < 3; ++s) {
            const double c2 = tri.restLength[s] * tri.restLength[s];
            const double a2 = std::pow(tri.restLength[(s + 1) % 3], 2);
            const double b2 = std::pow(tri.restLength[(s + 2) % 3], 2);
            springs_[tri.side[s]].k +=
                model == SpringModel::VanGelder
                    ? E * t / (1.0 + nu) * tri.restArea / c2 +
                          E * t * nu / (1.0 - nu * nu) * (a2 + b2 - c2) / (8.0 * tri.restArea)
                    : E * t / (8.0 * (1.0 - nu) * tri.restArea) * (a2 + b2 - c2);  // eq. 16-17
        }
        triangles_.push_back(tri);
    }
    const int n = int(p.size());
    springOffsets_.assign(n + 1, 0);
    for (const Spring& s : springs_) ++springOffsets_[s.i + 1], ++springOffsets_[s.j + 1];
    for (int i = 0; i < n; ++i) springOffsets_[i + 1] += springOffsets_[i];
    particleSprings_.resize(springOffsets_.back());
    std::vector<int> fill(springOffsets_.begin(), springOffsets_.end() - 1);
    for (int s = 0; s < int(springs_.size()); ++s) {
        particleSprings_[fill[springs_[s].i]++] = s + 1;
        particleSprings_[fill[springs_[s].j]++] = -(s + 1);
    }
    if (law_.kind == BondLawKind::Elastoplastic) plastic_.assign(springs_.size(), {});
    if (mapsProperty(maps, MappedProperty::YoungsModulus) ||
        mapsProperty(maps, MappedProperty::FractureEnergy)) {
        const std::vector<double> g = materialFactors(MappedProperty::FractureEnergy, maps, p);
        for (const Spring& s : springs_)
            strength_.push_back(std::sqrt((g[s.i] + g[s.j]) / (eFactor[s.i] + eFactor[s.j])));
    }
    std::vector<double>* factors[] = {&yield_, &softening_, &ratio_,
                                      &exponent_};  // in kLawProperties' order
    for (int k = 0; k < 4; ++k) {
        const MappedProperty property = kLawProperties[k];
        if (!mapsProperty(maps, property)) continue;
        const std::vector<double> f = materialFactors(property, maps, p);
        std::vector<double>& factor = *factors[k];
        for (const Spring& s : springs_) factor.push_back(0.5 * (f[s.i] + f[s.j]));
    }
    bindOwn({}, n, lattice.triangles);
}

std::unique_ptr<Solver> MassSpring::makeVanGelder(const SolverSetUp& s) {
    return std::make_unique<MassSpring>(s.lattice, SpringModel::VanGelder, s.material,
                                        s.params.sheet.thickness, springCriticalStrain(s.params),
                                        s.params.materialMaps);
}

std::unique_ptr<Solver> MassSpring::makeTwoParameter(const SolverSetUp& s) {
    return std::make_unique<MassSpring>(s.lattice, SpringModel::TwoParameter, s.material,
                                        s.params.sheet.thickness, bandCriticalStrain(s.params),
                                        s.params.materialMaps);
}

void MassSpring::onBind() {
    const auto& edges = damage_->edges();
    bool same = edges.size() == springs_.size();
    for (std::size_t s = 0; same && s < springs_.size(); ++s)
        same = edges[s] == std::array<int, 2>{springs_[s].i, springs_[s].j};
    if (!same) throw std::logic_error("the springs are not the damage state's edges");
}

std::unique_ptr<Workspace> MassSpring::makeWorkspace() const {
    auto work = std::make_unique<SpringWorkspace>();
    work->tension.resize(springs_.size());
    work->triangleTension.resize(triangles_.size());
    return work;
}

void MassSpring::fracture(const StepState& state, Workspace&) {
    if (plastic_.empty() && !std::isfinite(criticalStrain_)) return;  // nothing to record
    for (int s = 0; s < int(springs_.size()); ++s) {
        if (!springAlive(s)) continue;
        double thetaBar;
        const double eta = mechanicalStrain(s, state, thetaBar);
        if (!plastic_.empty())
            plastic_[s] = law_.yieldStep(eta / yieldOf(s), plastic_[s]);  // eq. 20
        const double limit = criticalStrain_ * material_.strengthFactor(thetaBar) *
                             (strength_.empty() ? 1.0 : strength_[s]);
        if (!(eta > limit)) continue;
        damage_->breakEdge(s);  // serial, in spring order
    }
}

void MassSpring::advance(const StepState& state, Workspace& work,
                         std::vector<Eigen::Vector3d>& force) {
    fracture(state, work);
    if (law_.kind == BondLawKind::PowerLaw)  // the clamp is the peridynamic loop's
        stiffening_ = stiffestSpring(state);
    forces(state, work, force);
}

void MassSpring::reportStrength(DamageState& damage) const {
    if (plastic_.empty()) return;
    for (int b = 0; b < int(damage.bondAlive().size()); ++b)
        if (const int s = damage.bondEdge(b); s >= 0)
            damage.weaken(b, lawOf(s).strengthLeft(plastic_[s]));  // eq. 27's gamma of the side
}

double MassSpring::stiffestSpring(const StepState& state) const {
    const auto& x = state.x;
    const auto& v = state.v;
    const double dt = state.dt;
    const bool own = ownLaws();
    const int count = int(springs_.size());
    const auto lookAhead = [&](int s, double& stiffest) {
        if (!springAlive(s)) return;
        double thetaBar;
        const double eta = mechanicalStrain(s, state, thetaBar);
        if (eta >= 0.0) return;
        const Spring& sp = springs_[s];
        const Eigen::Vector3d r = x[sp.j] - x[sp.i];
        const double rate = r.dot(v[sp.j] - v[sp.i]) / (r.norm() * sp.restLength);
        const double ahead = clampCompression(eta + std::min(0.0, dt * rate));
        stiffest = std::max(
            stiffest, own ? lawOf(s).powerLawStiffening(ahead) : law_.powerLawStiffening(ahead));
    };
    return largestOverIndices(count >= kParallelThreshold, 0, count, 1.0, lookAhead);
}

double MassSpring::mechanicalStrain(int s, const StepState& state, double& thetaBar) const {
    const Spring& sp = springs_[s];
    const auto& x = state.x;
    const auto& theta = state.theta;
    thetaBar = theta.empty() ? 0.0 : 0.5 * (theta[sp.i] + theta[sp.j]);
    return (x[sp.j] - x[sp.i]).norm() / sp.restLength - 1.0 - expansion_ * thetaBar;
}

void MassSpring::tensions(const StepState& state, SpringWorkspace& work) const {
    std::vector<double>& tension = work.tension;
    const int count = int(springs_.size());
    if (model_ == SpringModel::VanGelder) {
        forEachIndex(count >= kParallelThreshold, 0, count, [&](int s) {
            if (!springAlive(s)) {
                tension[s] = 0.0;
                return;
            }
            double thetaBar;
            const double eta = mechanicalStrain(s, state, thetaBar);
            const PlasticState plastic = plastic_.empty() ? PlasticState{} : plastic_[s];
            const double k = yieldOf(s);
            tension[s] = springs_[s].k * springs_[s].restLength * k *
                         lawOf(s).force(eta / k, plastic) * material_.stiffnessFactor(thetaBar);
        });
        return;
    }
    switch (law_.kind) {
        case BondLawKind::Linear:
            return twoParameterTensions<BondLawKind::Linear>(state, work);
        case BondLawKind::PowerLaw:
            return twoParameterTensions<BondLawKind::PowerLaw>(state, work);
        case BondLawKind::Elastoplastic:
            return twoParameterTensions<BondLawKind::Elastoplastic>(state, work);
    }
}

MassSpring::SideStrains MassSpring::sideStrains(int k, const StepState& state) const {
    const Triangle& tri = triangles_[k];
    const auto& thetas = state.theta;
    double theta = 0.0;
    if (!thetas.empty()) theta = (thetas[tri.v[0]] + thetas[tri.v[1]] + thetas[tri.v[2]]) / 3;
    return sideStrains(state.x, tri.v, tri.restLength, tri.restArea, theta);
}

MassSpring::SideStrains MassSpring::sideStrains(std::span<const Eigen::Vector3d> x,
                                                const std::array<int, 3>& v,
                                                const std::array<double, 3>& restLength,
                                                double restArea, double theta) const {
    SideStrains e;
    e.theta = theta;
    const Eigen::Vector3d& a = x[v[0]];
    const double area = 0.5 * (x[v[1]] - a).cross(x[v[2]] - a).norm();
    // The thermal strain scales the triangle's rest shape by s = 1 + alpha theta_bar: rest
    // lengths and heights by s.
    const double stretch = 1.0 + expansion_ * theta;
    for (int s = 0; s < 3; ++s) {
        const double l = (x[v[(s + 1) % 3]] - x[v[(s + 2) % 3]]).norm();
        const double l0 = restLength[s];
        e.tangent[s] = l / (l0 * stretch) - 1.0;
        e.normal[s] = (area / l) / (restArea / l0 * stretch) - 1.0;
    }
    return e;
}

// Each triangle's share of its three sides' tensions, then the sum per side in a fixed order
// (triangle by triangle), so the result does not depend on threads.
template <BondLawKind K>
void MassSpring::twoParameterTensions(const StepState& state, SpringWorkspace& work) const {
    const auto& x = state.x;
    std::vector<double>& tension = work.tension;
    std::vector<std::array<double, 3>>& triangleTension = work.triangleTension;
    const int triangles = int(triangles_.size());
    forEachIndex(triangles >= kParallelThreshold, 0, triangles, [&](int k) {
        const Triangle& tri = triangles_[k];
        if (!damage_->keptTriangles()[tri.triangle]) {
            triangleTension[k] = {0.0, 0.0, 0.0};
            return;
        }
        SideStrains e = sideStrains(k, state);
        // Elastoplastic: the rest triangle of sides l0 (1 + p), p the springs' permanent strains
        // (on the loading path, eq. 20's at the current strain). Left at l0 while elastic.
        std::array<double, 3> rest = tri.restLength;
        double restArea = tri.restArea, fixedPart = tri.fixedPart;
        if constexpr (K == BondLawKind::Elastoplastic) {
            bool yielded = false;
            for (int s = 0; s < 3; ++s) {
                const double strain = e.tangent[s];
                const int side = tri.side[s];
                const double k = yieldOf(side);
                const double p =
                    strain - k * lawOf(side).template forceAs<K>(strain / k, plastic_[side]);
                yielded = yielded || p != 0.0;
                rest[s] *= 1.0 + p;
            }
            if (yielded) {
                const double a = rest[0], b = rest[1], c = rest[2];  // Heron
                const double heron = (a + b + c) * (-a + b + c) * (a - b + c) * (a + b - c);
                restArea = 0.25 * std::sqrt(std::max(heron, 0.0));
                // A plastic flow that flattens the triangle leaves it nothing to carry.
                if (!(restArea > 1e-3 * tri.restArea)) {
                    triangleTension[k] = {0.0, 0.0, 0.0};
                    return;
                }
                fixedPart *= tri.restArea / restArea;  // eq. 12 for the new rest triangle
                e = sideStrains(x, tri.v, rest, restArea, e.theta);
            }
        }
        std::array<double, 3> q, l0sq;
        for (int s = 0; s < 3; ++s) {
            q[s] = e.normal[s] + poisson_ * e.tangent[s];  // eq. 9
            l0sq[s] = rest[s] * rest[s];
        }
        const double all = l0sq[0] * q[0] + l0sq[1] * q[1] + l0sq[2] * q[2];
        // The rest shape's scale s multiplies the forces (b0 Q a0^2 ~ s).
        const double stretch = 1.0 + expansion_ * e.theta;
        const double scale = stretch * material_.stiffnessFactor(e.theta);
        for (int s = 0; s < 3; ++s)  // eqs. 13-14 times eps_b b0
            triangleTension[k][s] = scale * fixedPart * rest[s] * (all - 2.0 * l0sq[s] * q[s]);
    });
    std::fill(tension.begin(), tension.end(), 0.0);
    for (int k = 0; k < triangles; ++k)
        for (int s = 0; s < 3; ++s) tension[triangles_[k].side[s]] += triangleTension[k][s];
    if constexpr (K == BondLawKind::PowerLaw) {  // each spring's secant phi(eta) / eta
        const int count = int(springs_.size());
        forEachIndex(count >= kParallelThreshold, 0, count, [&](int s) {
            double thetaBar;
            const double eta = mechanicalStrain(s, state, thetaBar);
            // Below 1e-6 the secant is 1 to within phi''(0) 1e-6: a part in a million of a
            // tension that is itself a millionth of the stiffness.
            if (std::abs(eta) > 1e-6)
                tension[s] *= (ownLaws() ? lawOf(s).forceAs<K>(eta) : law_.forceAs<K>(eta)) / eta;
        });
    }
}

void MassSpring::forces(const StepState& state, Workspace& work,
                        std::vector<Eigen::Vector3d>& force) const {
    SpringWorkspace& springs = static_cast<SpringWorkspace&>(work);
    tensions(state, springs);
    const auto& x = state.x;
    const int n = int(x.size());
    force.resize(n);
    forEachIndex(n >= kParallelThreshold, 0, n, [&](int i) {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int k = springOffsets_[i]; k < springOffsets_[i + 1]; ++k) {
            const int code = particleSprings_[k];
            const Spring& sp = springs_[std::abs(code) - 1];
            const int other = code > 0 ? sp.j : sp.i;
            const Eigen::Vector3d r = x[other] - x[i];
            sum += springs.tension[std::abs(code) - 1] / r.norm() * r;
        }
        force[i] = sum;
    });
}

std::vector<double> MassSpring::stiffnessRowSums(int particleCount) const {
    // Van Gelder: sum_j k_ij, as for the peridynamic bonds. The two-parameter force of a side
    // also depends on the other two sides and the heights; eq. 16's k times (1 + |nu|) bounds
    // that coupling (checked against a power iteration in the tests).
    const double coupling =
        model_ == SpringModel::VanGelder ? 1.0 : 2.0 * (1.0 + std::abs(poisson_));
    std::vector<double> sums(particleCount, 0.0);
    for (const Spring& s : springs_) {
        const double k = coupling * std::abs(s.k);
        sums[s.i] += k;
        sums[s.j] += k;
    }
    return sums;
}

double MassSpring::strainEnergy(const StepState& state, Workspace& work) const {
    const auto& x = state.x;
    double sum = 0.0;
    if (model_ == SpringModel::VanGelder) {  // k L0^2 Psi(eta), Psi the law's energy at c = 1
        for (int s = 0; s < int(springs_.size()); ++s) {
            if (!springAlive(s)) continue;
            double thetaBar;
            const double eta = mechanicalStrain(s, state, thetaBar);
            const PlasticState plastic = plastic_.empty() ? PlasticState{} : plastic_[s];
            sum += springs_[s].k * springs_[s].restLength * springs_[s].restLength * yieldOf(s) *
                   yieldOf(s) * lawOf(s).energy(eta / yieldOf(s), plastic) *
                   material_.stiffnessFactor(thetaBar);
        }
        return sum;
    }
    // The two-parameter forces are not the gradient of an energy; report the springs' energy at
    // their current tensions, 1/2 T (l - l0).
    SpringWorkspace& springs = static_cast<SpringWorkspace&>(work);
    tensions(state, springs);
    for (int s = 0; s < int(springs_.size()); ++s)
        sum += 0.5 * springs.tension[s] *
               ((x[springs_[s].j] - x[springs_[s].i]).norm() - springs_[s].restLength);
    return sum;
}

}  // namespace rend::sim
