#include "sim/Contact.h"

#include <omp.h>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <limits>

#include "sim/Parallel.h"
#include "sim/PointHash.h"

namespace rend::sim {
namespace {

/// Damping of the self-contact's normal force as a fraction of critical: a landing flap stops
/// rather than bounces.
constexpr double kContactDamping = 0.5;
/// A particle closes on a neighbour by at most this fraction of d in a step.
constexpr double kStepFraction = 0.25;
/// The self-contact's stiffness follows the fastest particle: sqrt(rate) >= kStopping vmax / d
/// stops two particles closing at 2 vmax within d / 2 (the spring's energy over d / 2 is
/// (kStopping / 4)^2 times their kinetic energy), and with the step limit a contact's own
/// frequency stays at sqrt(rate) dt <= kStopping kStepFraction / 2 = 0.625.
constexpr double kStopping = 5.0;
/// The candidate lists' skin, in units of d: at first, and its bounds. A list lasts until some
/// particle has moved skin / 2; each build sizes the next skin so that a list lasts about
/// kListSteps steps at the speeds the last one saw: a fast scene (a falling sheet) rebuilds less
/// often with a wide skin, a slow one (a pile at rest) checks fewer candidates with a thin one.
constexpr double kSkin = 1.0, kSkinMin = 0.25, kSkinMax = 2.0;
constexpr long kListSteps = 24;
/// ContactCulling's tiles, in units of the bond reach: wide enough that tiles two apart are
/// told apart by their bounding spheres, narrow enough that a gently bent sheet fits an affine
/// map over three of them (a bend's residual grows as the square of that width: film_poke at
/// dx = 0.01 spent 14% less in list builds with 2 than with 3; foil_drape and towel_pile the same).
constexpr double kTileSize = 2.0;
constexpr double kCullingReach = 0.6;
/// A triangle whose centroid is this many times farther from a corner than the widest at rest
/// goes into the stretched triangles' hash.
constexpr double kStretchedTriangle = 2.0;

/// The sum of f(i) over [0, n) by fixed blocks, each summed in order, the blocks added in order:
/// the same bits for any thread count.
template <class T, class F>
T blockSum(int n, T zero, F&& f) {
    constexpr int kBlock = 4096;
    const int blocks = (n + kBlock - 1) / kBlock;
    std::vector<T> part(std::size_t(blocks), zero);
    forEachIndex(n >= kParallelThreshold, 0, blocks, [&](int b) {
        for (int i = b * kBlock; i < std::min(n, (b + 1) * kBlock); ++i)
            part[std::size_t(b)] += f(i);
    });
    T sum = zero;
    for (const T& p : part) sum += p;
    return sum;
}

Eigen::Vector3d centroid(const std::array<int, 3>& t, std::span<const Eigen::Vector3d> x) {
    return (x[t[0]] + x[t[1]] + x[t[2]]) / 3.0;
}

}  // namespace

Contact::Contact(const ContactParams& params, double thickness, double horizon,
                 double stiffnessRate, std::span<const std::array<int, 3>> triangles,
                 std::span<const Eigen::Vector3d> rest)
    : params_(params),
      thickness_(thickness),
      offset_(0.5 * thickness),
      baseStiffnessRate_(stiffnessRate) {
    const double reach = horizon * (1.0 + 1e-9);  // the bond families' own reach (Bonds.cpp)
    restExclusion2_ = reach * reach;
    skin_ = kSkin * thickness_;
    if (params_.self.enabled) setUpTriangles(triangles, rest, reach);
    meshes_.resize(params_.colliders.size());
    for (const ColliderParams& collider : params_.colliders)
        colliderReach2_.push_back(std::pow(boundingRadius(collider) + offset_, 2));
    for (std::size_t c = 0; c < params_.colliders.size(); ++c) {
        const ColliderParams& collider = params_.colliders[c];
        // Reach: the offset and a step's worth of approach (stepLimit keeps it under 2 d).
        if (collider.shape == ColliderShape::Mesh && collider.mesh)
            meshes_[c].emplace(*collider.mesh, 4.0 * thickness_);
    }
    place(0.0);
}

void Contact::setUpTriangles(std::span<const std::array<int, 3>> triangles,
                             std::span<const Eigen::Vector3d> rest, double reach) {
    triangles_.assign(triangles.begin(), triangles.end());
    double widest = 0.0;
    restCentres_.resize(triangles_.size());
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        restCentres_[t] = centroid(triangles_[t], rest);
        for (const int c : triangles_[t])
            widest = std::max(widest, (rest[c] - restCentres_[t]).norm());
    }
    restWidest_ = widest;
    const std::size_t n = rest.size();
    vertexTriangleStart_.assign(n + 1, 0);
    for (const auto& tri : triangles_)
        for (const int corner : tri) ++vertexTriangleStart_[std::size_t(corner) + 1];
    for (std::size_t i = 0; i < n; ++i) vertexTriangleStart_[i + 1] += vertexTriangleStart_[i];
    vertexTriangles_.resize(std::size_t(vertexTriangleStart_[n]));
    std::vector<int> fill(vertexTriangleStart_.begin(), vertexTriangleStart_.end() - 1);
    for (std::size_t t = 0; t < triangles_.size(); ++t)
        for (const int corner : triangles_[t])
            vertexTriangles_[std::size_t(fill[std::size_t(corner)]++)] = int(t);
    isMover_.assign(n, 0);
    touchesMover_.assign(triangles_.size(), 0);
    allBonded2_ = reach > widest ? (reach - widest) * (reach - widest) : -1.0;
    noneBonded2_ = (reach + widest) * (reach + widest);
    culling_.emplace(rest, triangles, reach * reach, kTileSize * reach);
    // The widest skin that leaves ContactCulling room: on an undeformed sheet the reach d + skin
    // is at most kCullingReach of the rest clearance, and residuals of a quarter of it pass.
    skinCap_ = std::clamp(kCullingReach * culling_->restClearance() - thickness_,
                          kSkinMin * thickness_, kSkinMax * thickness_);
    skin_ = std::min(skin_, skinCap_);
}

void Contact::place(double t) {
    poses_.resize(params_.colliders.size());
    for (std::size_t c = 0; c < poses_.size(); ++c) poses_[c] = params_.colliders[c].poseAt(t);
}

// Out to the offset along the normal; then the normal velocity relative to the surface is
// removed if it approaches, and that removed speed bounds the friction: the tangential relative
// velocity stops if it needs no more than stiction times it, else slows by kinetic times it.
void Contact::pushOut(Eigen::Vector3d& x, Eigen::Vector3d& v, const SurfaceDistance& s,
                      const Eigen::Vector3d& surfaceVelocity, const Friction& friction) const {
    x += (offset_ - s.distance) * s.normal;
    const Eigen::Vector3d relative = v - surfaceVelocity;
    const double normalSpeed = relative.dot(s.normal);
    if (normalSpeed >= 0.0) return;  // already leaving (a collider pushing it catches it up)
    const Eigen::Vector3d tangential = relative - normalSpeed * s.normal;
    const double slide = tangential.norm();
    const double grip = -normalSpeed;
    const double keep = slide <= friction.stiction * grip
                            ? 0.0
                            : std::max(0.0, 1.0 - friction.kinetic * grip / slide);
    v = surfaceVelocity + keep * tangential;
}

void Contact::resolveParticle(Eigen::Vector3d& x, Eigen::Vector3d& v) const {
    const GroundParams& ground = params_.ground;
    for (std::size_t c = 0; c < poses_.size(); ++c) {
        const ColliderParams& collider = params_.colliders[c];
        const ColliderPose& pose = poses_[c];
        // Beyond its bounding sphere by the offset: no surface within the offset.
        if ((x - pose.position).squaredNorm() >= colliderReach2_[c]) continue;
        const std::optional<SurfaceDistance> local =
            signedDistance(collider, meshes_[c] ? &*meshes_[c] : nullptr, pose.toLocal(x));
        if (!local || local->distance >= offset_) continue;
        const SurfaceDistance world{local->distance, pose.rotation * local->normal};
        pushOut(x, v, world, pose.velocityAt(x), collider.friction);
    }
    // The ground last: whatever a collider did, nothing ends below it.
    if (ground.enabled && x.z() < ground.height + offset_) {
        const SurfaceDistance s{x.z() - ground.height, Eigen::Vector3d::UnitZ()};
        pushOut(x, v, s, Eigen::Vector3d::Zero(), ground.friction);
    }
}

void Contact::resolveNodeVelocity(const Eigen::Vector3d& at, Eigen::Vector3d& v,
                                  double reach) const {
    const double offset = offset_ + reach;
    for (std::size_t c = 0; c < poses_.size(); ++c) {
        const ColliderPose& pose = poses_[c];
        if ((at - pose.position).norm() >= std::sqrt(colliderReach2_[c]) + reach) continue;
        const std::optional<SurfaceDistance> local = signedDistance(
            params_.colliders[c], meshes_[c] ? &*meshes_[c] : nullptr, pose.toLocal(at));
        if (!local || local->distance >= offset) continue;
        Eigen::Vector3d x = at;
        pushOut(x, v, {local->distance, pose.rotation * local->normal}, pose.velocityAt(at),
                params_.colliders[c].friction);
    }
    const GroundParams& ground = params_.ground;
    if (ground.enabled && at.z() < ground.height + offset) {
        Eigen::Vector3d x = at;
        pushOut(x, v, {at.z() - ground.height, Eigen::Vector3d::UnitZ()}, Eigen::Vector3d::Zero(),
                ground.friction);
    }
}

void Contact::resolveColliders(std::vector<Eigen::Vector3d>& x, std::vector<Eigen::Vector3d>& v,
                               std::span<const double> mass, std::span<const std::uint8_t> free,
                               int first, int last) {
    const int n = last < 0 ? int(x.size()) - first : last - first;
    // Only the ground's height needs testing where there are no colliders: most particles are
    // well above it and cost one comparison.
    const bool colliders = !poses_.empty();
    const double floor = params_.ground.enabled ? params_.ground.height + offset_
                                                : -std::numeric_limits<double>::infinity();
    // Each particle's momentum change, and its size for the work bound, summed by fixed blocks
    // of particles (the same bits for any thread count); most blocks touch nothing.
    constexpr int kBlock = 4096;
    const int blocks = (n + kBlock - 1) / kBlock;
    std::vector<Eigen::Vector4d> part(std::size_t(blocks), Eigen::Vector4d::Zero());
    forEachIndex(n >= kParallelThreshold, 0, blocks, [&](int b) {
        for (int i = first + b * kBlock; i < first + std::min(n, (b + 1) * kBlock); ++i) {
            if (!free[i] || (!colliders && x[i].z() >= floor)) continue;
            const Eigen::Vector3d before = v[i];
            resolveParticle(x[i], v[i]);
            const Eigen::Vector3d p = mass[i] * (v[i] - before);
            part[std::size_t(b)] += Eigen::Vector4d(p.x(), p.y(), p.z(), p.norm());
        }
    });
    Eigen::Vector4d sum = Eigen::Vector4d::Zero();
    for (const Eigen::Vector4d& p : part) sum += p;
    impulse_ = sum.head<3>();
    work_ += colliderSpeed() * sum[3];
}

double Contact::colliderSpeed() const {
    double fastest = 0.0;
    for (std::size_t c = 0; c < poses_.size(); ++c)
        fastest =
            std::max(fastest, poses_[c].velocity.norm() + poses_[c].angularVelocity.norm() *
                                                              boundingRadius(params_.colliders[c]));
    return fastest;
}

double Contact::stepLimit(double maxSpeed) const {
    double limit = std::numeric_limits<double>::infinity();
    const double speed = colliderSpeed();
    for (const ColliderParams& collider : params_.colliders) {
        const double half =
            collider.shape == ColliderShape::Mesh ? 2.0 * thickness_ : halfThickness(collider);
        if (maxSpeed + speed > 0.0) limit = std::min(limit, half / (maxSpeed + speed));
    }
    if (params_.self.enabled && maxSpeed > 0.0)
        limit = std::min(limit, kStepFraction * thickness_ / (2.0 * maxSpeed));
    return limit;
}

// ---- self-contact ----------------------------------------------------------------------------

// A common translation changes no distance, so the list goes stale only once two particles may
// have closed by the skin: some particle has moved more than skin / 2 relative to a common
// displacement c (a falling sheet keeps its list). Any c bounds it, |u_i - u_j| <= |u_i - c| +
// |u_j - c|, so one pass measures against the mean displacement extrapolated from the last two
// evaluations (exact for a steady drift) while it sums the next mean. Past that, a stretching
// sheet may still keep it: see staleAfterAffineFit.
bool Contact::listStale(std::span<const Eigen::Vector3d> x) {
    if (builtAt_.size() != x.size()) return true;
    const int n = int(x.size());
    const Eigen::Vector3d centre = 2.0 * lastMean_[0] - lastMean_[1];
    struct Drift {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        double most = 0.0;  // squared
        Drift& operator+=(const Drift& o) {
            sum += o.sum;
            most = std::max(most, o.most);
            return *this;
        }
    };
    const Drift drift = blockSum(n, Drift{}, [&](int i) {
        const Eigen::Vector3d u = x[i] - builtAt_[i];
        return Drift{u, (u - centre).squaredNorm()};
    });
    const Eigen::Vector3d mean = drift.sum / double(n);
    lastMean_ = {mean, lastMean_[0]};
    drift_ = std::sqrt(drift.most);
    clearMovers();
    if (drift.most <= 0.25 * skin_ * skin_ || findMovers(x, centre)) return false;
    return staleAfterAffineFit(x, mean);
}

// The displacement since the build fitted by least squares as u = mean + G (X - centre), with
// F = I + G and r_i the residuals. Two points p, q of the build (particles, or points of
// triangles) at distance s are now at least sigma s - 2 max|r| apart, sigma the smallest
// singular value of F over the directions the build spans (a triangle's points are convex
// combinations of its corners, so each is off F's image by at most max|r| too). Everything left
// out of the list was at least d + skin away, so the list holds while
// sigma (d + skin) - 2 max|r| >= d. A sheet drawn apart keeps its list as long as it does not
// crumple or shrink across by skin / (d + skin).
bool Contact::staleAfterAffineFit(std::span<const Eigen::Vector3d> x,
                                  const Eigen::Vector3d& mean) const {
    if (builtSpan_.cols() == 0) return true;
    const int n = int(x.size());
    const Eigen::Matrix3d cross = blockSum(n, Eigen::Matrix3d::Zero().eval(), [&](int i) {
        return ((x[i] - builtAt_[i]) * (builtAt_[i] - builtCentre_).transpose()).eval();
    });
    const Eigen::Matrix3d g = cross * builtScatterInverse_;
    const double residual =  // squared
        largestOverIndices(n >= kParallelThreshold, 0, n, 0.0, [&](int i, double& most) {
            most = std::max(
                most, (x[i] - builtAt_[i] - mean - g * (builtAt_[i] - builtCentre_)).squaredNorm());
        });
    const Eigen::MatrixXd image = (Eigen::Matrix3d::Identity() + g) * builtSpan_;
    const double sigma = Eigen::JacobiSVD<Eigen::MatrixXd>(image).singularValues().minCoeff();
    return sigma * (thickness_ + skin_) - 2.0 * std::sqrt(residual) < thickness_;
}

// The build positions' centre and scatter, for staleAfterAffineFit.
void Contact::fitBuiltPositions() {
    const int n = int(builtAt_.size());
    builtCentre_ = blockSum(n, Eigen::Vector3d::Zero().eval(), [&](int i) { return builtAt_[i]; }) /
                   double(std::max(n, 1));
    const Eigen::Matrix3d scatter = blockSum(n, Eigen::Matrix3d::Zero().eval(), [&](int i) {
        const Eigen::Vector3d c = builtAt_[i] - builtCentre_;
        return (c * c.transpose()).eval();
    });
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(scatter);
    const double largest = eigen.eigenvalues().maxCoeff();
    builtScatterInverse_.setZero();
    std::vector<Eigen::Vector3d> span;
    for (int k = 0; k < 3; ++k) {
        const double lambda = eigen.eigenvalues()[k];
        if (!(largest > 0.0) || lambda <= 1e-12 * largest) continue;
        const Eigen::Vector3d q = eigen.eigenvectors().col(k);
        builtScatterInverse_ += q * q.transpose() / lambda;
        span.push_back(q);
    }
    builtSpan_.resize(3, Eigen::Index(span.size()));
    for (std::size_t k = 0; k < span.size(); ++k) builtSpan_.col(Eigen::Index(k)) = span[k];
}

// The skin scales with how long the last list lasted (in force evaluations, the same for any
// thread count), at most halved or doubled at once.
void Contact::sizeNextSkin() {
    const long lasted = evaluations_ - builtAtEvaluation_;
    builtAtEvaluation_ = evaluations_;
    if (builds_ <= 1 || lasted <= 0) return;
    const double scale = std::clamp(double(kListSteps) / double(lasted), 0.5, 2.0);
    skin_ = std::clamp(skin_ * scale, kSkinMin * thickness_, skinCap_);
}

bool Contact::bondedAtRest(int i, const std::array<int, 3>& tri,
                           std::span<const Eigen::Vector3d> rest) const {
    for (const int c : tri)
        if ((rest[i] - rest[c]).squaredNorm() <= restExclusion2_) return true;
    return false;
}

Contact::TriangleHash::TriangleHash(const Contact& contact, std::span<const int> which,
                                    std::span<const Eigen::Vector3d> centres,
                                    std::span<const double> radii, std::span<const int> kept,
                                    double reach)
    : hash(gather(which, centres), reach + widestOf(which, radii)) {
    items.resize(which.size());
    for (std::size_t slot = 0; slot < which.size(); ++slot) {
        const std::size_t k = std::size_t(which[std::size_t(hash.item(int(slot)))]);
        const int t = kept[k];
        items[slot] = {contact.restCentres_[std::size_t(t)], centres[k], radii[k], t};
    }
}

std::vector<Eigen::Vector3d> Contact::TriangleHash::gather(std::span<const int> which,
                                                           std::span<const Eigen::Vector3d> all) {
    std::vector<Eigen::Vector3d> some;
    for (const int k : which) some.push_back(all[std::size_t(k)]);
    return some;
}

double Contact::TriangleHash::widestOf(std::span<const int> which, std::span<const double> radii) {
    double widest = 0.0;
    for (const int k : which) widest = std::max(widest, radii[std::size_t(k)]);
    return widest;
}

// Every kept triangle within d + skin of particle i and not bonded to it at rest, and every
// particle within d + skin not bonded to it at rest. A particle and
// the triangles' corners each move less than skin / 2 before the next build, so no triangle
// left out comes within d before then. Each thread lists a contiguous range of particles, in
// order, so the lists do not depend on the thread count.
void Contact::buildList(const SheetState& s) {
    const double started = omp_get_wtime();
    const int n = int(s.x.size());
    const double reach = thickness_ + skin_;
    // Only the particles ContactCulling marks 1 can have anything within reach, and only
    // triangles with a corner marked 1 or 2 can be it.
    std::vector<std::uint8_t> active;
    lastActive_ = culling_->mark(s.x, reach, triangles_, s.kept, active);
    // The kept triangles (torn ones are never touched), their centroids and each one's largest
    // distance from its centroid to a corner.
    std::vector<int> kept;
    std::vector<Eigen::Vector3d> centres;
    std::vector<double> radii;  // each triangle's own
    for (std::size_t t = 0; lastActive_ > 0 && t < triangles_.size(); ++t) {
        if (!s.kept.empty() && !s.kept[t]) continue;
        const auto& tri = triangles_[t];
        if (!active[std::size_t(tri[0])] && !active[std::size_t(tri[1])] &&
            !active[std::size_t(tri[2])])
            continue;  // within reach of no particle marked 1 (ContactCulling::mark)
        kept.push_back(int(t));
        centres.push_back(centroid(tri, s.x));
        double r2 = 0.0;
        for (const int c : tri) r2 = std::max(r2, (s.x[c] - centres.back()).squaredNorm());
        radii.push_back(std::sqrt(r2));
    }
    std::vector<int> searched;
    std::vector<Eigen::Vector3d> searchedAt;
    for (int i = 0; i < n; ++i)
        if (active[std::size_t(i)] == 1) {
            searched.push_back(i);
            searchedAt.push_back(s.x[i]);
        }
    // Triangles stretched far past their rest size (a rubber film about a hole) would widen
    // every query: they get a hash of their own, with cells of their own reach.
    const auto [usual, stretched] = splitStretched(radii);
    const TriangleHash usualHash(*this, usual, centres, radii, kept, reach);
    const TriangleHash stretchedHash(*this, stretched, centres, radii, kept, reach);
    const PointHash points(searchedAt, reach);
    // What a query reads of each particle, in the hash's own order.
    struct ParticleItem {
        Eigen::Vector3d rest;
        int particle;
    };
    std::vector<ParticleItem> particleItems(searched.size());
    for (std::size_t slot = 0; slot < searched.size(); ++slot) {
        const int j = searched[std::size_t(points.item(int(slot)))];
        particleItems[slot] = {s.rest[j], j};
    }
    const auto triangleCandidates = [&](int i, std::vector<Candidate>& out) {
        for (const TriangleHash* h : {&usualHash, &stretchedHash})
            h->hash.nearSlots(s.x[i], [&](int slot) {
                const TriangleHash::Item& item = h->items[std::size_t(slot)];
                const double fromRest = (s.rest[i] - item.restCentre).squaredNorm();
                if (fromRest <= allBonded2_) return;      // every corner within the horizon
                const double near = reach + item.radius;  // a bound on its distance
                if ((s.x[i] - item.centre).squaredNorm() >= near * near) return;
                const auto& tri = triangles_[std::size_t(item.triangle)];
                if (fromRest <= noneBonded2_ && bondedAtRest(i, tri, s.rest)) return;
                const TrianglePoint c =
                    closestOnTriangle(s.x[i], s.x[tri[0]], s.x[tri[1]], s.x[tri[2]]);
                const double d2 =
                    (s.x[i] - c.at(s.x[tri[0]], s.x[tri[1]], s.x[tri[2]])).squaredNorm();
                if (d2 < reach * reach) out.push_back({i, item.triangle, std::sqrt(d2)});
            });
    };
    const auto candidates = [&](int i, std::vector<Candidate>& out) {
        triangleCandidates(i, out);
        points.nearSlots(s.x[i], [&](int slot) {
            const ParticleItem& item = particleItems[std::size_t(slot)];
            if (item.particle == i || (s.rest[i] - item.rest).squaredNorm() <= restExclusion2_)
                return;
            out.push_back({i, -(item.particle + 1), 0.0});  // a particle: negative
        });
    };
    std::vector<std::vector<Candidate>> found;
    inTeam(n >= kParallelThreshold, [&] {
#pragma omp single
        found.resize(std::size_t(omp_get_num_threads()));
        std::vector<Candidate>& mine = found[std::size_t(omp_get_thread_num())];
#pragma omp for schedule(static)
        for (int i = 0; i < n; ++i)
            if (active[std::size_t(i)] == 1) candidates(i, mine);
    });
    storeList(n, found);
    clearMovers();
    allUsual_.reset();
    allStretched_.reset();
    allPoints_.reset();
    builtAt_.assign(s.x.begin(), s.x.end());
    drift_ = 0.0;
    lastMean_ = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
    fitBuiltPositions();
    ++builds_;
    sizeNextSkin();
    buildSeconds_ += omp_get_wtime() - started;
}

std::array<std::vector<int>, 2> Contact::splitStretched(std::span<const double> radii) const {
    std::array<std::vector<int>, 2> split;
    for (std::size_t k = 0; k < radii.size(); ++k)
        split[radii[k] > kStretchedTriangle * restWidest_ ? 1 : 0].push_back(int(k));
    return split;
}

// The candidates as CSR lists, each particle's particles first, then its triangles nearest
// first at the build (ties by index), with those distances rounded down: nearestContact stops at
// the first triangle that cannot be nearer than the nearest found so far.
void Contact::storeList(int n, std::span<const std::vector<Candidate>> found) {
    listStart_.assign(std::size_t(n) + 1, 0);
    std::size_t total = 0;
    for (const auto& part : found) {
        total += part.size();
        for (const Candidate& c : part) ++listStart_[std::size_t(c.particle) + 1];
    }
    for (int i = 0; i < n; ++i) listStart_[std::size_t(i) + 1] += listStart_[std::size_t(i)];
    list_.resize(total);
    listDistance_.resize(total);
    std::vector<Candidate> all;  // thread order is particle order
    all.reserve(total);
    for (const auto& part : found) all.insert(all.end(), part.begin(), part.end());
    listed_.clear();
    for (int i = 0; i < n; ++i)
        if (listStart_[std::size_t(i) + 1] > listStart_[std::size_t(i)]) listed_.push_back(i);
    const int listed = int(listed_.size());
    forEachIndex(listed >= kParallelThreshold, 0, listed, [&](int k) {
        const int i = listed_[std::size_t(k)];
        const auto first = all.begin() + listStart_[std::size_t(i)];
        const auto last = all.begin() + listStart_[std::size_t(i) + 1];
        std::sort(first, last, [](const Candidate& a, const Candidate& b) {
            const bool pointA = a.target < 0, pointB = b.target < 0;
            if (pointA != pointB) return pointA;
            if (a.distance != b.distance) return a.distance < b.distance;
            return a.target < b.target;
        });
        for (auto c = first; c != last; ++c) {
            const std::size_t at = std::size_t(c - all.begin());
            list_[at] = c->target;
            // Rounded down: a float never above the double it stands for.
            float lower = float(c->distance);
            if (double(lower) > c->distance) lower = std::nextafter(lower, 0.0f);
            listDistance_[at] = lower;
        }
    });
}

// The force on particle i from the point of triangle `tri` with barycentric weights w: a damped
// spring over the overlap d - r along the line between them, never pulling, and Coulomb friction
// on the sliding velocity, at most what stops half of it this step. m_eff = m_i m_t / (m_i + m_t)
// (m_t the corners' masses by the weights) scales both, so the contact's own frequency is
// sqrt(stiffnessRate).
Eigen::Vector3d Contact::contactForce(int i, const std::array<int, 3>& tri,
                                      const Eigen::Vector3d& w, const Eigen::Vector3d& closest,
                                      const SheetState& s) const {
    const Eigen::Vector3d apart = s.x[i] - closest;
    const double r = apart.norm();
    if (!(r > 0.0)) return Eigen::Vector3d::Zero();  // on the triangle: no side to push to
    const Eigen::Vector3d normal = apart / r;
    const Eigen::Vector3d other = w[0] * s.v[tri[0]] + w[1] * s.v[tri[1]] + w[2] * s.v[tri[2]];
    const double otherMass = w[0] * s.mass[tri[0]] + w[1] * s.mass[tri[1]] + w[2] * s.mass[tri[2]];
    const Eigen::Vector3d relative = s.v[i] - other;
    const double closing = relative.dot(normal);  // > 0: separating
    const double massEff = s.mass[i] * otherMass / (s.mass[i] + otherMass);
    const double push =
        std::max(0.0, massEff * (stiffnessRate_ * (thickness_ - r) - dampingRate_ * closing));
    Eigen::Vector3d force = push * normal;
    const Eigen::Vector3d tangential = relative - closing * normal;
    const double slide = tangential.norm();
    if (slide > 0.0 && push > 0.0) {
        const Friction& f = params_.self.friction;
        const double stop = 0.5 * massEff * slide / s.dt;
        const double drag = stop <= f.stiction * push ? stop : std::min(stop, f.kinetic * push);
        force -= (drag / slide) * tangential;
    }
    return force;
}

void Contact::considerTriangle(int i, int t, const SheetState& s, double& best,
                               PointContact& contact, Eigen::Vector3d& closest) const {
    if (!s.kept.empty() && !s.kept[std::size_t(t)]) return;  // torn since the build
    const auto& tri = triangles_[std::size_t(t)];
    const TrianglePoint c = closestOnTriangle(s.x[i], s.x[tri[0]], s.x[tri[1]], s.x[tri[2]]);
    const Eigen::Vector3d point = c.at(s.x[tri[0]], s.x[tri[1]], s.x[tri[2]]);
    const double d2 = (s.x[i] - point).squaredNorm();
    if (d2 >= best) return;
    best = d2;
    contact.triangle = t;
    contact.weights = c.weights;
    closest = point;
}

void Contact::considerPoint(int i, int j, const SheetState& s, PointContact& contact) const {
    if ((s.x[i] - s.x[j]).squaredNorm() >= thickness_ * thickness_) return;
    contact.pointForce += contactForce(i, {j, j, j}, Eigen::Vector3d(1, 0, 0), s.x[j], s);
    ++contact.points;
}

// Particle i against its list: the nearest triangle within d, whose corners take the force back
// (scattered later), and every particle within d, whose own list holds i and computes the
// opposite force with the same arithmetic (gathered here). With movers, a mover's list is not
// read, nor the entries of others that hold a mover: its fresh candidates (`extra`) cover them.
template <bool kMovers>
Contact::PointContact Contact::nearestContact(int i, const SheetState& s,
                                              std::span<const int> extra) const {
    PointContact contact;
    double best = thickness_ * thickness_;
    Eigen::Vector3d closest;
    for (const int t : extra) {
        if (t < 0)
            considerPoint(i, -t - 1, s, contact);
        else
            considerTriangle(i, t, s, best, contact, closest);
    }
    const bool readList = !kMovers || !isMover_[std::size_t(i)];
    for (int k = listStart_[std::size_t(i)]; readList && k < listStart_[std::size_t(i) + 1]; ++k) {
        const int t = list_[std::size_t(k)];
        // Nothing since the build moved more than drift_ relative to the mean motion (movers
        // aside), so no point of a triangle closed on i by more than twice that; the rest of
        // the list was farther at the build.
        const double nearest = double(listDistance_[std::size_t(k)]) - 2.0 * drift_;
        if (t >= 0 && nearest > 0.0 && nearest * nearest >= best) break;
        if (t < 0) {
            if (kMovers && isMover_[std::size_t(-t - 1)]) continue;
            considerPoint(i, -t - 1, s, contact);
            continue;
        }
        if (kMovers && touchesMover_[std::size_t(t)]) continue;
        considerTriangle(i, t, s, best, contact, closest);
    }
    if (contact.triangle >= 0)
        contact.force =
            contactForce(i, triangles_[std::size_t(contact.triangle)], contact.weights, closest, s);
    return contact;
}

void Contact::addSelfContactForces(const SheetState& s, std::vector<Eigen::Vector3d>& force) {
    ++evaluations_;
    // A list that outlives its target by far was built with too wide a skin for this scene's
    // speeds (a pile at rest): rebuilding it lets the skin shrink, and the next lists hold fewer
    // candidates.
    const bool overdue =
        evaluations_ - builtAtEvaluation_ > 4 * kListSteps && skin_ > kSkinMin * thickness_;
    if (overdue || listStale(s.x)) buildList(s);
    pairs_ = 0;
    if (listed_.empty() && movers_.empty()) return;  // nothing within reach of anything
    const int n = int(s.x.size());
    const double fastest =  // squared
        largestOverIndices(n >= kParallelThreshold, 0, n, 0.0, [&](int i, double& most) {
            most = std::max(most, s.v[i].squaredNorm());
        });
    stiffnessRate_ =
        std::max(baseStiffnessRate_, kStopping * kStopping * fastest / (thickness_ * thickness_));
    dampingRate_ = 2.0 * kContactDamping * std::sqrt(stiffnessRate_);
    if (!movers_.empty()) {
        findMoverCandidates(s);
        ++moverEvaluations_;
    }
    const std::span<const int> order = movers_.empty() ? listed_ : order_;
    const int listed = int(order.size());
    contacts_.resize(order.size());
    const auto resolve = [&](int k, std::size_t& pairs) {
        const int i = order[std::size_t(k)];
        const PointContact& c = contacts_[std::size_t(k)] =
            movers_.empty() ? nearestContact<false>(i, s, {})
                            : nearestContact<true>(i, s,
                                                   std::span<const int>(extra_).subspan(
                                                       std::size_t(orderExtra_[std::size_t(k)]),
                                                       std::size_t(orderExtra_[std::size_t(k) + 1] -
                                                                   orderExtra_[std::size_t(k)])));
        force[std::size_t(i)] += c.pointForce;
        pairs += std::size_t(c.points);
        if (c.triangle < 0) return;
        force[std::size_t(i)] += c.force;
        ++pairs;
    };
    std::size_t pairs = 0;
    if (wakesTeam(listed >= kParallelThreshold)) {
#pragma omp parallel for schedule(static) reduction(+ : pairs)
        for (int k = 0; k < listed; ++k) resolve(k, pairs);
    } else {
        for (int k = 0; k < listed; ++k) resolve(k, pairs);
    }
    pairs_ = pairs;
    // The triangles' shares, in particle order: the same sums for any thread count.
    for (std::size_t k = 0; pairs > 0 && k < contacts_.size(); ++k) {
        const PointContact& c = contacts_[k];
        if (c.triangle < 0) continue;
        const auto& tri = triangles_[std::size_t(c.triangle)];
        for (int corner = 0; corner < 3; ++corner)
            force[std::size_t(tri[corner])] -= c.weights[corner] * c.force;
    }
}

}  // namespace rend::sim
