#pragma once
// The micro-spring bonds of the membrane paper (seeds/000_68a9cbaeb8170387.txt, Sections 4-5) as
// a Solver: every pair within the horizon R is a bond with one of the three laws (eqs. 18-20),
// broken for good past the critical stretch (eqs. 27-28), strained and weakened by the
// diffusing theta. The bonds are the Membrane's own BondFamilies (diffusion and the FrameView
// read them too); the force loop proposes the bonds past their limit to the DamageState, which
// breaks them after the loop (sim/DamageState.h).
//
// The force loop is compiled once per law and per whether theta exists and bonds can break,
// so a stage a scene does not need costs nothing per bond; advance() fuses fracture, yield and
// the power law's look-ahead into it.

#include <Eigen/Core>
#include <cstdint>
#include <limits>
#include <optional>
#include <span>
#include <utility>
#include <vector>

#include "sim/BondLaw.h"
#include "sim/Bonds.h"
#include "sim/Lattice.h"
#include "sim/Material.h"
#include "sim/PairSums.h"
#include "sim/Params.h"
#include "sim/Solver.h"

namespace rend::sim {

struct LinearPairInput;  // sim/PairKernels.h
struct ApproachRate;     // sim/PairKernels.h

class PeridynamicBonds final : public Solver {
public:
    /// Particles per tile of the vectorised pass's pair order (sim/PairKernels.h's kPairTile).
    static constexpr int kTile = 8;
    /// `bonds` is the Membrane's (kept by reference), `rest` and `volumes` its rest positions
    /// and particle volumes. Bind it (Solver::bind) to a DamageState over the same bonds before
    /// use.
    PeridynamicBonds(const MembraneParams& params, const Lattice& lattice,
                     const BondFamilies& bonds, std::span<const Eigen::Vector3d> rest,
                     std::span<const double> volumes);
    /// The registry's factory (sim/SolverRegistry.h).
    static std::unique_ptr<Solver> make(const SolverSetUp& s);

    std::unique_ptr<Workspace> makeWorkspace() const override {
        return std::make_unique<PairWorkspace>();
    }
    void forces(const StepState& s, Workspace& work,
                std::vector<Eigen::Vector3d>& force) const override;
    void advance(const StepState& s, Workspace& work, std::vector<Eigen::Vector3d>& force) override;
    std::vector<double> stiffnessRowSums(int particleCount) const override;
    double strainEnergy(const StepState& s, Workspace& work) const override;
    double stiffening() const override { return stiffening_; }
    /// How many rows of the vectorised pass's pairs have one rest length, scale and limit to the
    /// bit, one plus whole steps of its last bit per pair, or neither (setUpPairRows); of the
    /// stepped, how many have stepped limits.
    struct RowClasses {
        int exact = 0, stepped = 0, perPair = 0, steppedLimits = 0;
    };
    RowClasses rowClasses() const;
    /// The elastoplastic history once per bond, where both ends hold the same bits (they do: a
    /// pair's strain is computed once, or from either end with the same operations), else per
    /// directed bond; then the stiffening.
    void saveState(StateWriter& out) const override;
    void loadState(StateReader& in) override;
    void reportStrength(DamageState& damage) const override;
    std::optional<double> failureApproachRate(const StepState& s,
                                              const FailureApproach& f) const override;
    /// The linear and elastoplastic laws' passes (the power law's look-ahead reads dt).
    bool measuresApproachInPass() const override {
        return vectorised() && law_.kind != BondLawKind::PowerLaw;
    }
    bool restrictTo(const Slab& slab) override {
        slab_ = slab;
        return true;
    }
    /// The strain energy of the bonds whose smaller end is a particle of its slab.
    double slabStrainEnergy(const StepState& s) const {
        syncHistory();
        return strainEnergyOf(s, slab_.begin, slab_.end);
    }
    /// Per directed bond, the elastoplastic law's history (empty for the other laws). What is
    /// written to it is seen by the next step.
    std::vector<PlasticState>& plasticState() {
        syncHistory();
        heldBehind_ = true;
        return plastic_;
    }

    const BondLaw& law() const { return law_; }
    /// Directed bond b's force on its particle per unit of f(eta) (sim/BondLaw.h).
    double bondScale(int b) const { return bondScale_[b]; }
    /// eta_c at theta = 0; +infinity when the material has no fracture energy.
    double criticalStretch() const { return criticalStretch_; }
    /// Virial (Cauchy-like) stress of particle i at s.x: 1/(2 V_i) sum_j F_ij (x) r_ij.
    Eigen::Matrix3d particleStress(int i, const StepState& s) const;

private:
    void computeBondScales(const MembraneParams& params, double particleArea);
    void applySurfaceCorrection();
    void setUpFracture(const MaterialParams& m);
    void applyStiffnessMap(std::span<const MaterialMap> maps);
    /// A yield_strain map: each bond's eta0 times the mean of its ends' factors. With k that
    /// factor, eq. 20 at eta0 k is k f(eta / k) at eta0 (linear to k eta0, then the same decay
    /// in eta / eta0), so the bond keeps its law in units of its own yield strain: its plastic
    /// history is stored in them, and eq. 27's gamma follows unchanged.
    void applyYieldMap(std::span<const MaterialMap> maps);
    void setUpStretchMap(std::span<const MaterialMap> maps);
    /// What the force loop may change: with kUpdateBonds (advance()) the plastic history and
    /// the proposed breaks, through these pointers; otherwise nothing.
    struct Updates {
        PlasticState* plastic = nullptr;
        std::uint8_t* proposed = nullptr;
        int breaking = 0;       ///< out: the bonds proposed
        double stiffest = 1.0;  ///< out: the largest look-ahead tangent x stiffness factor, over c
        /// out: the vectorised power law's LinearPairOutput::nearest over its pairs
        double nearest = -std::numeric_limits<double>::infinity();
    };
    /// The scratch of the force loop: each pair's force on its smaller index (the linear law's
    /// as three arrays, and whether it is past its limit).
    struct PairWorkspace : Workspace {
        std::vector<Eigen::Vector3d> pairForce;
        std::vector<double> slots;       ///< the vectorised laws': a ring of slots per thread
        std::vector<std::uint8_t> over;  ///< a bit per pair (LinearPairOutput::over)
        std::vector<std::uint8_t> approaching;  ///< LinearPairOutput::approaching
        std::vector<double> blockForce;  ///< a fused block's forces per thread, where it moves them
    };
    /// The kernel's view of this step: the pair arrays, x, theta and the law's constants.
    LinearPairInput pairInput(const StepState& s, bool update, bool breakable) const;
    /// The vectorised laws' loop: sim/PairKernels.h's pairs and their sums, fused per thread.
    template <bool kUpdateBonds, bool kBreak>
    void vectorBondForces(const StepState& s, PairWorkspace& work,
                          std::vector<Eigen::Vector3d>& force, Updates& updates) const;
    void setUpPairArrays();
    /// StepState::motion where the vectorised pass moves the particles, else null.
    BlockMotion* movingMotion(const StepState& s) const;
    /// Particles per block of the fused pair pass and gather.
    static constexpr int kFusedBlock = 512;
    /// Whether the force loop takes sim/PairKernels.h's vectorised pass: the linear law, the
    /// power law with a whole exponent and the elastoplastic law, without maps of their own
    /// parameters.
    bool vectorised() const;
    /// failureApproachRate's pairs and constants.
    std::pair<LinearPairInput, ApproachRate> approachInput(const StepState& s,
                                                           const FailureApproach& f) const;
    int proposeBreaks(const std::vector<std::uint8_t>& over, std::uint8_t* proposed) const;
    double strainEnergyOf(const StepState& s, int begin, int end) const;
    double blockStrainEnergy(const StepState& s, int begin, int end) const;
    /// Whether every bond's two ends hold the same history, bit for bit.
    bool historyOncePerBond() const;
    /// The force loop for the scene's law.
    template <bool kUpdateBonds>
    void bondForces(const StepState& s, Workspace& work, std::vector<Eigen::Vector3d>& force,
                    Updates& updates) const;
    template <bool kUpdateBonds, BondLawKind kLaw, bool kTheta, bool kBreak>
    void bondForcesFor(const StepState& s, PairWorkspace& work, std::vector<Eigen::Vector3d>& force,
                       Updates& updates) const;
    /// Mechanical strain of bond b of particle i (diffusion strain removed) and its theta_bar.
    double mechanicalStrain(int i, int b, double length, std::span<const double> theta,
                            double& thetaBar) const;

    const BondFamilies& bonds_;
    BondPairs pairs_;  ///< each bond once, for the force loop
    /// The vectorised pass's pairs, in tiles of kTile particles (setUpPairArrays): per pair its
    /// ends, upper and lower copies, rest length, bond scale, critical stretch and whether it
    /// is a pad; per directed bond, its pair there.
    std::vector<int> tileBegin_;  ///< per tile, and one past the last: its first pair
    std::vector<int> pairFirst_, pairSecond_, pairUpper_, pairTwin_, slotOf_;
    std::vector<std::uint8_t> pairPad_;
    std::vector<double> pairRest_, pairScale_, pairLimit_;
    /// Per row of kTile pairs (setUpPairRows): the first particles of its ends' runs (-1: not
    /// runs), and the class of its rest lengths, scales and limits (LinearPairInput::uniform);
    /// per class, its smallest values and their last bits; per pair, its steps of those.
    std::vector<int> rowRunFirst_, rowRunSecond_, rowClass_;
    std::vector<double> classRest_, classScale_, classLimit_;
    std::vector<double> classRestUnit_, classScaleUnit_, classLimitUnit_;
    std::vector<std::uint16_t> pairRestSteps_, pairScaleSteps_, pairLimitSteps_;
    void setUpPairRows();
    PairSumTiles sumTiles_;  ///< the tiles whose sums run eight lanes wide (sim/PairSums.h)
    /// The first pair of the tile starting at particle p (a tile's first, or the particle count).
    int pairsBefore(int p) const { return tileBegin_[(p + kTile - 1) / kTile]; }
    /// p rounded down to its tile's first particle.
    static int tileStart(int p) { return p - p % kTile; }
    int reach_ = 0;  ///< the largest i - j over bonds i -> j: how far back a lower copy lies
    int ringPairs_ =
        1;  ///< slots in each thread's ring: a power of 2 >= the pairs a block's sums need
    /// In rows (setUpRowSlots): from a slot's x to its y, the doubles of each thread's ring,
    /// where each row's lane 0 lies (per row of pairs) and each directed bond's pair (per bond;
    /// -1: none).
    int rowStride_ = kTile, ringDoubles_ = 0;
    std::vector<int> rowSlot_, bondSlot_;
    void setUpRowSlots();
    std::span<const Eigen::Vector3d> rest_;
    std::span<const double> volume_;
    Material material_;
    double horizon_ = 0.0;
    BondLaw law_;
    double criticalStretch_ = 0.0;
    std::vector<double> bondScale_;      ///< force on i per unit of f(eta), see BondLaw.h
    std::vector<double> stretchFactor_;  ///< per bond, from material maps; empty: all 1
    /// Per bond; empty unless the law is elastoplastic. The vectorised pass keeps it per pair in
    /// pairHeld_ instead: plastic_ follows it when read (syncHistory()), and it follows
    /// plastic_ when that was written (heldBehind_).
    mutable std::vector<PlasticState> plastic_;
    mutable std::vector<int> historyFirstEnds_;  // saveState's bonds b < mirror(b)
    mutable std::vector<double> pairHeld_;
    mutable bool heldAhead_ = false, heldBehind_ = true;
    /// plastic_ from pairHeld_ where the pass moved it on.
    void syncHistory() const;
    /// Per row of kTile pairs, bit k: whether lane k's bond lives (LinearPairInput::livingRows),
    /// as of DamageState::version() livingVersion_.
    mutable std::vector<std::uint8_t> livingRows_;
    mutable std::uint64_t livingVersion_ = ~std::uint64_t(0);
    const std::uint8_t* livingRows() const;
    /// Per tile of kTile particles: whether all their bonds live (PairGather::tileLiving), as of
    /// DamageState::version() livingTilesVersion_.
    mutable std::vector<std::uint8_t> livingTiles_;
    mutable std::uint64_t livingTilesVersion_ = ~std::uint64_t(0);
    const std::uint8_t* livingTiles() const;
    /// Calls brokenBond(i, j) for the ends of each bond broken since `version` and answers
    /// true, or answers false where that is not known (DamageState::breaksSince): a copy of the
    /// flags made then is brought up to date by those bonds alone.
    template <class Each>
    bool forBreaksSince(std::uint64_t version, Each&& brokenBond) const;
    std::vector<double> yieldFactor_;      ///< per bond, eta0 over the law's (maps); empty: all 1
    std::vector<double> softeningFactor_;  ///< per bond, beta over the law's (maps); empty: all 1
    std::vector<double> ratioFactor_;      ///< per bond, c*/c over the law's (maps); empty: all 1
    std::vector<double> exponentFactor_;   ///< per bond, n over the law's (maps); empty: all 1
    double yieldOf(int b) const { return yieldFactor_.empty() ? 1.0 : yieldFactor_[b]; }
    /// Whether some bond has a law of its own (softening or power-law maps).
    bool ownLaws() const {
        return !softeningFactor_.empty() || !ratioFactor_.empty() || !exponentFactor_.empty();
    }
    /// Bond b's law: the material's, with its own beta, c*/c and n where maps set them.
    BondLaw lawOf(int b) const {
        auto at = [b](const std::vector<double>& f) { return f.empty() ? 1.0 : f[b]; };
        return law_.scaled(at(softeningFactor_), at(ratioFactor_), at(exponentFactor_));
    }
    double stiffening_ = 1.0;  ///< the most compressed bond's, over c (advance() only)
    Slab slab_;                ///< what this process computes; all of the sheet by default
    /// The power law's last advance(): the least eta - reach x rest of its pairs
    /// (LinearPairOutput::nearest) where its look-ahead found nothing above the stiffening
    /// asked for, `nearestNeeded_` (else -infinity), and the longest rest length.
    double nearestGap_ = -std::numeric_limits<double>::infinity(), nearestNeeded_ = 0.0;
    double longestRest_ = 0.0;
    /// Whether the power law's look-ahead in this pass cannot raise the stiffening above
    /// s.stiffeningNeeded (so the pass may move the particles): from the last pass's nearest
    /// gap and how far the particles and theta moved since (StepState::sinceLastPass).
    bool lookAheadClear(const StepState& s) const;
};

}  // namespace rend::sim
