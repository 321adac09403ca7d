#pragma once
// Domain decomposition across processes (issue 16, `mpirun -np N rend run`). The sheet is cut
// into slabs of consecutive particle indices: the lattice numbers its particles row by row, so a
// slab is a band of the rest configuration. Each process owns one slab, steps only its own
// particles, and keeps the particles just outside it (its ghosts: every particle its pairs reach)
// current by exchanging them with the slabs either side after every update. Every pair that
// touches a slab is computed from the same inputs as on one process, and every quantity that
// decides the step (time step, blow-up guard, breaks) is reduced over all of them, so the state
// is the one process's bit for bit. The set-up is replicated: every process builds the whole
// sheet. The transport (MPI) lives in app/; sim/ sees only this interface.

#include <span>
#include <stdexcept>
#include <vector>

#include "sim/Bonds.h"

namespace rend::sim {

/// The particles of one slab and what it reads around it.
struct Slab {
    int begin = 0, end = 0;            ///< owned particles [begin, end)
    int ghostBegin = 0, ghostEnd = 0;  ///< [ghostBegin, ghostEnd) holds every pair it computes
};

/// Slabs of equal particle counts. Throws std::invalid_argument when a slab's ghosts reach past
/// its neighbours (more processes than the sheet has rows of bonds for).
std::vector<Slab> partitionSlabs(const BondFamilies& bonds, int count);

/// The collective operations a decomposed Membrane needs; app/MpiDomain.h implements them.
class Domain {
public:
    virtual ~Domain() = default;
    int rank() const { return rank_; }
    int size() const { return int(slabs_.size()); }
    const Slab& slab() const { return slabs_[rank_]; }
    const std::vector<Slab>& slabs() const { return slabs_; }

    /// Refreshes this slab's ghosts in `values` (`width` numbers per particle) from the slabs
    /// that own them.
    virtual void exchange(double* values, int width) = 0;
    /// In place, over all processes: sums (the same order on every process) and maxima.
    virtual void sum(std::span<double> values) = 0;
    virtual void max(std::span<double> values) = 0;
    /// Brings every slab's own part of `values` (`width` items of `bytes` bytes per particle,
    /// or per directed bond with `perBond`) to process 0.
    virtual void gather(void* values, int width, int bytes, bool perBond) = 0;

    double sum(double v) { return sum(std::span<double>(&v, 1)), v; }
    double max(double v) { return max(std::span<double>(&v, 1)), v; }

protected:
    Domain(std::vector<Slab> slabs, int rank) : slabs_(std::move(slabs)), rank_(rank) {}

private:
    std::vector<Slab> slabs_;
    int rank_ = 0;
};

}  // namespace rend::sim
