// The batch lens trace in single precision on AVX2 (lens_trace.h,
// LensTracePrecision): the template of lens_trace_lanes.h over sixteen float
// lanes as two registers of eight, every operation issued for both back to
// back so that two dependency chains overlap, the batch in two groups (four
// registers spilled: AVX2 has sixteen). The batch stays in double: lanes are
// rounded to float on the way in and widened on the way out.
#include <immintrin.h>

#include <cstdint>

#include "lens/lens_trace.h"  // before the target pragma: its inline functions stay portable

#pragma GCC push_options
#pragma GCC target("avx2,fma")

namespace lc::avx2_single {

constexpr int kRegisters = 2;

struct M16 {
    __m256 r[kRegisters];  // all bits set where true

    static M16 load(const bool* p) {
        M16 m;
        for (int k = 0; k < kRegisters; ++k) {
            const bool* q = p + 8 * k;
            m.r[k] = _mm256_castsi256_ps(_mm256_set_epi32(-int32_t(q[7]), -int32_t(q[6]), -int32_t(q[5]),
                                                          -int32_t(q[4]), -int32_t(q[3]), -int32_t(q[2]),
                                                          -int32_t(q[1]), -int32_t(q[0])));
        }
        return m;
    }
    void store(bool* p) const {
        for (int k = 0; k < kRegisters; ++k) {
            const int bits = _mm256_movemask_ps(r[k]);
            for (int i = 0; i < 8; ++i) p[8 * k + i] = (bits >> i) & 1;
        }
    }
};

struct F16 {
    static constexpr int kLanes = 8 * kRegisters;
    using Scalar = float;
    __m256 r[kRegisters];

    F16() = default;
    explicit F16(double x) {
        for (__m256& v : r) v = _mm256_set1_ps(float(x));
    }
    // Eight doubles rounded to float (round to nearest, as float(x)).
    static __m256 narrow(__m256d a, __m256d b) {
        return _mm256_insertf128_ps(_mm256_castps128_ps256(_mm256_cvtpd_ps(a)), _mm256_cvtpd_ps(b), 1);
    }
    static F16 load(const double* p) {
        F16 f;
        for (int k = 0; k < kRegisters; ++k) f.r[k] = narrow(_mm256_loadu_pd(p + 8 * k), _mm256_loadu_pd(p + 8 * k + 4));
        return f;
    }
    void store(double* p) const {
        for (int k = 0; k < kRegisters; ++k) {
            _mm256_storeu_pd(p + 8 * k, _mm256_cvtps_pd(_mm256_castps256_ps128(r[k])));
            _mm256_storeu_pd(p + 8 * k + 4, _mm256_cvtps_pd(_mm256_extractf128_ps(r[k], 1)));
        }
    }
};

// Each operation once per register, spelt out: written with a lambda per
// operation the trace ran about four times slower (248 against 64 ns per
// lens ray, measured with four registers).
#define LC_EACH(expression_of_k)                                                                  \
    F16 f;                                                                                        \
    {                                                                                             \
        { constexpr int k = 0; f.r[k] = expression_of_k; }                                        \
        { constexpr int k = 1; f.r[k] = expression_of_k; }                                        \
    }                                                                                             \
    return f

inline F16 operator+(F16 a, F16 b) { LC_EACH(_mm256_add_ps(a.r[k], b.r[k])); }
inline F16 operator-(F16 a, F16 b) { LC_EACH(_mm256_sub_ps(a.r[k], b.r[k])); }
inline F16 operator*(F16 a, F16 b) { LC_EACH(_mm256_mul_ps(a.r[k], b.r[k])); }
inline F16 operator/(F16 a, F16 b) { LC_EACH(_mm256_div_ps(a.r[k], b.r[k])); }
inline F16 operator-(F16 a) { LC_EACH(_mm256_xor_ps(a.r[k], _mm256_set1_ps(-0.0f))); }
inline F16 sqrt(F16 a) { LC_EACH(_mm256_sqrt_ps(a.r[k])); }
// a * b + c, rounded once
inline F16 mul_add(F16 a, F16 b, F16 c) { LC_EACH(_mm256_fmadd_ps(a.r[k], b.r[k], c.r[k])); }
// |magnitude| with the sign of sign
inline F16 copysign(F16 magnitude, F16 sign) {
    const __m256 bit = _mm256_set1_ps(-0.0f);
    LC_EACH(_mm256_or_ps(_mm256_andnot_ps(bit, magnitude.r[k]), _mm256_and_ps(bit, sign.r[k])));
}
// a > b ? a : b, as the C++ ternary
inline F16 max(F16 a, F16 b) { LC_EACH(_mm256_max_ps(a.r[k], b.r[k])); }
// a < b ? a : b, as the C++ ternary
inline F16 min(F16 a, F16 b) { LC_EACH(_mm256_min_ps(a.r[k], b.r[k])); }

template <int kPredicate>
inline M16 compare(F16 a, F16 b) {
    M16 m;
    for (int k = 0; k < kRegisters; ++k) m.r[k] = _mm256_cmp_ps(a.r[k], b.r[k], kPredicate);
    return m;
}
inline M16 operator<(F16 a, F16 b) { return compare<_CMP_LT_OQ>(a, b); }
inline M16 operator>(F16 a, F16 b) { return compare<_CMP_GT_OQ>(a, b); }
inline M16 operator>=(F16 a, F16 b) { return compare<_CMP_GE_OQ>(a, b); }
inline M16 operator!=(F16 a, F16 b) { return compare<_CMP_NEQ_UQ>(a, b); }
inline M16 not_greater(F16 a, F16 b) { return compare<_CMP_NGT_UQ>(a, b); }

inline M16 operator&(M16 a, M16 b) {
    M16 m;
    for (int k = 0; k < kRegisters; ++k) m.r[k] = _mm256_and_ps(a.r[k], b.r[k]);
    return m;
}
inline M16 operator|(M16 a, M16 b) {
    M16 m;
    for (int k = 0; k < kRegisters; ++k) m.r[k] = _mm256_or_ps(a.r[k], b.r[k]);
    return m;
}
inline bool any(M16 m) {
    __m256 all = m.r[0];
    for (int k = 1; k < kRegisters; ++k) all = _mm256_or_ps(all, m.r[k]);
    return _mm256_movemask_ps(all) != 0;
}
// m ? a : b
inline F16 select(M16 m, F16 a, F16 b) { LC_EACH(_mm256_blendv_ps(b.r[k], a.r[k], m.r[k])); }
// m ? min(a, b) : a
inline F16 min_where(M16 m, F16 a, F16 b) { return select(m, min(a, b), a); }

#undef LC_EACH

}  // namespace lc::avx2_single

#include "lens/lens_trace_lanes.h"

namespace lc {

void trace_from_film_batch_single_avx2(const std::vector<LensElement>& elements, LensRayBatch* b) {
    trace_from_film_lanes<avx2_single::F16, avx2_single::M16, false>(elements.data(), elements.size(),
                                                                     LaneGlass{nullptr, nullptr}, b);
}

void trace_from_film_batch_single_avx2(const std::vector<LensElement>& elements, LaneGlass glass, LensRayBatch* b) {
    trace_from_film_lanes<avx2_single::F16, avx2_single::M16, true>(elements.data(), elements.size(), glass, b);
}

void trace_from_film_batch_single_margins_avx2(const std::vector<LensElement>& elements, LensRayBatch* b,
                                                double* margin) {
    trace_from_film_lanes<avx2_single::F16, avx2_single::M16, false, true>(elements.data(), elements.size(),
                                                                    LaneGlass{nullptr, nullptr}, b, margin);
}

}  // namespace lc

#pragma GCC pop_options
