// Movers: a few particles outrun the skin (the tip of a torn flap, a speck) while the rest of
// the sheet keeps within it. A full list build would search every particle the culling cannot
// vouch for; instead the list is kept and only what involves the movers is found afresh, at
// each evaluation, through hashes of every particle and kept triangle at the build's positions.
//
// The guarantee, with c the common displacement the staleness check measures against and D < s/2
// (s the skin) the most a non-mover drifted from it: two non-movers, or a non-mover and a
// triangle of non-movers, left out of the list were at least d + s apart at the build and are
// still more than d + s - 2D > d apart. A mover f and a non-mover j with |x_f - x_j| < d have
// |(x_f - c) - X_j| < d + D, X the build positions; a mover's triangle T and a non-mover j within
// d of it: j lies within d + D + rho of (p - c) for one of T's sample points p, every point of T
// within rho of one (T's corners and its edges' k-th points, rho = longest edge / k).

#include <algorithm>
#include <cmath>

#include "sim/Contact.h"

namespace rend::sim {

bool Contact::findMovers(std::span<const Eigen::Vector3d> x, const Eigen::Vector3d& centre) {
    const int n = int(x.size());
    // Beyond this many, a fresh search per mover costs about what a build would.
    const std::size_t most = std::max<std::size_t>(16, std::size_t(n) / 64);
    const double limit2 = 0.25 * skin_ * skin_;
    double others = 0.0;  // squared
    for (int i = 0; i < n; ++i) {
        const double u2 = (x[i] - builtAt_[std::size_t(i)] - centre).squaredNorm();
        if (u2 <= limit2) {
            others = std::max(others, u2);
        } else if (movers_.size() == most) {
            movers_.clear();
            return false;
        } else {
            movers_.push_back(i);
        }
    }
    moverCentre_ = centre;
    drift_ = std::sqrt(others);
    for (const int f : movers_) {
        isMover_[std::size_t(f)] = 1;
        for (int k = vertexTriangleStart_[std::size_t(f)];
             k < vertexTriangleStart_[std::size_t(f) + 1]; ++k)
            moverTriangles_.push_back(vertexTriangles_[std::size_t(k)]);
    }
    std::sort(moverTriangles_.begin(), moverTriangles_.end());
    moverTriangles_.erase(std::unique(moverTriangles_.begin(), moverTriangles_.end()),
                          moverTriangles_.end());
    for (const int t : moverTriangles_) touchesMover_[std::size_t(t)] = 1;
    return true;
}

void Contact::clearMovers() {
    for (const int f : movers_) isMover_[std::size_t(f)] = 0;
    for (const int t : moverTriangles_) touchesMover_[std::size_t(t)] = 0;
    movers_.clear();
    moverTriangles_.clear();
}

void Contact::buildMoverHashes(const SheetState& s) {
    std::vector<int> kept;
    std::vector<Eigen::Vector3d> centres;
    std::vector<double> radii;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        if (!s.kept.empty() && !s.kept[t]) continue;
        const auto& tri = triangles_[t];
        const Eigen::Vector3d centre =
            (builtAt_[std::size_t(tri[0])] + builtAt_[std::size_t(tri[1])] +
             builtAt_[std::size_t(tri[2])]) /
            3.0;
        double r2 = 0.0;
        for (const int c : tri)
            r2 = std::max(r2, (builtAt_[std::size_t(c)] - centre).squaredNorm());
        kept.push_back(int(t));
        centres.push_back(centre);
        radii.push_back(std::sqrt(r2));
    }
    const double reach = thickness_ + skin_;
    const auto [usual, stretched] = splitStretched(radii);
    allUsual_ = std::make_unique<TriangleHash>(*this, usual, centres, radii, kept, reach);
    allStretched_ = std::make_unique<TriangleHash>(*this, stretched, centres, radii, kept, reach);
    allPointsReach_ = reach + restWidest_;
    allPoints_ = std::make_unique<PointHash>(builtAt_, allPointsReach_);
}

// Mover f's triangles clear of movers, and the non-movers within d of it (both ends).
void Contact::findMoverCandidates(const SheetState& s) {
    if (!allPoints_) buildMoverHashes(s);
    const double d2 = thickness_ * thickness_;
    std::vector<std::array<int, 2>> pairs;  // (particle, target as in list_)
    for (const int f : movers_) {
        const Eigen::Vector3d q = s.x[f] - moverCentre_;
        for (const TriangleHash* h : {allUsual_.get(), allStretched_.get()})
            h->hash.nearSlots(q, [&](int slot) {
                const TriangleHash::Item& item = h->items[std::size_t(slot)];
                const int t = item.triangle;
                if (touchesMover_[std::size_t(t)]) return;  // addMoverTriangleCandidates
                const double fromRest = (s.rest[f] - item.restCentre).squaredNorm();
                if (fromRest <= allBonded2_) return;
                const double near = thickness_ + drift_ + item.radius;
                if ((q - item.centre).squaredNorm() >= near * near) return;
                const auto& tri = triangles_[std::size_t(t)];
                if (fromRest <= noneBonded2_ && bondedAtRest(f, tri, s.rest)) return;
                pairs.push_back({f, t});  // nearestContact measures it
            });
        allPoints_->near(q, [&](int j) {
            if (isMover_[std::size_t(j)] ||
                (s.rest[f] - s.rest[j]).squaredNorm() <= restExclusion2_)
                return;
            if ((s.x[f] - s.x[j]).squaredNorm() >= d2) return;
            pairs.push_back({f, -(j + 1)});
            pairs.push_back({j, -(f + 1)});
        });
        for (const int g : movers_)
            if (g != f && (s.rest[f] - s.rest[g]).squaredNorm() > restExclusion2_ &&
                (s.x[f] - s.x[g]).squaredNorm() < d2)
                pairs.push_back({f, -(g + 1)});
    }
    addMoverTriangleCandidates(s, pairs);
    std::sort(pairs.begin(), pairs.end());
    pairs.erase(std::unique(pairs.begin(), pairs.end()), pairs.end());
    // The evaluation's particles: the listed and those with fresh candidates, ascending.
    order_.clear();
    orderExtra_.assign(1, 0);
    extra_.clear();
    std::size_t p = 0, l = 0;
    while (l < listed_.size() || p < pairs.size()) {
        const int next = p == pairs.size()     ? listed_[l]
                         : l == listed_.size() ? pairs[p][0]
                                               : std::min(listed_[l], pairs[p][0]);
        order_.push_back(next);
        if (l < listed_.size() && listed_[l] == next) ++l;
        for (; p < pairs.size() && pairs[p][0] == next; ++p) extra_.push_back(pairs[p][1]);
        orderExtra_.push_back(int(extra_.size()));
    }
}

// The particles within d of a mover's triangle: non-movers through the build-position hash,
// queried at the centroid when every point of the triangle is within `margin` of it, else at
// sample points (corners and the edges' k-th points, every point within longest / k of one);
// movers directly (they are few).
void Contact::addMoverTriangleCandidates(const SheetState& s,
                                         std::vector<std::array<int, 2>>& pairs) {
    const double d2 = thickness_ * thickness_;
    const double margin = allPointsReach_ - thickness_ - drift_;  // >= restWidest_ + skin / 2
    for (const int t : moverTriangles_) {
        if (!s.kept.empty() && !s.kept[std::size_t(t)]) continue;
        const auto& tri = triangles_[std::size_t(t)];
        const Eigen::Vector3d a = s.x[tri[0]], b = s.x[tri[1]], c = s.x[tri[2]];
        const Eigen::Vector3d centroid = (a + b + c) / 3.0;
        const double radius =
            std::sqrt(std::max({(a - centroid).squaredNorm(), (b - centroid).squaredNorm(),
                                (c - centroid).squaredNorm()}));
        const auto near = [&](int j) {
            if (j == tri[0] || j == tri[1] || j == tri[2]) return false;
            const double fromRest = (s.rest[j] - restCentres_[std::size_t(t)]).squaredNorm();
            if (fromRest <= allBonded2_) return false;
            if (fromRest <= noneBonded2_ && bondedAtRest(j, tri, s.rest)) return false;
            const TrianglePoint cp = closestOnTriangle(s.x[j], a, b, c);
            return (s.x[j] - cp.at(a, b, c)).squaredNorm() < d2;
        };
        const auto query = [&](const Eigen::Vector3d& at) {
            allPoints_->near(at - moverCentre_, [&](int j) {
                if (!isMover_[std::size_t(j)] && near(j)) pairs.push_back({j, t});
            });
        };
        if (radius <= margin) {
            query(centroid);  // every point of T is within `radius` of it
        } else {
            const double longest = std::sqrt(
                std::max({(b - a).squaredNorm(), (c - b).squaredNorm(), (a - c).squaredNorm()}));
            const int k = int(std::ceil(longest / margin));
            for (int u = 0; u <= k; ++u)
                for (int v = 0; u + v <= k; ++v)
                    query(a + (double(u) / k) * (b - a) + (double(v) / k) * (c - a));
        }
        const double reach = thickness_ + radius;
        for (const int f : movers_)
            if ((s.x[f] - centroid).squaredNorm() < reach * reach && near(f))
                pairs.push_back({f, t});
    }
}

}  // namespace rend::sim
