#include "sim/Diffusion.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <optional>

#include "sim/Parallel.h"
#include "sim/Random.h"

namespace rend::sim {

bool Diffusion::needed(const MembraneParams& p) {
    const DiffusionParams& d = p.diffusion;
    return !d.spots.empty() || !d.scatters.empty() || !d.edges.empty() || d.initial != 0.0;
}

Diffusion::Diffusion(const MembraneParams& params, std::span<const Eigen::Vector3d> rest,
                     const BondFamilies& bonds, std::span<const double> volumes)
    : initial_(params.diffusion.initial), particles_(bonds.particleCount()) {
    const MaterialParams& m = params.material;
    const int n = bonds.particleCount();
    const double interior = interiorFamilySum(
        bonds, [&](int b) { return bonds.weight[b] * volumes[bonds.partners[b]]; });
    K_ = interior > 0.0 ? 4.0 * m.conductivity / interior : 0.0;
    // A density map changes the thermal mass rho C too (per particle: the flux between two
    // particles stays equal and opposite, so the heat, the sum of rho C V theta, is kept).
    const std::vector<double> density =
        materialFactors(MappedProperty::Density, params.materialMaps, rest);
    rate_.resize(bonds.directedCount());
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
        const double rhoC = m.density * density[i] * m.capacity;
        double total = 0.0;
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const double xi = bonds.restLength[b];
            rate_[b] = K_ * bonds.weight[b] * volumes[bonds.partners[b]] / (rhoC * xi * xi);
            total += rate_[b];
        }
        worst = std::max(worst, total);
    }
    stableDt_ = worst > 0.0 ? 1.0 / worst : std::numeric_limits<double>::infinity();
    const SheetParams& sheet = params.sheet;
    const bool seeded = sheet.seedSpacing > 0.0 && sheet.seedSpacing != sheet.dx;
    const std::optional<Lattice> seeds =
        seeded ? std::optional<Lattice>(seedLattice(sheet)) : std::nullopt;
    SourceFrame frame{rest, {}, seeds ? &*seeds : nullptr};
    for (const double v : volumes) frame.areas.push_back(v / sheet.thickness);
    for (const DiffusionSpot& spot : params.diffusion.spots) addSpot(spot, frame);
    for (const SpotScatter& scatter : params.diffusion.scatters) expandScatter(scatter, frame);
    for (const DiffusionEdge& edge : params.diffusion.edges)
        for (int i = 0; i < n; ++i)
            if (edge.region.contains(rest[i])) held_.emplace_back(i, edge.value);
}

namespace {

bool inSpot(const Eigen::Vector3d& x0, const DiffusionSpot& spot) {
    return (x0.head<2>() - spot.center).norm() <= spot.radius;
}

}  // namespace

void Diffusion::addSpot(const DiffusionSpot& spot, const SourceFrame& frame) {
    Spot s{spot.start, spot.start + spot.duration, spot.rate, {}};
    double area = 0.0;
    for (int i = 0; i < int(frame.rest.size()); ++i)
        if (inSpot(frame.rest[i], spot)) {
            s.particles.push_back(i);
            area += frame.areas[i];
        }
    if (s.particles.empty()) return;
    // The dose (theta x area per second) is the seed lattice's: a disc of a few particles
    // covers more or less than pi r^2, and a finer lattice must not change what it injects.
    if (frame.seeds) {
        const Lattice& seeds = *frame.seeds;
        const auto inside =
            std::count_if(seeds.positions.begin(), seeds.positions.end(),
                          [&](const Eigen::Vector3d& x0) { return inSpot(x0, spot); });
        if (inside > 0) s.rate *= double(inside) * seeds.particleArea / area;
    }
    spots_.push_back(std::move(s));
}

void Diffusion::expandScatter(const SpotScatter& scatter, const SourceFrame& frame) {
    // A spot centred on a random particle of the seed lattice is uniform over the sheet,
    // whatever its outline, and lands at the same place at every spacing.
    const std::span<const Eigen::Vector3d> at =
        frame.seeds ? std::span<const Eigen::Vector3d>(frame.seeds->positions) : frame.rest;
    for (int k = 0; k < scatter.count; ++k) {
        const double u = uniformFromHash(scatter.seed, 2 * std::uint64_t(k));
        const double v = uniformFromHash(scatter.seed, 2 * std::uint64_t(k) + 1);
        const int particle = std::min(int(u * double(at.size())), int(at.size()) - 1);
        DiffusionSpot spot;
        spot.center = at[particle].head<2>();
        spot.radius = scatter.radius;
        spot.rate = scatter.rate;
        spot.start = scatter.start + v * scatter.spread;
        spot.duration = scatter.duration;
        addSpot(spot, frame);
    }
}

std::vector<double> Diffusion::initialTheta() const {
    std::vector<double> theta(particles_, initial_);
    for (const auto& [i, value] : held_) theta[i] = value;
    return theta;
}

void Diffusion::step(std::vector<double>& theta, const BondFamilies& bonds,
                     std::span<const std::uint8_t> alive, double t, double dt) {
    const int n = int(theta.size());
    scratch_.resize(n);
    const int first = domain_ ? domain_->slab().begin : 0, last = domain_ ? domain_->slab().end : n;
    // Local restrict pointers: through the members, each store to scratch_ would reload them.
    const int* __restrict offsets = bonds.offsets.data();
    const int* __restrict partners = bonds.partners.data();
    const std::uint8_t* __restrict living = alive.data();
    const double* __restrict rate = rate_.data();
    const double* __restrict now = theta.data();
    double* __restrict next = scratch_.data();
#pragma omp parallel for schedule(static) if (n >= kParallelThreshold)
    for (int i = first; i < last; ++i) {
        double flux = 0.0;
        const double own = now[i];
        for (int b = offsets[i]; b < offsets[i + 1]; ++b)
            if (living[b]) flux += rate[b] * (now[partners[b]] - own);
        next[i] = own + dt * flux;
    }
    theta.swap(scratch_);
    for (const Spot& spot : spots_)  // serial, in a fixed order: identical for any thread count
        if (t >= spot.start && t < spot.end)
            for (int i : spot.particles) theta[i] += dt * spot.rate;
    for (const auto& [i, value] : held_) theta[i] = value;
    if (domain_) domain_->exchange(theta.data(), 1);
}

void Diffusion::advance(std::vector<double>& theta, const BondFamilies& bonds,
                        std::span<const std::uint8_t> alive, double t, double dt) {
    // 0.9 of the Gershgorin bound keeps a margin for rounding.
    const int substeps = std::max(1, int(std::ceil(dt / (0.9 * stableDt_))));
    const double h = dt / substeps;
    for (int k = 0; k < substeps; ++k) step(theta, bonds, alive, t + k * h, h);
}

}  // namespace rend::sim
