#pragma once
// Bond families in CSR form, each bond stored from both ends so a force loop over particle i
// writes only to i (LAMMPS PERI style): no atomics, identical bits for any thread count. Which
// bonds are broken is the DamageState's (sim/DamageState.h), not theirs.

#include <Eigen/Core>
#include <algorithm>
#include <cstdint>
#include <span>
#include <vector>

namespace rend::sim {

struct BondFamilies {
    std::vector<int> offsets;        ///< bonds of particle i: [offsets[i], offsets[i+1])
    std::vector<int> partners;       ///< j
    std::vector<double> restLength;  ///< |x0_j - x0_i|
    std::vector<double> weight;      ///< W0 = 1 - |r0|/R, eq. 23

    int particleCount() const { return int(offsets.size()) - 1; }
    std::size_t directedCount() const { return partners.size(); }
    std::size_t bondCount() const { return partners.size() / 2; }
    int familySize(int i) const { return offsets[i + 1] - offsets[i]; }
};

/// max over particles i of sum over i's bonds b of term(b): the sum of an interior particle,
/// whose family is complete. Calibrations match the continuum there.
template <class Term>
double interiorFamilySum(const BondFamilies& bonds, Term term) {
    double best = 0.0;
    for (int i = 0; i < bonds.particleCount(); ++i) {
        double sum = 0.0;
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) sum += term(b);
        best = std::max(best, sum);
    }
    return best;
}

/// Index of the bond i -> j in the CSR arrays, or -1 when i and j are not bonded.
inline int findBond(const BondFamilies& bonds, int i, int j) {
    for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b)
        if (bonds.partners[b] == j) return b;
    return -1;
}

/// Every pair closer than `horizon` in the rest configuration, partners sorted by index.
BondFamilies buildBondFamilies(std::span<const Eigen::Vector3d> rest, double horizon);

/// Each bond once (LAMMPS's half list, "newton on"): pair u joins i < j and is numbered in the
/// CSR order of its upper copy i -> j, so particle i's pairs are [pairBegin[i], pairBegin[i+1])
/// and their upper copies [upperBegin[i], offsets[i+1]) of the BondFamilies. A force loop
/// computes each pair's length once and each particle then gathers its bonds' pair forces in
/// CSR order: no atomics, and the bits of the loop over both copies.
struct BondPairs {
    std::vector<int> upperBegin;  ///< per particle: its first bond to a larger index
    std::vector<int> pairBegin;   ///< per particle, and one past the last: its first pair
    std::vector<int> pairOf;      ///< per directed bond: its pair
    std::vector<int> twin;        ///< per pair: the lower copy j -> i

    int pairCount() const { return int(twin.size()); }
    /// Whether directed bond b of particle i is its pair's upper copy (i the smaller index).
    bool isUpper(int i, int b) const { return b >= upperBegin[i]; }
};

/// The pairs of `bonds`; throws std::logic_error when a bond has no copy at its other end.
BondPairs buildBondPairs(const BondFamilies& bonds);

}  // namespace rend::sim
