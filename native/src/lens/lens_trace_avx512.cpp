// The batch lens trace and aim on AVX-512: sixteen lanes as two registers of
// eight, masks in mask registers. The same templates as the AVX2 kernel
// (lens_trace_lanes.h, lens_aim_lanes.h), half the instructions for
// everything but the square roots and divisions. (The two-register wrapper
// mirrors the AVX2 one by shape; only the intrinsics differ.)
#include <immintrin.h>

#include <cstdint>

#include <cstddef>

#include "lens/exit_pupil.h"
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
    __m512d lo, hi;

    D16() = default;
    D16(__m512d l, __m512d h) : lo(l), hi(h) {}
    explicit D16(double x) : lo(_mm512_set1_pd(x)), hi(lo) {}
    static D16 load(const double* p) { return {_mm512_loadu_pd(p), _mm512_loadu_pd(p + 8)}; }
    // base[index[i]] in lane i
    static D16 gather(const double* base, const int32_t* index) {
        return {_mm512_i32gather_pd(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(index)), base, 8),
                _mm512_i32gather_pd(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(index + 8)), base, 8)};
    }
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

namespace {

// Eight lanes of PupilPolygon fields, base + each lane's byte offset where m is set, else 0.
__m512d gather_or_zero(__mmask8 m, __m512i byte_offset, const char* base) {
    return _mm512_mask_i64gather_pd(_mm512_setzero_pd(), m, byte_offset, base, 1);
}
// The byte at base + offset in each lane (reads the three after it too, which
// lie inside the same PupilPolygon).
__m512i gather_byte(__m512i byte_offset, const char* base) {
    return _mm512_and_si512(_mm512_cvtepi32_epi64(_mm512_i64gather_epi32(byte_offset, base, 1)),
                            _mm512_set1_epi64(0xff));
}

}  // namespace

// ExitPupil::pick and LensSystemCamera::film_point, eight lanes at a time:
// the same IEEE operations in the same order, so the same bits.
void pick_batch_avx512(const ExitPupil& pupil, const FilmGrid& film, const Point2f* raster_px,
                       const Point2f* lens_sample, int n, LensAimBatch* aim, bool* alive, double* area_mm2) {
    const char* base = reinterpret_cast<const char*>(pupil.segments());
    const __m512d zero = _mm512_setzero_pd(), one = _mm512_set1_pd(1.0);
    const __m512d half_width = _mm512_set1_pd(0.5 * film.width_px), half_height = _mm512_set1_pd(0.5 * film.height_px);
    const __m512d mm_x = _mm512_set1_pd(film.mm_per_px_x), mm_y = _mm512_set1_pd(film.mm_per_px_y);
    const __m512d per_mm = _mm512_set1_pd(pupil.segments_per_mm()), cells = _mm512_set1_pd(kPupilGuideCells);
    const __m512i one_i = _mm512_set1_epi64(1), last_angle = _mm512_set1_epi64(kPupilAngles - 1);
    const __m512i polygon_bytes = _mm512_set1_epi64(sizeof(PupilPolygon));
    constexpr long long kCdf = offsetof(PupilPolygon, cdf), kStep = offsetof(PupilPolygon, inverse_cdf_step);
    constexpr long long kVx = offsetof(PupilPolygon, vertex_x_mm), kVy = offsetof(PupilPolygon, vertex_y_mm);
    for (int first = 0; first < kLensBatch; first += 8) {
        alignas(64) double rx[8], ry[8], ux[8], uy[8];
        unsigned in_batch = 0;
        for (int j = 0; j < 8; ++j) {
            const int i = first + j, s = i < n ? i : 0;
            rx[j] = double(raster_px[s].x), ry[j] = double(raster_px[s].y);
            ux[j] = double(lens_sample[s].x), uy[j] = double(lens_sample[s].y);
            in_batch |= unsigned(i < n) << j;
        }
        // Film point
        const __m512d x = _mm512_mul_pd(_mm512_sub_pd(half_width, _mm512_load_pd(rx)), mm_x);
        const __m512d y = _mm512_mul_pd(_mm512_sub_pd(_mm512_load_pd(ry), half_height), mm_y);
        const __m512d r = _mm512_sqrt_pd(_mm512_add_pd(_mm512_mul_pd(x, x), _mm512_mul_pd(y, y)));
        _mm512_storeu_pd(aim->film_x_mm + first, x), _mm512_storeu_pd(aim->film_y_mm + first, y);
        _mm512_storeu_pd(aim->film_r_mm + first, r);
        _mm512_storeu_pd(aim->u_radial + first, _mm512_load_pd(ux));
        // The ring's polygon, and whether it has light
        __m512i segment = _mm512_cvtepi32_epi64(_mm512_cvttpd_epi32(_mm512_mul_pd(r, per_mm)));
        segment = _mm512_min_epi64(_mm512_max_epi64(segment, _mm512_setzero_si512()),
                                   _mm512_set1_epi64(kPupilSegments - 1));
        const __m512i polygon = _mm512_mul_epu32(segment, polygon_bytes);
        const __mmask8 live = __mmask8(in_batch) &
                              _mm512_cmpeq_epi64_mask(gather_byte(polygon, base + offsetof(PupilPolygon, empty)),
                                                      _mm512_setzero_si512());
        // The first k with cdf[k] > u, from the guide
        const __m512d u = _mm512_load_pd(uy);
        __m512i guide_cell = _mm512_cvtepi32_epi64(_mm512_cvttpd_epi32(_mm512_mul_pd(u, cells)));
        guide_cell = _mm512_min_epi64(guide_cell, _mm512_set1_epi64(kPupilGuideCells - 1));
        __m512i k = gather_byte(_mm512_add_epi64(polygon, guide_cell), base + offsetof(PupilPolygon, guide));
        for (;;) {
            const __m512i at_k = _mm512_add_epi64(polygon, _mm512_slli_epi64(k, 3));
            const __mmask8 further = live & _mm512_cmplt_epi64_mask(k, last_angle);
            const __m512d cdf = gather_or_zero(further, at_k, base + kCdf);
            const __mmask8 step = further & _mm512_cmp_pd_mask(cdf, u, _CMP_LE_OQ);
            if (!step) break;
            k = _mm512_mask_add_epi64(k, step, k, one_i);
        }
        const __m512i at_k = _mm512_add_epi64(polygon, _mm512_slli_epi64(k, 3));
        const __m512i k1 = _mm512_and_si512(_mm512_add_epi64(k, one_i), _mm512_set1_epi64(kPupilAngles - 1));
        const __m512i at_k1 = _mm512_add_epi64(polygon, _mm512_slli_epi64(k1, 3));
        const __mmask8 after_first = live & _mm512_cmpgt_epi64_mask(k, _mm512_setzero_si512());
        const __m512d lo = gather_or_zero(after_first, _mm512_sub_epi64(at_k, _mm512_set1_epi64(8)), base + kCdf);
        const __m512d v = _mm512_mul_pd(_mm512_sub_pd(u, lo), gather_or_zero(live, at_k, base + kStep));
        // std::clamp(v, 0, 1): v < 0 ? 0 : 1 < v ? 1 : v
        __m512d across = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(one, v, _CMP_LT_OQ), v, one);
        across = _mm512_mask_blend_pd(_mm512_cmp_pd_mask(v, zero, _CMP_LT_OQ), across, zero);
        _mm512_storeu_pd(aim->across + first, _mm512_maskz_mov_pd(live, across));
        _mm512_storeu_pd(aim->centre_x_mm + first,
                         gather_or_zero(live, polygon, base + offsetof(PupilPolygon, centre_x_mm)));
        _mm512_storeu_pd(aim->a_x_mm + first, gather_or_zero(live, at_k, base + kVx));
        _mm512_storeu_pd(aim->a_y_mm + first, gather_or_zero(live, at_k, base + kVy));
        _mm512_storeu_pd(aim->b_x_mm + first, gather_or_zero(live, at_k1, base + kVx));
        _mm512_storeu_pd(aim->b_y_mm + first, gather_or_zero(live, at_k1, base + kVy));
        _mm512_storeu_pd(area_mm2 + first, gather_or_zero(live, polygon, base + offsetof(PupilPolygon, area_mm2)));
        for (int j = 0; j < 8; ++j) alive[first + j] = (live >> j) & 1;
    }
}

}  // namespace lc

#pragma GCC pop_options
