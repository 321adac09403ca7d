// Membrane::saveState and loadState: the evolving state of a run, for checkpoints. What the
// constructor derives from the scene (lattice, bonds, masses, the solver's rest quantities,
// diffusion's sources, the contact's triangles) is rebuilt, not stored.

#include <type_traits>

#include "sim/Membrane.h"

namespace rend::sim {

template <class Self, class Archive>
void Membrane::visitState(Self& m, Archive& a) {
    expectSize(a, m.x0_.size(), "particles");
    expectSize(a, m.bonds_.directedCount(), "directed bonds");
    a(m.x_), a(m.v_), a(m.forcesCurrent_), a(m.theta_), a(m.damage_);
    // Symplectic Euler recomputes the forces at a step's start; Verlet reuses the last step's.
    if (m.forcesCurrent_) a(m.force_);
    a(m.time_), a(m.steps_), a(m.dt_), a(m.stiffening_), a(m.subSteps_), a(m.lastDrift_);
    a(m.dtMin_), a(m.dtMax_);
    TimeStepController::visitState(m.controller_, a);
    BlowUpGuard::visitState(m.guard_, a);
    DamageState::visitState(m.damageState_, a);
    std::uint8_t hasContact = m.contact_.has_value();
    a(hasContact);
    if (bool(hasContact) != m.contact_.has_value())
        throw StateMismatch(hasContact ? "the state has contact, this scene none"
                                       : "this scene has contact, the state none");
    if (m.contact_) Contact::visitState(*m.contact_, a);
    std::uint8_t hasLevelSet = m.levelSet_.has_value();
    a(hasLevelSet);
    if (!hasLevelSet && m.levelSet_)
        throw StateMismatch(
            "this run draws surface = \"particle_level_set\", whose particle level set the state "
            "lacks (its run drew another surface)");
    if (m.levelSet_) {
        ParticleLevelSet::visitState(*m.levelSet_, a);
    } else if constexpr (!std::is_const_v<Self>) {
        if (hasLevelSet) {  // read past it: it never changed the motion
            ParticleLevelSet unused = m.makeLevelSet();
            ParticleLevelSet::visitState(unused, a);
        }
    }
}

std::vector<std::byte> Membrane::saveState(std::vector<std::byte> reuse) const {
    StateWriter out(std::move(reuse));
    visitState(*this, out);
    solver_->saveState(out);
    return out.take();
}

void Membrane::loadState(std::span<const std::byte> bytes) {
    StateReader in(bytes);
    speedBound_ = -1.0;
    driftSincePass_ = -1.0;
    visitState(*this, in);
    solver_->loadState(in);
    in.finish();
    if (x_.size() != x0_.size() || v_.size() != x0_.size() || force_.size() != x0_.size())
        throw StateMismatch(
            "the state's positions, velocities or forces do not match its particles");
    if (contact_) {
        contact_->expireList();
        contact_->place(time_);
    }
}

}  // namespace rend::sim
