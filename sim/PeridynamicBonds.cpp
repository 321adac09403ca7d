#include "sim/PeridynamicBonds.h"

#include <omp.h>

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <map>
#include <stdexcept>

#include "sim/Fracture.h"
#include "sim/PairKernels.h"
#include "sim/PairSums.h"
#include "sim/Parallel.h"
#include "sim/RowSteps.h"
#include "sim/SolverRegistry.h"
#include "sim/StepKernels.h"

namespace rend::sim {

static_assert(PeridynamicBonds::kTile == kPairTile);

PeridynamicBonds::PeridynamicBonds(const MembraneParams& params, const Lattice& lattice,
                                   const BondFamilies& bonds, std::span<const Eigen::Vector3d> rest,
                                   std::span<const double> volumes)
    : bonds_(bonds),
      pairs_(buildBondPairs(bonds)),
      rest_(rest),
      volume_(volumes),
      material_(params.material),
      horizon_(params.sheet.horizonFactor * params.sheet.dx) {
    computeBondScales(params, lattice.particleArea);
    setUpFracture(params.material);
    setUpStretchMap(params.materialMaps);
    setUpPairArrays();
    const int n = bonds_.particleCount();
    slab_ = {0, n, 0, n};
}

bool PeridynamicBonds::vectorised() const {
    if (law_.kind == BondLawKind::Linear) return true;
    if (law_.kind == BondLawKind::Elastoplastic) return yieldFactor_.empty() && !ownLaws();
    const double n = law_.powerN;  // sim/PairKernels.h takes whole exponents 2 to 4
    return law_.kind == BondLawKind::PowerLaw && !ownLaws() && (n == 2.0 || n == 3.0 || n == 4.0);
}

// Tiles: the k-th upper pair of the kTile particles of a tile lie side by side (pair
// tileBegin_[t] + kTile k + lane), so that on a regular lattice the kernels load eight pairs'
// ends and theta as runs of consecutive particles. A lane with fewer pairs than its tile's most
// repeats one of the tile's pairs (a pad: computed, never summed, never proposed).
void PeridynamicBonds::setUpPairArrays() {
    if (!vectorised()) return;
    const int n = bonds_.particleCount();
    reach_ = 0;
    for (int i = 0; i < n; ++i)
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b)
            reach_ = std::max(reach_, i - bonds_.partners[b]);
    const int tiles = (n + kTile - 1) / kTile;
    const auto uppers = [&](int i) {
        return i < n ? bonds_.offsets[i + 1] - pairs_.upperBegin[i] : 0;
    };
    tileBegin_.assign(tiles + 1, 0);
    for (int t = 0; t < tiles; ++t) {
        int most = 0;
        for (int lane = 0; lane < kTile; ++lane) most = std::max(most, uppers(kTile * t + lane));
        tileBegin_[t + 1] = tileBegin_[t] + kTile * most;
    }
    const int pairs = tileBegin_[tiles];
    pairFirst_.resize(pairs), pairSecond_.resize(pairs), pairUpper_.resize(pairs);
    pairTwin_.resize(pairs), pairPad_.assign(pairs, 1);
    pairRest_.resize(pairs), pairScale_.resize(pairs), pairLimit_.resize(pairs);
    slotOf_.assign(bonds_.directedCount(), -1);
    const auto place = [&](int u, int i, int b) {
        pairFirst_[u] = i, pairSecond_[u] = bonds_.partners[b];
        pairUpper_[u] = b, pairTwin_[u] = pairs_.twin[pairs_.pairOf[b]];
        pairRest_[u] = bonds_.restLength[b], pairScale_[u] = bondScale_[b];
        longestRest_ = std::max(longestRest_, pairRest_[u]);
        pairLimit_[u] = criticalStretch_;
        if (!stretchFactor_.empty()) pairLimit_[u] *= stretchFactor_[b];
    };
    for (int t = 0; t < tiles; ++t) {
        const int most = (tileBegin_[t + 1] - tileBegin_[t]) / kTile;
        int spare = -1, spareOf = -1;  // a real pair of the tile, for lanes without one
        for (int lane = 0; lane < kTile; ++lane)
            if (uppers(kTile * t + lane) > 0) {
                spareOf = kTile * t + lane, spare = pairs_.upperBegin[spareOf];
                break;
            }
        for (int lane = 0; lane < kTile; ++lane) {
            const int i = kTile * t + lane, count = uppers(i);
            for (int k = 0; k < most; ++k) {
                const int u = tileBegin_[t] + kTile * k + lane;
                if (k < count) {
                    const int b = pairs_.upperBegin[i] + k;
                    place(u, i, b);
                    pairPad_[u] = 0, slotOf_[b] = slotOf_[pairs_.twin[pairs_.pairOf[b]]] = u;
                } else if (count > 0) {
                    place(u, i, pairs_.upperBegin[i] + count - 1);
                } else {
                    place(u, spareOf, spare);
                }
            }
        }
    }
    setUpPairRows();
    // A ring holds the pairs of the tiles from reach_ particles before a block to its end.
    int window = kTile;
    for (int p = 0; p < n; p += kTile)
        window = std::max(window, pairsBefore(std::min(n, p + kFusedBlock)) -
                                      pairsBefore(tileStart(std::max(0, p - reach_))));
    ringPairs_ = 1;
    while (ringPairs_ < window) ringPairs_ *= 2;
    if (slotRows()) setUpRowSlots();
}

// In rows: where each row's lane 0 lies in a thread's ring: a ring of tiles per row index k, the
// k-th rows of consecutive tiles side by side, so that the lower copies of a tile's particles
// (lanes of two tiles' rows: a lattice's neighbours d particles back are lanes d % 8 on) load as
// one run where they were two and a blend, and a lattice's tiles are regular (sim/PairSums.h).
// Each k's ring is a line longer than its tiles, so that k's rows do not lie a multiple of 4 KiB
// apart (interleaved, crack_path_sources, 10^4 particles: linear 10.66 -> 10.49 ns,
// elastoplastic 12.37 -> 12.11). A sheet that streams from memory kept the rows in pair order
// while that was faster (10^6 particles: 13.0 against 13.3 by k); since the regular tiles' sums
// are straight code, by k is faster there too (crack_path_sources at 10^6, interleaved, best of
// three: linear 13.71 -> 13.20, power law 15.57 -> 14.90, elastoplastic 14.91 -> 14.43).
void PeridynamicBonds::setUpRowSlots() {
    const int n = bonds_.particleCount(), tiles = int(tileBegin_.size()) - 1;
    rowSlot_.assign(pairFirst_.size() / kTile, 0);
    int windowTiles = 1, rowsPerTile = 1;
    for (int p = 0; p < n; p += kTile)
        windowTiles = std::max(windowTiles, (std::min(n, p + kFusedBlock) + kTile - 1) / kTile -
                                                tileStart(std::max(0, p - reach_)) / kTile);
    for (int t = 0; t < tiles; ++t)
        rowsPerTile = std::max(rowsPerTile, (tileBegin_[t + 1] - tileBegin_[t]) / kTile);
    int ringTiles = 1;
    while (ringTiles < windowTiles) ringTiles *= 2;
    const int ringOfK = kTile * (ringTiles + 1);
    rowStride_ = rowsPerTile * ringOfK + kPairTile;  // x, then y, then z
    ringDoubles_ = kPairTile + 3 * rowStride_;
    for (int t = 0; t < tiles; ++t)
        for (int k = 0; k < (tileBegin_[t + 1] - tileBegin_[t]) / kTile; ++k)
            rowSlot_[tileBegin_[t] / kTile + k] = k * ringOfK + kTile * (t & (ringTiles - 1));
    bondSlot_.assign(bonds_.directedCount(), -1);
    for (std::size_t b = 0; b < bondSlot_.size(); ++b)
        if (const int u = slotOf_[b]; u >= 0) bondSlot_[b] = rowSlot_[u / kTile] + u % kTile;
    std::vector<int>().swap(slotOf_);  // the pairs' numbers: not read in rows
    sumTiles_ = PairSumTiles::build(bonds_.offsets.data(), pairs_.upperBegin.data(),
                                    bondSlot_.data(), bonds_.partners.data(), n);
}

// Per row of a tile (its particles' k-th pairs, side by side): whether its ends are two runs of
// consecutive particles, and whether its rest lengths, scales and limits are each one value to
// the bit, or one value plus whole steps of its last bit. Far from the origin a lattice's
// coordinates carry rounding, so the bonds of one direction differ in their last bits (on a
// 20 m sheet at dx 0.02, three rows in four): as a row's smallest value and 16 bits per pair (v =
// smallest + steps * unit, exact: steps * unit is a multiple of the smallest's last bit and the
// sum is v itself), the kernels read two bytes per pair where they read eight, with the same bits.
// On a regular lattice almost every row is a class, and the per-pair arrays stay in memory unread.
void PeridynamicBonds::setUpPairRows() {
    const int rows = int(pairFirst_.size()) / kTile;
    rowRunFirst_.assign(rows, -1), rowRunSecond_.assign(rows, -1), rowClass_.assign(rows, -1);
    classRest_.clear(), classScale_.clear(), classLimit_.clear();
    classRestUnit_.clear(), classScaleUnit_.clear(), classLimitUnit_.clear();
    pairRestSteps_.assign(pairFirst_.size(), 0), pairScaleSteps_.assign(pairFirst_.size(), 0);
    pairLimitSteps_.assign(pairFirst_.size(), 0);
    std::map<std::array<std::uint64_t, 3>, int> classes;
    for (int row = 0; row < rows; ++row) {
        const int u = kTile * row;
        bool run = true;
        for (int k = 1; k < kTile; ++k)
            run = run && pairFirst_[u + k] == pairFirst_[u] + k &&
                  pairSecond_[u + k] == pairSecond_[u] + k;
        if (run) rowRunFirst_[row] = pairFirst_[u], rowRunSecond_[row] = pairSecond_[u];
        const std::optional<RowSteps> rest = rowSteps(&pairRest_[u], &pairRestSteps_[u]);
        const std::optional<RowSteps> scale = rowSteps(&pairScale_[u], &pairScaleSteps_[u]);
        const std::optional<RowSteps> limit = rowSteps(&pairLimit_[u], &pairLimitSteps_[u]);
        if (!rest || !scale || !limit) continue;
        const std::array<std::uint64_t, 3> key{std::bit_cast<std::uint64_t>(rest->smallest),
                                               std::bit_cast<std::uint64_t>(scale->smallest),
                                               std::bit_cast<std::uint64_t>(limit->smallest)};
        const auto [at, added] = classes.try_emplace(key, int(classRest_.size()));
        if (added) {
            classRest_.push_back(rest->smallest), classScale_.push_back(scale->smallest);
            classLimit_.push_back(limit->smallest), classRestUnit_.push_back(rest->unit);
            classScaleUnit_.push_back(scale->unit), classLimitUnit_.push_back(limit->unit);
        }
        const bool exact = !rest->stepped && !scale->stepped && !limit->stepped;
        rowClass_[row] = exact ? at->second : steppedClass(at->second, limit->stepped);
    }
}

PeridynamicBonds::RowClasses PeridynamicBonds::rowClasses() const {
    RowClasses r;
    for (const int c : rowClass_) {
        (c >= 0 ? r.exact : c == -1 ? r.perPair : r.stepped) += 1;
        if (c <= kSteppedClass) r.steppedLimits += limitsStepped(c);
    }
    return r;
}

std::unique_ptr<Solver> PeridynamicBonds::make(const SolverSetUp& s) {
    return std::make_unique<PeridynamicBonds>(s.params, s.lattice, s.bonds, s.rest, s.volumes);
}

void PeridynamicBonds::computeBondScales(const MembraneParams& params, double particleArea) {
    const int n = bonds_.particleCount();
    const bool paper = params.material.micromodulus == MicromodulusMode::Paper;
    bondScale_.resize(bonds_.directedCount());
    for (int i = 0; i < n; ++i)
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
            const int j = bonds_.partners[b];
            // Literal eq. 22 multiplies by the area A_j; the consistent form by V_i V_j.
            const double measure = paper ? particleArea : volume_[i] * volume_[j];
            bondScale_[b] = bonds_.weight[b] * measure / bonds_.restLength[b];
        }
    const double interiorWeightedVolume = interiorFamilySum(
        bonds_, [&](int b) { return bonds_.weight[b] * volume_[bonds_.partners[b]]; });
    if (interiorWeightedVolume <= 0.0)
        throw std::invalid_argument(
            "no particle has a bond with non-zero weight: raise the horizon");
    if (params.material.surfaceCorrection) applySurfaceCorrection();
    applyStiffnessMap(params.materialMaps);
    const MaterialParams& m = params.material;
    const double c = paper ? paperMicromodulus(m.youngsModulus, m.poissonRatio, horizon_)
                           : calibratedMicromodulus(m.youngsModulus, interiorWeightedVolume);
    law_ = BondLaw::fromMaterial(m, c);
    applyYieldMap(params.materialMaps);
}

void PeridynamicBonds::applyYieldMap(std::span<const MaterialMap> maps) {
    std::vector<double>* factors[] = {&yieldFactor_, &softeningFactor_, &ratioFactor_,
                                      &exponentFactor_};  // in kLawProperties' order
    for (int p = 0; p < 4; ++p) {
        const MappedProperty property = kLawProperties[p];
        if (!mapsProperty(maps, property)) continue;
        const std::vector<double> y = materialFactors(property, maps, rest_);
        std::vector<double>& factor = *factors[p];
        factor.resize(bonds_.directedCount());
        for (int i = 0; i < bonds_.particleCount(); ++i)
            for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b)
                factor[b] = 0.5 * (y[i] + y[bonds_.partners[b]]);
    }
}

std::vector<double> PeridynamicBonds::stiffnessRowSums(int particleCount) const {
    std::vector<double> k(particleCount, 0.0);
    for (int i = 0; i < particleCount; ++i)
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b)
            k[i] += bondScale_[b] * law_.stiffness() / bonds_.restLength[b];
    return k;
}

namespace {

// Strain energy density of particle i under unit uniaxial stress along axis a, up to a constant
// common to all particles: sum_j W0 V_j |xi| s^2 (the linear law's micropotential c s^2 |xi| / 2),
// with the bond stretch s = n.eps.n of the plane-stress strain eps = a a - (1/3) a' a' (nu = 1/3)
// and W0 V_j |xi| written through the bond scale W0 V_i V_j / |xi| of equal particle volumes.
double uniaxialStressEnergy(const BondFamilies& bonds, const std::vector<double>& bondScale,
                            std::span<const Eigen::Vector3d> x0, int i, int a) {
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

void PeridynamicBonds::applySurfaceCorrection() {
    const int n = bonds_.particleCount();
    // Energy method (Madenci & Oterkus 2014, Sec. 4.2) with uniaxial stress, not strain, as the
    // loading: an edge is free of stress across it, so that is the state its particles meet.
    std::vector<Eigen::Vector2d> factor(n, Eigen::Vector2d::Ones());
    for (int a = 0; a < 2; ++a) {
        std::vector<double> energy(n);
        double interior = 0.0;
        for (int i = 0; i < n; ++i) {
            energy[i] = uniaxialStressEnergy(bonds_, bondScale_, rest_, i, a);
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
            const Eigen::Vector3d d = (rest_[j] - rest_[i]) / bonds_.restLength[b];
            const Eigen::Vector2d g = 0.5 * (factor[i] + factor[j]);
            bondScale_[b] /= std::hypot(d.x() / g.x(), d.y() / g.y());
        }
}

/// A bond's stiffness is the mean of its ends' E (issue 15's material maps).
void PeridynamicBonds::applyStiffnessMap(std::span<const MaterialMap> maps) {
    if (!mapsProperty(maps, MappedProperty::YoungsModulus)) return;
    const std::vector<double> e = materialFactors(MappedProperty::YoungsModulus, maps, rest_);
    for (int i = 0; i < bonds_.particleCount(); ++i)
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b)
            bondScale_[b] *= 0.5 * (e[i] + e[bonds_.partners[b]]);
}

/// A bond's critical stretch goes as sqrt(G_f / E) (eq. 28 and its calibrated form), with the
/// means of its ends' factors; empty when no map changes either.
void PeridynamicBonds::setUpStretchMap(std::span<const MaterialMap> maps) {
    stretchFactor_.clear();
    if (!std::isfinite(criticalStretch_) || (!mapsProperty(maps, MappedProperty::YoungsModulus) &&
                                             !mapsProperty(maps, MappedProperty::FractureEnergy)))
        return;
    const std::vector<double> e = materialFactors(MappedProperty::YoungsModulus, maps, rest_);
    const std::vector<double> g = materialFactors(MappedProperty::FractureEnergy, maps, rest_);
    stretchFactor_.resize(bonds_.directedCount());
    for (int i = 0; i < bonds_.particleCount(); ++i)
        for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
            const int j = bonds_.partners[b];
            stretchFactor_[b] = std::sqrt((g[i] + g[j]) / (e[i] + e[j]));
        }
}

void PeridynamicBonds::setUpFracture(const MaterialParams& m) {
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
}

double PeridynamicBonds::mechanicalStrain(int i, int b, double length,
                                          std::span<const double> theta, double& thetaBar) const {
    const double eta = length / bonds_.restLength[b] - 1.0;  // eq. 10
    if (theta.empty()) {
        thetaBar = 0.0;
        return eta;
    }
    // The printed eqs. 18-20 use theta_j alone; the mean is symmetric, so the pair forces stay
    // equal and opposite and momentum is conserved.
    thetaBar = 0.5 * (theta[i] + theta[bonds_.partners[b]]);
    return eta - material_.expansion() * thetaBar;
}

// Two passes in one parallel region. The first computes each pair's force once, from its upper
// copy i -> j, and writes only that pair's slot and its two copies' plastic state and proposed
// break; the second sums each particle's pair forces in CSR order, minus where it is the upper
// index (x_i - x_j = -(x_j - x_i) exactly). So no loop needs atomics, the bits are those of a
// loop over both copies, and they are the same for any thread count. Both copies of a bond see
// the same strain bit for bit, so they break and yield together; a bond past its limit carries
// nothing already in this step, so breaking after the loop gives the bits of breaking in place.
template <bool kUpdateBonds, BondLawKind kLaw, bool kTheta, bool kBreak>
void PeridynamicBonds::bondForcesFor(const StepState& s, PairWorkspace& work,
                                     std::vector<Eigen::Vector3d>& force, Updates& updates) const {
    const int n = bonds_.particleCount();
    force.resize(n);
    work.pairForce.resize(pairs_.pairCount());
    Eigen::Vector3d* pairForce = work.pairForce.data();
    // Raw arrays, loaded once: the stores to `proposed` (a char type) and to `plastic` would
    // otherwise make the compiler reload every vector's data pointer after each of them.
    const int* offsets = bonds_.offsets.data();
    const int* partners = bonds_.partners.data();
    const int* upperBegin = pairs_.upperBegin.data();
    const int* pairBegin = pairs_.pairBegin.data();
    const int* pairOf = pairs_.pairOf.data();
    const int* twin = pairs_.twin.data();
    const double* restLength = bonds_.restLength.data();
    const double* bondScale = bondScale_.data();
    const double* stretchFactor = stretchFactor_.empty() ? nullptr : stretchFactor_.data();
    const double* yieldFactor = yieldFactor_.empty() ? nullptr : yieldFactor_.data();
    const bool ownLaws = this->ownLaws();
    const std::uint8_t* alive = damage_->bondAlive().data();
    std::uint8_t* proposed = updates.proposed;
    PlasticState* plastic = updates.plastic;
    const PlasticState* plasticIn = kUpdateBonds ? plastic : plastic_.data();
    const Eigen::Vector3d* xs = s.x.data();
    const double* theta = s.theta.data();
    const Eigen::Vector3d* v = s.v.data();
    const double dt = s.dt;
    const double expansion = material_.expansion();
    // The stiffest compressed bond's tangent over c, for the power law (or the least the step
    // needs known, StepState::stiffeningNeeded).
    double stiffest = std::max(1.0, s.stiffeningNeeded);
    int breaking = 0;
    // Pair u = (i, j) through its upper copy b: its force on i, or zero where it carries none;
    // the thread's own stiffest tangent and count of breaking copies moved on.
    auto pairForceOf = [&](int i, const Eigen::Vector3d& xi, int b, int u, double& stiffest,
                           int& breaking) -> Eigen::Vector3d {
        if (!alive[b]) return Eigen::Vector3d::Zero();
        const int j = partners[b];
        const Eigen::Vector3d r = xs[j] - xi;
        const double length = r.norm();
        double eta = length / restLength[b] - 1.0;  // eq. 10
        double thetaBar = 0.0;
        if constexpr (kTheta) {  // see mechanicalStrain()
            thetaBar = 0.5 * (theta[i] + theta[j]);
            eta -= expansion * thetaBar;
        }
        if constexpr (kBreak) {  // eq. 27/28
            double limit = criticalStretch_;
            if (stretchFactor) limit *= stretchFactor[b];
            if constexpr (kTheta) limit *= material_.strengthFactor(thetaBar);
            if (eta > limit) {
                if constexpr (kUpdateBonds) proposed[b] = proposed[twin[u]] = 1, breaking += 2;
                return Eigen::Vector3d::Zero();
            }
        }
        PlasticState state;
        double yield = 1.0;  // eta0's factor: the law runs in units of the bond's own eta0
        if constexpr (kLaw == BondLawKind::Elastoplastic) {
            if (yieldFactor) yield = yieldFactor[b];
            state = law_.yieldStep(eta / yield, plasticIn[b]);
            if constexpr (kUpdateBonds) plastic[b] = plastic[twin[u]] = state;
        }
        if constexpr (kUpdateBonds && kLaw == BondLawKind::PowerLaw) {
            if (eta < 0.0 && i >= slab_.begin) {  // its tangent in dt, if it closes (own i)
                const double rate = r.dot(v[j] - v[i]) / (length * restLength[b]);
                const double ahead = clampCompression(eta + std::min(0.0, dt * rate));
                double tangent =
                    ownLaws ? lawOf(b).powerLawStiffening(ahead) : law_.powerLawStiffening(ahead);
                // A dissolved bond (theta past 1 / stiffness_loss) is squashed by its own
                // swelling, yet carries no force: only the stiffness it has counts.
                if constexpr (kTheta) tangent *= material_.stiffnessFactor(thetaBar);
                stiffest = std::max(stiffest, tangent);
            }
        }
        // A copy of the law only where maps give this bond its own.
        double f = ownLaws ? yield * lawOf(b).template forceAs<kLaw>(eta / yield, state)
                           : yield * law_.template forceAs<kLaw>(eta / yield, state);
        if constexpr (kTheta) f *= material_.stiffnessFactor(thetaBar);
        return (bondScale[b] * f / length) * r;
    };
    // Each thread's maximum and count, combined once it is done (an OpenMP reduction would not
    // reach the lambda's updates: it captured the shared variables, not the private copies).
    const double needed = stiffest;
    inTeam(n >= kParallelThreshold, [&] {
        double mostHere = needed;
        int breakingHere = 0;
#pragma omp for schedule(static)
        for (int i = slab_.ghostBegin; i < slab_.end; ++i) {
            const Eigen::Vector3d xi = xs[i];
            for (int b = upperBegin[i], u = pairBegin[i]; b < offsets[i + 1]; ++b, ++u)
                pairForce[u] = pairForceOf(i, xi, b, u, mostHere, breakingHere);
        }
#pragma omp critical(rend_scalar_pair_pass)
        {
            stiffest = std::max(stiffest, mostHere);
            breaking += breakingHere;
        }
#pragma omp for schedule(static)
        for (int i = slab_.begin; i < slab_.end; ++i) {
            Eigen::Vector3d sum = Eigen::Vector3d::Zero();
            for (int b = offsets[i]; b < upperBegin[i]; ++b) sum -= pairForce[pairOf[b]];
            for (int u = pairBegin[i]; u < pairBegin[i + 1]; ++u) sum += pairForce[u];
            force[i] = sum;
        }
    });
    updates.breaking = breaking;
    updates.stiffest = stiffest;
}

bool PeridynamicBonds::historyOncePerBond() const {
    const int directed = int(plastic_.size());
    for (int b = 0; b < directed; ++b)
        if (std::memcmp(&plastic_[b], &plastic_[damage_->mirror(b)], sizeof(PlasticState)) != 0)
            return false;
    return true;
}

// The history is 8 bytes per directed bond: on the final foil (elastoplastic, 752K bonds) 12 of
// the state's 43 MB, which both ends of a bond held twice.
void PeridynamicBonds::saveState(StateWriter& out) const {
    syncHistory();
    const std::uint8_t once = !plastic_.empty() && historyOncePerBond();
    out(once);
    if (once) {
        std::vector<int>& first = historyFirstEnds_;  // b < mirror(b), kept between frames
        if (first.empty())
            for (int b = 0; b < int(plastic_.size()); ++b)
                if (b < damage_->mirror(b)) first.push_back(b);
        out.vectorOf<PlasticState>(first.size(),
                                   [&](std::uint64_t k) { return plastic_[first[k]]; });
    } else {
        out(plastic_);
    }
    out(stiffening_);
}

void PeridynamicBonds::loadState(StateReader& in) {
    std::uint8_t once = 0;
    in(once);
    if (once) {
        std::vector<PlasticState> perBond;
        in(perBond);
        std::size_t k = 0;
        plastic_.resize(bonds_.directedCount());
        for (int b = 0; b < int(plastic_.size()); ++b)
            if (b < damage_->mirror(b)) {
                if (k == perBond.size()) break;
                plastic_[b] = plastic_[damage_->mirror(b)] = perBond[k++];
            }
        if (k != perBond.size() || 2 * k != plastic_.size())
            throw StateMismatch("the state holds the history of " + std::to_string(perBond.size()) +
                                " bonds, this scene " + std::to_string(plastic_.size() / 2));
    } else {
        in(plastic_);
    }
    in(stiffening_);
    heldAhead_ = false, heldBehind_ = true;
}

void PeridynamicBonds::syncHistory() const {
    if (!heldAhead_) return;
    for (std::size_t u = 0; u < pairHeld_.size(); ++u)
        if (!pairPad_[u])
            plastic_[pairUpper_[u]].maxStrain = plastic_[pairTwin_[u]].maxStrain = pairHeld_[u];
    heldAhead_ = false;
}

// Rebuilt whenever a bond broke (as diffusion's copy of the life flags is): a byte read per row
// where the elastoplastic kernel read eight flags through eight bond indices, behind a branch
// on whether a lane grew that missed about every other row (crack_path_sources 12.8 -> 11.8 ns).
template <class Each>
bool PeridynamicBonds::forBreaksSince(std::uint64_t version, Each&& brokenBond) const {
    const auto broken = damage_->breaksSince(version);
    if (!broken) return false;
    const std::vector<int>& offsets = bonds_.offsets;
    for (const auto& [b, mirror] : *broken) {
        const int i =
            mirror >= 0
                ? bonds_.partners[mirror]
                : int(std::upper_bound(offsets.begin(), offsets.end(), b) - offsets.begin()) - 1;
        brokenBond(i, bonds_.partners[b]);
    }
    return true;
}

// Where only breaks happened since the last copy, the rows of their pairs' tiles again (a pad
// repeats a pair of its own tile), else every row: a shipped foil tearing at final quality
// spent 1.7% of its samples on the whole copy, made on every step that broke a bond.
const std::uint8_t* PeridynamicBonds::livingRows() const {
    const std::uint64_t now = damage_->version();
    if (livingVersion_ == now) return livingRows_.data();
    const std::uint8_t* alive = damage_->bondAlive().data();
    const auto rowsOf = [&](std::size_t first, std::size_t end) {
        for (std::size_t u = first; u < end; ++u) {
            std::uint8_t& row = livingRows_[u / kTile];
            const unsigned bit = 1u << (u % kTile);
            row = std::uint8_t(alive[pairUpper_[u]] != 0 ? row | bit : row & ~bit);
        }
    };
    const bool updated = forBreaksSince(livingVersion_, [&](int i, int j) {
        const int t = std::min(i, j) / kTile;  // the pair's tile: its first end's
        rowsOf(std::size_t(tileBegin_[t]), std::size_t(tileBegin_[t + 1]));
    });
    if (!updated) {
        livingRows_.assign(pairUpper_.size() / kTile, 0);
        rowsOf(0, pairUpper_.size());
    }
    livingVersion_ = now;
    return livingRows_.data();
}

// Kept as livingRows(): the tile sums read a byte per tile where they read its 48-96 flags. A
// broken bond's two ends' tiles no longer live.
const std::uint8_t* PeridynamicBonds::livingTiles() const {
    const std::uint64_t now = damage_->version();
    if (livingTilesVersion_ == now) return livingTiles_.data();
    const bool updated = forBreaksSince(livingTilesVersion_, [&](int i, int j) {
        livingTiles_[i / kTile] = 0, livingTiles_[j / kTile] = 0;
    });
    if (!updated) {
        const std::uint8_t* alive = damage_->bondAlive().data();
        const int* offsets = bonds_.offsets.data();
        const int n = bonds_.particleCount(), tiles = (n + kTile - 1) / kTile;
        livingTiles_.assign(tiles, 0);
        forEachIndex(n >= kParallelThreshold, 0, tiles, [&](int t) {
            const int first = offsets[kTile * t], last = offsets[std::min(n, kTile * (t + 1))];
            livingTiles_[t] =
                std::all_of(alive + first, alive + last, [](std::uint8_t a) { return a != 0; });
        });
    }
    livingTilesVersion_ = now;
    return livingTiles_.data();
}

LinearPairInput PeridynamicBonds::pairInput(const StepState& s, bool update, bool breakable) const {
    LinearPairInput in{pairFirst_.data(),
                       pairSecond_.data(),
                       pairRest_.data(),
                       pairScale_.data(),
                       breakable ? pairLimit_.data() : nullptr,
                       s.x.data()->data(),
                       s.theta.empty() ? nullptr : s.theta.data(),
                       law_.c,
                       material_.expansion(),
                       material_.params().stiffnessLoss,
                       material_.params().strengthLoss};
    in.law = &law_;
    in.powerC = law_.powerC, in.powerCStar = law_.powerCStar, in.powerN = law_.powerN;
    in.yieldStrain = law_.yieldStrain, in.softening = law_.softening;
    in.update = update;
    in.v = update ? s.v.data()->data() : nullptr, in.dt = s.dt;
    in.alive = damage_->bondAlive().data(), in.upper = pairUpper_.data();
    in.ownBegin = slab_.begin;
    in.allAlive = damage_->brokenBondCount() == 0;
    in.twin = pairTwin_.data();
    if (!plastic_.empty()) {
        if (heldBehind_) {
            pairHeld_.resize(pairUpper_.size());
            for (std::size_t u = 0; u < pairHeld_.size(); ++u)
                pairHeld_[u] = plastic_[pairUpper_[u]].maxStrain;
            heldBehind_ = false;
        }
        in.held = pairHeld_.data();
        heldAhead_ = heldAhead_ || update;
        if (update && !in.allAlive) in.livingRows = livingRows();
    }
    in.runFirst = rowRunFirst_.data(), in.runSecond = rowRunSecond_.data();
    // Past the furthest partner, by about 24 KiB of positions (512 to 4,096 measured alike).
    in.prefetchAhead = reach_ + 1024, in.particles = int(s.x.size());
    in.pairs = int(pairFirst_.size());
    in.uniform = rowClass_.data();
    in.classRest = classRest_.data(), in.classScale = classScale_.data();
    in.classLimit = classLimit_.data();
    in.classRestUnit = classRestUnit_.data(), in.classScaleUnit = classScaleUnit_.data();
    in.classLimitUnit = classLimitUnit_.data();
    in.restSteps = pairRestSteps_.data(), in.scaleSteps = pairScaleSteps_.data();
    in.limitSteps = pairLimitSteps_.data();
    return in;
}

namespace {

/// The largest |component| of the velocities of particles [p, e), for windows that move forward
/// (a thread's blocks, each with the reach of its bonds): chunks of kChunk particles, each read
/// once into a ring, so that a window's particles are not read again for every block that
/// reaches them. A chunk may hold particles outside the window: a larger bound, still a bound.
/// The look-ahead skips far rows while fewer than 1 in kNearShare vectors were near (measured:
/// 3% and 8% on crack_path_sources and stretch's 10^4 sheets, 41% on a 10^6 sheet mostly at
/// rest).
constexpr int kNearShare = 6, kProbe = 8;

class SpeedWindow {
public:
    SpeedWindow(const double* v, int n) : v_(v), n_(n) {}

    double over(int p, int e) {
        e = std::min(e, n_);
        const int c0 = p / kChunk, c1 = (e + kChunk - 1) / kChunk;
        if (c1 - c0 > kRing)
            return largestMagnitude(v_ + 3 * std::size_t(p), 3 * std::size_t(std::max(0, e - p)));
        if (next_ < c0 || c0 < next_ - kRing) next_ = c0;  // nothing kept is in the window
        for (; next_ < c1; ++next_) {
            const int begin = next_ * kChunk, end = std::min(n_, begin + kChunk);
            ring_[next_ % kRing] =
                largestMagnitude(v_ + 3 * std::size_t(begin), 3 * std::size_t(end - begin));
        }
        double largest = 0.0;
        for (int c = c0; c < c1; ++c) largest = std::max(largest, ring_[c % kRing]);
        return largest;
    }

private:
    static constexpr int kChunk = 256, kRing = 64;
    const double* v_;
    int n_, next_ = 0;
    double ring_[kRing];
};

void moveRange(BlockMotion& motion, int begin, int end) {
    if (begin < end) motion.move(begin, end, nullptr, 0);
}

}  // namespace

// The motion a step's pass takes on. The power law's look-ahead may cut the step into pieces
// (Membrane::piecesOfStep) only once every pair is seen, after the first blocks would have
// moved: it takes none unless the last pass shows that no pair can reach that far.
BlockMotion* PeridynamicBonds::movingMotion(const StepState& s) const {
    return law_.kind != BondLawKind::PowerLaw || lookAheadClear(s) ? s.motion : nullptr;
}

// A pair may raise the stiffening only where eta - reach x rest < lookAheadSlack of this step
// (pairLoopSimd's screen). Since the last pass each length changed by at most the drift's
// lookAheadSlack (|x_j - x_i| moved by at most |v_j - v_i| drift, and v has not changed since),
// each eta by rest |alpha| times theta's change more, and the rounding of a position and of the
// terms by a micro-strain of the longest bond and 2^-44 of the largest coordinate. Nothing else
// moved the particles (StepState::SinceLastPass), and the reach is the same where the stiffening
// asked for is.
bool PeridynamicBonds::lookAheadClear(const StepState& s) const {
    const StepState::SinceLastPass& since = s.sinceLastPass;
    if (!(since.drift >= 0.0 && s.speedBound >= 0.0 && since.thetaChange >= 0.0)) return false;
    if (nearestNeeded_ != std::max(1.0, s.stiffeningNeeded)) return false;
    const double swelling =
        s.theta.empty() ? 0.0 : longestRest_ * std::fabs(material_.expansion()) * since.thetaChange;
    const double rounding = 1e-6 * longestRest_ + 0x1p-44 * since.positionScale;
    const double left =
        nearestGap_ - lookAheadSlack(s.speedBound, since.drift) - swelling - rounding;
    return left >= lookAheadSlack(s.speedBound, s.dt);  // false for a NaN
}

template <bool kUpdateBonds, bool kBreak>
void PeridynamicBonds::vectorBondForces(const StepState& s, PairWorkspace& work,
                                        std::vector<Eigen::Vector3d>& force,
                                        Updates& updates) const {
    const int n = bonds_.particleCount();
    force.resize(n);
    const int teams = n >= kParallelThreshold ? omp_get_max_threads() : 1;
    // In rows, each ring has kPairTile doubles before it and after x, y and z (setUpRowSlots):
    // the tile sums (sim/PairSums.h) read a row's lanes from a run's slot of lane 0, which may
    // lie before the first slot, and read up to kPairTile - 1 past the last.
    const bool rows = slotRows();
    const std::size_t ringSize = rows ? std::size_t(ringDoubles_) : 4 * std::size_t(ringPairs_);
    work.slots.resize(ringSize * teams);
    if (kUpdateBonds && movingMotion(s))
        work.blockForce.resize(3 * std::size_t(kFusedBlock) * teams);
    const std::size_t rowCount = (pairFirst_.size() + kPairTile - 1) / kPairTile;
    if (kBreak) work.over.resize(rowCount);
    const std::uint8_t* const tileLiving = rows ? livingTiles() : nullptr;
    const LinearPairInput in = pairInput(s, kUpdateBonds, kBreak);
    LinearPairInput halo = in;  // pairs another thread owns: no history or look-ahead
    halo.update = false;
    // As the scalar loop's; a reduction's private copies start from the lowest double.
    const double needed = std::max(1.0, s.stiffeningNeeded);
    double stiffest = needed;
    // Membrane::failureApproachRate at the step's start, asked for by an adaptive step whose
    // length waits for it: each block's pairs measured just after its forces, in cache, instead
    // of in a pass of their own (no motion, so x and v are the step's start). A maximum: the
    // same for any thread count and order.
    // The kernels flag the pairs loaded past half eta_c as they compute their forces (their
    // screen's bits), so only those are measured (the shipped foil at final quality: a pass of
    // its own took 14% of a run's samples, measuring every pair in cache after the kernel 12%).
    std::optional<std::pair<LinearPairInput, ApproachRate>> approach;
    if (kUpdateBonds && kBreak && s.approach && !s.motion && !s.v.empty()) {
        approach = approachInput(s, *s.approach);
        work.approaching.resize(rowCount);
    }
    double fastestApproach = 0.0;
    double nearest = std::numeric_limits<double>::infinity();  // LinearPairOutput::nearest
    // Each thread takes a run of particles and, block by block, computes their pairs into its
    // own ring of slots and at once sums them into the block's particles, while the slots are
    // in cache (a ring, so that they never go to memory). A particle's lower copies reach back
    // at most reach_ particles: each thread first computes the pairs of the reach_ particles
    // before its run (read-only, before the barrier, so before any owner moves the histories
    // on). Every slot holds the bits the owner computes, and each sum is in the gather's order:
    // the same bits for any thread count. Runs and blocks start at a tile's first particle.
    stiffest = largestInTeam(n >= kParallelThreshold, stiffest, [&](double& stiffest) {
        const int threads = omp_get_num_threads(), t = omp_get_thread_num();
        const std::int64_t span = slab_.end - slab_.ghostBegin;
        const int from = tileStart(slab_.ghostBegin + int(span * t / threads));
        const int to = t + 1 == threads
                           ? slab_.end
                           : tileStart(slab_.ghostBegin + int(span * (t + 1) / threads));
        double* ring = work.slots.data() + ringSize * t + (rows ? kPairTile : 0);
        // Each block's look-ahead starts from the largest tangent of the thread's blocks before
        // it: fewer lanes raise it (190,450 to 5,363 in stretch's 4 frames), the same maximum.
        // It skips the rows with no lane near the reach (LinearPairInput::skipFar) while the
        // last block that tried had few such rows, and tries again every kProbe blocks; where
        // most rows have one (a sheet at rest, whose rounding compresses half its bonds by
        // 1e-16), the branch would miss too often.
        SpeedWindow speeds(in.v, n);
        // Where the membrane knows a bound on every speed (the last check's), one slack for every
        // block: |v| bounds each component, and v is not read again for it (crack_path_sources,
        // power law: the windows' reads were 0.23 of 12.3 ns per particle-step).
        const bool known = s.speedBound >= 0.0;
        const double knownSlack = known ? lookAheadSlack(s.speedBound, s.dt) : 0.0;
        bool skipFar = false;
        int block = 0;
        const bool lookAhead = in.update && law_.kind == BondLawKind::PowerLaw;
        // The thread's own copies (328 bytes each), taken once per step rather than per block:
        // each block sets what it changes.
        LinearPairInput own = in, ghosts = halo;
        double ownNearest = std::numeric_limits<double>::infinity();
        const auto compute = [&](LinearPairInput& input, int p, int q) {
            double most = std::max(needed, stiffest);
            int near = 0;
            input.lookAheadSlack = in.lookAheadSlack, input.skipFar = in.skipFar;
            if (input.update && lookAhead && (skipFar || block++ % kProbe == 0)) {
                input.lookAheadSlack =
                    known ? knownSlack : lookAheadSlack(speeds.over(p, q + reach_), s.dt);
                input.skipFar = true;
            }
            const int first = pairsBefore(p), end = pairsBefore(q);
            for (int u = first; u < end;) {  // split at the ring's wrap
                const int base = u - int(unsigned(u) & (ringPairs_ - 1));
                const int stop = std::min(end, base + ringPairs_);
                input.stiffestKnown = most;
                LinearPairOutput out{ring, work.over.data()};
                out.slotBase = base, out.rows = rows;
                if (approach && &input == &own)
                    out.approaching = work.approaching.data(), out.approach = &approach->second;
                if (lookAhead && &input == &own) out.nearest = &ownNearest;
                if (rows) out.rowSlot = rowSlot_.data(), out.stride = rowStride_;
                out.nearRows = &near;
                most = std::max(most, linearPairForces(input, out, u, stop));
                u = stop;
            }
            if (input.skipFar) skipFar = kNearShare * near * simdWidth() < end - first;
            return most;
        };
        compute(ghosts, tileStart(std::max(slab_.ghostBegin, from - reach_)), from);
        double approaching = 0.0;  // the flagged pairs of the thread's blocks
#pragma omp barrier
        PairGather gather{bonds_.offsets.data(),
                          pairs_.upperBegin.data(),
                          rows ? bondSlot_.data() : slotOf_.data(),
                          damage_->bondAlive().data(),
                          ring,
                          force.data()->data(),
                          unsigned(ringPairs_ - 1),
                          &sumTiles_,
                          rows,
                          streamsForces(slab_.end - slab_.ghostBegin),
                          rowStride_};
        gather.tileLiving = tileLiving;
        // Each block moved as soon as it is summed (StepState::motion), while its forces,
        // positions and velocities are in cache: a block's pairs read the positions of the
        // particles up to reach_ past it and never before it, so this thread reads a summed
        // block no more; the thread before reads this thread's first reach_ particles, moved
        // after the barrier at the end. The forces are read back at once: not streamed.
        BlockMotion* const motion = kUpdateBonds ? movingMotion(s) : nullptr;
        const int settled = t == 0 ? from : std::min(to, from + reach_);
        if (motion) gather.stream = false;
        // A block moved at once has its forces summed into a block of the thread's own, which
        // stays in L1, and moved from there: the force array's lines are neither read nor
        // written for it. At 10^6 particles they went to memory and came back every step
        // (crack_path_sources, linear, one thread, with and without it in alternate spans of
        // one run: 14.10 -> 13.44, 14.70 -> 14.00 ns per particle-step; 10^4: 10.93 -> 10.93).
        // The particles moved after the barrier keep theirs in the force array.
        double* const forceArray = gather.force;
        double* const ownBlock = work.blockForce.data() + 3 * std::size_t(kFusedBlock) * t;
        for (int p = from; p < to; p += kFusedBlock) {
            const int q = std::min(to, p + kFusedBlock);
            // The first pair of the block after next, asked for now: on a sheet that streams
            // from memory, pairsBefore()'s read had missed every cache once per block (10^6
            // particles, power law: 3.2% of the samples in this loop's own code, then 0.4%).
            __builtin_prefetch(&tileBegin_[std::min(q + 2 * kFusedBlock, n) / kTile]);
            stiffest = std::max(stiffest, compute(own, p, q));
            if (approach)
                approaching =
                    std::max(approaching, flaggedApproachRate(approach->first, approach->second,
                                                              work.approaching.data(),
                                                              pairsBefore(p), pairsBefore(q)));
            const int first = std::max(p, slab_.begin);
            const bool inBlock = motion && first >= settled;
            gather.force = inBlock ? ownBlock : forceArray;
            gather.forceFirst = inBlock ? p : 0;
            gatherPairForces(gather, first, q);
            if constexpr (kUpdateBonds) {  // forces() never moves
                if (inBlock)
                    motion->move(first, q, ownBlock, p);
                else if (motion)
                    moveRange(*motion, std::max(first, settled), q);
            }
        }
        if (motion) {
#pragma omp barrier
            moveRange(*motion, std::max(from, slab_.begin), settled);
        }
#pragma omp critical(rend_approach)
        {
            fastestApproach = std::max(fastestApproach, approaching);
            nearest = std::min(nearest, ownNearest);
        }
    });
    if (approach) *s.approachRate = fastestApproach;
    if (kUpdateBonds && law_.kind == BondLawKind::PowerLaw) updates.nearest = nearest;
    updates.breaking = kUpdateBonds && kBreak ? proposeBreaks(work.over, updates.proposed) : 0;
    updates.stiffest = stiffest;
}

// The pairs past their limit among the upper copies this process computes (not the pads): both
// copies proposed. A decomposed run computes the pairs of its ghosts below its own particles
// too, with the owner's bits, and breaks them as the owner does: a bond between a ghost and an
// own particle breaks on both processes in the same step (the scalar loop's rule too).
int PeridynamicBonds::proposeBreaks(const std::vector<std::uint8_t>& over,
                                    std::uint8_t* proposed) const {
    const std::uint8_t* alive = damage_->bondAlive().data();
    int breaking = 0;
    const int end = pairsBefore(slab_.end), endRow = (end + kPairTile - 1) / kPairTile;
    for (int row = pairsBefore(tileStart(slab_.ghostBegin)) / kPairTile; row < endRow; ++row) {
        std::uint64_t eight = 0;  // 64 pairs at once where none is past its limit
        if (row + 8 <= endRow && (std::memcpy(&eight, &over[row], 8), eight == 0)) {
            row += 7;
            continue;
        }
        for (unsigned bits = over[row]; bits != 0; bits &= bits - 1) {
            const int u = kPairTile * row + std::countr_zero(bits);
            if (u >= end) break;
            const bool computed = pairFirst_[u] >= slab_.ghostBegin && pairFirst_[u] < slab_.end;
            if (!pairPad_[u] && computed && alive[pairTwin_[u]]) {
                proposed[pairTwin_[u]] = 1;
                proposed[pairUpper_[u]] = 1;
                breaking += 2;
            }
        }
    }
    return breaking;
}

template <bool kUpdateBonds>
void PeridynamicBonds::bondForces(const StepState& s, Workspace& work,
                                  std::vector<Eigen::Vector3d>& force, Updates& updates) const {
    PairWorkspace& pairs = static_cast<PairWorkspace&>(work);
    if (vectorised()) {
        if (std::isfinite(criticalStretch_))
            return vectorBondForces<kUpdateBonds, true>(s, pairs, force, updates);
        return vectorBondForces<kUpdateBonds, false>(s, pairs, force, updates);
    }
    const bool theta = !s.theta.empty();
    const bool breakable = std::isfinite(criticalStretch_);
    auto forLaw = [&]<BondLawKind kLaw>() {
        if (theta && breakable)
            bondForcesFor<kUpdateBonds, kLaw, true, true>(s, pairs, force, updates);
        if (theta && !breakable)
            bondForcesFor<kUpdateBonds, kLaw, true, false>(s, pairs, force, updates);
        if (!theta && breakable)
            bondForcesFor<kUpdateBonds, kLaw, false, true>(s, pairs, force, updates);
        if (!theta && !breakable)
            bondForcesFor<kUpdateBonds, kLaw, false, false>(s, pairs, force, updates);
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

void PeridynamicBonds::forces(const StepState& s, Workspace& work,
                              std::vector<Eigen::Vector3d>& force) const {
    Updates none;
    bondForces<false>(s, work, force, none);
}

void PeridynamicBonds::advance(const StepState& s, Workspace& work,
                               std::vector<Eigen::Vector3d>& force) {
    Updates updates{plastic_.data(), damage_->proposals()};
    bondForces<true>(s, work, force, updates);
    if (updates.breaking > 0) damage_->applyProposals();
    if (law_.kind != BondLawKind::PowerLaw) return;
    stiffening_ = updates.stiffest;
    nearestNeeded_ = std::max(1.0, s.stiffeningNeeded);
    nearestGap_ = updates.stiffest == nearestNeeded_ ? updates.nearest
                                                     : -std::numeric_limits<double>::infinity();
}

std::pair<LinearPairInput, ApproachRate> PeridynamicBonds::approachInput(
    const StepState& s, const FailureApproach& f) const {
    LinearPairInput in = pairInput(s, false, false);
    in.v = s.v.data()->data();
    return {in, ApproachRate{f.criticalStretch, f.expansion, f.strengthLoss, f.maxStretchIncrement,
                             pairPad_.data(), slab_.begin, slab_.end}};
}

// The vectorised pass's pairs, each bond once through its upper copy, as Membrane's loop takes
// them (j > i, living, i this process's).
std::optional<double> PeridynamicBonds::failureApproachRate(const StepState& s,
                                                            const FailureApproach& f) const {
    if (!vectorised() || s.v.empty()) return std::nullopt;
    const std::pair<LinearPairInput, ApproachRate> input = approachInput(s, f);
    const LinearPairInput& in = input.first;  // named: a lambda below reads them
    const ApproachRate& a = input.second;
    const int n = bonds_.particleCount(), first = pairsBefore(tileStart(slab_.begin));
    const int last = pairsBefore(slab_.end);
    double fastest = 0.0;  // a maximum: the same for any thread count
    return largestInTeam(n >= kParallelThreshold, fastest, [&](double& fastest) {
        const int threads = omp_get_num_threads(), t = omp_get_thread_num();
        const std::int64_t span = last - first;
        const int from = first + kTile * int(span / kTile * t / threads);
        const int to =
            t + 1 == threads ? last : first + kTile * int(span / kTile * (t + 1) / threads);
        fastest = std::max(fastest, pairApproachRate(in, a, from, to));
    });
}

void PeridynamicBonds::reportStrength(DamageState& damage) const {
    syncHistory();
    for (std::size_t b = 0; b < plastic_.size(); ++b)
        damage.weaken(int(b), lawOf(int(b)).strengthLeft(plastic_[b]));  // eq. 27
}

double PeridynamicBonds::strainEnergy(const StepState& s, Workspace&) const {
    syncHistory();
    return strainEnergyOf(s, 0, bonds_.particleCount());
}

// In blocks of particles summed in order, so its bits are the same on any thread count: each
// frame's stats row takes it, and on one thread it was 3-5% of a final-quality foil.
double PeridynamicBonds::strainEnergyOf(const StepState& s, int begin, int end) const {
    constexpr int kBlock = 8192;
    const int blocks = (end - begin + kBlock - 1) / kBlock;
    if (blocks <= 1) return blockStrainEnergy(s, begin, end);
    std::vector<double> partial(std::size_t(blocks), 0.0);
#pragma omp parallel for schedule(static)
    for (int k = 0; k < blocks; ++k)
        partial[std::size_t(k)] =
            blockStrainEnergy(s, begin + k * kBlock, std::min(end, begin + (k + 1) * kBlock));
    double sum = 0.0;
    for (const double e : partial) sum += e;
    return sum;
}

double PeridynamicBonds::blockStrainEnergy(const StepState& s, int begin, int end) const {
    const auto& x = s.x;
    double sum = 0.0;
    // Each bond once, from its upper copy i -> j (i < j), as the force loop computes its force:
    // the particle of the smaller index counts the whole U_ij (eqs. 12-14).
    for (int i = begin; i < end; ++i)
        for (int b = pairs_.upperBegin[i]; b < bonds_.offsets[i + 1]; ++b) {
            if (!damage_->bondAlive()[b]) continue;
            double thetaBar;
            const double length = (x[bonds_.partners[b]] - x[i]).norm();
            const double eta = mechanicalStrain(i, b, length, s.theta, thetaBar);
            const PlasticState state = plastic_.empty() ? PlasticState{} : plastic_[b];
            const double k = yieldOf(b);
            sum += bondScale_[b] * bonds_.restLength[b] * material_.stiffnessFactor(thetaBar) * k *
                   k * lawOf(b).energy(eta / k, state);
        }
    return sum;
}

Eigen::Matrix3d PeridynamicBonds::particleStress(int i, const StepState& s) const {
    syncHistory();
    const auto& x = s.x;
    Eigen::Matrix3d sigma = Eigen::Matrix3d::Zero();
    for (int b = bonds_.offsets[i]; b < bonds_.offsets[i + 1]; ++b) {
        if (!damage_->bondAlive()[b]) continue;
        const Eigen::Vector3d r = x[bonds_.partners[b]] - x[i];
        const double length = r.norm();
        double thetaBar;
        const double eta = mechanicalStrain(i, b, length, s.theta, thetaBar);
        const PlasticState state = plastic_.empty() ? PlasticState{} : plastic_[b];
        const double k = yieldOf(b);
        const double f = material_.stiffnessFactor(thetaBar) * k * lawOf(b).force(eta / k, state);
        sigma += (bondScale_[b] * f / length) * r * r.transpose();
    }
    return sigma / (2.0 * volume_[i]);
}

}  // namespace rend::sim
