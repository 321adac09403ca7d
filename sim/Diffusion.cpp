#include "sim/Diffusion.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>

#include "sim/PairKernels.h"
#include "sim/Parallel.h"
#include "sim/Random.h"

namespace rend::sim {

bool Diffusion::needed(const MembraneParams& p) {
    const DiffusionParams& d = p.diffusion;
    return !d.spots.empty() || !d.scatters.empty() || !d.edges.empty() || d.initial != 0.0;
}

namespace {

/// A bond's length and W0 for eq. 25's rate: where its rest length is a lattice's, dx sqrt(k)
/// for a whole k (1, 2, 4, 5 on a square lattice; 1, 3, 4 on a hexagonal one) to within its
/// coordinates' rounding, that length exactly, and W0 = 1 - |xi| / R of it. Far from the origin
/// the rounding of a lattice's coordinates spreads one direction's rest lengths over thousands
/// of last bits, and so its rates: the diffusion's rows then read 16 bits of steps per bond
/// (sim/RowSteps.h), which a sheet past the caches streams from memory every step. Taken from
/// the lattice, a direction's rates are one value and its rows one class (crack_path_sources at
/// 10^6 particles, interleaved: 12.81 -> 11.83 ns per particle-step with one rate for all,
/// timing only). The length is the same for a bond's two copies, so every pair's flux stays
/// equal and opposite; the rates move by about 1e-13 of themselves, and theta's bits with them.
struct LatticeLength {
    double dx, horizon;

    std::pair<double, double> of(double length, double weight) const {
        const double k = (length / dx) * (length / dx), whole = std::round(k);
        if (!(whole >= 1.0 && std::abs(k - whole) <= 1e-9 * whole)) return {length, weight};
        const double exact = dx * std::sqrt(whole);
        return {exact, std::max(0.0, 1.0 - exact / horizon)};
    }
};

}  // namespace

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
    std::vector<double> rate(bonds.directedCount());
    const LatticeLength lattice{params.sheet.dx, params.sheet.horizonFactor * params.sheet.dx};
    double worst = 0.0;
    for (int i = 0; i < n; ++i) {
        const double rhoC = m.density * density[i] * m.capacity;
        double total = 0.0;
        for (int b = bonds.offsets[i]; b < bonds.offsets[i + 1]; ++b) {
            const auto [xi, weight] = lattice.of(bonds.restLength[b], bonds.weight[b]);
            rate[b] = K_ * weight * volumes[bonds.partners[b]] / (rhoC * xi * xi);
            total += rate[b];
        }
        worst = std::max(worst, total);
    }
    stableDt_ = worst > 0.0 ? 1.0 / worst : std::numeric_limits<double>::infinity();
    tiles_ = DiffusionTiles::build(bonds, rate);
    const SheetParams& sheet = params.sheet;
    const bool seeded = sheet.seedSpacing > 0.0 && sheet.seedSpacing != sheet.dx;
    const std::optional<Lattice> seeds =
        seeded ? std::optional<Lattice>(seedLattice(sheet)) : std::nullopt;
    SourceFrame frame{rest, {}, seeds ? &*seeds : nullptr};
    for (const double v : volumes) frame.areas.push_back(v / sheet.thickness);
    if (!params.diffusion.spots.empty() || !params.diffusion.scatters.empty()) {
        frame.restByX = orderByX(rest);
        if (seeds) frame.seedsByX = orderByX(seeds->positions);
    }
    for (const DiffusionSpot& spot : params.diffusion.spots) addSpot(spot, frame);
    for (const SpotScatter& scatter : params.diffusion.scatters) expandScatter(scatter, frame);
    for (const DiffusionEdge& edge : params.diffusion.edges)
        for (int i = 0; i < n; ++i)
            if (edge.region.contains(rest[i])) held_.emplace_back(i, edge.value);
}

std::vector<int> orderByX(std::span<const Eigen::Vector3d> points) {
    std::vector<int> order(points.size());
    for (int i = 0; i < int(order.size()); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(),
                     [&](int a, int b) { return points[a].x() < points[b].x(); });
    return order;
}

std::vector<int> pointsInDisc(std::span<const Eigen::Vector3d> points, std::span<const int> byX,
                              const Eigen::Vector2d& center, double radius) {
    // |p - c| <= r implies |p.x - c.x| <= r with the same rounded difference (a correctly
    // rounded root of a sum of rounded squares is at least each |component|), and that
    // difference never falls as p.x grows: the points tested are one run of the order by x.
    const auto within = [&](int i) { return (points[i].head<2>() - center).norm() <= radius; };
    const auto offset = [&](int i) { return points[i].x() - center.x(); };
    std::vector<int> inside;
    if (byX.size() == points.size()) {
        const auto first = std::partition_point(byX.begin(), byX.end(),
                                                [&](int i) { return !(offset(i) >= -radius); });
        const auto last =
            std::partition_point(first, byX.end(), [&](int i) { return offset(i) <= radius; });
        // A run of at most a quarter of the points, those within sorted back into index order
        // (a strip across the sheet holds several times the disc's); a wider disc is cheaper to
        // find by testing every point.
        if (4 * (last - first) <= std::ptrdiff_t(points.size())) {
            std::copy_if(first, last, std::back_inserter(inside), within);
            std::sort(inside.begin(), inside.end());
            return inside;
        }
    }
    for (int i = 0; i < int(points.size()); ++i)
        if (within(i)) inside.push_back(i);
    return inside;
}

void Diffusion::addSpot(const DiffusionSpot& spot, const SourceFrame& frame) {
    Spot s{spot.start, spot.start + spot.duration, spot.rate, {}};
    s.particles = pointsInDisc(frame.rest, frame.restByX, spot.center, spot.radius);
    if (s.particles.empty()) return;
    double area = 0.0;
    for (const int i : s.particles) area += frame.areas[i];
    // The dose (theta x area per second) is the seed lattice's: a disc of a few particles
    // covers more or less than pi r^2, and a finer lattice must not change what it injects.
    if (frame.seeds) {
        const Lattice& seeds = *frame.seeds;
        const std::size_t inside =
            pointsInDisc(seeds.positions, frame.seedsByX, spot.center, spot.radius).size();
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

double Diffusion::step(std::vector<double>& theta, const DamageState& damage, double t, double dt,
                       bool takeSums) {
    const int n = int(theta.size());
    scratch_.resize(n);
    tiles_.refresh(damage);
    const int first = domain_ ? domain_->slab().begin : 0, last = domain_ ? domain_->slab().end : n;
    // The whole tiles of [first, last) eight at a time, the few particles at its ends alone.
    constexpr int kTile = DiffusionTiles::kTile;
    const int firstTile = (first + kTile - 1) / kTile, lastTile = std::max(firstTile, last / kTile);
    const int chunks = (lastTile - firstTile + kChunk - 1) / kChunk;
    const double* now = theta.data();
    double* next = scratch_.data();
    // The largest change of each chunk (lastChange()) and the guard's sums of its new theta
    // (thetaSums()), read back while it is in cache.
    chunkChange_.assign(measure_ ? std::max(chunks, 0) : 0, 0.0);
    chunkSums_.assign(takeSums ? std::max(chunks, 0) : 0, GuardSums{});
    forEachIndex(n >= kParallelThreshold, 0, chunks, [&](int c) {
        const int begin = firstTile + c * kChunk, end = std::min(lastTile, begin + kChunk);
        if (!measure_ && !takeSums) return diffuseTiles(tiles_, now, next, dt, begin, end);
        DiffusionMeasures taken;
        diffuseTiles(tiles_, now, next, dt, begin, end, std::nullopt, &taken);
        if (measure_) chunkChange_[c] = taken.largestChange;
        if (takeSums) chunkSums_[c] = taken.theta;
    });
    double change = 0.0;
    for (const double c : chunkChange_) change = std::max(change, c);
    const int headEnd = std::min(last, kTile * firstTile),
              tailBegin = std::max(first, kTile * lastTile);
    for (int i = first; i < headEnd; ++i) diffuseParticle(tiles_, now, next, dt, i);
    for (int i = tailBegin; i < last; ++i) diffuseParticle(tiles_, now, next, dt, i);
    if (measure_ && first < headEnd)
        change = std::max(change, largestChange(now + first, next + first, headEnd - first));
    if (measure_ && tailBegin < last)
        change =
            std::max(change, largestChange(now + tailBegin, next + tailBegin, last - tailBegin));
    theta.swap(scratch_);
    // The chunks whose particles the sources set or moved after their sums were taken.
    std::vector<std::uint8_t> touched(chunkSums_.size(), 0);
    const auto touch = [&](int i) {
        const int tile = i / kTile;
        if (takeSums && tile >= firstTile && tile < lastTile)
            touched[(tile - firstTile) / kChunk] = 1;
    };
    for (const Spot& spot : spots_)  // serial, in a fixed order: identical for any thread count
        if (t >= spot.start && t < spot.end) {
            for (int i : spot.particles) theta[i] += dt * spot.rate, touch(i);
            change += std::fabs(dt * spot.rate);
        }
    for (const auto& [i, value] : held_) {
        theta[i] = value, touch(i);
        change = std::max(change, std::fabs(value - scratch_[i]));
    }
    if (takeSums)
        takeThetaSums(theta, touched, firstTile, lastTile, first, headEnd, tailBegin, last);
    if (domain_) domain_->exchange(theta.data(), 1);
    return change;
}

void Diffusion::takeThetaSums(const std::vector<double>& theta,
                              const std::vector<std::uint8_t>& touched, int firstTile, int lastTile,
                              int first, int headEnd, int tailBegin, int last) {
    constexpr int kTile = DiffusionTiles::kTile;
    GuardSums sums;
    for (std::size_t c = 0; c < chunkSums_.size(); ++c) {
        const int begin = firstTile + int(c) * kChunk, end = std::min(lastTile, begin + kChunk);
        addThetaSums(sums, touched[c] ? guardThetaSums(theta.data(), kTile * begin, kTile * end)
                                      : chunkSums_[c]);
    }
    if (first < headEnd) addThetaSums(sums, guardThetaSums(theta.data(), first, headEnd));
    if (tailBegin < last) addThetaSums(sums, guardThetaSums(theta.data(), tailBegin, last));
    thetaSums_ = sums, thetaSumsTaken_ = true;
}

void Diffusion::advance(std::vector<double>& theta, const DamageState& damage, double t,
                        double dt) {
    // 0.9 of the Gershgorin bound keeps a margin for rounding.
    const int substeps = std::max(1, int(std::ceil(dt / (0.9 * stableDt_))));
    const double h = dt / substeps;
    lastChange_ = 0.0;
    for (int k = 0; k < substeps; ++k)
        lastChange_ += step(theta, damage, t + k * h, h, k + 1 == substeps);
    // Each sum rounded up by far more than its rounding: a bound.
    lastChange_ *= 1.0 + 0x1p-30;
}

}  // namespace rend::sim
