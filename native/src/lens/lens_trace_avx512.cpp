// The batch lens trace and aim on AVX-512: sixteen lanes as two registers of
// eight, masks in mask registers. The same templates as the AVX2 kernel
// (lens_trace_lanes.h, lens_aim_lanes.h), half the instructions for
// everything but the square roots and divisions. (The two-register wrapper
// mirrors the AVX2 one by shape; only the intrinsics differ.)
#include <immintrin.h>

#include <cstdint>

#include "lens/lens_aim.h"
#include "lens/lens_trace.h"  // before the target pragma: its inline functions stay portable

#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq")

namespace lc::avx512 {

// Sixteen lanes as two registers, every operation issued for both halves
// back to back, so that two dependency chains overlap.
struct M16 {
    __mmask8 lo, hi;

    static M16 load(const bool* p) {
        unsigned bits = 0;
        for (int i = 0; i < 16; ++i) bits |= unsigned(p[i]) << i;
        return {__mmask8(bits & 0xff), __mmask8(bits >> 8)};
    }
    void store(bool* p) const {
        const unsigned bits = unsigned(lo) | (unsigned(hi) << 8);
        for (int i = 0; i < 16; ++i) p[i] = (bits >> i) & 1;
    }
};

struct D16 {
    static constexpr int kLanes = 16;
    using Scalar = double;
    __m512d lo, hi;

    D16() = default;
    D16(__m512d l, __m512d h) : lo(l), hi(h) {}
    explicit D16(double x) : lo(_mm512_set1_pd(x)), hi(lo) {}
    static D16 load(const double* p) { return {_mm512_loadu_pd(p), _mm512_loadu_pd(p + 8)}; }
    void store(double* p) const { _mm512_storeu_pd(p, lo), _mm512_storeu_pd(p + 8, hi); }
};

inline D16 operator+(D16 a, D16 b) { return {_mm512_add_pd(a.lo, b.lo), _mm512_add_pd(a.hi, b.hi)}; }
inline D16 operator-(D16 a, D16 b) { return {_mm512_sub_pd(a.lo, b.lo), _mm512_sub_pd(a.hi, b.hi)}; }
inline D16 operator*(D16 a, D16 b) { return {_mm512_mul_pd(a.lo, b.lo), _mm512_mul_pd(a.hi, b.hi)}; }
inline D16 operator/(D16 a, D16 b) { return {_mm512_div_pd(a.lo, b.lo), _mm512_div_pd(a.hi, b.hi)}; }
inline D16 operator-(D16 a) {
    const __m512d sign = _mm512_set1_pd(-0.0);
    return {_mm512_xor_pd(a.lo, sign), _mm512_xor_pd(a.hi, sign)};
}
inline D16 sqrt(D16 a) { return {_mm512_sqrt_pd(a.lo), _mm512_sqrt_pd(a.hi)}; }
inline D16 abs(D16 a) {
    const __m512d sign = _mm512_set1_pd(-0.0);
    return {_mm512_andnot_pd(sign, a.lo), _mm512_andnot_pd(sign, a.hi)};
}
// |magnitude| with the sign of sign
inline D16 copysign(D16 magnitude, D16 sign) {
    const __m512d bit = _mm512_set1_pd(-0.0);
    return {_mm512_or_pd(_mm512_andnot_pd(bit, magnitude.lo), _mm512_and_pd(bit, sign.lo)),
            _mm512_or_pd(_mm512_andnot_pd(bit, magnitude.hi), _mm512_and_pd(bit, sign.hi))};
}
// a * b + c, rounded twice as the scalar trace does
inline D16 mul_add(D16 a, D16 b, D16 c) { return a * b + c; }
// a > b ? a : b, as the C++ ternary
inline D16 max(D16 a, D16 b) { return {_mm512_max_pd(a.lo, b.lo), _mm512_max_pd(a.hi, b.hi)}; }

template <int kPredicate>
inline M16 compare(D16 a, D16 b) {
    return {_mm512_cmp_pd_mask(a.lo, b.lo, kPredicate), _mm512_cmp_pd_mask(a.hi, b.hi, kPredicate)};
}
inline M16 operator<(D16 a, D16 b) { return compare<_CMP_LT_OQ>(a, b); }
inline M16 operator>(D16 a, D16 b) { return compare<_CMP_GT_OQ>(a, b); }
inline M16 operator>=(D16 a, D16 b) { return compare<_CMP_GE_OQ>(a, b); }
inline M16 operator!=(D16 a, D16 b) { return compare<_CMP_NEQ_UQ>(a, b); }
inline M16 not_greater(D16 a, D16 b) { return compare<_CMP_NGT_UQ>(a, b); }

inline M16 operator&(M16 a, M16 b) { return {__mmask8(a.lo & b.lo), __mmask8(a.hi & b.hi)}; }
inline M16 operator|(M16 a, M16 b) { return {__mmask8(a.lo | b.lo), __mmask8(a.hi | b.hi)}; }
inline bool any(M16 m) { return (m.lo | m.hi) != 0; }
// m ? a : b
inline D16 select(M16 m, D16 a, D16 b) {
    return {_mm512_mask_blend_pd(m.lo, b.lo, a.lo), _mm512_mask_blend_pd(m.hi, b.hi, a.hi)};
}

}  // namespace lc::avx512

#include "lens/lens_aim_lanes.h"
#include "lens/lens_trace_lanes.h"

namespace lc {

void trace_from_film_batch_avx512(const std::vector<LensElement>& elements, LensRayBatch* b) {
    trace_from_film_lanes<avx512::D16, avx512::M16, false>(elements.data(), elements.size(),
                                                            LaneGlass{nullptr, nullptr}, b);
}

void trace_from_film_batch_avx512(const std::vector<LensElement>& elements, LaneGlass glass, LensRayBatch* b) {
    trace_from_film_lanes<avx512::D16, avx512::M16, true>(elements.data(), elements.size(), glass, b);
}

void aim_batch_avx512(const LensAimBatch& in, AimPlanes planes, LensRayBatch* out) {
    aim_lanes<avx512::D16, avx512::M16>(in, planes, out);
}

}  // namespace lc

#pragma GCC pop_options
