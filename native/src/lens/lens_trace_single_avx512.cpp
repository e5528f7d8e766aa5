// The batch lens trace in single precision on AVX-512: the render loop's
// trace (lens_trace.h, LensTracePrecision). The template of
// lens_trace_lanes.h over thirty-two float lanes as two registers of sixteen,
// the whole batch in one group: twice the lanes of the double kernel per
// instruction, and float square roots and divisions cost the divider a
// fraction of double ones. The batch stays in double: lanes are rounded to
// float on the way in and widened on the way out.
#include <immintrin.h>

#include <cstdint>

#include "lens/lens_trace.h"  // before the target pragma: its inline functions stay portable

#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq")

namespace lc::avx512_single {

struct M32 {
    __mmask16 lo, hi;

    static M32 load(const bool* p) {
        uint32_t bits = 0;
        for (int i = 0; i < 32; ++i) bits |= uint32_t(p[i]) << i;
        return {__mmask16(bits & 0xffff), __mmask16(bits >> 16)};
    }
    void store(bool* p) const {
        const uint32_t bits = uint32_t(lo) | (uint32_t(hi) << 16);
        for (int i = 0; i < 32; ++i) p[i] = (bits >> i) & 1;
    }
};

struct F32 {
    static constexpr int kLanes = 32;
    using Scalar = float;
    __m512 lo, hi;

    F32() = default;
    F32(__m512 l, __m512 h) : lo(l), hi(h) {}
    explicit F32(double x) : lo(_mm512_set1_ps(float(x))), hi(lo) {}
    // Sixteen doubles rounded to float (round to nearest, as float(x)).
    static __m512 narrow(__m512d a, __m512d b) {
        return _mm512_insertf32x8(_mm512_castps256_ps512(_mm512_cvtpd_ps(a)), _mm512_cvtpd_ps(b), 1);
    }
    static F32 load(const double* p) {
        return {narrow(_mm512_loadu_pd(p), _mm512_loadu_pd(p + 8)),
                narrow(_mm512_loadu_pd(p + 16), _mm512_loadu_pd(p + 24))};
    }
    void store(double* p) const {
        _mm512_storeu_pd(p, _mm512_cvtps_pd(_mm512_castps512_ps256(lo)));
        _mm512_storeu_pd(p + 8, _mm512_cvtps_pd(_mm512_extractf32x8_ps(lo, 1)));
        _mm512_storeu_pd(p + 16, _mm512_cvtps_pd(_mm512_castps512_ps256(hi)));
        _mm512_storeu_pd(p + 24, _mm512_cvtps_pd(_mm512_extractf32x8_ps(hi, 1)));
    }
};

inline F32 operator+(F32 a, F32 b) { return {_mm512_add_ps(a.lo, b.lo), _mm512_add_ps(a.hi, b.hi)}; }
inline F32 operator-(F32 a, F32 b) { return {_mm512_sub_ps(a.lo, b.lo), _mm512_sub_ps(a.hi, b.hi)}; }
inline F32 operator*(F32 a, F32 b) { return {_mm512_mul_ps(a.lo, b.lo), _mm512_mul_ps(a.hi, b.hi)}; }
inline F32 operator/(F32 a, F32 b) { return {_mm512_div_ps(a.lo, b.lo), _mm512_div_ps(a.hi, b.hi)}; }
inline F32 operator-(F32 a) {
    const __m512 sign = _mm512_set1_ps(-0.0f);
    return {_mm512_xor_ps(a.lo, sign), _mm512_xor_ps(a.hi, sign)};
}
inline F32 sqrt(F32 a) { return {_mm512_sqrt_ps(a.lo), _mm512_sqrt_ps(a.hi)}; }
// |magnitude| with the sign of sign
inline F32 copysign(F32 magnitude, F32 sign) {
    const __m512 bit = _mm512_set1_ps(-0.0f);
    return {_mm512_or_ps(_mm512_andnot_ps(bit, magnitude.lo), _mm512_and_ps(bit, sign.lo)),
            _mm512_or_ps(_mm512_andnot_ps(bit, magnitude.hi), _mm512_and_ps(bit, sign.hi))};
}
// a * b + c, rounded once
inline F32 mul_add(F32 a, F32 b, F32 c) {
    return {_mm512_fmadd_ps(a.lo, b.lo, c.lo), _mm512_fmadd_ps(a.hi, b.hi, c.hi)};
}
// a > b ? a : b, as the C++ ternary
inline F32 max(F32 a, F32 b) { return {_mm512_max_ps(a.lo, b.lo), _mm512_max_ps(a.hi, b.hi)}; }
// a < b ? a : b, as the C++ ternary
inline F32 min(F32 a, F32 b) { return {_mm512_min_ps(a.lo, b.lo), _mm512_min_ps(a.hi, b.hi)}; }

template <int kPredicate>
inline M32 compare(F32 a, F32 b) {
    return {_mm512_cmp_ps_mask(a.lo, b.lo, kPredicate), _mm512_cmp_ps_mask(a.hi, b.hi, kPredicate)};
}
inline M32 operator<(F32 a, F32 b) { return compare<_CMP_LT_OQ>(a, b); }
inline M32 operator>(F32 a, F32 b) { return compare<_CMP_GT_OQ>(a, b); }
inline M32 operator>=(F32 a, F32 b) { return compare<_CMP_GE_OQ>(a, b); }
inline M32 operator!=(F32 a, F32 b) { return compare<_CMP_NEQ_UQ>(a, b); }
inline M32 not_greater(F32 a, F32 b) { return compare<_CMP_NGT_UQ>(a, b); }

inline M32 operator&(M32 a, M32 b) { return {__mmask16(a.lo & b.lo), __mmask16(a.hi & b.hi)}; }
inline M32 operator|(M32 a, M32 b) { return {__mmask16(a.lo | b.lo), __mmask16(a.hi | b.hi)}; }
inline bool any(M32 m) { return (m.lo | m.hi) != 0; }
// m ? a : b
inline F32 select(M32 m, F32 a, F32 b) {
    return {_mm512_mask_blend_ps(m.lo, b.lo, a.lo), _mm512_mask_blend_ps(m.hi, b.hi, a.hi)};
}
// m ? min(a, b) : a, in one masked instruction
inline F32 min_where(M32 m, F32 a, F32 b) {
    return {_mm512_mask_min_ps(a.lo, m.lo, a.lo, b.lo), _mm512_mask_min_ps(a.hi, m.hi, a.hi, b.hi)};
}

}  // namespace lc::avx512_single

#include "lens/lens_trace_lanes.h"

namespace lc {

void trace_from_film_batch_single_avx512(const std::vector<LensElement>& elements, LensRayBatch* b) {
    trace_from_film_lanes<avx512_single::F32, avx512_single::M32, false>(elements.data(), elements.size(),
                                                                         LaneGlass{nullptr, nullptr}, b);
}

void trace_from_film_batch_single_avx512(const std::vector<LensElement>& elements, LaneGlass glass,
                                         LensRayBatch* b) {
    trace_from_film_lanes<avx512_single::F32, avx512_single::M32, true>(elements.data(), elements.size(), glass, b);
}

void trace_from_film_batch_single_margins_avx512(const std::vector<LensElement>& elements, LensRayBatch* b,
                                                double* margin) {
    trace_from_film_lanes<avx512_single::F32, avx512_single::M32, false, true>(elements.data(), elements.size(),
                                                                    LaneGlass{nullptr, nullptr}, b, margin);
}

}  // namespace lc

#pragma GCC pop_options
