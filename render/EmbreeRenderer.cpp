#include "render/EmbreeRenderer.h"

#include <embree3/rtcore.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <numbers>
#include <span>
#include <stdexcept>
#include <vector>

#include "render/Denoise.h"
#include "render/GlMath.h"
#include "render/Look.h"
#include "render/ToneMap.h"

namespace rend::render {

namespace {

using Vec3 = Eigen::Vector3f;
static_assert(sizeof(Vec3) == 3 * sizeof(float), "Vector3f arrays are copied as packed floats");

constexpr float kPi = std::numbers::pi_v<float>;
constexpr int kTileSize = 16;
// Fresnel reflectance at normal incidence of a dielectric with IOR 1.5: ((n - 1) / (n + 1))^2.
constexpr float kFilmF0 = 0.04f;
// Russian roulette only after a few bounces: the early ones carry most of the image.
constexpr int kRouletteDepth = 3;
// Firefly clamp: a contribution after the first bounce is scaled down to at most this linear
// value per channel. Display white is 1.0, so ordinary sky and sun light is untouched; only
// rare diffuse -> glossy -> sun paths (caustics the sampler finds once in thousands) are cut.
constexpr float kIndirectClamp = 4.0f;
// A film shadow ray passes through at most this many sheet layers before it counts as blocked.
constexpr int kMaxShadowLayers = 8;
// Slightly below GGX's singular alpha = 0 (a perfect mirror), which NEE cannot evaluate.
constexpr float kMinAlpha = 1e-3f;

// ---- Counter-based random numbers ------------------------------------------------------------

// SplitMix64's finaliser (Steele, Lea & Flood 2014): a bijective 64-bit avalanche mix.
std::uint64_t mix64(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
    return z ^ (z >> 31);
}

std::uint32_t reverseBits(std::uint32_t x) {
    x = __builtin_bswap32(x);
    x = ((x & 0x0F0F0F0Fu) << 4) | ((x & 0xF0F0F0F0u) >> 4);
    x = ((x & 0x33333333u) << 2) | ((x & 0xCCCCCCCCu) >> 2);
    return ((x & 0x55555555u) << 1) | ((x & 0xAAAAAAAAu) >> 1);
}

/// Second dimension of the Sobol sequence at the sample index whose bits reversed are `r`. Its
/// generator matrix is Pascal's triangle mod 2, whose columns follow v_{k+1} = v_k ^ (v_k >> 1);
/// with the van der Corput first dimension (which is r itself) the pair is a (0, 2)-sequence:
/// every aligned block of 2^k points stratifies the unit square. The columns' XOR for each
/// value of each byte of r is tabulated: four look-ups, however many bits the index has.
constexpr std::array<std::array<std::uint32_t, 256>, 4> sobolSecondTables() {
    std::array<std::uint32_t, 32> columns{};
    std::uint32_t column = 1u << 31;
    for (std::uint32_t& c : columns) {
        c = column;
        column ^= column >> 1;
    }
    std::array<std::array<std::uint32_t, 256>, 4> tables{};
    for (int byte = 0; byte < 4; ++byte)
        for (std::uint32_t value = 0; value < 256; ++value)
            for (int bit = 0; bit < 8; ++bit)  // bit b of r is bit 31 - b of the index
                if (value & (1u << bit)) tables[byte][value] ^= columns[31 - (8 * byte + bit)];
    return tables;
}

constexpr auto kSobolSecond = sobolSecondTables();

std::uint32_t sobolSecondOfReversed(std::uint32_t r) {
    return kSobolSecond[0][r & 0xFFu] ^ kSobolSecond[1][(r >> 8) & 0xFFu] ^
           kSobolSecond[2][(r >> 16) & 0xFFu] ^ kSobolSecond[3][r >> 24];
}

/// Laine & Karras's permutation with Burley's constants ("Practical Hash-based Owen Scrambling",
/// JCGT 2020): bit k of the result depends only on bits 0..k of `x` and on the seed. On a
/// bit-reversed sample index it is a nested uniform scramble: an aligned block of 2^k indices
/// (a (0, k, 2)-net of the sequence) is shuffled among itself.
std::uint32_t laineKarras(std::uint32_t x, std::uint32_t seed) {
    x += seed;
    x ^= x * 0x6c50b47cu;
    x ^= x * 0xb82f1e52u;
    x ^= x * 0xc7afe638u;
    x ^= x * 0x8d22f6e6u;
    return x;
}

float unitFloat(std::uint32_t bits) { return float(bits >> 8) * 0x1p-24f; }  // [0, 1), never 1

/// Random numbers of one (pixel, sample) path, a pure function of (pixel, sample, dimension):
/// the n-th request of a path always gets the same value, so a pixel never depends on which
/// thread renders it, or in which order. Each request (camera jitter, sun cone, lobe choice,
/// BSDF lobe shape, roulette) is a point of the Sobol (0, 2)-sequence, randomised per pixel and
/// request by a digit XOR (a random digital shift, which keeps the stratification), at a sample
/// index shuffled per request by a nested uniform (Owen) scramble (Burley 2020's padded Sobol,
/// with the Laine-Karras hash). The shuffle is non-linear on purpose: a digit XOR on the index
/// would commute with the sequence's linear digits, every request would be a fixed function of
/// the first, and a pixel would converge to a value of its own instead of the integral.
class Sampler {
public:
    Sampler(std::uint64_t pixel, std::uint32_t sample)
        : pixelKey_(mix64(pixel)), reversedSample_(reverseBits(sample)) {}

    float next1D() {
        const std::uint64_t h = dimensionHash();
        return unitFloat(reversedIndex(h) ^ std::uint32_t(h >> 32));
    }

    std::array<float, 2> next2D() {
        const std::uint64_t h = dimensionHash();
        const std::uint32_t r = reversedIndex(h);
        const std::uint64_t shift = mix64(h);
        return {unitFloat(r ^ std::uint32_t(shift)),
                unitFloat(sobolSecondOfReversed(r) ^ std::uint32_t(shift >> 32))};
    }

private:
    /// Independent of the sample index: the scrambles are shared by a pixel's samples.
    std::uint64_t dimensionHash() {
        return mix64(pixelKey_ ^ (++dimension_ * 0x9E3779B97F4A7C15ULL));
    }

    /// This request's sample index, Owen-scrambled under the request's own seed, bit-reversed
    /// (which is its van der Corput point).
    std::uint32_t reversedIndex(std::uint64_t h) const {
        return laineKarras(reversedSample_, std::uint32_t(h));
    }

    std::uint64_t pixelKey_;
    std::uint32_t reversedSample_;
    std::uint64_t dimension_ = 0;
};

// ---- Small vector helpers --------------------------------------------------------------------

float maxComponent(const Vec3& v) { return v.maxCoeff(); }

Vec3 toFloat(const Eigen::Vector3d& v) { return v.cast<float>(); }

/// Orthonormal basis around a unit normal, n as local +z (Duff et al. 2017, "Building an
/// Orthonormal Basis, Revisited"): no branch on a preferred axis, no singularity.
struct Frame {
    Vec3 t, b, n;

    explicit Frame(const Vec3& normal) : n(normal) {
        const float sign = std::copysign(1.0f, n.z());
        const float a = -1.0f / (sign + n.z());
        const float c = n.x() * n.y() * a;
        t = Vec3(1.0f + sign * n.x() * n.x() * a, sign * c, -sign * n.x());
        b = Vec3(c, sign + n.y() * n.y() * a, -n.y());
    }
    Vec3 toLocal(const Vec3& v) const { return Vec3(v.dot(t), v.dot(b), v.dot(n)); }
    Vec3 toWorld(const Vec3& v) const { return v.x() * t + v.y() * b + v.z() * n; }
};

/// Veach's power heuristic: the weight of a sample drawn with density `mine` when `other`
/// could have drawn it too.
float powerHeuristic(float mine, float other) {
    const float a = mine * mine, b = other * other;
    return a + b > 0.0f ? a / (a + b) : 0.0f;
}

Vec3 sampleCosineHemisphere(float u1, float u2) {
    const float r = std::sqrt(u1);
    const float phi = 2.0f * kPi * u2;
    return Vec3(r * std::cos(phi), r * std::sin(phi), std::sqrt(std::max(0.0f, 1.0f - u1)));
}

// ---- GGX microfacet model (Walter et al. 2007, "Microfacet Models for Refraction through
// Rough Surfaces"), in the local frame where the shading normal is +z ------------------------

float ggxD(const Vec3& h, float alpha) {
    const float a2 = alpha * alpha;
    const float d = h.z() * h.z() * (a2 - 1.0f) + 1.0f;
    return a2 / (kPi * d * d);
}

/// Smith's Lambda for GGX; G1 = 1 / (1 + Lambda), height-correlated G2 = 1 / (1 + L(o) + L(i))
/// (Heitz 2014, "Understanding the Masking-Shadowing Function").
float ggxLambda(const Vec3& v, float alpha) {
    const float cos2 = v.z() * v.z();
    const float tan2 = std::max(0.0f, 1.0f - cos2) / std::max(cos2, 1e-12f);
    return 0.5f * (std::sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
}

/// Schlick 1994: F = F0 + (1 - F0)(1 - cos)^5.
Vec3 schlick(const Vec3& f0, float cosTheta) {
    const float m = std::clamp(1.0f - cosTheta, 0.0f, 1.0f);
    const float m5 = (m * m) * (m * m) * m;
    return f0 + (Vec3::Ones() - f0) * m5;
}

float schlick(float f0, float cosTheta) { return schlick(Vec3::Constant(f0), cosTheta).x(); }

/// A microfacet normal drawn from GGX's distribution of normals visible from wo (Heitz 2018,
/// "Sampling the GGX Distribution of Visible Normals"): the pdf cancels D and G1, so the
/// sample weight is G2 / G1 <= 1 and grazing views do not blow up.
Vec3 sampleGgxVisibleNormal(const Vec3& wo, float alpha, float u1, float u2) {
    const Vec3 vh = Vec3(alpha * wo.x(), alpha * wo.y(), wo.z()).normalized();
    const float lensq = vh.x() * vh.x() + vh.y() * vh.y();
    const Vec3 t1 =
        lensq > 0.0f ? Vec3(Vec3(-vh.y(), vh.x(), 0.0f) / std::sqrt(lensq)) : Vec3(Vec3::UnitX());
    const Vec3 t2 = vh.cross(t1);
    const float r = std::sqrt(u1);
    const float phi = 2.0f * kPi * u2;
    const float p1 = r * std::cos(phi);
    const float s = 0.5f * (1.0f + vh.z());
    const float p2 = (1.0f - s) * std::sqrt(std::max(0.0f, 1.0f - p1 * p1)) + s * r * std::sin(phi);
    const Vec3 nh = p1 * t1 + p2 * t2 + std::sqrt(std::max(0.0f, 1.0f - p1 * p1 - p2 * p2)) * vh;
    return Vec3(alpha * nh.x(), alpha * nh.y(), std::max(0.0f, nh.z())).normalized();
}

/// GGX reflection lobe times cos(wi): D G2 / (4 cos(wo)), Fresnel left to the caller.
float ggxReflection(const Vec3& wo, const Vec3& wi, float alpha) {
    const Vec3 h = (wo + wi).normalized();
    const float g2 = 1.0f / (1.0f + ggxLambda(wo, alpha) + ggxLambda(wi, alpha));
    return ggxD(h, alpha) * g2 / (4.0f * wo.z());
}

Vec3 reflect(const Vec3& wo, const Vec3& h) { return 2.0f * wo.dot(h) * h - wo; }

// ---- Materials -------------------------------------------------------------------------------

/// One shading point's scattering, in the local frame (wo.z > 0: the normal faces the viewer).
/// Reflection leaves with wi.z > 0, transmission with wi.z < 0.
struct Bsdf {
    MaterialKind kind = MaterialKind::Diffuse;
    Vec3 albedo = Vec3::Constant(0.5f);
    float alpha = 0.1f;
    float transmission = 0.0f;

    /// f(wo, wi) |cos(wi)|: what next-event estimation multiplies the sun's irradiance by.
    Vec3 evalCos(const Vec3& wo, const Vec3& wi) const;

    /// Draws wi; `weight` = f |cos| / pdf (each component <= 1). False: the path is absorbed.
    /// `delta`: wi is the film's straight-through direction, which no light sample can draw.
    bool sample(const Vec3& wo, Sampler& rng, Vec3& wi, Vec3& weight, bool& delta) const;

    /// The solid-angle density with which sample() draws wi (its non-delta lobes), for
    /// multiple importance sampling of the sun.
    float pdf(const Vec3& wo, const Vec3& wi) const;

    /// Fraction of light passing straight through (film only; other sheets are opaque to
    /// shadow rays).
    Vec3 straightTransmission(float cosTheta) const {
        if (kind != MaterialKind::Film) return Vec3::Zero();
        return (1.0f - schlick(kFilmF0, cosTheta)) * transmission * albedo;
    }
};

Vec3 Bsdf::evalCos(const Vec3& wo, const Vec3& wi) const {
    const float lambert = std::abs(wi.z()) / kPi;
    switch (kind) {
        case MaterialKind::Diffuse:
            return wi.z() > 0.0f ? Vec3(albedo * lambert) : Vec3::Zero();
        case MaterialKind::Conductor: {
            if (wi.z() <= 0.0f) return Vec3::Zero();
            const Vec3 f = schlick(albedo, wo.dot((wo + wi).normalized()));
            return f * ggxReflection(wo, wi, alpha);
        }
        case MaterialKind::Film: {
            // The straight-through part is a delta lobe: NEE cannot hit it.
            if (wi.z() <= 0.0f) return Vec3::Zero();
            const float fo = schlick(kFilmF0, wo.z());
            const Vec3 diffuse = (1.0f - fo) * (1.0f - transmission) * albedo * lambert;
            return Vec3::Constant(fo * ggxReflection(wo, wi, alpha)) + diffuse;
        }
        case MaterialKind::Translucent: {
            const float side = wi.z() > 0.0f ? 1.0f - transmission : transmission;
            return side * albedo * lambert;
        }
    }
    return Vec3::Zero();
}

/// Density of the visible-normal GGX reflection of wo into wi: D_wo(h) / (4 wo.h) with
/// D_wo(h) = G1(wo) (wo.h) D(h) / wo.z (Heitz 2018), i.e. G1(wo) D(h) / (4 wo.z).
float ggxReflectionPdf(const Vec3& wo, const Vec3& wi, float alpha) {
    if (wi.z() <= 0.0f) return 0.0f;
    const Vec3 h = (wo + wi).normalized();
    const float g1 = 1.0f / (1.0f + ggxLambda(wo, alpha));
    return g1 * ggxD(h, alpha) / (4.0f * wo.z());
}

float Bsdf::pdf(const Vec3& wo, const Vec3& wi) const {
    const float cosine = std::abs(wi.z()) / kPi;
    switch (kind) {
        case MaterialKind::Diffuse:
            return wi.z() > 0.0f ? cosine : 0.0f;
        case MaterialKind::Conductor:
            return ggxReflectionPdf(wo, wi, alpha);
        case MaterialKind::Film: {
            const float fo = schlick(kFilmF0, wo.z());
            const float diffuse =
                wi.z() > 0.0f ? (1.0f - fo) * (1.0f - transmission) * cosine : 0.0f;
            return fo * ggxReflectionPdf(wo, wi, alpha) + diffuse;
        }
        case MaterialKind::Translucent:
            return (wi.z() > 0.0f ? 1.0f - transmission : transmission) * cosine;
    }
    return 0.0f;
}

bool Bsdf::sample(const Vec3& wo, Sampler& rng, Vec3& wi, Vec3& weight, bool& delta) const {
    delta = false;
    const float u0 = rng.next1D();
    const auto [u1, u2] = rng.next2D();
    switch (kind) {
        case MaterialKind::Diffuse:
            wi = sampleCosineHemisphere(u1, u2);
            weight = albedo;
            return true;
        case MaterialKind::Conductor: {
            const Vec3 h = sampleGgxVisibleNormal(wo, alpha, u1, u2);
            wi = reflect(wo, h);
            if (wi.z() <= 0.0f) return false;  // reflected into the surface: masked
            const float g1 = 1.0f / (1.0f + ggxLambda(wo, alpha));
            const float g2 = 1.0f / (1.0f + ggxLambda(wo, alpha) + ggxLambda(wi, alpha));
            weight = schlick(albedo, wo.dot(h)) * (g2 / g1);
            return true;
        }
        case MaterialKind::Film: {
            // Lobes chosen with probabilities equal to their weights: Fresnel (taken at the
            // macro normal, hence "dielectric-ish") for the gloss, then transmission, then
            // diffuse, so every sample's weight stays <= 1.
            const float fo = schlick(kFilmF0, wo.z());
            if (u0 < fo) {
                wi = reflect(wo, sampleGgxVisibleNormal(wo, alpha, u1, u2));
                if (wi.z() <= 0.0f) return false;
                const float g1 = 1.0f / (1.0f + ggxLambda(wo, alpha));
                const float g2 = 1.0f / (1.0f + ggxLambda(wo, alpha) + ggxLambda(wi, alpha));
                weight = Vec3::Constant(g2 / g1);
                return true;
            }
            weight = albedo;
            if ((u0 - fo) / (1.0f - fo) < transmission) {
                wi = -wo;  // a thin sheet: no refraction offset
                delta = true;
                return true;
            }
            wi = sampleCosineHemisphere(u1, u2);
            return true;
        }
        case MaterialKind::Translucent:
            wi = sampleCosineHemisphere(u1, u2);
            if (u0 < transmission) wi.z() = -wi.z();
            weight = albedo;
            return true;
    }
    return false;
}

// ---- Scene traversal -------------------------------------------------------------------------

/// A collider's triangles and its look's material, which neither the sheet's look layers nor
/// its colour map touch.
struct ColliderSurface {
    const Mesh* mesh = nullptr;
    Bsdf bsdf;
};

struct SurfaceHit {
    float t = std::numeric_limits<float>::infinity();
    Vec3 position;
    Vec3 geometricNormal;  ///< unit, facing the incoming ray
    Vec3 shadingNormal;    ///< unit, on the same side as geometricNormal
    Vec3 albedo;
    float alpha = 0.0f;         ///< the look's GGX alpha here (sheet hits only)
    float transmission = 0.0f;  ///< the look's transmission here (sheet hits only)
    float theta = 0.0f;         ///< the mesh's diffusing quantity, when it has one
    bool ground = false;
    const ColliderSurface* collider = nullptr;     ///< the collider hit, if one was
    std::uint32_t prim = RTC_INVALID_GEOMETRY_ID;  ///< the sheet's disc or triangle hit
};

/// Embree hands the context to filter callbacks, so it carries what the disc filter needs.
struct TraceContext {
    RTCIntersectContext embree;  ///< first member: Embree sees a plain RTCIntersectContext
    const Splats* splats = nullptr;
    std::uint32_t fromPrim = RTC_INVALID_GEOMETRY_ID;  ///< the disc the ray leaves
};

/// Overlapping discs of one sheet (neighbours lying near each other's tangent plane) shadow
/// each other at grazing angles even though the surface they approximate does not: rays
/// leaving a disc ignore those neighbours. A disc of another layer (a fold) is far off the
/// tangent plane and still occludes.
bool isNeighbourDisc(const Splats& splats, std::uint32_t from, std::uint32_t other) {
    if (from == other) return true;
    const Vec3 d = splats.centers[other] - splats.centers[from];
    const float reach = splats.radii[from] + splats.radii[other];
    if (d.squaredNorm() >= reach * reach) return false;
    return std::abs(splats.normals[from].dot(d)) < 0.5f * d.norm();  // within 30 degrees
}

void rejectNeighbourDiscs(const RTCFilterFunctionNArguments* args) {
    const auto* context = reinterpret_cast<const TraceContext*>(args->context);
    if (!context->splats || context->fromPrim == RTC_INVALID_GEOMETRY_ID) return;
    for (unsigned i = 0; i < args->N; ++i) {
        const std::uint32_t prim = RTCHitN_primID(args->hit, args->N, i);
        if (args->valid[i] != 0 && isNeighbourDisc(*context->splats, context->fromPrim, prim))
            args->valid[i] = 0;
    }
}

RTCRayHit makeRayHit(const Vec3& origin, const Vec3& direction, float tfar) {
    RTCRayHit rh;
    rh.ray.org_x = origin.x();
    rh.ray.org_y = origin.y();
    rh.ray.org_z = origin.z();
    rh.ray.tnear = 0.0f;
    rh.ray.dir_x = direction.x();
    rh.ray.dir_y = direction.y();
    rh.ray.dir_z = direction.z();
    rh.ray.time = 0.0f;
    rh.ray.tfar = tfar;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    return rh;
}

/// Both normals face the viewer (two-sided sheets); a shading normal that still points away,
/// at a silhouette of a smooth-shaded mesh, falls back to the geometric one.
void orientNormals(SurfaceHit& hit, const Vec3& direction) {
    if (hit.geometricNormal.dot(direction) > 0.0f) hit.geometricNormal = -hit.geometricNormal;
    if (hit.shadingNormal.dot(hit.geometricNormal) < 0.0f) hit.shadingNormal = -hit.shadingNormal;
    if (-hit.shadingNormal.dot(direction) <= 1e-4f) hit.shadingNormal = hit.geometricNormal;
}

Vec3 safeNormalized(const Vec3& v, const Vec3& fallback) {
    const float n = v.norm();
    return n > 1e-20f && std::isfinite(n) ? Vec3(v / n) : fallback;
}

/// The normal of a smooth-shaded triangle at Embree's (u, v), which weight vertices 1 and 2.
Vec3 interpolatedNormal(const Mesh& mesh, const RTCHit& h, const Vec3& fallback) {
    const auto& tri = mesh.triangles[h.primID];
    const auto& n = mesh.normals;
    return safeNormalized((1.0f - h.u - h.v) * n[tri[0]] + h.u * n[tri[1]] + h.v * n[tri[2]],
                          fallback);
}

/// What the path tracer needs from the settings, in float, computed once per frame.
struct Tracer {
    RTCScene scene = nullptr;
    const Mesh* mesh = nullptr;
    const Splats* splats = nullptr;
    /// By Embree geometry ID: the collider of that ID, or none (mesh null) for the sheet.
    std::vector<ColliderSurface> colliders;
    Vec3 defaultAlbedo;
    Bsdf material;
    /// Per vertex (mesh) or disc (splats): the look's (GGX alpha, transmission) under its layer;
    /// empty: the material's everywhere.
    std::vector<std::array<float, 2>> layerParams;
    ToneMapping tone;
    int maxDepth = 1;
    std::uint64_t seedKey = 0;  ///< XORed into the pixel index above any pixel's bits
    float epsilon = 1e-4f;      ///< ray origin offset, relative to the scene's size
    bool ground = false;
    float groundZ = 0.0f;
    Vec3 groundColor;
    bool sky = true;
    Vec3 background, zenith, horizon;
    Vec3 sunDirection;
    Vec3 sunIrradiance;
    float sunCosMax = 1.0f;
    Frame sunFrame{Vec3::UnitZ()};

    bool hasTheta() const { return mesh && !mesh->theta.empty(); }

    /// Solid-angle density of a uniform sample of the sun's cone; 0 for a point sun, which only
    /// next-event estimation can reach.
    float sunPdf() const {
        return sunCosMax < 1.0f ? 1.0f / (2.0f * kPi * (1.0f - sunCosMax)) : 0.0f;
    }
    bool inSun(const Vec3& d) const { return sunCosMax < 1.0f && d.dot(sunDirection) >= sunCosMax; }

    Vec3 environment(const Vec3& d) const {
        if (!sky) return background;
        const float t = std::clamp(d.z(), 0.0f, 1.0f);
        return horizon + (zenith - horizon) * t;
    }

    /// The environment's mean over cosine-distributed directions about +z, i.e. its irradiance
    /// on an upward-facing plane over pi: (1/pi) int (h + (z - h) cos) cos dw = h + 2/3 (z - h).
    Vec3 skyIrradianceOverPi() const {
        return sky ? Vec3(horizon + (zenith - horizon) * (2.0f / 3.0f)) : background;
    }

    float groundDistance(const Vec3& origin, const Vec3& direction) const {
        if (!ground || direction.z() == 0.0f) return std::numeric_limits<float>::infinity();
        const float t = (groundZ - origin.z()) / direction.z();
        return t > 0.0f ? t : std::numeric_limits<float>::infinity();
    }

    TraceContext context(std::uint32_t fromPrim) const {
        TraceContext c;
        rtcInitIntersectContext(&c.embree);
        c.splats = splats;
        c.fromPrim = fromPrim;
        return c;
    }

    const ColliderSurface* colliderOf(std::uint32_t geomID) const {
        return geomID < colliders.size() && colliders[geomID].mesh ? &colliders[geomID] : nullptr;
    }

    bool intersect(const Vec3& origin, const Vec3& direction, std::uint32_t fromPrim,
                   SurfaceHit& hit, long long& rays) const;
    void fillSurface(const RTCHit& h, SurfaceHit& hit) const;
    void fillCollider(const RTCHit& h, const ColliderSurface& collider, SurfaceHit& hit) const;
    Bsdf bsdfAt(const SurfaceHit& hit) const;
    Vec3 shadowTransmittance(Vec3 origin, const Vec3& direction, std::uint32_t fromPrim,
                             long long& rays) const;
    Vec3 sunLight(const SurfaceHit& hit, const Bsdf& bsdf, const Frame& frame, const Vec3& wo,
                  Sampler& rng, long long& rays) const;
    Vec3 radiance(Vec3 origin, Vec3 direction, Sampler& rng, long long& rays) const;

    Vec3 spawnOrigin(const SurfaceHit& hit, const Vec3& direction) const {
        const float side = hit.geometricNormal.dot(direction) >= 0.0f ? 1.0f : -1.0f;
        return hit.position + side * epsilon * hit.geometricNormal;
    }
};

void Tracer::fillSurface(const RTCHit& h, SurfaceHit& hit) const {
    const Vec3 ng = safeNormalized(Vec3(h.Ng_x, h.Ng_y, h.Ng_z), Vec3::UnitZ());
    hit.geometricNormal = ng;
    if (mesh) {
        // Embree's (u, v) weight vertices 1 and 2 of the triangle.
        const auto& tri = mesh->triangles[h.primID];
        const float w0 = 1.0f - h.u - h.v;
        hit.shadingNormal = interpolatedNormal(*mesh, h, ng);
        const auto& c = mesh->colors;
        hit.albedo =
            c.empty() ? defaultAlbedo : Vec3(w0 * c[tri[0]] + h.u * c[tri[1]] + h.v * c[tri[2]]);
        const auto& th = mesh->theta;
        hit.theta = th.empty() ? 0.0f : w0 * th[tri[0]] + h.u * th[tri[1]] + h.v * th[tri[2]];
        if (layerParams.empty()) return;
        const auto& l = layerParams;
        hit.alpha = w0 * l[tri[0]][0] + h.u * l[tri[1]][0] + h.v * l[tri[2]][0];
        hit.transmission = w0 * l[tri[0]][1] + h.u * l[tri[1]][1] + h.v * l[tri[2]][1];
    } else {
        hit.shadingNormal = safeNormalized(splats->normals[h.primID], ng);
        hit.albedo = splats->colors.empty() ? defaultAlbedo : splats->colors[h.primID];
        if (layerParams.empty()) return;
        hit.alpha = layerParams[h.primID][0];
        hit.transmission = layerParams[h.primID][1];
    }
}

/// Theta is 0 on a collider, as on the ground: the EXR's theta layer shows the sheet alone.
void Tracer::fillCollider(const RTCHit& h, const ColliderSurface& collider, SurfaceHit& hit) const {
    hit.geometricNormal = safeNormalized(Vec3(h.Ng_x, h.Ng_y, h.Ng_z), Vec3::UnitZ());
    hit.shadingNormal = interpolatedNormal(*collider.mesh, h, hit.geometricNormal);
    hit.albedo = collider.bsdf.albedo;
    hit.theta = 0.0f;
    hit.collider = &collider;
}

/// The ground is plain Lambert, a collider its look; the sheet is the material with the hit's
/// colour and, where the look's layer is on, its roughness and transmission.
Bsdf Tracer::bsdfAt(const SurfaceHit& hit) const {
    if (hit.ground) return Bsdf{MaterialKind::Diffuse, hit.albedo};
    if (hit.collider) return hit.collider->bsdf;
    Bsdf bsdf = material;
    bsdf.albedo = hit.albedo;
    if (layerParams.empty()) return bsdf;
    bsdf.alpha = hit.alpha;
    bsdf.transmission = hit.transmission;
    return bsdf;
}

bool Tracer::intersect(const Vec3& origin, const Vec3& direction, std::uint32_t fromPrim,
                       SurfaceHit& hit, long long& rays) const {
    const float tGround = groundDistance(origin, direction);
    RTCRayHit rh = makeRayHit(origin, direction, tGround);
    TraceContext c = context(fromPrim);
    rtcIntersect1(scene, &c.embree, &rh);
    ++rays;
    if (const ColliderSurface* collider = colliderOf(rh.hit.geomID)) {
        hit.t = rh.ray.tfar;
        fillCollider(rh.hit, *collider, hit);
    } else if (rh.hit.geomID != RTC_INVALID_GEOMETRY_ID) {
        hit.t = rh.ray.tfar;
        fillSurface(rh.hit, hit);
        hit.ground = false;
        hit.prim = rh.hit.primID;
    } else if (std::isfinite(tGround)) {
        hit.t = tGround;
        hit.geometricNormal = hit.shadingNormal = Vec3::UnitZ();
        hit.albedo = groundColor;
        hit.ground = true;
    } else {
        return false;
    }
    hit.position = origin + hit.t * direction;
    orientNormals(hit, direction);
    return true;
}

/// How much sunlight reaches along `direction`: 0 or 1 for opaque sheets (one rtcOccluded1),
/// the product of every film layer's straight-through transmission for film.
Vec3 Tracer::shadowTransmittance(Vec3 origin, const Vec3& direction, std::uint32_t fromPrim,
                                 long long& rays) const {
    if (std::isfinite(groundDistance(origin, direction))) return Vec3::Zero();
    if (material.kind != MaterialKind::Film) {
        RTCRay ray = makeRayHit(origin, direction, std::numeric_limits<float>::infinity()).ray;
        TraceContext c = context(fromPrim);
        rtcOccluded1(scene, &c.embree, &ray);
        ++rays;
        return ray.tfar < 0.0f ? Vec3::Zero() : Vec3::Ones();  // Embree sets tfar = -inf on a hit
    }
    Vec3 transmittance = Vec3::Ones();
    for (int layer = 0; layer < kMaxShadowLayers; ++layer) {
        SurfaceHit hit;
        if (!intersect(origin, direction, fromPrim, hit, rays)) return transmittance;
        const Bsdf layerBsdf = bsdfAt(hit);
        transmittance = transmittance.cwiseProduct(
            layerBsdf.straightTransmission(-direction.dot(hit.geometricNormal)));
        if (maxComponent(transmittance) < 1e-3f) break;
        origin = spawnOrigin(hit, direction);
        fromPrim = hit.prim;
    }
    return Vec3::Zero();
}

/// Next-event estimation of the sun, a cone of directions of uniform radiance whose total
/// irradiance at normal incidence is sunIrradiance: with a uniform cone sample, radiance / pdf
/// is exactly that irradiance.
Vec3 Tracer::sunLight(const SurfaceHit& hit, const Bsdf& bsdf, const Frame& frame, const Vec3& wo,
                      Sampler& rng, long long& rays) const {
    const auto [u1, u2] = rng.next2D();
    if (maxComponent(sunIrradiance) <= 0.0f) return Vec3::Zero();
    const float cosTheta = 1.0f - u1 * (1.0f - sunCosMax);
    const float sinTheta = std::sqrt(std::max(0.0f, 1.0f - cosTheta * cosTheta));
    const float phi = 2.0f * kPi * u2;
    const Vec3 wiWorld =
        sunFrame.toWorld(Vec3(sinTheta * std::cos(phi), sinTheta * std::sin(phi), cosTheta));
    const Vec3 wi = frame.toLocal(wiWorld);
    // Shading and geometric normals must agree on the side, or light leaks through the sheet.
    if ((wi.z() > 0.0f) != (hit.geometricNormal.dot(wiWorld) > 0.0f)) return Vec3::Zero();
    const Vec3 f = bsdf.evalCos(wo, wi);
    if (maxComponent(f) <= 0.0f) return Vec3::Zero();
    const Vec3 visible = shadowTransmittance(spawnOrigin(hit, wiWorld), wiWorld, hit.prim, rays);
    const float weight = sunPdf() > 0.0f ? powerHeuristic(sunPdf(), bsdf.pdf(wo, wi)) : 1.0f;
    return weight * f.cwiseProduct(visible).cwiseProduct(sunIrradiance);
}

Vec3 clampContribution(const Vec3& c, int depth) {
    if (depth == 0) return c;
    const float m = maxComponent(c);
    return m > kIndirectClamp ? Vec3(c * (kIndirectClamp / m)) : c;
}

/// Unidirectional path tracing: the environment when a path escapes, and the sun both by
/// next-event estimation at every vertex and by the BSDF's own sample when it escapes into the
/// sun's cone, the two weighted by the power heuristic (Veach 1997, ch. 9). A glossy metal's lobe
/// is narrower than the sun: its cone samples then rarely land in the lobe, with huge values
/// (glints that take thousands of samples to settle), while its BSDF samples hit the sun.
///
/// Sky light on the ground plane uses a control variate: the ground's cosine-sampled bounce
/// would see the sky gradient L(d), whose cosine-weighted mean is known in closed form
/// (skyIrradianceOverPi). The ground vertex adds that mean, and the bounce then contributes
/// only what differs from an open sky: nothing when it escapes, and its radiance minus L(d)
/// when it hits the sheet. The estimate stays unbiased (the mean of L(d) over the sampled
/// directions is exactly what is added), and the open ground, most of a frame's pixels, loses
/// all of its sky noise: L varies eightfold between zenith and horizon.
Vec3 Tracer::radiance(Vec3 origin, Vec3 direction, Sampler& rng, long long& rays) const {
    Vec3 result = Vec3::Zero();
    Vec3 throughput = Vec3::Ones();
    std::uint32_t fromPrim = RTC_INVALID_GEOMETRY_ID;
    bool skyControl = false;  // the last vertex already added the open sky's mean
    // The density with which the last scattering vertex drew this direction (0: the camera), and
    // that vertex's depth: a path that escapes into the sun's cone is the other half of that
    // vertex's sun sample, weighted against it.
    float misPdf = 0.0f;
    int misDepth = 0;
    for (int depth = 0;; ++depth) {
        SurfaceHit hit;
        if (!intersect(origin, direction, fromPrim, hit, rays)) {
            if (!skyControl)
                result += clampContribution(throughput.cwiseProduct(environment(direction)), depth);
            if (misPdf > 0.0f && inSun(direction)) {
                const Vec3 sun = sunIrradiance * (sunPdf() * powerHeuristic(misPdf, sunPdf()));
                result += clampContribution(throughput.cwiseProduct(sun), misDepth);
            }
            break;
        }
        if (skyControl) result -= throughput.cwiseProduct(environment(direction));
        skyControl = false;
        if (depth == maxDepth) break;
        const Bsdf bsdf = bsdfAt(hit);
        const Frame frame(hit.shadingNormal);
        const Vec3 wo = frame.toLocal(-direction);
        result += clampContribution(
            throughput.cwiseProduct(sunLight(hit, bsdf, frame, wo, rng, rays)), depth);
        if (hit.ground && hit.geometricNormal.z() > 0.0f) {
            // The ground's bounce is cosine-distributed about +z with weight = its albedo.
            result += clampContribution(
                throughput.cwiseProduct(bsdf.albedo).cwiseProduct(skyIrradianceOverPi()),
                depth + 1);
            skyControl = true;
        }
        Vec3 wi, weight;
        bool delta = false;
        if (!bsdf.sample(wo, rng, wi, weight, delta)) break;
        direction = frame.toWorld(wi).normalized();
        if ((wi.z() > 0.0f) != (hit.geometricNormal.dot(direction) > 0.0f)) break;
        if (!delta) {  // straight through a film keeps the direction, and its density
            misPdf = bsdf.pdf(wo, wi);
            misDepth = depth;
        }
        throughput = throughput.cwiseProduct(weight);
        if (depth >= kRouletteDepth) {
            const float survive = std::clamp(maxComponent(throughput), 0.05f, 1.0f);
            if (rng.next1D() >= survive) break;
            throughput /= survive;
        }
        origin = spawnOrigin(hit, direction);
        fromPrim = hit.prim;
    }
    return result.allFinite() ? result : Vec3::Zero();
}

// ---- Frame set-up ----------------------------------------------------------------------------

void checkGeometry(const Mesh& mesh) { checkMesh(mesh, "EmbreeRenderer"); }

void checkGeometry(const Splats& splats) {
    const std::size_t n = splats.centers.size();
    if (splats.normals.size() != n || splats.radii.size() != n ||
        (!splats.colors.empty() && splats.colors.size() != n) ||
        (!splats.layers.empty() && splats.layers.size() != n))
        throw std::invalid_argument("EmbreeRenderer: splat attribute arrays differ in length");
}

/// Largest absolute coordinate of the geometry, the colliders and the camera: the scale of
/// float round-off.
float sceneScale(const Geometry& geometry, std::span<const Mesh> colliders,
                 const RenderSettings& s) {
    float scale = std::max(1.0f, float(s.camera.position.cwiseAbs().maxCoeff()));
    const auto& points = std::holds_alternative<Mesh>(geometry)
                             ? std::get<Mesh>(geometry).positions
                             : std::get<Splats>(geometry).centers;
    for (const Vec3& p : points) scale = std::max(scale, p.cwiseAbs().maxCoeff());
    for (const Mesh& collider : colliders)
        for (const Vec3& p : collider.positions) scale = std::max(scale, p.cwiseAbs().maxCoeff());
    return scale;
}

float ggxAlpha(double roughness) { return std::max(kMinAlpha, float(roughness * roughness)); }

/// The look's layer, evaluated once per vertex or disc rather than at every hit. A layer keeps
/// the material's kind, so the frame-wide kind (film or opaque shadow rays) stays right.
std::vector<std::array<float, 2>> layerParams(const Geometry& geometry, const RenderSettings& s) {
    const auto& layers = std::holds_alternative<Mesh>(geometry) ? std::get<Mesh>(geometry).layers
                                                                : std::get<Splats>(geometry).layers;
    const Shading base = baseShading(s);
    std::vector<std::array<float, 2>> params;
    params.reserve(layers.size());
    for (const Eigen::Vector2f& l : layers) {
        const Shading here = layeredShading(s.look, base, l.x(), l.y());
        params.push_back({ggxAlpha(here.roughness), std::clamp(here.transmission, 0.0f, 1.0f)});
    }
    return params;
}

Bsdf colliderBsdf(const ColliderLook& look) {
    const Vec3 color = toFloat(look.color).cwiseMax(0.0f).cwiseMin(1.0f);
    if (!look.metal) return Bsdf{MaterialKind::Diffuse, color};
    return Bsdf{MaterialKind::Conductor, color, ggxAlpha(look.roughness)};
}

/// `geometryOf[c]`: the Embree geometry ID of collider c, or RTC_INVALID_GEOMETRY_ID when it has
/// no triangles.
std::vector<ColliderSurface> colliderSurfaces(std::span<const Mesh> colliders,
                                              std::span<const std::uint32_t> geometryOf,
                                              const RenderSettings& s) {
    std::vector<ColliderSurface> byGeometry;
    for (std::size_t c = 0; c < colliders.size(); ++c) {
        if (geometryOf[c] == RTC_INVALID_GEOMETRY_ID) continue;
        if (byGeometry.size() <= geometryOf[c]) byGeometry.resize(geometryOf[c] + 1);
        byGeometry[geometryOf[c]] = {&colliders[c], colliderBsdf(s.colliderLook(c))};
    }
    return byGeometry;
}

Tracer makeTracer(const Geometry& geometry, std::span<const Mesh> colliders,
                  const RenderSettings& s) {
    const PathTracing& pt = s.pathTracing;
    Tracer tr;
    tr.defaultAlbedo = toFloat(s.albedo);
    tr.material.kind = pt.material;
    tr.material.alpha = ggxAlpha(pt.roughness);
    tr.material.transmission = std::clamp(float(pt.transmission), 0.0f, 1.0f);
    tr.layerParams = layerParams(geometry, s);
    tr.tone = s.tone;
    tr.maxDepth = std::max(1, pt.maxDepth);
    tr.seedKey = std::uint64_t(pt.seed) << 40;  // images have fewer than 2^40 pixels
    tr.epsilon = 1e-4f * sceneScale(geometry, colliders, s);
    tr.ground = s.ground;
    tr.groundZ = float(s.groundHeight);
    tr.groundColor = toFloat(s.groundColor);
    tr.sky = pt.sky;
    tr.background = toFloat(s.background);
    tr.zenith = toFloat(pt.skyZenith);
    tr.horizon = toFloat(pt.skyHorizon);
    tr.sunDirection = safeNormalized(toFloat(s.sun.direction), Vec3::UnitZ());
    // Irradiance pi * colour * intensity: a white Lambert sheet facing the sun then reflects
    // radiance colour * intensity, the same brightness the OSMesa preview gives it.
    tr.sunIrradiance = toFloat(std::numbers::pi * s.sun.color * s.sun.intensity).cwiseMax(0.0f);
    const double radius = std::clamp(pt.sunAngularRadiusDegrees, 0.0, 90.0);
    tr.sunCosMax = float(std::cos(radius * std::numbers::pi / 180.0));
    tr.sunFrame = Frame(tr.sunDirection);
    if (const Mesh* m = std::get_if<Mesh>(&geometry))
        tr.mesh = m;
    else
        tr.splats = &std::get<Splats>(geometry);
    return tr;
}

/// Primary rays. cameraRayDirection is linear in the image coordinates, so it is evaluated
/// three times per frame and each ray is forward + (x, y) offsets in float: no tan() or double
/// arithmetic per sample.
struct CameraRays {
    Vec3 origin;
    Vec3 topLeft, stepX, stepY;  ///< unnormalised direction at pixel (0, 0)'s corner, per pixel
    int width = 1;
    int height = 1;

    CameraRays(const RenderSettings& s) : width(s.width), height(s.height) {
        origin = toFloat(s.camera.position);
        const auto basis = detail::viewBasis(s.camera.position, s.camera.lookAt, s.camera.up);
        const double aspect = double(width) / height;
        auto at = [&](double ndcX, double ndcY) {
            return detail::cameraRayDirection(basis, s.camera.fovYDegrees, aspect, ndcX, ndcY);
        };
        // Image rows run top-down: y grows as ndcY falls.
        topLeft = toFloat(at(-1.0, 1.0));
        stepX = toFloat((at(1.0, 1.0) - at(-1.0, 1.0)) / width);
        stepY = toFloat((at(-1.0, -1.0) - at(-1.0, 1.0)) / height);
    }

    Vec3 direction(int x, int y, float jx, float jy) const {
        return (topLeft + (float(x) + jx) * stepX + (float(y) + jy) * stepY).normalized();
    }
};

/// The first hit of pixel (x, y)'s centre ray, for the EXR's layers and the denoiser's guides:
/// one ray, not an average over the pixel's samples, which would invent surfaces between two
/// depths at a silhouette.
bool centreHit(const Tracer& tracer, const CameraRays& camera, int x, int y, SurfaceHit& hit,
               long long& rays) {
    const Vec3 d = camera.direction(x, y, 0.5f, 0.5f);
    return tracer.intersect(camera.origin, d, RTC_INVALID_GEOMETRY_ID, hit, rays);
}

void storeLayers(const SurfaceHit* hit, std::size_t pixel, FrameLayers& layers) {
    if (!hit) {
        layers.depth[pixel] = FrameLayers::kNoHit;
        return;
    }
    layers.depth[pixel] = hit->t;
    for (int k = 0; k < 3; ++k) layers.normal[pixel * 3 + k] = hit->shadingNormal[k];
    if (!layers.theta.empty())
        layers.theta[pixel] = hit->ground || hit->collider ? 0.0f : hit->theta;
}

void storeGuides(const SurfaceHit* hit, std::size_t pixel, float variance, DenoiseGuides& g) {
    g.variance[pixel] = variance;
    g.depth[pixel] = hit ? hit->t : FrameLayers::kNoHit;
    for (int k = 0; k < 3; ++k) {
        g.albedo[pixel * 3 + k] = hit ? hit->albedo[k] : 1.0f;
        g.normal[pixel * 3 + k] = hit ? hit->shadingNormal[k] : 0.0f;
    }
}

/// Sizes `g` for the image, keeping its buffers' memory from the frame before.
void sizeGuides(const CameraRays& camera, DenoiseGuides& g) {
    const std::size_t pixels = std::size_t(camera.width) * camera.height;
    g.width = camera.width;
    g.height = camera.height;
    g.albedo.resize(pixels * 3);
    g.normal.resize(pixels * 3);
    g.depth.resize(pixels);
    g.variance.resize(pixels);
}

}  // namespace

// ---- Embree device and scene -----------------------------------------------------------------

struct EmbreeRenderer::Impl {
    enum class Kind { None, Mesh, Splats };

    /// One collider's triangle geometry in the scene, kept to refit it while its topology holds.
    struct ColliderGeometry {
        std::uint32_t id = RTC_INVALID_GEOMETRY_ID;  ///< invalid: the collider has no triangles
        RTCGeometry geometry = nullptr;
        float* vertices = nullptr;
        std::size_t vertexCount = 0;
        std::vector<std::array<std::uint32_t, 3>> triangles;
    };

    RTCDevice device = nullptr;
    RTCScene scene = nullptr;
    RTCGeometry geometry = nullptr;  ///< owned by the scene; kept to update its buffers
    Kind kind = Kind::None;
    std::size_t vertexCount = 0;
    std::vector<std::array<std::uint32_t, 3>> triangles;  ///< the last frame's topology
    float* vertices = nullptr;                            ///< Embree-owned buffers of `geometry`
    float* normals = nullptr;
    std::vector<ColliderGeometry> colliders;  ///< index for index with the frame's colliders
    std::string lastError;
    long long rays = 0;
    // Per-frame buffers, kept so that a 1080p frame does not fault in 100 MB of fresh pages.
    std::vector<float> linear;
    std::vector<long long> pixelRays;  ///< counted per pixel: the same sum in any tile order
    DenoiseGuides guides;
    Denoiser denoiser;

    ~Impl();
    void check(const char* what);
    void upload(const Geometry& geometry, std::span<const Mesh> colliderMeshes);
    bool sameTopology(const Geometry& geometry) const;
    bool sameColliders(std::span<const Mesh> colliderMeshes) const;
    void rebuild(const Geometry& geometry);
    void createMesh(const Mesh& mesh);
    void createSplats(const Splats& splats);
    void copyVertices(const Geometry& geometry);
    void refit();
    void syncColliders(std::span<const Mesh> colliderMeshes);
    ColliderGeometry createCollider(const Mesh& mesh);
    std::vector<std::uint32_t> colliderIds() const;
    Image trace(const Tracer& tracer, const CameraRays& camera, int spp, bool denoised,
                FrameLayers* layers);
    Vec3 samplePixel(const Tracer& tracer, const CameraRays& camera, int spp, int x, int y,
                     long long& rays, float& variance) const;
};

EmbreeRenderer::Impl::~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
}

void EmbreeRenderer::Impl::check(const char* what) {
    const RTCError code = rtcGetDeviceError(device);
    if (code == RTC_ERROR_NONE) return;
    throw std::runtime_error(
        std::string("EmbreeRenderer: ") + what +
        " failed: " + (lastError.empty() ? "error " + std::to_string(int(code)) : lastError));
}

bool EmbreeRenderer::Impl::sameTopology(const Geometry& g) const {
    if (const Mesh* mesh = std::get_if<Mesh>(&g))
        return kind == Kind::Mesh && mesh->positions.size() == vertexCount &&
               mesh->triangles == triangles;
    return kind == Kind::Splats && std::get<Splats>(g).centers.size() == vertexCount;
}

bool EmbreeRenderer::Impl::sameColliders(std::span<const Mesh> meshes) const {
    if (meshes.size() != colliders.size()) return false;
    for (std::size_t c = 0; c < meshes.size(); ++c)
        if (meshes[c].positions.size() != colliders[c].vertexCount ||
            meshes[c].triangles != colliders[c].triangles)
            return false;
    return true;
}

/// The sheet and the colliders are refitted while their topology holds; the scene is committed
/// once, after both.
void EmbreeRenderer::Impl::upload(const Geometry& g, std::span<const Mesh> colliderMeshes) {
    if (geometry && sameTopology(g)) {
        copyVertices(g);
        refit();
    } else {
        rebuild(g);
    }
    syncColliders(colliderMeshes);
    rtcCommitScene(scene);
    check("building the BVH");
}

void EmbreeRenderer::Impl::rebuild(const Geometry& g) {
    if (scene) rtcReleaseScene(scene);
    colliders.clear();  // released with the scene
    geometry = nullptr;
    kind = Kind::None;
    vertexCount = 0;
    triangles.clear();
    scene = rtcNewScene(device);
    // Dynamic: rebuilt or refitted every frame. Robust: watertight shared edges, so no sunlight
    // leaks through the seams of a closed sheet.
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_DYNAMIC | RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_LOW);
    if (const Mesh* mesh = std::get_if<Mesh>(&g)) {
        if (!mesh->triangles.empty()) createMesh(*mesh);
    } else if (!std::get<Splats>(g).centers.empty()) {
        createSplats(std::get<Splats>(g));
    }
}

void EmbreeRenderer::Impl::createMesh(const Mesh& mesh) {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    check("creating a triangle geometry");
    rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_LOW);
    vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(Vec3), mesh.positions.size()));
    auto* index = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(std::uint32_t), mesh.triangles.size()));
    check("allocating triangle buffers");
    std::memcpy(index, mesh.triangles.data(), mesh.triangles.size() * 3 * sizeof(std::uint32_t));
    kind = Kind::Mesh;
    vertexCount = mesh.positions.size();
    triangles = mesh.triangles;
    geometry = geom;
    copyVertices(mesh);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);  // the scene holds the reference now
}

void EmbreeRenderer::Impl::createSplats(const Splats& splats) {
    RTCGeometry geom = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_ORIENTED_DISC_POINT);
    check("creating an oriented-disc geometry");
    rtcSetGeometryBuildQuality(geom, RTC_BUILD_QUALITY_LOW);
    rtcSetGeometryIntersectFilterFunction(geom, rejectNeighbourDiscs);
    rtcSetGeometryOccludedFilterFunction(geom, rejectNeighbourDiscs);
    const std::size_t n = splats.centers.size();
    vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), n));
    normals = static_cast<float*>(rtcSetNewGeometryBuffer(geom, RTC_BUFFER_TYPE_NORMAL, 0,
                                                          RTC_FORMAT_FLOAT3, sizeof(Vec3), n));
    check("allocating disc buffers");
    kind = Kind::Splats;
    vertexCount = n;
    geometry = geom;
    copyVertices(splats);
    rtcCommitGeometry(geom);
    rtcAttachGeometry(scene, geom);
    rtcReleaseGeometry(geom);
}

void EmbreeRenderer::Impl::copyVertices(const Geometry& g) {
    if (const Mesh* mesh = std::get_if<Mesh>(&g)) {
        std::memcpy(vertices, mesh->positions.data(), mesh->positions.size() * sizeof(Vec3));
        return;
    }
    const Splats& splats = std::get<Splats>(g);
    for (std::size_t i = 0; i < splats.centers.size(); ++i) {
        float* v = vertices + 4 * i;
        v[0] = splats.centers[i].x();
        v[1] = splats.centers[i].y();
        v[2] = splats.centers[i].z();
        v[3] = splats.radii[i];
    }
    std::memcpy(normals, splats.normals.data(), splats.normals.size() * sizeof(Vec3));
}

void EmbreeRenderer::Impl::refit() {
    rtcUpdateGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0);
    if (kind == Kind::Splats) rtcUpdateGeometryBuffer(geometry, RTC_BUFFER_TYPE_NORMAL, 0);
    // Same topology: moving the existing BVH's boxes is far cheaper than a rebuild.
    rtcSetGeometryBuildQuality(geometry, RTC_BUILD_QUALITY_REFIT);
    rtcCommitGeometry(geometry);
}

/// Colliders move every frame but rarely change shape: the same triangles refit, others replace
/// every collider geometry.
void EmbreeRenderer::Impl::syncColliders(std::span<const Mesh> meshes) {
    if (sameColliders(meshes)) {
        for (std::size_t c = 0; c < meshes.size(); ++c) {
            if (!colliders[c].geometry) continue;
            std::memcpy(colliders[c].vertices, meshes[c].positions.data(),
                        meshes[c].positions.size() * sizeof(Vec3));
            rtcUpdateGeometryBuffer(colliders[c].geometry, RTC_BUFFER_TYPE_VERTEX, 0);
            rtcSetGeometryBuildQuality(colliders[c].geometry, RTC_BUILD_QUALITY_REFIT);
            rtcCommitGeometry(colliders[c].geometry);
        }
        return;
    }
    for (const ColliderGeometry& c : colliders)
        if (c.geometry) rtcDetachGeometry(scene, c.id);
    colliders.clear();
    for (const Mesh& mesh : meshes) colliders.push_back(createCollider(mesh));
}

EmbreeRenderer::Impl::ColliderGeometry EmbreeRenderer::Impl::createCollider(const Mesh& mesh) {
    ColliderGeometry c;
    c.vertexCount = mesh.positions.size();
    c.triangles = mesh.triangles;
    if (mesh.triangles.empty()) return c;
    c.geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    check("creating a collider's triangle geometry");
    c.vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
        c.geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, sizeof(Vec3), c.vertexCount));
    auto* index = static_cast<std::uint32_t*>(
        rtcSetNewGeometryBuffer(c.geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                3 * sizeof(std::uint32_t), mesh.triangles.size()));
    check("allocating a collider's triangle buffers");
    std::memcpy(index, mesh.triangles.data(), mesh.triangles.size() * 3 * sizeof(std::uint32_t));
    std::memcpy(c.vertices, mesh.positions.data(), c.vertexCount * sizeof(Vec3));
    rtcCommitGeometry(c.geometry);
    c.id = rtcAttachGeometry(scene, c.geometry);
    rtcReleaseGeometry(c.geometry);  // the scene holds the reference now
    return c;
}

std::vector<std::uint32_t> EmbreeRenderer::Impl::colliderIds() const {
    std::vector<std::uint32_t> ids;
    for (const ColliderGeometry& c : colliders) ids.push_back(c.id);
    return ids;
}

namespace {

/// Every tile of the image, in parallel; `body(x0, y0, x1, y1)` gets the tile's pixel range.
/// Each pixel's random numbers depend on (pixel, sample, dimension) only, so the dynamic tile
/// order cannot change a byte.
template <class Body>
void forEachTile(const CameraRays& camera, const Body& body) {
    const int tilesX = (camera.width + kTileSize - 1) / kTileSize;
    const int tiles = tilesX * ((camera.height + kTileSize - 1) / kTileSize);
#pragma omp parallel for schedule(dynamic)
    for (int tile = 0; tile < tiles; ++tile) {
        const int x0 = (tile % tilesX) * kTileSize, y0 = (tile / tilesX) * kTileSize;
        body(x0, y0, std::min(x0 + kTileSize, camera.width),
             std::min(y0 + kTileSize, camera.height));
    }
}

}  // namespace

/// The mean of pixel (x, y)'s spp samples, linear, and the variance of that mean's luminance
/// from the samples' spread (0 for one sample); adds the rays traced to `rays`.
Vec3 EmbreeRenderer::Impl::samplePixel(const Tracer& tracer, const CameraRays& camera, int spp,
                                       int x, int y, long long& rays, float& variance) const {
    const std::size_t pixel = std::size_t(y) * camera.width + x;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    double sumSquares = 0.0;
    for (int s = 0; s < spp; ++s) {
        Sampler rng(pixel ^ tracer.seedKey, std::uint32_t(s));
        const auto [jx, jy] = rng.next2D();
        const Eigen::Vector3d c =
            tracer.radiance(camera.origin, camera.direction(x, y, jx, jy), rng, rays)
                .cast<double>();
        sum += c;
        const double l = 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
        sumSquares += l * l;
    }
    const Eigen::Vector3d mean = sum / spp;
    const double l = 0.2126 * mean.x() + 0.7152 * mean.y() + 0.0722 * mean.z();
    variance = spp > 1 ? float(std::max(0.0, sumSquares / spp - l * l) / (spp - 1)) : 0.0f;
    return mean.cast<float>();
}

Image EmbreeRenderer::Impl::trace(const Tracer& tracer, const CameraRays& camera, int spp,
                                  bool denoised, FrameLayers* layers) {
    const std::size_t pixels = std::size_t(camera.width) * camera.height;
    linear.resize(pixels * 3);
    if (layers) {
        *layers = FrameLayers{camera.width, camera.height, {}, {}, {}, {}};
        layers->depth.resize(pixels);
        layers->normal.resize(pixels * 3);
        if (tracer.hasTheta()) layers->theta.resize(pixels);
    }
    if (denoised) sizeGuides(camera, guides);
    pixelRays.assign(pixels, 0);
    forEachTile(camera, [&](int x0, int y0, int x1, int y1) {
        for (int y = y0; y < y1; ++y) {
            for (int x = x0; x < x1; ++x) {
                const std::size_t pixel = std::size_t(y) * camera.width + x;
                float variance = 0.0f;
                const Vec3 c = samplePixel(tracer, camera, spp, x, y, pixelRays[pixel], variance);
                for (int k = 0; k < 3; ++k) linear[pixel * 3 + k] = c[k];
                if (!layers && !denoised) continue;
                SurfaceHit hit;
                const bool found = centreHit(tracer, camera, x, y, hit, pixelRays[pixel]);
                if (layers) storeLayers(found ? &hit : nullptr, pixel, *layers);
                if (denoised) storeGuides(found ? &hit : nullptr, pixel, variance, guides);
            }
        }
    });
    rays = 0;
    for (long long r : pixelRays) rays += r;
    if (denoised && spp == 1) guides.variance.clear();  // no spread from one sample
    if (denoised) denoiser(linear, guides);
    Image image{camera.width, camera.height, std::vector<std::uint8_t>(pixels * 3)};
    displayBytes(linear, image.rgb, tracer.tone);
    if (layers) layers->rgb = linear;
    return image;
}

// ---- Public interface ------------------------------------------------------------------------

EmbreeRenderer::EmbreeRenderer() : impl_(std::make_unique<Impl>()) {
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device)
        throw std::runtime_error("EmbreeRenderer: rtcNewDevice failed (error " +
                                 std::to_string(int(rtcGetDeviceError(nullptr))) + ")");
    rtcSetDeviceErrorFunction(
        impl_->device,
        [](void* user, RTCError, const char* message) {
            static_cast<Impl*>(user)->lastError = message ? message : "";
        },
        impl_.get());
    if (!rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_POINT_GEOMETRY_SUPPORTED) ||
        !rtcGetDeviceProperty(impl_->device, RTC_DEVICE_PROPERTY_FILTER_FUNCTION_SUPPORTED))
        throw std::runtime_error(
            "EmbreeRenderer: this Embree was built without point geometry or filter functions");
}

EmbreeRenderer::~EmbreeRenderer() = default;

Image EmbreeRenderer::render(const Geometry& geometry, const RenderSettings& settings,
                             FrameLayers* layers, std::span<const Mesh> colliders) {
    if (settings.width <= 0 || settings.height <= 0)
        throw std::invalid_argument("EmbreeRenderer: image size must be positive");
    std::visit([](const auto& g) { checkGeometry(g); }, geometry);
    for (const Mesh& collider : colliders) checkMesh(collider, "EmbreeRenderer (a collider)");
    impl_->upload(geometry, colliders);
    Tracer tracer = makeTracer(geometry, colliders, settings);
    tracer.colliders = colliderSurfaces(colliders, impl_->colliderIds(), settings);
    tracer.scene = impl_->scene;
    const CameraRays camera(settings);
    const int spp = std::max(1, settings.pathTracing.samplesPerPixel);
    return impl_->trace(tracer, camera, spp, settings.pathTracing.denoise, layers);
}

std::string EmbreeRenderer::deviceDescription() {
    auto property = [&](RTCDeviceProperty p) {
        return std::to_string(rtcGetDeviceProperty(impl_->device, p));
    };
    return "Embree " + property(RTC_DEVICE_PROPERTY_VERSION_MAJOR) + "." +
           property(RTC_DEVICE_PROPERTY_VERSION_MINOR) + "." +
           property(RTC_DEVICE_PROPERTY_VERSION_PATCH);
}

long long EmbreeRenderer::raysTraced() const { return impl_->rays; }

}  // namespace rend::render
