// The batch lens trace on AVX-512: eight lanes in one register, masks in mask
// registers. The same template as the AVX2 kernel (lens_trace_lanes.h),
// half the instructions for everything but the square roots and divisions.
#include <immintrin.h>

#include <cstdint>

#include "lens/lens_trace.h"  // before the target pragma: its inline functions stay portable

#pragma GCC push_options
#pragma GCC target("avx512f,avx512dq")

namespace lc::avx512 {

struct M8 {
    __mmask8 bits;

    static M8 load(const bool* p) {
        unsigned bits = 0;
        for (int i = 0; i < 8; ++i) bits |= unsigned(p[i]) << i;
        return {__mmask8(bits)};
    }
    void store(bool* p) const {
        for (int i = 0; i < 8; ++i) p[i] = (bits >> i) & 1;
    }
};

struct D8 {
    __m512d v;

    D8() = default;
    D8(__m512d x) : v(x) {}
    explicit D8(double x) : v(_mm512_set1_pd(x)) {}
    static D8 load(const double* p) { return {_mm512_loadu_pd(p)}; }
    void store(double* p) const { _mm512_storeu_pd(p, v); }
};

inline D8 operator+(D8 a, D8 b) { return _mm512_add_pd(a.v, b.v); }
inline D8 operator-(D8 a, D8 b) { return _mm512_sub_pd(a.v, b.v); }
inline D8 operator*(D8 a, D8 b) { return _mm512_mul_pd(a.v, b.v); }
inline D8 operator/(D8 a, D8 b) { return _mm512_div_pd(a.v, b.v); }
inline D8 operator-(D8 a) { return _mm512_xor_pd(a.v, _mm512_set1_pd(-0.0)); }
inline D8 sqrt(D8 a) { return _mm512_sqrt_pd(a.v); }
inline D8 abs(D8 a) { return _mm512_andnot_pd(_mm512_set1_pd(-0.0), a.v); }
// |magnitude| with the sign of sign
inline D8 copysign(D8 magnitude, D8 sign) {
    const __m512d bit = _mm512_set1_pd(-0.0);
    return _mm512_or_pd(_mm512_andnot_pd(bit, magnitude.v), _mm512_and_pd(bit, sign.v));
}
// a > b ? a : b, as the C++ ternary
inline D8 max(D8 a, D8 b) { return _mm512_max_pd(a.v, b.v); }

template <int kPredicate>
inline M8 compare(D8 a, D8 b) { return {_mm512_cmp_pd_mask(a.v, b.v, kPredicate)}; }
inline M8 operator<(D8 a, D8 b) { return compare<_CMP_LT_OQ>(a, b); }
inline M8 operator>(D8 a, D8 b) { return compare<_CMP_GT_OQ>(a, b); }
inline M8 operator>=(D8 a, D8 b) { return compare<_CMP_GE_OQ>(a, b); }
inline M8 operator!=(D8 a, D8 b) { return compare<_CMP_NEQ_UQ>(a, b); }
inline M8 not_greater(D8 a, D8 b) { return compare<_CMP_NGT_UQ>(a, b); }

inline M8 operator&(M8 a, M8 b) { return {__mmask8(a.bits & b.bits)}; }
inline M8 operator|(M8 a, M8 b) { return {__mmask8(a.bits | b.bits)}; }
inline bool any(M8 m) { return m.bits != 0; }
// m ? a : b
inline D8 select(M8 m, D8 a, D8 b) { return _mm512_mask_blend_pd(m.bits, b.v, a.v); }

}  // namespace lc::avx512

#include "lens/lens_trace_lanes.h"

namespace lc {

void trace_from_film_batch_avx512(const std::vector<LensElement>& elements, LensRayBatch* b) {
    trace_from_film_lanes<avx512::D8, avx512::M8>(elements.data(), elements.size(), b);
}

}  // namespace lc

#pragma GCC pop_options
