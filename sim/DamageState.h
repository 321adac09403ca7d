#pragma once
// The one owner of fracture state: which bonds are broken and how much strength they have
// left (eq. 27's gamma), which rest triangles are removed, and the maps between rest-lattice
// edges, the two copies of their bonds and their triangles, built once at set-up. The Membrane
// owns it; solvers change it only through breakBond, breakEdge, removeTriangle and weaken, and
// every reader (the pressure load, the FrameView's surfaces, diffusion, the damage field) sees
// the same answer.
//
// Determinism. Serial code applies an operation at once. A parallel loop (the peridynamic
// bonds) proposes breaks into a second buffer, one flag per directed bond written only by the
// bond's own particle, and applyProposals() breaks them after the loop in bond index order, as
// LAMMPS PERI does. Both copies of a bond see the same strain bit for bit and a bond past its
// limit already carries no force in the step it breaks, so the buffered break gives the same
// bits as breaking in place, for any thread count.
//
// A triangle is kept (FrameView::keptTriangles) while it is not removed and none of its edges
// is broken; an edge breaks with its bond.

#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <type_traits>
#include <vector>

#include "sim/Bonds.h"

namespace rend::sim {

class DamageState {
public:
    DamageState() = default;
    /// Every bond intact at full strength, every triangle kept; the edge maps of `triangles`
    /// (counter-clockwise, side s opposite vertex s) onto `bonds`.
    DamageState(const BondFamilies& bonds, std::span<const std::array<int, 3>> triangles);

    // The maps, fixed at set-up.
    /// Rest-lattice edges {i, j}, i < j, numbered in order of first appearance over the
    /// triangles' sides (side s of a triangle joins its vertices s + 1 and s + 2).
    const std::vector<std::array<int, 2>>& edges() const { return edges_; }
    /// The bonds i -> j and j -> i of edge e; -1 where the horizon is shorter than the edge.
    const std::array<int, 2>& edgeBonds(int e) const { return edgeBonds_[e]; }
    /// The one or two triangles holding edge e, the lower index first; -1 for a free edge.
    const std::array<int, 2>& edgeTriangles(int e) const { return edgeTriangles_[e]; }
    /// Edge of side s of triangle t.
    const std::array<int, 3>& triangleEdges(int t) const { return triangleEdges_[t]; }
    /// The edge bond b runs along, or -1.
    int bondEdge(int b) const { return bondEdge_[b]; }
    /// The other copy of bond b (j -> i for i -> j).
    int mirror(int b) const { return mirror_[b]; }

    // The state.
    /// Per directed bond: 1 intact, 0 broken; both copies always agree.
    const std::vector<std::uint8_t>& bondAlive() const { return bondAlive_; }
    /// Per directed bond, eq. 27's gamma as last reported by weaken(); 1 when never weakened.
    const std::vector<double>& strength() const { return strength_; }
    bool edgeIntact(int e) const { return edgeAlive_[e] != 0; }
    /// Per rest triangle: 1 until removeTriangle().
    const std::vector<std::uint8_t>& triangleAlive() const { return triangleAlive_; }
    /// Per rest triangle: 1 while it is alive and all three edges are intact.
    const std::vector<std::uint8_t>& keptTriangles() const { return kept_; }
    std::size_t brokenBondCount() const { return brokenBonds_; }
    /// Moves on whenever bondAlive() changes (a break, a loaded state): a copy made at one
    /// version is current while it holds.
    std::uint64_t version() const { return version_; }
    /// Both copies of each bond broken since `version`, in order, where every change since was a
    /// break (a copy made then is brought up to date by clearing their flags alone); nullopt
    /// where the state was loaded since, or `version` is not one it had.
    std::optional<std::span<const std::array<int, 2>>> breaksSince(std::uint64_t version) const;
    std::size_t removedTriangleCount() const { return removedTriangles_; }

    // The operations.
    /// Breaks both copies of bond b and the edge it runs along, if any.
    void breakBond(int b);
    /// Breaks edge e and both copies of its bond.
    void breakEdge(int e);
    /// Removes triangle t (element erosion); its edges stay as they are.
    void removeTriangle(int t);
    /// Sets the strength left of the copy b of a bond to gamma (a solver reports both copies).
    void weaken(int b, double gamma);

    /// A parallel loop's break of bond b, applied by applyProposals(); safe from any thread as
    /// long as each directed bond is proposed only by its own particle.
    void proposeBreak(int b) { proposed_[b] = 1; }
    /// The buffer proposeBreak() writes, for a hot loop that keeps its pointers in registers.
    std::uint8_t* proposals() { return proposed_.data(); }
    /// Breaks the proposed bonds in index order and clears the buffer.
    void applyProposals();

    /// What a checkpoint keeps (sim/StateArchive.h); the maps are rebuilt from the scene.
    template <class Self, class Archive>
    static void visitState(Self& s, Archive& a) {
        a(s.bondAlive_), a(s.edgeAlive_), a(s.triangleAlive_), a(s.kept_), a(s.strength_);
        a(s.brokenBonds_), a(s.removedTriangles_);
        if constexpr (!std::is_const_v<Self>) {  // loading
            ++s.version_;
            s.breaks_.clear(), s.logBase_ = s.version_;
        }
    }

private:
    void killEdge(int e);

    std::vector<std::array<int, 2>> edges_, edgeBonds_, edgeTriangles_;
    std::vector<std::array<int, 3>> triangleEdges_;
    std::vector<int> bondEdge_, mirror_;
    std::vector<std::uint8_t> bondAlive_, proposed_, edgeAlive_, triangleAlive_, kept_;
    std::vector<double> strength_;
    std::size_t brokenBonds_ = 0, removedTriangles_ = 0;
    std::uint64_t version_ = 0;
    /// The breaks since version logBase_, one a version: version_ is logBase_ + their count.
    std::vector<std::array<int, 2>> breaks_;
    std::uint64_t logBase_ = 0;
};

}  // namespace rend::sim
