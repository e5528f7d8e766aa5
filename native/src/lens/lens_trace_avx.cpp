// The lockstep batch trace of lens_trace.h written with AVX intrinsics: four
// doubles per register, a batch's eight lanes in two registers that are
// interleaved so that their latencies overlap. GCC does not vectorise the
// portable lane loops, and this is where a lens render spends its time.
//
// Bit-identical to the portable loops: the same IEEE operations in the same
// order, no FMA (a fused multiply-add rounds once and would change the bits),
// ordered compares where the C++ compares are ordered and unordered ones where
// the C++ negates a compare. Compiled for AVX by a target attribute and called
// only when the CPU has AVX (see lens_trace_kernel_available).
#include <immintrin.h>

#include "lens/lens_trace.h"

#define LC_AVX __attribute__((target("avx2")))

namespace lc {
namespace {

constexpr int kHalves = kLensBatch / 4;

// Four lanes of a batch.
struct Lanes {
    __m256d ox, oy, oz, dx, dy, dz;
    __m256d alive;  // all-ones bits where the ray is still going
};

LC_AVX inline __m256d splat(double v) { return _mm256_set1_pd(v); }
LC_AVX inline __m256d add(__m256d a, __m256d b) { return _mm256_add_pd(a, b); }
LC_AVX inline __m256d sub(__m256d a, __m256d b) { return _mm256_sub_pd(a, b); }
LC_AVX inline __m256d mul(__m256d a, __m256d b) { return _mm256_mul_pd(a, b); }
LC_AVX inline __m256d div(__m256d a, __m256d b) { return _mm256_div_pd(a, b); }
LC_AVX inline __m256d both(__m256d a, __m256d b) { return _mm256_and_pd(a, b); }
LC_AVX inline __m256d either(__m256d a, __m256d b) { return _mm256_or_pd(a, b); }
// mask ? a : b
LC_AVX inline __m256d select(__m256d mask, __m256d a, __m256d b) { return _mm256_blendv_pd(b, a, mask); }
template <int kPredicate>
LC_AVX inline __m256d compare(__m256d a, __m256d b) { return _mm256_cmp_pd(a, b, kPredicate); }

// One surface for four lanes; mirrors cross_toward_scene_batch in lens_trace.h.
LC_AVX inline void cross(const LensElement& e, Lanes* l) {
    const __m256d zero = _mm256_setzero_pd(), one = splat(1.0), inf = splat(INFINITY);
    const __m256d c = splat(e.curvature_per_mm), v = splat(e.vertex_z_mm);
    const __m256d behind = splat(-kBehindToleranceMm);
    const __m256d sign_bit = splat(-0.0);
    __m256d t, ok;
    if (e.curvature_per_mm == 0.0) {
        t = div(sub(v, l->oz), l->dz);
        ok = both(both(l->alive, compare<_CMP_NEQ_UQ>(l->dz, zero)), compare<_CMP_GE_OQ>(t, behind));
    } else {
        const __m256d pz = sub(l->oz, v);
        const __m256d a = mul(c, add(add(mul(l->dx, l->dx), mul(l->dy, l->dy)), mul(l->dz, l->dz)));
        const __m256d bq = mul(splat(2.0), sub(mul(c, add(add(mul(l->ox, l->dx), mul(l->oy, l->dy)), mul(pz, l->dz))),
                                               l->dz));
        const __m256d k = sub(mul(c, add(add(mul(l->ox, l->ox), mul(l->oy, l->oy)), mul(pz, pz))), mul(splat(2.0), pz));
        const __m256d disc = sub(mul(bq, bq), mul(mul(splat(4.0), a), k));
        const __m256d real = compare<_CMP_GE_OQ>(disc, zero);
        const __m256d sq = _mm256_sqrt_pd(select(real, disc, zero));
        // copysign(sq, bq): sq is never negative
        const __m256d q = mul(splat(-0.5), add(bq, either(_mm256_andnot_pd(sign_bit, sq), both(sign_bit, bq))));
        const __m256d t0 = select(compare<_CMP_NEQ_UQ>(a, zero), div(q, a), inf);
        const __m256d t1 = select(compare<_CMP_NEQ_UQ>(q, zero), div(k, q), inf);
        const __m256d swap = compare<_CMP_GT_OQ>(t0, t1);
        const __m256d lo = select(swap, t1, t0), hi = select(swap, t0, t1);
        auto on_cap = [&](__m256d root) LC_AVX {
            return both(both(compare<_CMP_GE_OQ>(root, behind),
                             compare<_CMP_LT_OQ>(_mm256_andnot_pd(sign_bit, root), inf)),
                        compare<_CMP_LT_OQ>(mul(c, add(pz, mul(root, l->dz))), one));
        };
        const __m256d lo_ok = on_cap(lo), hi_ok = on_cap(hi);
        ok = both(both(l->alive, real), either(lo_ok, hi_ok));
        t = select(lo_ok, lo, hi);
    }
    // Hit point and aperture test
    const __m256d px = add(l->ox, mul(l->dx, t)), py = add(l->oy, mul(l->dy, t)), pz = add(l->oz, mul(l->dz, t));
    const double semi2 = e.semi_aperture_mm * e.semi_aperture_mm;
    ok = both(ok, compare<_CMP_NGT_UQ>(add(mul(px, px), mul(py, py)), splat(semi2)));
    __m256d nx = l->dx, ny = l->dy, nz = l->dz;
    if (!(e.is_stop || e.n_scene_side == e.n_film_side)) {
        const double eta_scalar = e.n_film_side / e.n_scene_side;
        const __m256d eta = splat(eta_scalar), eta2 = splat(eta_scalar * eta_scalar);
        const __m256d minus_c = splat(-e.curvature_per_mm);
        __m256d mx = mul(minus_c, px), my = mul(minus_c, py), mz = sub(one, mul(c, sub(pz, v)));
        __m256d cos_i = _mm256_xor_pd(sign_bit, add(add(mul(mx, l->dx), mul(my, l->dy)), mul(mz, l->dz)));
        const __m256d flip = select(compare<_CMP_LT_OQ>(cos_i, zero), splat(-1.0), one);
        mx = mul(mx, flip), my = mul(my, flip), mz = mul(mz, flip), cos_i = mul(cos_i, flip);
        // max_pd(x, 0) is x > 0 ? x : 0, as in the portable code
        const __m256d sin2_t = mul(eta2, _mm256_max_pd(sub(one, mul(cos_i, cos_i)), zero));
        const __m256d transmits = compare<_CMP_LT_OQ>(sin2_t, one);
        const __m256d cos_t = _mm256_sqrt_pd(select(transmits, sub(one, sin2_t), zero));
        const __m256d s = sub(mul(eta, cos_i), cos_t);
        nx = add(mul(l->dx, eta), mul(mx, s)), ny = add(mul(l->dy, eta), mul(my, s)),
        nz = add(mul(l->dz, eta), mul(mz, s));
        ok = both(both(ok, transmits), compare<_CMP_LT_OQ>(nz, zero));
    }
    // Dead lanes keep their old values
    l->ox = select(ok, px, l->ox), l->oy = select(ok, py, l->oy), l->oz = select(ok, pz, l->oz);
    l->dx = select(ok, nx, l->dx), l->dy = select(ok, ny, l->dy), l->dz = select(ok, nz, l->dz);
    l->alive = ok;
}

}  // namespace

LC_AVX void trace_from_film_batch_avx(const std::vector<LensElement>& elements, LensRayBatch* b) {
    Lanes lanes[kHalves];
    for (int h = 0; h < kHalves; ++h) {
        Lanes& l = lanes[h];
        const int first = 4 * h;
        l.ox = _mm256_loadu_pd(b->ox + first), l.oy = _mm256_loadu_pd(b->oy + first);
        l.oz = _mm256_loadu_pd(b->oz + first);
        l.dx = _mm256_loadu_pd(b->dx + first), l.dy = _mm256_loadu_pd(b->dy + first);
        l.dz = _mm256_loadu_pd(b->dz + first);
        // alive && dz < 0, as in the portable entry
        const __m256d was_alive = _mm256_castsi256_pd(_mm256_set_epi64x(
            -int64_t(b->alive[first + 3]), -int64_t(b->alive[first + 2]), -int64_t(b->alive[first + 1]),
            -int64_t(b->alive[first])));
        l.alive = both(was_alive, compare<_CMP_LT_OQ>(l.dz, _mm256_setzero_pd()));
    }
    const LensElement* surfaces = elements.data();
    for (size_t s = elements.size(); s-- > 0;) {
        for (int h = 0; h < kHalves; ++h) cross(surfaces[s], &lanes[h]);
        int any = 0;
        for (int h = 0; h < kHalves; ++h) any |= _mm256_movemask_pd(lanes[h].alive);
        if (!any) break;
    }
    for (int h = 0; h < kHalves; ++h) {
        const Lanes& l = lanes[h];
        const int first = 4 * h;
        _mm256_storeu_pd(b->ox + first, l.ox), _mm256_storeu_pd(b->oy + first, l.oy);
        _mm256_storeu_pd(b->oz + first, l.oz);
        _mm256_storeu_pd(b->dx + first, l.dx), _mm256_storeu_pd(b->dy + first, l.dy);
        _mm256_storeu_pd(b->dz + first, l.dz);
        const int alive_bits = _mm256_movemask_pd(l.alive);
        for (int i = 0; i < 4; ++i) b->alive[first + i] = (alive_bits >> i) & 1;
    }
}

}  // namespace lc

namespace lc {

bool lens_trace_kernel_available(LensTraceKernel kernel) {
    return kernel == LensTraceKernel::Portable || __builtin_cpu_supports("avx2");
}

LensTraceKernel best_lens_trace_kernel() {
    static const LensTraceKernel best =
        lens_trace_kernel_available(LensTraceKernel::Avx) ? LensTraceKernel::Avx : LensTraceKernel::Portable;
    return best;
}

}  // namespace lc
