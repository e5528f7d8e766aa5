// The float test that the own primitives (sphere_lanes.h, quad_lanes.h) run
// first, to skip a primitive no lane of a packet comes near (and the
// packet in double for their exact tests): the squared
// distance of each lane's line from a bounding sphere's centre against its
// radius, with a margin of some hundred float steps of the coordinates (the
// exact test in double decides). Written once as always_inline bodies so that
// each caller's per-instruction-set functions compile it for their own set.
#pragma once

#include <cmath>
#include <cstdint>

#include <immintrin.h>

namespace lc::lanes {

// Which instruction set a kernel body is compiled for: any_set's test of a
// row of flags differs by set (the rest of a body is plain lane loops).
struct PortableSet {};
struct Avx2Set {};
struct Avx512Set {};

// Whether any of N (a multiple of 16) int flags is nonzero. As an OR over a
// loop GCC reduces the lanes with a chain of shuffles before the branch that
// waits on it (a third of the own quads' closest test, perf); a whole-row
// test is one instruction per 8 or 16 flags. Each overload only inlines into
// bodies compiled for its set.
template <int N>
[[gnu::always_inline]] inline bool any_set(PortableSet, const int* flags) {
    int any = 0;
    for (int i = 0; i < N; ++i) any |= flags[i];
    return any != 0;
}
template <int N>
[[gnu::target("avx2")]] inline bool any_set(Avx2Set, const int* flags) {
    __m256i any = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(flags));
    for (int i = 8; i < N; i += 8)
        any = _mm256_or_si256(any, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(flags + i)));
    return !_mm256_testz_si256(any, any);
}
template <int N>
[[gnu::target("avx512f")]] inline bool any_set(Avx512Set, const int* flags) {
    __m512i any = _mm512_loadu_si512(flags);
    for (int i = 16; i < N; i += 16) any = _mm512_or_si512(any, _mm512_loadu_si512(flags + i));
    return _mm512_test_epi32_mask(any, any) != 0;
}

// Bit i set where flags[i] (i < 16) is nonzero. As a loop of (flag << i)
// ORed together GCC built a vector of bits and reduced it with shuffles (a
// third of near_capsule, perf); AVX-512 compares straight into a bit mask.
[[gnu::always_inline]] inline uint32_t bits_set(PortableSet, const int* flags) {
    uint32_t bits = 0;
    for (int i = 0; i < 16; ++i) bits |= flags[i] != 0 ? uint32_t(1) << i : 0u;
    return bits;
}
[[gnu::target("avx2")]] inline uint32_t bits_set(Avx2Set, const int* flags) {
    const __m256i zero = _mm256_setzero_si256();
    uint32_t bits = 0;
    for (int h = 0; h < 2; ++h) {
        const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(flags + 8 * h));
        const __m256i is_zero = _mm256_cmpeq_epi32(v, zero);
        bits |= uint32_t(~_mm256_movemask_ps(_mm256_castsi256_ps(is_zero)) & 0xff) << (8 * h);
    }
    return bits;
}
[[gnu::target("avx512f")]] inline uint32_t bits_set(Avx512Set, const int* flags) {
    const __m512i v = _mm512_loadu_si512(flags);
    return uint32_t(_mm512_test_epi32_mask(v, v));
}

// out[i] = flags[i] for i < 16, in one or two widening loads (as a loop GCC
// wrote sixteen narrow stores, which the next wide load waited on).
[[gnu::always_inline]] inline void widen_flags(PortableSet, const bool* flags, int* out) {
    for (int i = 0; i < 16; ++i) out[i] = flags[i];
}
[[gnu::target("avx2")]] inline void widen_flags(Avx2Set, const bool* flags, int* out) {
    const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(flags));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out), _mm256_cvtepu8_epi32(bytes));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + 8), _mm256_cvtepu8_epi32(_mm_srli_si128(bytes, 8)));
}
[[gnu::target("avx512f")]] inline void widen_flags(Avx512Set, const bool* flags, int* out) {
    // maskz: the plain form trips GCC 12's -Wuninitialized in its own header
    const __m128i bytes = _mm_loadu_si128(reinterpret_cast<const __m128i*>(flags));
    _mm512_storeu_si512(out, _mm512_maskz_cvtepu8_epi32(__mmask16(0xffff), bytes));
}

// Whether a lane may meet the sphere c (centre xyz, radius) anywhere on its
// line; NaN keeps the lane. Returns whether any lane may.
template <int N, class Set>
[[gnu::always_inline]] inline bool near_line(Set set, const float* c, const float* const origin[3],
                                             const float* const direction[3], const float* inv_dd,
                                             const float* origin_size, const int* active) {
    float centre_size = 1.0f;
    for (int a = 0; a < 4; ++a) centre_size = std::fabs(c[a]) > centre_size ? std::fabs(c[a]) : centre_size;
    alignas(64) int near[N];
    for (int i = 0; i < N; ++i) {
        const float dx = direction[0][i], dy = direction[1][i], dz = direction[2][i];
        const float fx = origin[0][i] - c[0], fy = origin[1][i] - c[1], fz = origin[2][i] - c[2];
        const float s = (fx * dx + fy * dy + fz * dz) * inv_dd[i];
        const float px = fx - s * dx, py = fy - s * dy, pz = fz - s * dz;
        const float reach = c[3] * (1.0f + 1e-5f) + 1e-5f * (centre_size + origin_size[i]);
        // & not &&: a branch per lane keeps GCC from running the lanes side by side
        near[i] = -int((active[i] != 0) & !(px * px + py * py + pz * pz > reach * reach));
    }
    return any_set<N>(set, near);
}

// The largest of v[0..16) (v is overwritten), halving with fixed widths:
// GCC runs each step in lanes, where a running maximum stayed scalar.
[[gnu::always_inline]] inline float largest_of_16(float (&v)[16]) {
    for (int i = 0; i < 8; ++i) v[i] = v[i + 8] > v[i] ? v[i + 8] : v[i];
    for (int i = 0; i < 4; ++i) v[i] = v[i + 4] > v[i] ? v[i + 4] : v[i];
    for (int i = 0; i < 2; ++i) v[i] = v[i + 2] > v[i] ? v[i + 2] : v[i];
    return v[1] > v[0] ? v[1] : v[0];
}

// Per lane: 1 / |d|^2 and the largest origin coordinate, which near_line takes.
template <int N>
[[gnu::always_inline]] inline void lane_scales(const float* const origin[3], const float* const direction[3],
                                               float* inv_dd, float* origin_size) {
    for (int i = 0; i < N; ++i) {
        inv_dd[i] = 1.0f / (direction[0][i] * direction[0][i] + direction[1][i] * direction[1][i] +
                            direction[2][i] * direction[2][i]);
        const float x = std::fabs(origin[0][i]), y = std::fabs(origin[1][i]), z = std::fabs(origin[2][i]);
        // Two plain selects, the same result as x > y ? (x > z ? x : z) :
        // (y > z ? y : z) for every input: nested, GCC left them scalar.
        const float xy = x > y ? x : y;
        origin_size[i] = xy > z ? xy : z;
    }
}

// A packet's float origins and directions in double, converted once for
// all the primitives the exact tests (in double) take it through, and only
// when a primitive first needs them (load_once): most packets pass none of
// the spheres' culls, and the conversion is a dozen vector stores and loads.
template <int N>
struct DoubleLanes {
    double o[3][N], d[3][N];
    bool loaded = false;
    [[gnu::always_inline]] void load_once(const float* const origin[3], const float* const direction[3]) {
        if (loaded) return;
        for (int a = 0; a < 3; ++a)
            for (int i = 0; i < N; ++i) o[a][i] = origin[a][i], d[a][i] = direction[a][i];
        loaded = true;
    }
};

}  // namespace lc::lanes
