#include "sim/StepKernels.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <string_view>

#include "sim/SimdRuns.h"

namespace rend::sim {
namespace {

constexpr std::int16_t kFree = -1;

/// Particle i's mass: the one mass where the sheet has one.
template <class Input>
inline double massOf(const Input& in, int i) {
    return in.oneMass > 0.0 ? in.oneMass : in.mass[i];
}

/// One particle; returns whether it is free and not above the floor (NaN included).
inline bool kickDriftOne(const KickDrift& k, int i) {
    double* v = k.v + 3 * i;
    const std::int16_t c = k.constraint[i];
    const double* f = k.forceOf(i);
    if (c == kFree) {
        const double mass = massOf(k, i);
        for (int a = 0; a < 3; ++a) v[a] += k.h * (f[a] / mass + k.gravity[a] - k.damping * v[a]);
    } else {
        for (int a = 0; a < 3; ++a) v[a] = c < 0 ? 0.0 : k.boundaryVelocity[3 * c + a];
        if (k.keptForce)
            for (int a = 0; a < 3; ++a) k.keptForce[3 * i + a] = f[a];
    }
    for (int a = 0; a < 3; ++a) k.x[3 * i + a] += k.dt * v[a];
    return c == kFree && !(k.x[3 * i + 2] >= k.floor);
}

/// Whether `count` particles from `constraint` are all free (kFree is all bits set).
inline bool allFree(const std::int16_t* constraint, int count) {
    for (int k = 0; k < count; k += 4) {
        std::uint64_t tags;
        std::memcpy(&tags, constraint + k, sizeof tags);
        if (tags != ~std::uint64_t(0)) return false;
    }
    return true;
}

/// The guard's sums of one chain (sim/BlowUpGuard.h).
struct GuardPart {
    double kinetic = 0.0, boundaryPower = 0.0, gravityPower = 0.0;
};

/// Particle i's speed check, its share of the sums and whether it is the fastest so far.
inline void guardVisit(const GuardInput& g, int i, GuardPart& p, GuardSums& s) {
    const double* v = g.v + 3 * i;
    const double speedSquared = (v[0] * v[0] + v[1] * v[1]) + v[2] * v[2];
    if (!(speedSquared <= g.limitSquared) && s.firstBad < 0) s.firstBad = i;
    const std::int16_t c = g.constraint[i];
    if (c != kFree) {
        const double* f = g.force + 3 * i;
        if (c >= 0) p.boundaryPower += std::abs((f[0] * v[0] + f[1] * v[1]) + f[2] * v[2]);
        return;
    }
    const double mass = massOf(g, i);
    p.kinetic += 0.5 * mass * speedSquared;
    const double* a = g.gravity;
    if (g.hasGravity) p.gravityPower += mass * std::abs((a[0] * v[0] + a[1] * v[1]) + a[2] * v[2]);
    if (speedSquared > s.maxSpeedSquared) s.maxSpeedSquared = speedSquared, s.fastest = i;
}

/// The largest |theta| skips NaN (std::max keeps its first argument); NaN and inf are bad.
inline void guardVisitTheta(const double* theta, int i, GuardSums& s) {
    if (!std::isfinite(theta[i]) && s.firstBad < 0) s.firstBad = i;
    s.maxAbsTheta = std::max(s.maxAbsTheta, std::abs(theta[i]));
}

GuardSums guardThetaScalar(const double* theta, int begin, int end) {
    GuardSums s;
    for (int i = begin; i < end; ++i) guardVisitTheta(theta, i, s);
    return s;
}

/// The four chains' sums into s, added (0 + 1) + (2 + 3).
inline void addChains(const GuardPart (&p)[4], GuardSums& s) {
    const auto total = [&](double GuardPart::*field) {
        return (p[0].*field + p[1].*field) + (p[2].*field + p[3].*field);
    };
    s.kinetic = total(&GuardPart::kinetic);
    s.boundaryPower = total(&GuardPart::boundaryPower);
    s.gravityPower = total(&GuardPart::gravityPower);
}

/// Four chains, of every fourth particle, added in a fixed order.
GuardSums guardScalar(const GuardInput& g, int begin, int end) {
    GuardSums s;
    GuardPart p[4];
    int i = begin;
    for (; i + 4 <= end; i += 4)
        for (int k = 0; k < 4; ++k) guardVisit(g, i + k, p[k], s);
    for (; i < end; ++i) guardVisit(g, i, p[0], s);
    addChains(p, s);
    return s;
}

#if defined(__x86_64__)
// Four free particles are twelve doubles, three lanes of four: x0 y0 z0 x1 | y1 z1 x2 y2 |
// z2 x3 y3 z3, with the masses and gravity spread to match. Its own copy of the input and a
// local `below`, as kickDriftAvx512's: through the references, every store to x and v read the
// input's pointers again, and each lane's test of the floor read and wrote `below` in memory, a
// chain of store-to-load forwards (cpu-clock samples on those instructions: a third of the
// loop's). One mass for the sheet (kOne) and a floor (kFloor) are constants of the loop: a
// branch on the one, and the other's test where there is no floor, were 12 of a quad's 76
// instructions (scripts/bench_instructions.sh); the lanes below the floor are gathered in a
// vector and asked once. A quad with a pinned or driven particle (mixed()) is kicked as if free
// and theirs then take their prescribed velocities from a blend: one at a time, such a quad was
// about 490 instructions (stretch's grips: a third of the kick's count).
template <bool kOne, bool kFloor>
struct KickQuadsAvx2 {
    const KickDrift k;  // its own copy (above)
    __m256d h, dt, damping, floor, oneMass, gravity[3], zLanes[3];
    __m256d belowLanes;

    [[gnu::target("avx2")]] explicit KickQuadsAvx2(const KickDrift& input) : k(input) {
        h = _mm256_set1_pd(k.h), dt = _mm256_set1_pd(k.dt);
        damping = _mm256_set1_pd(k.damping), floor = _mm256_set1_pd(k.floor);
        const double* g = k.gravity;
        gravity[0] = _mm256_setr_pd(g[0], g[1], g[2], g[0]);
        gravity[1] = _mm256_setr_pd(g[1], g[2], g[0], g[1]);
        gravity[2] = _mm256_setr_pd(g[2], g[0], g[1], g[2]);
        // Where the z's sit in each lane.
        zLanes[0] = _mm256_castsi256_pd(_mm256_setr_epi64x(0, 0, -1, 0));
        zLanes[1] = _mm256_castsi256_pd(_mm256_setr_epi64x(0, -1, 0, 0));
        zLanes[2] = _mm256_castsi256_pd(_mm256_setr_epi64x(-1, 0, 0, -1));
        belowLanes = _mm256_setzero_pd();
        // One mass for the sheet: one broadcast, the mass array unread (kickDriftAvx512's).
        oneMass = _mm256_set1_pd(k.oneMass);
    }
    /// Free particles i to i + 3 kicked and drifted; their new velocities in `vel`'s lanes.
    [[gnu::always_inline, gnu::target("avx2")]] void free(int i, __m256d (&vel)[3]) {
        quad<false>(i, vel);
    }
    /// Particles i to i + 3, some pinned or driven: kickDriftOne's bits in every lane.
    [[gnu::always_inline, gnu::target("avx2")]] void mixed(int i, __m256d (&vel)[3]) {
        quad<true>(i, vel);
    }
    /// Lanes of the particles i to i + 3 that are not free (all bits set), and their
    /// velocities (pinned: 0); their forces copied where a block kept them (KickDrift::keptForce).
    [[gnu::always_inline, gnu::target("avx2")]] void prescribedOf(int i, __m256d (&held)[3],
                                                                  __m256d (&prescribed)[3]) const {
        alignas(32) double velocity[12];
        alignas(32) std::int64_t tag[12];
        for (int p = 0; p < 4; ++p) {
            const std::int16_t c = k.constraint[i + p];
            for (int a = 0; a < 3; ++a) {
                velocity[3 * p + a] = c >= 0 ? k.boundaryVelocity[3 * c + a] : 0.0;
                tag[3 * p + a] = c == kFree ? 0 : -1;
            }
            if (c != kFree && k.keptForce)
                for (int a = 0; a < 3; ++a) k.keptForce[3 * (i + p) + a] = k.forceOf(i + p)[a];
        }
        for (int lane = 0; lane < 3; ++lane) {
            prescribed[lane] = _mm256_load_pd(velocity + 4 * lane);
            held[lane] = _mm256_castsi256_pd(
                _mm256_load_si256(reinterpret_cast<const __m256i*>(tag + 4 * lane)));
        }
    }
    template <bool kMixed>
    [[gnu::always_inline, gnu::target("avx2")]] void quad(int i, __m256d (&vel)[3]) {
        __m256d held[3], prescribed[3];
        if constexpr (kMixed) prescribedOf(i, held, prescribed);
        __m256d mass[3] = {oneMass, oneMass, oneMass};
        if constexpr (!kOne) {
            const double* m = k.mass + i;
            mass[0] = _mm256_setr_pd(m[0], m[0], m[0], m[1]);
            mass[1] = _mm256_setr_pd(m[1], m[1], m[2], m[2]);
            mass[2] = _mm256_setr_pd(m[2], m[3], m[3], m[3]);
        }
        for (int lane = 0; lane < 3; ++lane) {
            double* v = k.v + 3 * i + 4 * lane;
            double* x = k.x + 3 * i + 4 * lane;
            const __m256d f = _mm256_loadu_pd(k.forceOf(i) + 4 * lane);
            __m256d u = _mm256_loadu_pd(v);
            const __m256d acceleration =
                _mm256_sub_pd(_mm256_add_pd(_mm256_div_pd(f, mass[lane]), gravity[lane]),
                              _mm256_mul_pd(damping, u));
            u = _mm256_add_pd(u, _mm256_mul_pd(h, acceleration));
            if constexpr (kMixed) u = _mm256_blendv_pd(u, prescribed[lane], held[lane]);
            _mm256_storeu_pd(v, u);
            const __m256d to = _mm256_add_pd(_mm256_loadu_pd(x), _mm256_mul_pd(dt, u));
            _mm256_storeu_pd(x, to);
            if constexpr (kFloor) {
                const __m256d z =
                    kMixed ? _mm256_andnot_pd(held[lane], zLanes[lane]) : zLanes[lane];
                belowLanes = _mm256_or_pd(belowLanes,
                                          _mm256_and_pd(_mm256_cmp_pd(to, floor, _CMP_NGE_UQ), z));
            }
            vel[lane] = u;
        }
    }
    /// Whether a lane ended below the floor.
    [[gnu::target("avx2")]] bool below() const { return _mm256_movemask_pd(belowLanes) != 0; }
};

template <bool kOne, bool kFloor>
[[gnu::target("avx2")]] int kickQuadsAvx2(const KickDrift& input, int begin, int end,
                                          bool& belowFloor) {
    KickQuadsAvx2<kOne, kFloor> kick(input);
    int i = begin;
    for (; i + 4 <= end; i += 4) {
        __m256d vel[3];
        if (allFree(kick.k.constraint + i, 4))
            kick.free(i, vel);
        else
            kick.mixed(i, vel);
    }
    belowFloor = belowFloor || kick.below();
    return i;
}

int kickDriftAvx2(const KickDrift& k, int begin, int end, bool& belowFloor) {
    const bool one = k.oneMass > 0.0, floor = k.floor != -std::numeric_limits<double>::infinity();
    if (floor)
        return one ? kickQuadsAvx2<true, true>(k, begin, end, belowFloor)
                   : kickQuadsAvx2<false, true>(k, begin, end, belowFloor);
    return one ? kickQuadsAvx2<true, false>(k, begin, end, belowFloor)
               : kickQuadsAvx2<false, false>(k, begin, end, belowFloor);
}

// Eight particles are twenty-four doubles, three lanes of eight, the masses and gravity spread
// by permutes (KickQuadsAvx2's, at eight lanes): an octet with a pinned or driven particle is
// kicked as if free and theirs then take their prescribed velocities by a masked blend.
template <bool kOne, bool kFloor>
struct KickOctetsAvx512 {
    const KickDrift k;  // its own copy (KickQuadsAvx2's)
    __m512d h, dt, damping, floor, oneMass, gravity[3];
    __m512i particle[3];
    unsigned below = 0;
    /// Component (3 p + a) of lane l: particle p = (8 l + slot) / 3, axis a = (8 l + slot) % 3.
    static constexpr __mmask8 kZLanes[3] = {0b00100100, 0b01001001, 0b10010010};

    [[gnu::target("avx2,avx512f")]] explicit KickOctetsAvx512(const KickDrift& input) : k(input) {
        h = _mm512_set1_pd(k.h), dt = _mm512_set1_pd(k.dt);
        damping = _mm512_set1_pd(k.damping), floor = _mm512_set1_pd(k.floor);
        oneMass = _mm512_set1_pd(k.oneMass);
        const __m512d g = _mm512_setr_pd(k.gravity[0], k.gravity[1], k.gravity[2], 0, 0, 0, 0, 0);
        const __m512i axis[3] = {_mm512_setr_epi64(0, 1, 2, 0, 1, 2, 0, 1),
                                 _mm512_setr_epi64(2, 0, 1, 2, 0, 1, 2, 0),
                                 _mm512_setr_epi64(1, 2, 0, 1, 2, 0, 1, 2)};
        particle[0] = _mm512_setr_epi64(0, 0, 0, 1, 1, 1, 2, 2);
        particle[1] = _mm512_setr_epi64(2, 3, 3, 3, 4, 4, 4, 5);
        particle[2] = _mm512_setr_epi64(5, 5, 6, 6, 6, 7, 7, 7);
        for (int lane = 0; lane < 3; ++lane) gravity[lane] = _mm512_permutexvar_pd(axis[lane], g);
    }
    /// The components of particles i to i + 7 that are not free, and their velocities (pinned:
    /// 0); their forces copied where a block kept them (KickDrift::keptForce).
    [[gnu::always_inline, gnu::target("avx2,avx512f")]] void prescribedOf(
        int i, __mmask8 (&held)[3], __m512d (&prescribed)[3]) const {
        alignas(64) double velocity[24];
        unsigned tags = 0;
        for (int p = 0; p < 8; ++p) {
            const std::int16_t c = k.constraint[i + p];
            for (int a = 0; a < 3; ++a)
                velocity[3 * p + a] = c >= 0 ? k.boundaryVelocity[3 * c + a] : 0.0;
            if (c == kFree) continue;
            tags |= 7u << (3 * p);
            if (k.keptForce)
                for (int a = 0; a < 3; ++a) k.keptForce[3 * (i + p) + a] = k.forceOf(i + p)[a];
        }
        for (int lane = 0; lane < 3; ++lane) {
            prescribed[lane] = _mm512_load_pd(velocity + 8 * lane);
            held[lane] = __mmask8(tags >> (8 * lane));
        }
    }
    /// Particles i to i + 7 kicked and drifted (kickDriftOne's bits in every lane); their new
    /// velocities in `vel`'s lanes. kMixed: some are pinned or driven.
    template <bool kMixed>
    [[gnu::always_inline, gnu::target("avx2,avx512f")]] void octet(int i, __m512d (&vel)[3]) {
        __mmask8 held[3] = {0, 0, 0};
        __m512d prescribed[3];
        if constexpr (kMixed) prescribedOf(i, held, prescribed);
        const __m512d masses = kOne ? oneMass : _mm512_loadu_pd(k.mass + i);
        for (int lane = 0; lane < 3; ++lane) {
            double* v = k.v + 3 * i + 8 * lane;
            double* x = k.x + 3 * i + 8 * lane;
            const __m512d mass = kOne ? oneMass : _mm512_permutexvar_pd(particle[lane], masses);
            const __m512d f = _mm512_loadu_pd(k.forceOf(i) + 8 * lane);
            __m512d u = _mm512_loadu_pd(v);
            const __m512d acceleration = _mm512_sub_pd(
                _mm512_add_pd(_mm512_div_pd(f, mass), gravity[lane]), _mm512_mul_pd(damping, u));
            u = _mm512_add_pd(u, _mm512_mul_pd(h, acceleration));
            if constexpr (kMixed) u = _mm512_mask_blend_pd(held[lane], u, prescribed[lane]);
            _mm512_storeu_pd(v, u);
            const __m512d to = _mm512_add_pd(_mm512_loadu_pd(x), _mm512_mul_pd(dt, u));
            _mm512_storeu_pd(x, to);
            if constexpr (kFloor)
                below |= _mm512_mask_cmp_pd_mask(__mmask8(kZLanes[lane] & ~held[lane]), to, floor,
                                                 _CMP_NGE_UQ);
            vel[lane] = u;
        }
    }
};

// One mass for the sheet (its 8 bytes a particle not streamed: 10^6 particles, interleaved,
// crack_path_sources, linear law, 13.86 -> 13.51 ns, power law 15.68 -> 15.32) and a floor are
// constants of the loop.
template <bool kOne, bool kFloor>
[[gnu::target("avx2,avx512f")]] int kickOctetsAvx512(const KickDrift& input, int begin, int end,
                                                     bool& belowFloor) {
    KickOctetsAvx512<kOne, kFloor> kick(input);
    int i = begin;
    for (; i + 8 <= end; i += 8) {
        __m512d vel[3];
        if (allFree(kick.k.constraint + i, 8))
            kick.template octet<false>(i, vel);
        else
            kick.template octet<true>(i, vel);
    }
    belowFloor = belowFloor || kick.below != 0;
    return i;
}

int kickDriftAvx512(const KickDrift& k, int begin, int end, bool& belowFloor) {
    const bool one = k.oneMass > 0.0, floor = k.floor != -std::numeric_limits<double>::infinity();
    if (floor)
        return one ? kickOctetsAvx512<true, true>(k, begin, end, belowFloor)
                   : kickOctetsAvx512<false, true>(k, begin, end, belowFloor);
    return one ? kickOctetsAvx512<true, false>(k, begin, end, belowFloor)
               : kickOctetsAvx512<false, false>(k, begin, end, belowFloor);
}

// Four particles at a time, lane k the scalar loop's chain k (guardScalar's): the same bits.
// A quad with a particle that is not free takes each lane's terms by its tag, from blends. The
// scalar loop had 0.12 of a step's cpu-clock samples on one Zen 3 core (crack_path_sources at
// 10^4, linear law), this one 0.05. One mass for the sheet (kOne) and gravity (kGravity) are
// constants of the loop, and the lanes' indices a vector that moves on by four: a branch on
// each, and the index converted and broadcast, were 10 of a quad's 58 instructions
// (scripts/bench_instructions.sh).
/// The four chains of guardQuadsAvx2, a quad at a time from `begin`: a free quad's velocities in
/// lanes (free()), a quad with a particle that is not free (mixed()), the tail and the totals
/// (finish()).
template <bool kOne, bool kGravity>
struct GuardQuadsAvx2 {
    const GuardInput& g;
    GuardSums s;
    GuardPart p[4];
    __m256d half, limit, gx, gy, gz, sign, four, oneMass, halfOneMass;
    __m256d kinetic, gravityPower, boundaryPower, best, bestAt, at;  // bestAt, at: exact indices

    [[gnu::target("avx2")]] GuardQuadsAvx2(const GuardInput& input, int begin) : g(input) {
        half = _mm256_set1_pd(0.5), limit = _mm256_set1_pd(g.limitSquared);
        gx = _mm256_set1_pd(g.gravity[0]), gy = _mm256_set1_pd(g.gravity[1]);
        gz = _mm256_set1_pd(g.gravity[2]), sign = _mm256_set1_pd(-0.0);
        four = _mm256_set1_pd(4.0), oneMass = _mm256_set1_pd(g.oneMass);
        halfOneMass = _mm256_mul_pd(half, oneMass);
        kinetic = gravityPower = boundaryPower = best = _mm256_setzero_pd();
        bestAt = _mm256_set1_pd(-1.0);
        at = _mm256_add_pd(_mm256_set1_pd(double(begin)), _mm256_setr_pd(0.0, 1.0, 2.0, 3.0));
    }
    /// Free particles i to i + 3, whose lanes are `at` (then moved on by four).
    [[gnu::always_inline, gnu::target("avx2")]] void free(__m256d vx, __m256d vy, __m256d vz,
                                                          int i) {
        visit<false>(vx, vy, vz, i, _mm256_setzero_pd());
    }
    /// Particles i to i + 3, some pinned or driven (guardVisit's terms by each lane's tag): the
    /// driven add |f . v| to their chain's boundary power, the free as free().
    [[gnu::always_inline, gnu::target("avx2")]] void mixed(__m256d vx, __m256d vy, __m256d vz,
                                                           int i) {
        const __m256i tags = _mm256_cvtepi16_epi64(
            _mm_loadl_epi64(reinterpret_cast<const __m128i*>(g.constraint + i)));
        const __m256i freeTag = _mm256_set1_epi64x(kFree);
        const __m256d free = _mm256_castsi256_pd(_mm256_cmpeq_epi64(tags, freeTag));
        const __m256d driven = _mm256_castsi256_pd(_mm256_cmpgt_epi64(tags, freeTag));
        __m256d fx, fy, fz;
        loadRun4(g.force + 3 * std::size_t(i), fx, fy, fz);
        const __m256d power = _mm256_andnot_pd(
            sign, _mm256_add_pd(_mm256_add_pd(_mm256_mul_pd(fx, vx), _mm256_mul_pd(fy, vy)),
                                _mm256_mul_pd(fz, vz)));
        boundaryPower =
            _mm256_blendv_pd(boundaryPower, _mm256_add_pd(boundaryPower, power), driven);
        visit<true>(vx, vy, vz, i, free);
    }
    /// sum + term; with kMixed only in the lanes of `free` (a blend: adding 0 to -0.0 is +0.0).
    template <bool kMixed>
    [[gnu::always_inline, gnu::target("avx2")]] static __m256d addWhere(__m256d sum, __m256d term,
                                                                        __m256d free) {
        const __m256d more = _mm256_add_pd(sum, term);
        return kMixed ? _mm256_blendv_pd(sum, more, free) : more;
    }
    /// With kMixed, only the lanes of `free` are free.
    template <bool kMixed>
    [[gnu::always_inline, gnu::target("avx2")]] void visit(__m256d vx, __m256d vy, __m256d vz,
                                                           int i, __m256d free) {
        const __m256d ss = _mm256_add_pd(
            _mm256_add_pd(_mm256_mul_pd(vx, vx), _mm256_mul_pd(vy, vy)), _mm256_mul_pd(vz, vz));
        const int bad = _mm256_movemask_pd(_mm256_cmp_pd(ss, limit, _CMP_NLE_UQ));
        if (bad != 0 && s.firstBad < 0) s.firstBad = i + __builtin_ctz(unsigned(bad));
        const __m256d m = kOne ? oneMass : _mm256_loadu_pd(g.mass + i);
        const __m256d halfMass = kOne ? halfOneMass : _mm256_mul_pd(half, m);
        kinetic = addWhere<kMixed>(kinetic, _mm256_mul_pd(halfMass, ss), free);
        if constexpr (kGravity) {
            const __m256d along = _mm256_add_pd(
                _mm256_add_pd(_mm256_mul_pd(gx, vx), _mm256_mul_pd(gy, vy)), _mm256_mul_pd(gz, vz));
            gravityPower = addWhere<kMixed>(gravityPower,
                                            _mm256_mul_pd(m, _mm256_andnot_pd(sign, along)), free);
        }
        __m256d faster = _mm256_cmp_pd(ss, best, _CMP_GT_OQ);
        if constexpr (kMixed) faster = _mm256_and_pd(faster, free);
        // ss > best ? ss : best, a NaN keeping best: max's bits, the blend's only where held
        // lanes are left out.
        best = kMixed ? _mm256_blendv_pd(best, ss, faster) : _mm256_max_pd(ss, best);
        bestAt = _mm256_blendv_pd(bestAt, at, faster);
        at = _mm256_add_pd(at, four);
    }
    /// Particles [i, end) one by one into chain 0, then the chains' totals.
    [[gnu::target("avx2")]] GuardSums finish(int i, int end) {
        double k[4], w[4], b[4], speeds[4], lanes[4];
        _mm256_storeu_pd(k, kinetic), _mm256_storeu_pd(w, gravityPower);
        _mm256_storeu_pd(b, boundaryPower);
        _mm256_storeu_pd(speeds, best), _mm256_storeu_pd(lanes, bestAt);
        for (int l = 0; l < 4; ++l)
            p[l].kinetic = k[l], p[l].gravityPower = w[l], p[l].boundaryPower = b[l];
        for (; i < end; ++i) guardVisit(g, i, p[0], s);
        addChains(p, s);
        for (int l = 0; l < 4; ++l) {
            const bool higher = speeds[l] > s.maxSpeedSquared;
            const bool tie = speeds[l] == s.maxSpeedSquared && int(lanes[l]) < s.fastest;
            if (lanes[l] >= 0.0 && (higher || tie))
                s.maxSpeedSquared = speeds[l], s.fastest = int(lanes[l]);
        }
        return s;
    }
};

template <bool kOne, bool kGravity>
[[gnu::target("avx2")]] GuardSums guardQuadsAvx2(const GuardInput& g, int begin, int end) {
    GuardQuadsAvx2<kOne, kGravity> chains(g, begin);
    int i = begin;
    for (; i + 4 <= end; i += 4) {
        __m256d vx, vy, vz;
        loadRun4(g.v + 3 * std::size_t(i), vx, vy, vz);
        if (allFree(g.constraint + i, 4))
            chains.free(vx, vy, vz, i);
        else
            chains.mixed(vx, vy, vz, i);
    }
    return chains.finish(i, end);
}

// The kick and drift of a block and the blow-up guard's sums of it in one loop (kickDriftSampled):
// each free quad's new velocities split into lanes from the registers the kick stored them from,
// not loaded again; the kick's and the guard's quads from the same `begin`, so the same chains.
template <bool kOne, bool kFloor, bool kGravity>
[[gnu::target("avx2")]] GuardSums kickGuardQuadsAvx2(const KickDrift& input, const GuardInput& g,
                                                     int begin, int end, bool& belowFloor) {
    KickQuadsAvx2<kOne, kFloor> kick(input);
    GuardQuadsAvx2<kOne, kGravity> chains(g, begin);
    bool below = false;
    int i = begin;
    for (; i + 4 <= end; i += 4) {
        __m256d vel[3], vx, vy, vz;
        if (allFree(kick.k.constraint + i, 4)) {
            kick.free(i, vel);
            splitRun4(vel[0], vel[1], vel[2], vx, vy, vz);
            chains.free(vx, vy, vz, i);
        } else {
            kick.mixed(i, vel);
            splitRun4(vel[0], vel[1], vel[2], vx, vy, vz);
            chains.mixed(vx, vy, vz, i);
        }
    }
    for (int p = i; p < end; ++p) below |= kickDriftOne(kick.k, p);
    belowFloor = belowFloor || below || kick.below();
    return chains.finish(i, end);
}

GuardSums guardAvx2(const GuardInput& g, int begin, int end) {
    const bool one = g.oneMass > 0.0;
    if (g.hasGravity)
        return one ? guardQuadsAvx2<true, true>(g, begin, end)
                   : guardQuadsAvx2<false, true>(g, begin, end);
    return one ? guardQuadsAvx2<true, false>(g, begin, end)
               : guardQuadsAvx2<false, false>(g, begin, end);
}

// Four at a time; NaN and inf are bad (not <= the largest double), a NaN lane keeps the max.
[[gnu::target("avx2")]] GuardSums guardThetaAvx2(const double* theta, int begin, int end) {
    GuardSums s;
    const __m256d finite = _mm256_set1_pd(std::numeric_limits<double>::max());
    const __m256d sign = _mm256_set1_pd(-0.0);
    __m256d largest = _mm256_setzero_pd();
    int i = begin;
    for (; i + 4 <= end; i += 4) {
        const __m256d a = _mm256_andnot_pd(sign, _mm256_loadu_pd(theta + i));
        const int bad = _mm256_movemask_pd(_mm256_cmp_pd(a, finite, _CMP_NLE_UQ));
        if (bad != 0 && s.firstBad < 0) s.firstBad = i + __builtin_ctz(unsigned(bad));
        largest = _mm256_max_pd(a, largest);
    }
    for (; i < end; ++i) guardVisitTheta(theta, i, s);
    double lanes[4];
    _mm256_storeu_pd(lanes, largest);
    for (const double l : lanes) s.maxAbsTheta = std::max(s.maxAbsTheta, l);
    return s;
}

/// Eight lanes' sums, added pairwise in lane order.
[[gnu::target("avx2,avx512f")]] inline double laneSum(__m512d a) {
    double l[8];
    _mm512_storeu_pd(l, a);
    return ((l[0] + l[1]) + (l[2] + l[3])) + ((l[4] + l[5]) + (l[6] + l[7]));
}

/// Eight chains, one a lane, of eight particles at a time from `begin` (GuardQuadsAvx2's at eight
/// lanes): a free octet's velocities in lanes (free()), an octet with a particle that is not free
/// by each lane's tag (mixed()), then the tail one at a time in a chain of its own and the totals
/// (finish()). The lanes' largest speeds and their indices meet at the end, the lowest index
/// winning a tie.
template <bool kOne, bool kGravity>
struct GuardOctetsAvx512 {
    const GuardInput& g;
    GuardSums s;
    GuardPart p;
    __m512d half, limit, gx, gy, gz, oneMass, halfOneMass;
    __m512d kinetic, gravityPower, boundaryPower, best;
    __m512i bestAt, at;

    [[gnu::target("avx2,avx512f")]] GuardOctetsAvx512(const GuardInput& input, int begin)
        : g(input) {
        half = _mm512_set1_pd(0.5), limit = _mm512_set1_pd(g.limitSquared);
        gx = _mm512_set1_pd(g.gravity[0]), gy = _mm512_set1_pd(g.gravity[1]);
        gz = _mm512_set1_pd(g.gravity[2]);
        oneMass = _mm512_set1_pd(g.oneMass), halfOneMass = _mm512_mul_pd(half, oneMass);
        kinetic = gravityPower = boundaryPower = best = _mm512_setzero_pd();
        bestAt = _mm512_set1_epi64(-1);
        at = _mm512_add_epi64(_mm512_set1_epi64(begin), _mm512_setr_epi64(0, 1, 2, 3, 4, 5, 6, 7));
    }
    [[gnu::always_inline, gnu::target("avx2,avx512f")]] void free(__m512d vx, __m512d vy,
                                                                  __m512d vz, int i) {
        visit<false>(vx, vy, vz, i, 0xff);
    }
    /// Particles i to i + 7, some pinned or driven (guardVisit's terms by each lane's tag): the
    /// driven add |f . v| to their chain's boundary power, the free as free().
    [[gnu::always_inline, gnu::target("avx2,avx512f")]] void mixed(__m512d vx, __m512d vy,
                                                                   __m512d vz, int i) {
        const __m512i tags = _mm512_cvtepi16_epi64(
            _mm_loadu_si128(reinterpret_cast<const __m128i*>(g.constraint + i)));
        const __m512i freeTag = _mm512_set1_epi64(kFree);
        const __mmask8 free = _mm512_cmpeq_epi64_mask(tags, freeTag);
        const __mmask8 driven = _mm512_cmpgt_epi64_mask(tags, freeTag);
        __m512d fx, fy, fz;
        loadRun8(g.force + 3 * std::size_t(i), fx, fy, fz);
        const __m512d power = _mm512_abs_pd(_mm512_add_pd(
            _mm512_add_pd(_mm512_mul_pd(fx, vx), _mm512_mul_pd(fy, vy)), _mm512_mul_pd(fz, vz)));
        boundaryPower = _mm512_mask_add_pd(boundaryPower, driven, boundaryPower, power);
        visit<true>(vx, vy, vz, i, free);
    }
    /// With kMixed, only the lanes of `free` are free.
    template <bool kMixed>
    [[gnu::always_inline, gnu::target("avx2,avx512f")]] void visit(__m512d vx, __m512d vy,
                                                                   __m512d vz, int i,
                                                                   __mmask8 free) {
        const __m512d ss = _mm512_add_pd(
            _mm512_add_pd(_mm512_mul_pd(vx, vx), _mm512_mul_pd(vy, vy)), _mm512_mul_pd(vz, vz));
        const unsigned bad = _mm512_cmp_pd_mask(ss, limit, _CMP_NLE_UQ);
        if (bad != 0 && s.firstBad < 0) s.firstBad = i + __builtin_ctz(bad);
        const __m512d m = kOne ? oneMass : _mm512_loadu_pd(g.mass + i);
        const __m512d energy = _mm512_mul_pd(kOne ? halfOneMass : _mm512_mul_pd(half, m), ss);
        kinetic = kMixed ? _mm512_mask_add_pd(kinetic, free, kinetic, energy)
                         : _mm512_add_pd(kinetic, energy);
        if constexpr (kGravity) {
            const __m512d along = _mm512_add_pd(
                _mm512_add_pd(_mm512_mul_pd(gx, vx), _mm512_mul_pd(gy, vy)), _mm512_mul_pd(gz, vz));
            const __m512d power = _mm512_mul_pd(m, _mm512_abs_pd(along));
            gravityPower = kMixed ? _mm512_mask_add_pd(gravityPower, free, gravityPower, power)
                                  : _mm512_add_pd(gravityPower, power);
        }
        const __mmask8 faster = _mm512_mask_cmp_pd_mask(free, ss, best, _CMP_GT_OQ);
        best = _mm512_mask_blend_pd(faster, best, ss);
        bestAt = _mm512_mask_blend_epi64(faster, bestAt, at);
        at = _mm512_add_epi64(at, _mm512_set1_epi64(8));
    }
    /// Particles [i, end) one by one into a chain of their own, then the totals.
    [[gnu::target("avx2,avx512f")]] GuardSums finish(int i, int end) {
        for (; i < end; ++i) guardVisit(g, i, p, s);
        s.kinetic = laneSum(kinetic) + p.kinetic;
        s.gravityPower = laneSum(gravityPower) + p.gravityPower;
        s.boundaryPower = laneSum(boundaryPower) + p.boundaryPower;
        double speeds[8];
        std::int64_t lanes[8];
        _mm512_storeu_pd(speeds, best);
        _mm512_storeu_si512(lanes, bestAt);
        for (int l = 0; l < 8; ++l) {
            const bool higher = speeds[l] > s.maxSpeedSquared;
            const bool tie = speeds[l] == s.maxSpeedSquared && lanes[l] < s.fastest;
            if (lanes[l] >= 0 && (higher || tie))
                s.maxSpeedSquared = speeds[l], s.fastest = int(lanes[l]);
        }
        return s;
    }
};

template <bool kOne, bool kGravity>
[[gnu::target("avx2,avx512f")]] GuardSums guardOctetsAvx512(const GuardInput& g, int begin,
                                                            int end) {
    GuardOctetsAvx512<kOne, kGravity> chains(g, begin);
    int i = begin;
    for (; i + 8 <= end; i += 8) {
        __m512d vx, vy, vz;
        loadRun8(g.v + 3 * std::size_t(i), vx, vy, vz);
        if (allFree(g.constraint + i, 8))
            chains.free(vx, vy, vz, i);
        else
            chains.mixed(vx, vy, vz, i);
    }
    return chains.finish(i, end);
}

GuardSums guardAvx512(const GuardInput& g, int begin, int end) {
    const bool one = g.oneMass > 0.0;
    if (g.hasGravity)
        return one ? guardOctetsAvx512<true, true>(g, begin, end)
                   : guardOctetsAvx512<false, true>(g, begin, end);
    return one ? guardOctetsAvx512<true, false>(g, begin, end)
               : guardOctetsAvx512<false, false>(g, begin, end);
}

/// How far ahead the eight-lane kick asks for the velocities (an address, not a pointer: past
/// the array's end a prefetch does nothing).
constexpr int kVelocitiesAhead = 256;

// The kick and drift of a block and the guard's sums of it in one loop, at eight lanes
// (kickGuardQuadsAvx2's): each octet's new velocities split into lanes from registers.
template <bool kOne, bool kFloor, bool kGravity>
[[gnu::target("avx2,avx512f")]] GuardSums kickGuardOctetsAvx512(const KickDrift& input,
                                                                const GuardInput& g, int begin,
                                                                int end, bool& belowFloor) {
    KickOctetsAvx512<kOne, kFloor> kick(input);
    GuardOctetsAvx512<kOne, kGravity> chains(g, begin);
    int i = begin;
    for (; i + 8 <= end; i += 8) {
        // The velocities kVelocitiesAhead particles on, asked for now (sim/PairKernelSimd.inc's
        // prefetchPositions: the force pass leaves them to the kick).
        const std::uintptr_t ahead =
            std::uintptr_t(kick.k.v) + 24 * (std::size_t(i) + kVelocitiesAhead);
        for (int line = 0; line < 3; ++line)
            __builtin_prefetch(reinterpret_cast<const void*>(ahead + 64 * line), 1);
        __m512d vel[3], vx, vy, vz;
        if (allFree(kick.k.constraint + i, 8)) {
            kick.template octet<false>(i, vel);
            splitRun8(vel[0], vel[1], vel[2], vx, vy, vz);
            chains.free(vx, vy, vz, i);
        } else {
            kick.template octet<true>(i, vel);
            splitRun8(vel[0], vel[1], vel[2], vx, vy, vz);
            chains.mixed(vx, vy, vz, i);
        }
    }
    bool below = false;
    for (int q = i; q < end; ++q) below |= kickDriftOne(kick.k, q);
    belowFloor = belowFloor || below || kick.below != 0;
    return chains.finish(i, end);
}

/// loop.operator()<kOne, kFloor, kGravity>() for the kick's one mass and floor and the guard's
/// gravity: the constants of kickGuardQuadsAvx2's and kickGuardOctetsAvx512's loops.
template <class Loop>
GuardSums withLoopConstants(const KickDrift& k, const GuardInput& g, Loop&& loop) {
    const auto gravity = [&]<bool kOne, bool kFloor>() {
        return g.hasGravity ? loop.template operator()<kOne, kFloor, true>()
                            : loop.template operator()<kOne, kFloor, false>();
    };
    const auto floor = [&]<bool kOne>() {
        return k.floor != -std::numeric_limits<double>::infinity()
                   ? gravity.template operator()<kOne, true>()
                   : gravity.template operator()<kOne, false>();
    };
    return k.oneMass > 0.0 ? floor.template operator()<true>() : floor.template operator()<false>();
}

// Eight at a time; NaN and inf are bad (not <= the largest double), a NaN lane keeps the max.
[[gnu::target("avx2,avx512f")]] GuardSums guardThetaAvx512(const double* theta, int begin,
                                                           int end) {
    GuardSums s;
    const __m512d finite = _mm512_set1_pd(std::numeric_limits<double>::max());
    __m512d largest = _mm512_setzero_pd();
    int i = begin;
    for (; i + 8 <= end; i += 8) {
        const __m512d a = _mm512_abs_pd(_mm512_loadu_pd(theta + i));
        const unsigned bad = _mm512_cmp_pd_mask(a, finite, _CMP_NLE_UQ);
        if (bad != 0 && s.firstBad < 0) s.firstBad = i + __builtin_ctz(bad);
        largest = _mm512_max_pd(a, largest);
    }
    for (; i < end; ++i) guardVisitTheta(theta, i, s);
    double lanes[8];
    _mm512_storeu_pd(lanes, largest);
    for (const double l : lanes) s.maxAbsTheta = std::max(s.maxAbsTheta, l);
    return s;
}

#endif

}  // namespace

GuardSums guardMotionSums(const GuardInput& g, int begin, int end) {
#if defined(__x86_64__)
    if (simdWidth() == 8) return guardAvx512(g, begin, end);
    if (simdWidth() == 4) return guardAvx2(g, begin, end);
#endif
    return guardScalar(g, begin, end);
}

GuardSums guardThetaSums(const double* theta, int begin, int end) {
#if defined(__x86_64__)
    if (simdWidth() == 8) return guardThetaAvx512(theta, begin, end);
    if (simdWidth() == 4) return guardThetaAvx2(theta, begin, end);
#endif
    return guardThetaScalar(theta, begin, end);
}

void addThetaSums(GuardSums& motion, const GuardSums& theta) {
    motion.maxAbsTheta = std::max(motion.maxAbsTheta, theta.maxAbsTheta);
    if (theta.firstBad >= 0 && (motion.firstBad < 0 || theta.firstBad < motion.firstBad))
        motion.firstBad = theta.firstBad;
}

GuardSums guardSums(const GuardInput& g, int begin, int end) {
    GuardSums s = guardMotionSums(g, begin, end);
    if (g.theta) addThetaSums(s, guardThetaSums(g.theta, begin, end));
    return s;
}

int simdWidth() {
    static const int width = [] {
        const char* cap = std::getenv("REND_SIMD");
        const std::string_view wanted = cap ? cap : "";
        int lanes = 1;
#if defined(__x86_64__)
        // AVX2 with fused multiply-adds (eq. 20's e^x takes them; every AVX2 CPU but a few VIA).
        const bool fma = __builtin_cpu_supports("fma");
        if (__builtin_cpu_supports("avx2") && fma) lanes = 4;
        // AVX-512 with byte masks and bit extraction (every AVX-512 CPU but Xeon Phi).
        if (__builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512bw") &&
            __builtin_cpu_supports("bmi2") && fma)
            lanes = 8;
#endif
        if (wanted == "scalar") return 1;
        if (wanted == "avx2") return std::min(lanes, 4);
        return lanes;
    }();
    return width;
}

bool kickDrift(const KickDrift& k, int begin, int end) {
    bool below = false;
#if defined(__x86_64__)
    if (simdWidth() == 8)
        begin = kickDriftAvx512(k, begin, end, below);
    else if (simdWidth() == 4)
        begin = kickDriftAvx2(k, begin, end, below);
#endif
    for (int i = begin; i < end; ++i) below |= kickDriftOne(k, i);
    // No floor (-inf): nothing is below it, whatever its height (the four-lane loop does not ask).
    return below && k.floor != -std::numeric_limits<double>::infinity();
}

GuardSums kickDriftSampled(const KickDrift& k, const GuardInput& g, int begin, int end,
                           bool& below) {
#if defined(__x86_64__)
    // One loop where both read the same velocities and agree on one mass.
    if (simdWidth() >= 4 && g.v == k.v && g.oneMass == k.oneMass) {
        bool under = false;
        const bool wide = simdWidth() == 8;
        const GuardSums s = withLoopConstants(k, g, [&]<bool kOne, bool kFloor, bool kGravity>() {
            return wide ? kickGuardOctetsAvx512<kOne, kFloor, kGravity>(k, g, begin, end, under)
                        : kickGuardQuadsAvx2<kOne, kFloor, kGravity>(k, g, begin, end, under);
        });
        below = under && k.floor != -std::numeric_limits<double>::infinity();
        return s;
    }
#endif
    below = kickDrift(k, begin, end);
    return guardMotionSums(g, begin, end);
}

}  // namespace rend::sim
