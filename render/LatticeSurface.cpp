#include "render/LatticeSurface.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <span>
#include <unordered_map>

#include "render/ColorMap.h"
#include "render/RestTopology.h"

namespace rend::render {

namespace {

constexpr std::uint32_t kUnassigned = std::numeric_limits<std::uint32_t>::max();

// A crossing stays this far from either end of its edge, so no piece thins to a sliver.
constexpr double kCrossingMargin = 0.15;
// Jacobi passes that move the crossings onto the crack's line: one straightens the middle of a
// straight crack in the hexagonal lattice exactly; its ends, extrapolated from their
// neighbours, take a few more to settle.
constexpr int kSmoothingPasses = 4;
// A particle's intact neighbours span its tangent plane when their spread's determinant is at
// least this fraction of a full ring's: two neighbours 60 degrees apart give 0.75, two opposite
// ones (or one) 0.
constexpr double kSpanRatio = 0.05;

void smoothNormals(const std::vector<Eigen::Vector3f>& positions,
                   const std::vector<std::array<std::uint32_t, 3>>& tris,
                   std::vector<Eigen::Vector3f>& normals) {
    normals.assign(positions.size(), Eigen::Vector3f::Zero());
    for (const auto& t : tris) {
        // The unnormalised cross product is twice the area, which gives area weighting.
        const Eigen::Vector3f n =
            (positions[t[1]] - positions[t[0]]).cross(positions[t[2]] - positions[t[0]]);
        for (std::uint32_t v : t) normals[v] += n;
    }
    for (auto& n : normals) {
        const float len = n.norm();
        n = len > 0.0f ? Eigen::Vector3f(n / len) : Eigen::Vector3f::UnitZ();
    }
}

int vertexCount(const sim::FrameView& rest, const std::vector<std::array<int, 3>>& tris) {
    int n = static_cast<int>(rest.particleCount());
    for (const auto& t : tris) n = std::max(n, 1 + std::max({t[0], t[1], t[2]}));
    return n;
}

// Edges used by exactly one triangle, directed as that triangle walks them. With the fans
// split at cracks these are the sheet's outline and both lips of every crack.
std::vector<std::array<std::uint32_t, 2>> boundaryEdges(
    const std::vector<std::array<std::uint32_t, 3>>& tris) {
    struct Directed {
        std::uint64_t key;  // undirected: (min, max)
        std::uint32_t from, to;
    };
    std::vector<Directed> edges;
    edges.reserve(tris.size() * 3);
    for (const auto& t : tris) {
        for (int e = 0; e < 3; ++e) {
            const std::uint32_t a = t[e];
            const std::uint32_t b = t[(e + 1) % 3];
            const auto [lo, hi] = std::minmax(a, b);
            edges.push_back({(std::uint64_t(lo) << 32) | hi, a, b});
        }
    }
    std::sort(edges.begin(), edges.end(),
              [](const Directed& x, const Directed& y) { return x.key < y.key; });
    std::vector<std::array<std::uint32_t, 2>> boundary;
    for (std::size_t i = 0; i < edges.size();) {
        std::size_t j = i + 1;
        while (j < edges.size() && edges[j].key == edges[i].key) ++j;
        if (j - i == 1) boundary.push_back({edges[i].from, edges[i].to});
        i = j;
    }
    return boundary;
}

// Outward wall normals, one per boundary vertex: the sum over its boundary edges of
// (b - a) x n, which points away from the kept triangle on a counter-clockwise edge a -> b.
std::vector<Eigen::Vector3f> wallNormals(const Mesh& sheet,
                                         const std::vector<std::array<std::uint32_t, 2>>& edges) {
    std::vector<Eigen::Vector3f> normals(sheet.positions.size(), Eigen::Vector3f::Zero());
    for (const auto& [a, b] : edges) {
        const Eigen::Vector3f n = sheet.normals[a] + sheet.normals[b];
        const Eigen::Vector3f out = (sheet.positions[b] - sheet.positions[a]).cross(n);
        normals[a] += out;
        normals[b] += out;
    }
    for (auto& n : normals) n.normalize();
    return normals;
}

// Wall vertices get their own copies (with the wall's normal), so the rim is shaded as a wall
// rather than smeared between the two faces; their positions are exact copies of the face
// vertices, so the solid is closed once coincident vertices are welded.
void addWalls(Mesh& mesh, std::uint32_t sheetVertices,
              const std::vector<std::array<std::uint32_t, 2>>& edges,
              const std::vector<Eigen::Vector3f>& normals) {
    std::vector<std::uint32_t> wall(sheetVertices, kUnassigned);  // top copy; bottom is + 1
    auto wallVertex = [&](std::uint32_t v) {
        if (wall[v] != kUnassigned) return wall[v];
        wall[v] = static_cast<std::uint32_t>(mesh.positions.size());
        for (std::uint32_t face : {v, v + sheetVertices}) {
            mesh.positions.push_back(mesh.positions[face]);
            mesh.normals.push_back(normals[v]);
            mesh.colors.push_back(mesh.colors[v]);
            if (!mesh.layers.empty()) mesh.layers.push_back(mesh.layers[v]);
            if (!mesh.theta.empty()) mesh.theta.push_back(mesh.theta[v]);
            if (!mesh.points.empty()) mesh.points.push_back(mesh.points[v]);
        }
        return wall[v];
    };
    for (const auto& [a, b] : edges) {
        const std::uint32_t ta = wallVertex(a);
        const std::uint32_t tb = wallVertex(b);
        mesh.triangles.push_back({ta, ta + 1, tb + 1});
        mesh.triangles.push_back({ta, tb + 1, tb});
    }
}

// The sheet offset by +-thickness/2 along its vertex normals (the bottom copy wound the other
// way so it faces out) and closed by walls along every boundary edge.
void extrude(Mesh& mesh, double thickness) {
    const auto n = static_cast<std::uint32_t>(mesh.positions.size());
    const auto edges = boundaryEdges(mesh.triangles);
    const auto walls = wallNormals(mesh, edges);
    const float half = static_cast<float>(0.5 * thickness);
    mesh.positions.reserve(2 * n + 2 * edges.size());
    for (std::uint32_t v = 0; v < n; ++v) {
        mesh.positions.push_back(mesh.positions[v] - half * mesh.normals[v]);
        mesh.positions[v] += half * mesh.normals[v];
        mesh.normals.push_back(-mesh.normals[v]);
        mesh.colors.push_back(mesh.colors[v]);
        if (!mesh.layers.empty()) mesh.layers.push_back(mesh.layers[v]);
        if (!mesh.theta.empty()) mesh.theta.push_back(mesh.theta[v]);
        if (!mesh.points.empty()) mesh.points.push_back(mesh.points[v]);
    }
    const std::size_t faces = mesh.triangles.size();
    for (std::size_t t = 0; t < faces; ++t) {
        const auto tri = mesh.triangles[t];
        mesh.triangles.push_back({tri[0] + n, tri[2] + n, tri[1] + n});
    }
    addWalls(mesh, n, edges, walls);
}

// Where the crack's line through a and b meets the line of the edge p0 -> p1, as the parameter
// along the edge of the closest point between the two lines (they meet in a flat sheet); NaN
// where they are parallel.
double crossingParameter(const Eigen::Vector3d& p0, const Eigen::Vector3d& p1,
                         const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    const Eigen::Vector3d d1 = p1 - p0, d2 = b - a, r = p0 - a;
    const double aa = d1.dot(d1), ab = d1.dot(d2), bb = d2.dot(d2);
    const double denominator = aa * bb - ab * ab;
    if (!(denominator > 1e-12 * aa * bb)) return std::numeric_limits<double>::quiet_NaN();
    return (ab * d2.dot(r) - bb * d1.dot(r)) / denominator;
}

}  // namespace

/// One frame's broken edges and which triangles take part.
struct LatticeSurface::Cuts {
    std::vector<std::uint8_t> brokenSides;  ///< per triangle: how many of its sides broke
    std::vector<std::uint8_t> present;      ///< per triangle: 0 where it is dropped whole
    std::vector<int> index;                 ///< per edge: its place in `edges`, or -1
    std::vector<int> edges;                 ///< the broken edges of present triangles
    std::vector<double> t;  ///< per broken edge: its crossing, from ends[0] (0) to ends[1] (1)

    bool broken(int e) const { return index[e] >= 0; }
};

/// One frame's positions: the particles', but for the outline's notch particles, which move
/// onto the outline (rest position too) while both their outline bonds hold. Looked up, not
/// copied: the cut reads only a few.
class LatticeSurface::Placed {
public:
    Placed(const LatticeSurface& surface, const sim::FrameView& frame)
        : s_(surface), frame_(frame), holds_(surface.notches_.size(), 0) {
        const auto holds = [&](int b) {
            return b < 0 || frame.bondAlive.empty() || frame.bondAlive[b];
        };
        for (std::size_t k = 0; k < holds_.size(); ++k)
            holds_[k] = holds(s_.notches_[k].bondP) && holds(s_.notches_[k].bondN);
    }

    std::size_t size() const { return frame_.positions.size(); }

    Eigen::Vector3d x(int v) const {
        const Notch* notch = moved(v);
        return notch ? Eigen::Vector3d(0.5 *
                                       (frame_.positions[notch->p] + frame_.positions[notch->n]))
                     : frame_.positions[v];
    }

    Eigen::Vector3d rest(int v) const {
        const Notch* notch = moved(v);
        return notch ? Eigen::Vector3d(0.5 * (s_.rest_[notch->p] + s_.rest_[notch->n]))
                     : s_.rest_[v];
    }

private:
    const Notch* moved(int v) const {
        const int k = v < static_cast<int>(s_.notchOf_.size()) ? s_.notchOf_[v] : -1;
        return k >= 0 && holds_[k] ? &s_.notches_[k] : nullptr;
    }

    const LatticeSurface& s_;
    const sim::FrameView& frame_;
    std::vector<std::uint8_t> holds_;  ///< per notch
};

LatticeSurface::LatticeSurface(const sim::FrameView& rest, Outline outline)
    : outline_(outline),
      triangles_(rest.restTriangles.begin(), rest.restTriangles.end()),
      edges_(restEdges(triangles_)),
      rest_(rest.restPositions.begin(), rest.restPositions.end()) {
    const std::size_t vertices = vertexCount(rest, triangles_);
    // Ascending triangle order fixes which fan keeps the particle's own vertex.
    incidentTriangles(triangles_, vertices, incidentOffsets_, incident_);
    const bool hasBonds = rest.bondOffsets.size() == rest.particleCount() + 1;
    const auto bond = [&](int i, int j) { return hasBonds ? rest.findBond(i, j) : -1; };
    edgeBond_.reserve(edges_.ends.size());
    for (const auto& [i, j] : edges_.ends) edgeBond_.push_back(bond(i, j));
    if (rest_.size() < vertices) rest_.resize(vertices, Eigen::Vector3d::Zero());
    restNormal_.assign(vertices, Eigen::Vector3d::Zero());
    for (const auto& c : triangles_) {
        const Eigen::Vector3d n = (rest_[c[1]] - rest_[c[0]]).cross(rest_[c[2]] - rest_[c[0]]);
        for (int v : c) restNormal_[v] += n;
    }
    for (auto& n : restNormal_)
        n = n.norm() > 0.0 ? Eigen::Vector3d(n.normalized()) : Eigen::Vector3d::UnitZ();
    if (outline_ == Outline::LevelSet) return;  // the level set's band draws the outline
    const auto notches = outlineNotches(triangles_, edges_, rest_);
    notchOf_.assign(notches.size(), -1);
    for (int v = 0; v < int(notches.size()); ++v) {
        const auto [p, n] = notches[v];
        if (p < 0) continue;
        notchOf_[v] = static_cast<int>(notches_.size());
        notches_.push_back({v, p, n, bond(v, p), bond(v, n)});
    }
}

std::vector<int> LatticeSurface::keptTriangles(const sim::FrameView& frame) const {
    std::vector<int> kept;
    kept.reserve(triangles_.size());
    for (std::size_t t = 0; t < triangles_.size(); ++t)
        if (frame.triangleKept(t)) kept.push_back(static_cast<int>(t));
    return kept;
}

LatticeSurface::Cuts LatticeSurface::findCuts(const sim::FrameView& frame) const {
    const std::size_t edgeCount = edges_.ends.size();
    std::vector<std::uint8_t> broken(edgeCount, 0);
    if (!frame.bondAlive.empty())
        for (std::size_t e = 0; e < edgeCount; ++e)
            broken[e] = edgeBond_[e] >= 0 && !frame.bondAlive[edgeBond_[e]];
    Cuts cuts;
    cuts.brokenSides.assign(triangles_.size(), 0);
    cuts.present.assign(triangles_.size(), 0);
    cuts.index.assign(edgeCount, -1);
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        for (int e : edges_.ofTriangle[t]) cuts.brokenSides[t] += broken[e];
        // Not kept with every side intact: removed (element erosion), so dropped whole.
        const bool alive = frame.triangleAlive.empty() || frame.triangleAlive[t];
        cuts.present[t] = alive && (frame.triangleKept(t) || cuts.brokenSides[t] > 0);
        if (!cuts.present[t]) continue;
        for (int e : edges_.ofTriangle[t]) {
            if (!broken[e] || cuts.index[e] >= 0) continue;
            cuts.index[e] = static_cast<int>(cuts.edges.size());
            cuts.edges.push_back(e);
        }
    }
    cuts.t.assign(cuts.edges.size(), 0.5);
    return cuts;
}

// Smooths the crack: each crossing moves along its edge onto the line through its neighbours
// along the crack (see the class comment). The neighbours of a crossing are, per triangle of
// its edge, the other crossing of a triangle with two broken sides, or the centroid of one
// with one or three (the tip's slit and the junction meet there).
void LatticeSurface::placeCrossings(const Placed& placed, Cuts& cuts) const {
    const auto rest = [&](int v) { return placed.rest(v); };
    struct Link {
        int crossing = -1;  ///< index into cuts.edges, or -1 for `point`
        Eigen::Vector3d point = Eigen::Vector3d::Zero();
        bool set = false;
    };
    std::vector<std::array<Link, 2>> links(cuts.edges.size());
    const auto add = [&](int e, const Link& link) {
        auto& slots = links[cuts.index[e]];
        (slots[0].set ? slots[1] : slots[0]) = link;
    };
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        if (!cuts.present[t] || cuts.brokenSides[t] == 0) continue;
        const auto& side = edges_.ofTriangle[t];
        if (cuts.brokenSides[t] == 2) {
            std::array<int, 2> pair{};
            int found = 0;
            for (int e : side)
                if (cuts.broken(e)) pair[found++] = e;
            add(pair[0], {cuts.index[pair[1]], {}, true});
            add(pair[1], {cuts.index[pair[0]], {}, true});
            continue;
        }
        const auto& c = triangles_[t];
        const Eigen::Vector3d centroid = (rest(c[0]) + rest(c[1]) + rest(c[2])) / 3.0;
        for (int e : side)
            if (cuts.broken(e)) add(e, {-1, centroid, true});
    }
    const auto at = [&](const std::vector<double>& t, const Link& link) -> Eigen::Vector3d {
        if (link.crossing < 0) return link.point;
        const auto& [i, j] = edges_.ends[cuts.edges[link.crossing]];
        return (1.0 - t[link.crossing]) * rest(i) + t[link.crossing] * rest(j);
    };
    std::vector<double> next(cuts.t.size());
    for (int pass = 0; pass < kSmoothingPasses; ++pass) {
        for (std::size_t k = 0; k < cuts.edges.size(); ++k) {
            next[k] = cuts.t[k];
            const auto& [l0, l1] = links[k];
            Eigen::Vector3d a, b;
            if (l0.set && l1.set) {
                a = at(cuts.t, l0);
                b = at(cuts.t, l1);
            } else if (l0.set && l0.crossing >= 0) {  // the crack's end: extend its last step
                const auto& beyond = links[l0.crossing];
                const Link& far = beyond[0].crossing == int(k) ? beyond[1] : beyond[0];
                if (!far.set) continue;
                a = at(cuts.t, l0);
                b = at(cuts.t, far);
            } else {
                continue;
            }
            const auto& [i, j] = edges_.ends[cuts.edges[k]];
            const double s = crossingParameter(rest(i), rest(j), a, b);
            if (std::isfinite(s)) next[k] = std::clamp(s, kCrossingMargin, 1.0 - kCrossingMargin);
        }
        cuts.t.swap(next);
    }
}

int LatticeSurface::cornerOf(int triangle, int particle) const {
    const auto& t = triangles_[triangle];
    return t[0] == particle ? 0 : (t[1] == particle ? 1 : 2);
}

// Gives `vertex` to particle's corner in every present triangle reachable from `start` across
// sides through the particle (two triangles both holding the particle and sharing a side share
// one through it, so only the two sides at its corner need following). A broken side joins
// them too: both keep the half of it on the particle's side.
void LatticeSurface::walkFan(int start, int particle, std::uint32_t vertex,
                             const std::vector<std::uint8_t>& present, Corners& corners,
                             std::vector<int>& stack) const {
    stack.assign(1, start);
    corners.vertex[start][cornerOf(start, particle)] = vertex;
    while (!stack.empty()) {
        const int t = stack.back();
        stack.pop_back();
        const int c = cornerOf(t, particle);
        for (int e : {c, (c + 2) % 3}) {
            const int n = edges_.neighbours[t][e];
            if (n < 0 || !present[n]) continue;
            std::uint32_t& slot = corners.vertex[n][cornerOf(n, particle)];
            if (slot != kUnassigned) continue;
            slot = vertex;
            stack.push_back(n);
        }
    }
}

// Only particles at a triangle dropped whole can have more than one fan: around any other, the
// present triangles run unbroken around it, so its corners simply keep its own vertex.
LatticeSurface::Corners LatticeSurface::splitFans(const std::vector<std::uint8_t>& present,
                                                  std::size_t particleCount) const {
    Corners corners;
    corners.vertex.resize(triangles_.size());
    std::vector<int> atDropped;
    for (std::size_t t = 0; t < triangles_.size(); ++t) {
        for (int k = 0; k < 3; ++k) {
            corners.vertex[t][k] = static_cast<std::uint32_t>(triangles_[t][k]);
            if (!present[t]) atDropped.push_back(triangles_[t][k]);
        }
    }
    std::sort(atDropped.begin(), atDropped.end());
    atDropped.erase(std::unique(atDropped.begin(), atDropped.end()), atDropped.end());
    std::vector<int> stack;
    for (int p : atDropped) {
        const int first = incidentOffsets_[p], last = incidentOffsets_[p + 1];
        for (int k = first; k < last; ++k)
            corners.vertex[incident_[k]][cornerOf(incident_[k], p)] = kUnassigned;
        bool own = true;
        for (int k = first; k < last; ++k) {
            const int t = incident_[k];
            if (!present[t] || corners.vertex[t][cornerOf(t, p)] != kUnassigned) continue;
            std::uint32_t vertex = static_cast<std::uint32_t>(p);
            if (!own) {
                vertex = static_cast<std::uint32_t>(particleCount + corners.copyOf.size());
                corners.copyOf.push_back(p);
            }
            own = false;
            walkFan(t, p, vertex, present, corners, stack);
        }
    }
    return corners;
}

/// Writes one frame's mesh: the particles' vertices and their fan copies, two lip vertices per
/// crossing, then each present triangle's pieces (with their centroid vertices).
class LatticeSurface::Builder {
public:
    Builder(const LatticeSurface& surface, const sim::FrameView& frame, const Placed& placed,
            const Cuts& cuts, const Corners& corners, const RenderSettings& settings, Mesh& mesh)
        : s_(surface), cuts_(cuts), corners_(corners), placed_(placed), mesh_(mesh) {
        colours_ = particleColors(frame, settings);
        layers_ = particleLayers(frame, settings);
        theta_ = frame.theta;
        velocities_ = frame.velocities;
        damage_ = frame.damage;
        const std::size_t vertices = placed.size() + corners.copyOf.size() + 2 * cuts.edges.size();
        mesh.positions.reserve(vertices);
        mesh.colors.reserve(vertices);
        mesh.layers.reserve(layers_.empty() ? 0 : vertices);
        mesh.theta.reserve(theta_.empty() ? 0 : vertices);
        mesh.points.reserve(vertices);
        for (int i = 0; i < static_cast<int>(placed.size()); ++i) add(x(i), attributes(i));
        for (int p : corners.copyOf) add(x(p), attributes(p));
        lipBase_ = static_cast<std::uint32_t>(mesh.positions.size());
        for (std::size_t k = 0; k < cuts.edges.size(); ++k) {
            const auto [i, j] = s_.edges_.ends[cuts.edges[k]];
            const double t = cuts.t[k];
            const Attributes crossing = attributes(i, j, float(t));
            add(lipPosition(i, j, t), withPoint(crossing, i, crossing.point.rest));
            add(lipPosition(j, i, 1.0 - t), withPoint(crossing, j, crossing.point.rest));
        }
        mesh.triangles.reserve(s_.triangles_.size() + 3 * cuts.edges.size());
    }

    void addPieces(int t) {
        const auto& c = s_.triangles_[t];
        const auto& side = s_.edges_.ofTriangle[t];
        const auto& v = corners_.vertex[t];
        switch (cuts_.brokenSides[t]) {
            case 0:
                mesh_.triangles.push_back(v);
                return;
            case 1: {  // the slit from the crossing to the centroid
                const int k = cuts_.broken(side[0]) ? 0 : (cuts_.broken(side[1]) ? 1 : 2);
                const int a = k, b = (k + 1) % 3, o = (k + 2) % 3;
                const std::uint32_t g = add(meanX(c), meanAttributes(c));
                mesh_.triangles.push_back({v[a], lip(side[k], c[a]), g});
                mesh_.triangles.push_back({lip(side[k], c[b]), v[b], g});
                mesh_.triangles.push_back({v[b], v[o], g});
                mesh_.triangles.push_back({v[o], v[a], g});
                return;
            }
            case 2: {  // the corner between the broken sides, and the quad opposite
                const int k = !cuts_.broken(side[0]) ? 0 : (!cuts_.broken(side[1]) ? 1 : 2);
                const int p = k, q = (k + 1) % 3, lone = (k + 2) % 3;
                const int toQ = side[q], toP = side[lone];  // sides q -> lone and lone -> p
                mesh_.triangles.push_back({v[lone], lip(toP, c[lone]), lip(toQ, c[lone])});
                const std::uint32_t mp = lip(toP, c[p]), mq = lip(toQ, c[q]);
                mesh_.triangles.push_back({mp, v[p], v[q]});
                mesh_.triangles.push_back({mp, v[q], mq});
                return;
            }
            default: {  // a junction: one quad per corner, meeting at the centroid
                const Eigen::Vector3d restCentroid = (rest(c[0]) + rest(c[1]) + rest(c[2])) / 3.0;
                const Eigen::Vector3d centroid = meanX(c);
                const Attributes centre = meanAttributes(c);
                for (int k = 0; k < 3; ++k) {
                    const std::uint32_t g = add(ownSide(c[k], restCentroid, centroid), centre);
                    mesh_.triangles.push_back({v[k], lip(side[k], c[k]), g});
                    mesh_.triangles.push_back({v[k], g, lip(side[(k + 2) % 3], c[k])});
                }
            }
        }
    }

    /// The particle level set's outline: each kept band triangle's inside part (Phi <= 0), cut
    /// at Phi = 0 along its particle-ghost edges, in the triangle's own (counter-clockwise)
    /// order. A particle on the outline (Phi = 0) is its own crossing, and the slivers that
    /// leaves are left out.
    void addBand(const sim::FrameView& frame) {
        const int n = static_cast<int>(frame.particleCount());
        std::unordered_map<std::uint64_t, std::uint32_t> crossings;
        const auto crossing = [&](int i, int g) {
            const std::uint64_t key = (std::uint64_t(i) << 32) | std::uint32_t(g);
            if (const auto found = crossings.find(key); found != crossings.end())
                return found->second;
            const double phi = frame.levelSet[i];
            if (!(phi < 0.0)) return static_cast<std::uint32_t>(i);  // the particle is on it
            const double t = phi / (phi - frame.ghostLevelSet[g]);
            const Eigen::Vector3d restPoint = rest(i) + t * (frame.ghostRestPositions[g] - rest(i));
            const std::uint32_t v = add(x(i) + t * (frame.ghostPositions[g] - x(i)),
                                        withPoint(attributes(i), i, restPoint.cast<float>()));
            crossings.emplace(key, v);
            return v;
        };
        const double sliver = 1e-6 * areaScale(frame);
        for (std::size_t t = 0; t < frame.bandTriangles.size(); ++t) {
            if (!frame.bandKept[t]) continue;
            const auto& c = frame.bandTriangles[t];
            std::array<std::uint32_t, 4> polygon;
            int count = 0;
            bool usable = true;
            for (int k = 0; k < 3; ++k) {
                const int a = c[k], b = c[(k + 1) % 3];
                if (a >= n && !(frame.ghostLevelSet[a - n] > 0.0)) usable = false;
                if (a < n) polygon[count++] = static_cast<std::uint32_t>(a);
                if ((a < n) != (b < n) && count < 4)
                    polygon[count++] = a < n ? crossing(a, b - n) : crossing(b, a - n);
            }
            if (!usable) continue;
            for (int k = 1; k + 1 < count; ++k) {
                const std::array<std::uint32_t, 3> tri = {polygon[0], polygon[k], polygon[k + 1]};
                if (restArea(tri) > sliver) mesh_.triangles.push_back(tri);
            }
        }
    }

private:
    /// The band's slivers are measured against the square of a particle's spacing.
    static double areaScale(const sim::FrameView& frame) {
        const double spacing = frame.bondRestLength.empty() ? 1.0 : frame.bondRestLength[0];
        return spacing * spacing;
    }

    double restArea(const std::array<std::uint32_t, 3>& t) const {
        const Eigen::Vector3f& a = mesh_.points[t[0]].rest;
        return 0.5 *
               double((mesh_.points[t[1]].rest - a).cross(mesh_.points[t[2]].rest - a).norm());
    }

    /// What a vertex carries besides its position: the colour and, with a look, its layer.
    struct Attributes {
        Eigen::Vector3f colour;
        Eigen::Vector2f layer = Eigen::Vector2f::Zero();
        float theta = 0.0f;
        Mesh::Point point;
    };

    Mesh::Point point(int i) const {
        Mesh::Point p;
        p.id = i;
        if (!velocities_.empty()) p.velocity = velocities_[i].cast<float>();
        p.damage = damage_.empty() ? 0.0f : float(damage_[i]);
        p.rest = rest(i).cast<float>();
        return p;
    }

    Attributes attributes(int i) const {
        return {colours_[i], layers_.empty() ? Eigen::Vector2f::Zero() : layers_[i],
                theta_.empty() ? 0.0f : float(theta_[i]), point(i)};
    }

    /// Interpolated at fraction t of the way from particle i to j (the point data as i's but
    /// for the rest position).
    Attributes attributes(int i, int j, float t) const {
        const Attributes a = attributes(i), b = attributes(j);
        return {(1.0f - t) * a.colour + t * b.colour, (1.0f - t) * a.layer + t * b.layer,
                (1.0f - t) * a.theta + t * b.theta,
                withRest(a.point, (1.0f - t) * a.point.rest + t * b.point.rest)};
    }

    Attributes meanAttributes(const std::array<int, 3>& c) const {
        const Attributes a = attributes(c[0]), b = attributes(c[1]), d = attributes(c[2]);
        Mesh::Point mean = a.point;  // its first corner's id
        mean.velocity = (a.point.velocity + b.point.velocity + d.point.velocity) / 3.0f;
        mean.damage = (a.point.damage + b.point.damage + d.point.damage) / 3.0f;
        mean.rest = (a.point.rest + b.point.rest + d.point.rest) / 3.0f;
        return {(a.colour + b.colour + d.colour) / 3.0f, (a.layer + b.layer + d.layer) / 3.0f,
                (a.theta + b.theta + d.theta) / 3.0f, mean};
    }

    static Mesh::Point withRest(Mesh::Point p, const Eigen::Vector3f& rest) {
        p.rest = rest;
        return p;
    }

    /// A crack lip on particle i's side: i's point data, at the crossing's rest position.
    Attributes withPoint(Attributes a, int i, const Eigen::Vector3f& rest) const {
        a.point = withRest(point(i), rest);
        return a;
    }

    Eigen::Vector3d x(int v) const { return placed_.x(v); }
    Eigen::Vector3d rest(int v) const { return placed_.rest(v); }
    Eigen::Vector3d meanX(const std::array<int, 3>& c) const {
        return (x(c[0]) + x(c[1]) + x(c[2])) / 3.0;
    }

    std::uint32_t add(const Eigen::Vector3d& position, const Attributes& attributes) {
        mesh_.positions.push_back(position.cast<float>());
        mesh_.colors.push_back(attributes.colour);
        if (!layers_.empty()) mesh_.layers.push_back(attributes.layer);
        if (!theta_.empty()) mesh_.theta.push_back(attributes.theta);
        mesh_.points.push_back(attributes.point);
        return static_cast<std::uint32_t>(mesh_.positions.size() - 1);
    }

    /// The vertex of edge e's crossing on particle's side.
    std::uint32_t lip(int e, int particle) const {
        const int k = cuts_.index[e];
        return lipBase_ + 2 * static_cast<std::uint32_t>(k) + (particle == s_.edges_.ends[e][1]);
    }

    /// The crossing at fraction t of the way from particle a to b, on a's side.
    Eigen::Vector3d lipPosition(int a, int b, double t) {
        return ownSide(a, (1.0 - t) * rest(a) + t * rest(b), (1.0 - t) * x(a) + t * x(b));
    }

    /// A point of particle a's side, `restTarget` at rest: mapped by the deformation of a's
    /// intact neighbourhood (below) where it has one, so each lip follows its own side and a
    /// crack opens by how far the sides moved apart; else `target` (interpolated across the
    /// crack) where it is no farther from a than at rest, else that rest distance from a
    /// towards it, in a's tangent plane.
    Eigen::Vector3d ownSide(int a, const Eigen::Vector3d& restTarget,
                            const Eigen::Vector3d& target) {
        const Eigen::Vector3d offset = restTarget - rest(a);
        Eigen::Matrix3d F;
        if (deformation(a, F) || neighbourDeformation(a, F)) return x(a) + F * offset;
        Eigen::Vector3d d = target - x(a);
        const double reach = offset.norm();
        const double length = d.norm();
        if (length <= reach) return target;
        const Eigen::Vector3d n = wholeNormal(a);
        const Eigen::Vector3d inPlane = d - d.dot(n) * n;
        if (inPlane.norm() > 1e-3 * length) d = inPlane;
        return x(a) + reach * d.normalized();
    }

    /// The deformation of the first intact neighbour that has one: a particle at a corner of
    /// its piece may have a single intact side.
    bool neighbourDeformation(int a, Eigen::Matrix3d& F) {
        return anyIntactNeighbour(a, [&](int j) { return deformation(j, F); });
    }

    /// Calls visit(j) for each lattice neighbour j of particle a through an intact side of a
    /// present triangle (twice where two triangles share the side) until visit returns true;
    /// returns whether one did.
    template <class Visit>
    bool anyIntactNeighbour(int a, Visit&& visit) const {
        for (int k = s_.incidentOffsets_[a]; k < s_.incidentOffsets_[a + 1]; ++k) {
            const int t = s_.incident_[k];
            if (!cuts_.present[t]) continue;
            const int c = s_.cornerOf(t, a);
            for (int side : {c, (c + 2) % 3}) {
                const int e = s_.edges_.ofTriangle[t][side];
                if (cuts_.broken(e)) continue;
                const auto& ends = s_.edges_.ends[e];
                if (visit(ends[0] == a ? ends[1] : ends[0])) return true;
            }
        }
        return false;
    }

    /// The least-squares deformation gradient F (x_j - x_a ~ F (X_j - X_a)) over particle a's
    /// lattice neighbours through intact sides, on a's rest tangent plane; false where those
    /// neighbours do not span the plane (fewer than two directions).
    bool deformation(int a, Eigen::Matrix3d& F) {
        // Each particle's is fitted once per frame: a particle owns several lip vertices.
        if (fitted_.empty()) fitted_.assign(placed_.size(), kNotFitted);
        int& slot = fitted_[a];
        if (slot == kNotFitted) {
            slot = kNoFit;
            if (fitDeformation(a, F)) {
                slot = static_cast<int>(fits_.size());
                fits_.push_back(F);
            }
        }
        if (slot == kNoFit) return false;
        F = fits_[slot];
        return true;
    }

    bool fitDeformation(int a, Eigen::Matrix3d& F) const {
        Eigen::Matrix3d moved = Eigen::Matrix3d::Zero(), spread = Eigen::Matrix3d::Zero();
        anyIntactNeighbour(a, [&](int j) {
            const Eigen::Vector3d restOffset = rest(j) - rest(a);
            moved += (x(j) - x(a)) * restOffset.transpose();
            spread += restOffset * restOffset.transpose();
            return false;
        });
        // The rest normal, scaled like the in-plane spread, makes the spread invertible; it
        // maps nothing, since the offsets F is applied to lie in the plane.
        const double scale = 0.5 * spread.trace();
        if (!(scale > 0.0)) return false;
        const Eigen::Vector3d& n = s_.restNormal_[a];
        spread += scale * n * n.transpose();
        if (!(spread.determinant() > kSpanRatio * scale * scale * scale)) return false;
        F = moved * spread.inverse();
        return true;
    }

    /// Unit normal of particle a's uncut triangles, or zero where it has none.
    Eigen::Vector3d wholeNormal(int a) const {
        Eigen::Vector3d sum = Eigen::Vector3d::Zero();
        for (int k = s_.incidentOffsets_[a]; k < s_.incidentOffsets_[a + 1]; ++k) {
            const int t = s_.incident_[k];
            if (!cuts_.present[t] || cuts_.brokenSides[t] > 0) continue;
            const auto& c = s_.triangles_[t];
            sum += (x(c[1]) - x(c[0])).cross(x(c[2]) - x(c[0]));
        }
        const double length = sum.norm();
        return length > 0.0 ? Eigen::Vector3d(sum / length) : Eigen::Vector3d::Zero();
    }

    const LatticeSurface& s_;
    const Cuts& cuts_;
    const Corners& corners_;
    const Placed& placed_;
    std::vector<Eigen::Vector3f> colours_;
    std::vector<Eigen::Vector2f> layers_;  ///< empty where a colour map replaces the look
    std::span<const double> theta_;        ///< the frame's; empty without diffusion (EXR layer)
    std::span<const Eigen::Vector3d> velocities_;  ///< the frame's; empty in some tests
    std::span<const double> damage_;               ///< the frame's; empty if nothing breaks
    Mesh& mesh_;
    std::uint32_t lipBase_ = 0;
    static constexpr int kNotFitted = -1, kNoFit = -2;
    std::vector<int> fitted_;  ///< per particle: index into fits_, or kNotFitted / kNoFit
    std::vector<Eigen::Matrix3d> fits_;
};

Mesh LatticeSurface::build(const sim::FrameView& frame, const RenderSettings& settings) const {
    Mesh mesh;
    build(frame, settings, mesh);
    return mesh;
}

void LatticeSurface::build(const sim::FrameView& frame, const RenderSettings& settings,
                           Mesh& mesh) const {
    const Placed placed(*this, frame);
    Cuts cuts = findCuts(frame);
    placeCrossings(placed, cuts);
    const Corners corners = splitFans(cuts.present, frame.particleCount());
    mesh.clear();
    Builder builder(*this, frame, placed, cuts, corners, settings, mesh);
    for (int t = 0; t < static_cast<int>(triangles_.size()); ++t)
        if (cuts.present[t]) builder.addPieces(t);
    if (outline_ == Outline::LevelSet && !frame.bandTriangles.empty()) builder.addBand(frame);
    smoothNormals(mesh.positions, mesh.triangles, mesh.normals);
    if (settings.thickness > 0.0) extrude(mesh, settings.thickness);
}

}  // namespace rend::render
