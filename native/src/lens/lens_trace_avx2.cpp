// The batch lens trace on AVX2: eight lanes as two 4-wide registers, every
// operation issued for both halves back to back, so that the two
// dependency chains (long ones: two square roots and two divisions per
// surface) overlap. GCC does not vectorise the portable lane loops; this is
// where a lens render spends its time.
#include <immintrin.h>

#include <cstdint>

#include "lens/lens_aim.h"
#include "lens/lens_trace.h"  // before the target pragma: its inline functions stay portable

#pragma GCC push_options
#pragma GCC target("avx2")

namespace lc::avx2 {

struct M8 {
    __m256d lo, hi;  // all bits set where true

    static M8 load(const bool* p) {
        auto half = [](const bool* q) {
            return _mm256_castsi256_pd(
                _mm256_set_epi64x(-int64_t(q[3]), -int64_t(q[2]), -int64_t(q[1]), -int64_t(q[0])));
        };
        return {half(p), half(p + 4)};
    }
    void store(bool* p) const {
        const int bits = _mm256_movemask_pd(lo) | (_mm256_movemask_pd(hi) << 4);
        for (int i = 0; i < 8; ++i) p[i] = (bits >> i) & 1;
    }
};

struct D8 {
    static constexpr int kLanes = 8;
    using Scalar = double;
    __m256d lo, hi;

    D8() = default;
    D8(__m256d l, __m256d h) : lo(l), hi(h) {}
    explicit D8(double v) : lo(_mm256_set1_pd(v)), hi(lo) {}
    static D8 load(const double* p) { return {_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4)}; }
    void store(double* p) const { _mm256_storeu_pd(p, lo), _mm256_storeu_pd(p + 4, hi); }
};

inline D8 operator+(D8 a, D8 b) { return {_mm256_add_pd(a.lo, b.lo), _mm256_add_pd(a.hi, b.hi)}; }
inline D8 operator-(D8 a, D8 b) { return {_mm256_sub_pd(a.lo, b.lo), _mm256_sub_pd(a.hi, b.hi)}; }
inline D8 operator*(D8 a, D8 b) { return {_mm256_mul_pd(a.lo, b.lo), _mm256_mul_pd(a.hi, b.hi)}; }
inline D8 operator/(D8 a, D8 b) { return {_mm256_div_pd(a.lo, b.lo), _mm256_div_pd(a.hi, b.hi)}; }
inline D8 operator-(D8 a) {
    const __m256d sign = _mm256_set1_pd(-0.0);
    return {_mm256_xor_pd(a.lo, sign), _mm256_xor_pd(a.hi, sign)};
}
inline D8 sqrt(D8 a) { return {_mm256_sqrt_pd(a.lo), _mm256_sqrt_pd(a.hi)}; }
inline D8 abs(D8 a) {
    const __m256d sign = _mm256_set1_pd(-0.0);
    return {_mm256_andnot_pd(sign, a.lo), _mm256_andnot_pd(sign, a.hi)};
}
// |magnitude| with the sign of sign
inline D8 copysign(D8 magnitude, D8 sign) {
    const __m256d bit = _mm256_set1_pd(-0.0);
    return {_mm256_or_pd(_mm256_andnot_pd(bit, magnitude.lo), _mm256_and_pd(bit, sign.lo)),
            _mm256_or_pd(_mm256_andnot_pd(bit, magnitude.hi), _mm256_and_pd(bit, sign.hi))};
}
// a * b + c, rounded twice as the scalar trace does
inline D8 mul_add(D8 a, D8 b, D8 c) { return a * b + c; }
// a > b ? a : b, as the C++ ternary
inline D8 max(D8 a, D8 b) { return {_mm256_max_pd(a.lo, b.lo), _mm256_max_pd(a.hi, b.hi)}; }

template <int kPredicate>
inline M8 compare(D8 a, D8 b) { return {_mm256_cmp_pd(a.lo, b.lo, kPredicate), _mm256_cmp_pd(a.hi, b.hi, kPredicate)}; }
inline M8 operator<(D8 a, D8 b) { return compare<_CMP_LT_OQ>(a, b); }
inline M8 operator>(D8 a, D8 b) { return compare<_CMP_GT_OQ>(a, b); }
inline M8 operator>=(D8 a, D8 b) { return compare<_CMP_GE_OQ>(a, b); }
inline M8 operator!=(D8 a, D8 b) { return compare<_CMP_NEQ_UQ>(a, b); }
inline M8 not_greater(D8 a, D8 b) { return compare<_CMP_NGT_UQ>(a, b); }

inline M8 operator&(M8 a, M8 b) { return {_mm256_and_pd(a.lo, b.lo), _mm256_and_pd(a.hi, b.hi)}; }
inline M8 operator|(M8 a, M8 b) { return {_mm256_or_pd(a.lo, b.lo), _mm256_or_pd(a.hi, b.hi)}; }
inline bool any(M8 m) { return (_mm256_movemask_pd(m.lo) | _mm256_movemask_pd(m.hi)) != 0; }
// m ? a : b
inline D8 select(M8 m, D8 a, D8 b) { return {_mm256_blendv_pd(b.lo, a.lo, m.lo), _mm256_blendv_pd(b.hi, a.hi, m.hi)}; }

}  // namespace lc::avx2

#include "lens/lens_aim_lanes.h"
#include "lens/lens_trace_lanes.h"

namespace lc {

void trace_from_film_batch_avx2(const std::vector<LensElement>& elements, LensRayBatch* b) {
    trace_from_film_lanes<avx2::D8, avx2::M8, false>(elements.data(), elements.size(), LaneGlass{nullptr, nullptr},
                                                     b);
}

void trace_from_film_batch_avx2(const std::vector<LensElement>& elements, LaneGlass glass, LensRayBatch* b) {
    trace_from_film_lanes<avx2::D8, avx2::M8, true>(elements.data(), elements.size(), glass, b);
}

void aim_batch_avx2(const LensAimBatch& in, AimPlanes planes, LensRayBatch* out) {
    aim_lanes<avx2::D8, avx2::M8>(in, planes, out);
}

}  // namespace lc

#pragma GCC pop_options
