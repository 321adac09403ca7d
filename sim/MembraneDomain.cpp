// The Membrane's decomposed runs (sim/Domain.h): what one process steps, the ghosts it
// refreshes, and the gather that gives process 0 the whole sheet between frames.

#include <algorithm>

#include "sim/Membrane.h"
#include "sim/PeridynamicBonds.h"

namespace rend::sim {

namespace {

/// What a decomposed run does not carry, or an empty string.
std::string notDecomposed(const MembraneParams& p, const Solver& solver) {
    if (solver.carriesMomentum()) return "the MPM's grid";
    if (p.time.integrator == Integrator::VelocityVerlet)
        return "time.integrator = \"velocity_verlet\"";
    if (p.contact.self.enabled) return "contact.self (self-contact pairs cross slabs)";
    if (p.remesh.every > 0) return "remesh (it moves particles between slabs)";
    if (p.particleLevelSet) return "the particle level set surface";
    if (p.pressure != 0.0) return "pressure (its triangles cross slabs)";
    return "";
}

}  // namespace

void Membrane::decompose(Domain& domain) {
    if (const std::string what = notDecomposed(params_, *solver_); !what.empty())
        throw std::invalid_argument("a run on several processes does not support " + what +
                                    ": run it on one process");
    if (!solver_->restrictTo(domain.slab()))
        throw std::invalid_argument("solver \"" + params_.solver +
                                    "\" runs on one process only: its forces are not split into "
                                    "slabs (use solver = \"peridynamic\", or one process)");
    domain_ = &domain;
    begin_ = domain.slab().begin;
    end_ = domain.slab().end;
    if (diffusion_) diffusion_->restrictTo(domain);
}

void Membrane::exchangeMotion() {
    domain_->exchange(x_.data()->data(), 3);
    domain_->exchange(v_.data()->data(), 3);
}

double Membrane::totalEnergy() const {
    if (!domain_) return kineticEnergy() + strainEnergy();
    double kinetic = 0.0;
    for (int i = begin_; i < end_; ++i) kinetic += 0.5 * mass_[i] * v_[i].squaredNorm();
    const auto& bonds = static_cast<const PeridynamicBonds&>(*solver_);  // decompose() checked
    return domain_->sum(kinetic + bonds.slabStrainEnergy(stepState()));
}

double Membrane::colliderWork() {
    const double work = contact_ ? contact_->takeWork() : 0.0;
    return domain_ ? domain_->sum(work) : work;
}

double Membrane::slabMaxSpeed() const {
    if (!domain_) return maxSpeed();
    double fastest = 0.0;  // squared
    for (int i = begin_; i < end_; ++i) fastest = std::max(fastest, v_[i].squaredNorm());
    return std::sqrt(domain_->max(fastest));
}

void Membrane::gatherToFirst() {
    if (!domain_) return;
    domain_->gather(x_.data()->data(), 3, sizeof(double), false);
    domain_->gather(v_.data()->data(), 3, sizeof(double), false);
    if (!theta_.empty()) domain_->gather(theta_.data(), 1, sizeof(double), false);
    std::vector<std::uint8_t> alive = damageState_.bondAlive();
    domain_->gather(alive.data(), 1, 1, true);
    if (auto* bonds = dynamic_cast<PeridynamicBonds*>(solver_.get());
        bonds && !bonds->plasticState().empty())
        domain_->gather(bonds->plasticState().data(), 1, sizeof(PlasticState), true);
    if (domain_->rank() != 0) return;
    for (int b = 0; b < int(alive.size()); ++b)  // bonds never heal: only breaks arrive
        if (!alive[b]) damageState_.breakBond(b);
}

}  // namespace rend::sim
