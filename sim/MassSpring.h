#pragma once
// Mass-spring membranes of the mass-spring paper (seeds/003): one spring on every edge of the
// rest lattice's triangles, f = k (|r| - L0) along the current edge.
//
//  - Van Gelder (eq. 1): k_c = sum over the edge's triangles of
//        E t / (1 + nu) |T| / c^2 + E t nu / (1 - nu^2) (a^2 + b^2 - c^2) / (8 |T|),
//    fixed at set-up. Exact for nu = 1/3 on equilateral triangles (it is then Lloyd's
//    sqrt(3)/4 E t per triangle, eq. 3); a central spring network cannot carry another nu.
//  - Two-parameter, TP-MSS (eqs. 10-17): k_b = sum_i Q_i q_i, with the fixed part
//    Q_i = E t / (8 (1 - nu^2) |T0_i|) (eq. 12) and the variable part
//    q_i = (a0^2 q_a - b0^2 q_b + c0^2 q_c) / eps_b (eq. 14), q_s = eps_n,s + nu eps_t,s (eq. 9):
//    eps_t,s the side's strain, eps_n,s the strain of the triangle's height onto side s. The
//    spring force k_b (b - b0) = k_b eps_b b0 makes eps_b cancel:
//        F_b = b0 sum_i Q_i (a0^2 q_a - b0^2 q_b + c0^2 q_c),
//    which is what we evaluate, so the division by zero that eq. 16 guards against never
//    arises. Eq. 16's k (zero strain) gives the stiffness for the stable time step.
//
// Bond laws (membrane paper, seeds/000, eqs. 18-20), through their shape at unit stiffness,
// phi(eta) = f(eta)/c (slope 1 at rest, so small strains are untouched). Each spring's own strain
// eta (thermal part removed) sets its law:
//  - Van Gelder: tension = k L0 phi(eta).
//  - Two-parameter, power law (eq. 19): the linear TP tension times the spring's secant
//    phi(eta)/eta. The TP spreads load over a triangle's sides; the secant bends each side's
//    share by its own 1D law. Along a lattice row the diagonal springs carry nothing, so a
//    uniaxial pull gives T_law / T_linear = phi(e)/e exactly (to 1e-15, tests/sim/
//    spring_laws_test.cpp); an equibiaxial one too.
//  - Two-parameter, elastoplastic (eq. 20): the law is linear about the permanent strain
//    p = eta - phi(eta) (on the loading path, eq. 20's at the current strain), so the secant
//    would be infinite at the rest length once yielded. Instead a triangle is the linear TP
//    about its plastic rest triangle, of sides l0 (1 + p) (its area by Heron, eq. 12's Q from
//    it): a permanent set, and the TP's geometric non-linearity stays at the size of the elastic
//    strain. Unloaded along a row the sheet rests at the 1D permanent strain (to 1e-10); on the
//    loading path it carries about E h (e - p) / ((1 + p)(1 + p/3)), the heights across the pull
//    shrinking by p/3: within 5.5% of eta0 of f/c up to e = 0.2 at beta = 1.
//  Measured and dropped: phi on every strain of eq. 9 (each side and height with its own
//  history): a microplane model whose 30-degree heights and 60-degree sides carry the pull, so
//  T_law / T_linear was 0.95 where phi(e)/e = 0.52 (power law, e = 0.6), and it left the
//  elastoplastic sheet a plateau at 8 times f/c; phi on the sides with the heights' compatible
//  linear correction: swamped by the TP's own geometric non-linearity (the linear TP gives 0.36 E h
//  for e = 0.6). The linear law takes neither path: today's TP bit for bit.
// A power-law spring in compression stiffens as phi'(eta) ~ s^-4: stiffening() reports phi' of
// the most compressed spring looked ahead by dt along its rate, as the peridynamic loop does.
// Yielded springs report eq. 27's gamma to the damage field through reportStrength().

#include <Eigen/Geometry>
#include <array>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "sim/BondLaw.h"
#include "sim/Lattice.h"
#include "sim/Material.h"
#include "sim/Solver.h"

namespace rend::sim {

enum class SpringModel { VanGelder, TwoParameter };

class MassSpring final : public Solver {
public:
    /// criticalStrain: a spring breaks once stretched past it (infinity: never). Both models
    /// take the material's bond law (its shape, see above), its thermal strain alpha theta_bar
    /// and its stiffness and strength losses, as the bonds do.
    /// `maps`: issue 15's material maps; a triangle takes its corners' mean E, a spring the
    /// critical strain's factor sqrt(mean G_f / mean E) of its two ends.
    MassSpring(const Lattice& lattice, SpringModel model, const Material& material,
               double thickness, double criticalStrain, std::span<const MaterialMap> maps = {});
    /// The registry's factories: Van Gelder's springs break at springCriticalStrain(), the
    /// two-parameter ones (whose triangles go with a side) at bandCriticalStrain().
    static std::unique_ptr<Solver> makeVanGelder(const SolverSetUp& s);
    static std::unique_ptr<Solver> makeTwoParameter(const SolverSetUp& s);

    std::unique_ptr<Workspace> makeWorkspace() const override;
    void forces(const StepState& s, Workspace& work,
                std::vector<Eigen::Vector3d>& force) const override;
    std::vector<double> stiffnessRowSums(int particleCount) const override;
    double strainEnergy(const StepState& s, Workspace& work) const override;
    void fracture(const StepState& s, Workspace& work) override;
    void advance(const StepState& s, Workspace& work, std::vector<Eigen::Vector3d>& force) override;
    double stiffening() const override { return stiffening_; }
    void saveState(StateWriter& out) const override { out(plastic_), out(stiffening_); }
    void loadState(StateReader& in) override { in(plastic_), in(stiffening_); }
    /// Each of the Membrane's bonds along a spring reports that spring's strength left.
    void reportStrength(DamageState& damage) const override;

    int springCount() const { return int(springs_.size()); }
    /// Van Gelder's k of spring s (eq. 1) [N/m].
    double vanGelderStiffness(int s) const { return springs_[s].k; }

private:
    struct Spring {
        int i, j;
        double restLength;
        double k;  ///< Van Gelder (eq. 1); eq. 16's zero-strain k for the two-parameter model
    };
    struct Triangle {
        std::array<int, 3> v;
        std::array<int, 3> side;  ///< spring index of side s = the edge opposite vertex s
        std::array<double, 3> restLength;
        double restArea;
        double fixedPart;  ///< Q (eq. 12)
        int triangle;      ///< index into the lattice's triangles
    };
    /// The forces' scratch: every spring's tension [N] and each two-parameter triangle's share
    /// of its sides' (summed per side in triangle order).
    struct SpringWorkspace : Workspace {
        std::vector<double> tension;
        std::vector<std::array<double, 3>> triangleTension;
    };
    /// Tension of every spring [N] at state.x into the workspace.
    void tensions(const StepState& state, SpringWorkspace& work) const;
    template <BondLawKind K>
    void twoParameterTensions(const StepState& state, SpringWorkspace& work) const;

    /// Per intact two-parameter triangle k and side s, the mechanical strains of eq. 9:
    /// tangent = eps_t,s, normal = eps_n,s, and the triangle's theta.
    struct SideStrains {
        std::array<double, 3> tangent, normal;
        double theta;
    };
    SideStrains sideStrains(int k, const StepState& state) const;
    /// The same about any rest triangle of vertices v.
    SideStrains sideStrains(std::span<const Eigen::Vector3d> x, const std::array<int, 3>& v,
                            const std::array<double, 3>& restLength, double restArea,
                            double theta) const;

    /// The most compressed spring's strain looked ahead by dt along its rate; 0 when nothing is
    /// in compression.
    /// The power law's largest tangent over c among the compressed springs, each where it will
    /// be in dt if it keeps closing (1 when none stiffens).
    double stiffestSpring(const StepState& state) const;

    /// Spring s is the DamageState's edge s (both are numbered over the triangles' sides in
    /// order). A broken spring carries nothing; a two-parameter triangle with a broken side is
    /// no longer kept and carries nothing either (its sides' forces are coupled through its
    /// shape).
    bool springAlive(int s) const { return damage_->edgeIntact(s); }
    void onBind() override;

    /// Mechanical strain of spring s at x (thermal strain removed) and its theta_bar.
    double mechanicalStrain(int s, const StepState& state, double& thetaBar) const;

    SpringModel model_;
    Material material_;
    double poisson_;
    BondLaw law_;  ///< the material's law with c = 1: tension = k L0 f(eta)
    double expansion_ = 0.0;
    std::vector<PlasticState> plastic_;  ///< per spring; empty unless elastoplastic
    double stiffening_ = 1.0;
    double criticalStrain_;
    std::vector<double> strength_;  ///< per spring, from material maps; empty: all 1
    // Law maps, per spring, its ends' mean factor; empty: all 1. The spring runs eq. 20 in
    // units of its own eta0 (k f(eta / k), as the bonds: sim/PeridynamicBonds.h) with its own
    // beta, c*/c and n.
    std::vector<double> yield_, softening_, ratio_, exponent_;
    double yieldOf(int s) const { return yield_.empty() ? 1.0 : yield_[s]; }
    bool ownLaws() const { return !softening_.empty() || !ratio_.empty() || !exponent_.empty(); }
    BondLaw lawOf(int s) const {
        auto at = [s](const std::vector<double>& f) { return f.empty() ? 1.0 : f[s]; };
        return law_.scaled(at(softening_), at(ratio_), at(exponent_));
    }
    std::vector<Spring> springs_;
    std::vector<Triangle> triangles_;
    // Per particle, its springs (signed: +s+1 when it is end i, -(s+1) when end j), so each
    // particle sums its own forces.
    std::vector<int> springOffsets_, particleSprings_;
};

}  // namespace rend::sim
