// The lockstep lens trace of lens_trace.h, D::kLanes lanes per group, written
// once for the SIMD kernels. Each kernel file (lens_trace_avx2.cpp: eight
// lanes, lens_trace_avx512.cpp: sixteen) defines a double type D of D::kLanes
// lanes and its mask M with the operations used below, switches the compiler
// to its instruction set with #pragma GCC target, and only then includes this
// header, so that the templates are compiled for that instruction set.
//
// In double, bit-identical to cross_toward_scene_batch: the same IEEE
// operations in the same order, mul_add(a, b, c) being a * b + c rounded
// twice (no FMA: it rounds once and would change the bits; the sums are
// written so that only their operands' order differs, which IEEE addition
// does not see). In single precision (the render's trace) mul_add is fused
// on every kernel, the portable one through std::fma, so they agree to the
// bit with each other and do a fifth fewer operations. Comparisons
// are ordered (false on NaN) where the C++ compares, unordered where it
// negates a compare (not_greater) or tests !=, as in C++.
//
// Only templates here: a plain inline function compiled under two targets
// could be merged by the linker into the wrong one.
#pragma once

#include <cmath>
#include <cstddef>

#include "lens/lens_trace.h"

namespace lc {

// A surface's scalar terms, worked out once per batch rather than once per
// group of lanes: each division here occupies the divider the lanes' square
// roots and divisions wait for. The same values as the scalar trace's.
struct SurfaceScalars {
    double four_c, radius_mm, semi2_mm2, eta, eta2;
    bool refracts, direct_near_root;

    // single: for the single-precision trace, which always divides (its
    // divider is cheap, and the direct root's cancellation would cost
    // eps_float |R|, microns).
    static SurfaceScalars of(const LensElement& e, bool single = false) {
        SurfaceScalars f;
        f.four_c = 4.0 * e.curvature_per_mm;
        f.radius_mm = e.curvature_per_mm != 0.0 ? 1.0 / e.curvature_per_mm : 0.0;
        f.semi2_mm2 = e.semi_aperture_mm * e.semi_aperture_mm;
        f.direct_near_root = !single && lc::direct_near_root(e.curvature_per_mm);
        f.refracts = !(e.is_stop || e.n_scene_side == e.n_film_side);
        f.eta = f.refracts ? e.n_film_side / e.n_scene_side : 1.0;
        f.eta2 = f.eta * f.eta;
        return f;
    }
};

// Whether lanes of type D are the single-precision trace's.
template <class D>
constexpr bool kSingleLanes = sizeof(typename D::Scalar) == sizeof(float);

template <class D, class M>
struct LaneGroup {
    D ox, oy, oz, dx, dy, dz;
    M alive;
    D margin;  // kMargins' traces: the least clearance of the rims met so far
};

// Snell refraction of l's directions at the surface points p with index ratio
// eta (its square eta2) into n; the lanes that transmit and go on toward the
// scene (not totally reflected, not turned back toward the film: pbrt-v3 #92).
template <class D, class M>
inline M refract_lanes(const LensElement& e, D px, D py, D pz, D cos_i, D cos2_i, D eta, D eta2,
                       const LaneGroup<D, M>& l, D* nx, D* ny, D* nz) {
    const D zero(0.0), one(1.0), c(e.curvature_per_mm), v(e.vertex_z_mm);
    // Normal (0,0,1) - c (p - vertex)
    const D mx = -c * px, my = -c * py, mz = mul_add(-c, pz - v, one);
    const D sin2_t = eta2 * max(one - cos2_i, zero);
    const M transmits = sin2_t < one;
    const D cos_t = sqrt(select(transmits, one - sin2_t, zero));
    // refract() turns the normal to face the ray (m and cos_i negated when
    // cos_i < 0); negating cos_t instead negates s, the same bits for fewer
    // instructions.
    const D s = mul_add(eta, cos_i, select(cos_i < zero, cos_t, -cos_t));
    *nx = mul_add(mx, s, l.dx * eta), *ny = mul_add(my, s, l.dy * eta), *nz = mul_add(mz, s, l.dz * eta);
    return transmits & (*nz < zero);
}

// kDispersed: each lane refracts with its own row of glass.dispersion
// (glass.eta_lanes, laid_out); otherwise every lane with e's indices, and glass,
// surface and first go unused. kMargins: the rims stop no lane; each lane's
// margin keeps the least (rim^2 - height^2) / rim^2 over the surfaces it
// meets (the blades' (apothem - distance) / apothem), whose sign says whether
// the rims would have passed it (lens_system_bands.cpp).
template <class D, class M, bool kDispersed, bool kMargins = false>
inline void cross_toward_scene_lanes_body(const LensElement& e, const SurfaceScalars& f, size_t surface,
                                          LaneGlass glass, int first, LaneGroup<D, M>* l) {
    const D zero(0.0), one(1.0), inf(INFINITY);
    const D behind(kSingleLanes<D> ? -kBehindToleranceSingleMm : -kBehindToleranceMm);
    const D c(e.curvature_per_mm), v(e.vertex_z_mm);
    D t, cos_i, cos2_i;
    M ok;
    if (e.curvature_per_mm == 0.0) {
        t = (v - l->oz) / l->dz;
        ok = l->alive & (l->dz != zero) & (t >= behind);
        cos_i = -l->dz, cos2_i = l->dz * l->dz;
    } else {
        const D pz = l->oz - v;
        const D dot = mul_add(pz, l->dz, mul_add(l->oy, l->dy, l->ox * l->dx));
        const D bq = D(2.0) * mul_add(c, dot, -l->dz);
        const D k = mul_add(c, mul_add(pz, pz, mul_add(l->oy, l->oy, l->ox * l->ox)), -(D(2.0) * pz));
        const D disc = mul_add(bq, bq, -(D(f.four_c) * k));
        const M real = disc >= zero;
        const D sq = sqrt(select(real, disc, zero));
        const D q = D(-0.5) * (bq + copysign(sq, bq));
        const D t0 = q * D(f.radius_mm);
        const D t1 = f.direct_near_root ? (copysign(sq, bq) - bq) * D(0.5 * f.radius_mm)
                                        : select(q != zero, k / q, inf);
        const M swap = t0 > t1;
        const D lo = select(swap, t1, t0), hi = select(swap, t0, t1);
        // lo >= behind rules out -inf (and NaN): lo < inf is then |lo| < inf.
        const M lo_ok = (lo >= behind) & (lo < inf) & (c * mul_add(lo, l->dz, pz) < one);
        const M hi_ok = (hi >= behind) & (hi < inf) & (c * mul_add(hi, l->dz, pz) < one);
        ok = l->alive & real & (lo_ok | hi_ok);
        t = select(lo_ok, lo, hi);
        const D h = D(0.5) * copysign(sq, bq), mh = -h;
        cos_i = select(lo_ok, select(swap, h, mh), select(swap, mh, h));
        cos2_i = D(0.25) * disc;
    }
    // Hit point and aperture test
    const D px = mul_add(l->dx, t, l->ox), py = mul_add(l->dy, t, l->oy), pz = mul_add(l->dz, t, l->oz);
    const M hit = ok;
    if constexpr (kMargins) {
        // min(a, b): a < b ? a : b (the instruction's, and the C++ ternary's, NaN and all)
        const D inverse_semi2(f.semi2_mm2 > 0.0 ? 1.0 / f.semi2_mm2 : 0.0);
        D margin = (D(f.semi2_mm2) - mul_add(py, py, px * px)) * inverse_semi2;
        for (int k = 0; k < e.blades; ++k)
            margin = min(margin, (D(e.apothem_mm) - mul_add(py, D(e.edge_normal_y[size_t(k)]),
                                                              px * D(e.edge_normal_x[size_t(k)]))) *
                                     D(1.0 / e.apothem_mm));
        l->margin = min_where(hit, l->margin, margin);
    } else {
        ok = ok & not_greater(mul_add(py, py, px * px), D(f.semi2_mm2));
        for (int k = 0; k < e.blades; ++k)
            ok = ok & not_greater(mul_add(py, D(e.edge_normal_y[size_t(k)]), px * D(e.edge_normal_x[size_t(k)])),
                                  D(e.apothem_mm));
    }
    D nx = l->dx, ny = l->dy, nz = l->dz;
    if constexpr (kDispersed) {
        const LensDispersion& d = *glass.dispersion;
        if (d.bends[surface] != LensDispersion::Bends::Never) {
            const size_t lanes = surface * kLensBatch + size_t(first);
            const D eta = D::load(glass.eta_lanes + lanes);
            M passes = refract_lanes(e, px, py, pz, cos_i, cos2_i, eta, eta * eta, *l, &nx, &ny, &nz);
            if (d.bends[surface] == LensDispersion::Bends::Some) {
                // Lanes where this surface does not refract go straight on, untested.
                const D bends_at = D::load(glass.bends_at_lanes + lanes);
                const M bends = bends_at > zero;
                nx = select(bends, nx, l->dx), ny = select(bends, ny, l->dy), nz = select(bends, nz, l->dz);
                passes = passes | not_greater(bends_at, zero);
            }
            ok = ok & passes;
        }
    } else if (f.refracts) {
        ok = ok & refract_lanes(e, px, py, pz, cos_i, cos2_i, D(f.eta), D(f.eta2), *l, &nx, &ny, &nz);
    }
    // Lanes that found no hit keep their old values; those that hit go on
    // from there whether or not the rim, total internal reflection or the
    // turn-back test then stopped them (finite values either way, and a dead
    // lane's are never read), so the next surface need not wait for those tests.
    l->ox = select(hit, px, l->ox), l->oy = select(hit, py, l->oy), l->oz = select(hit, pz, l->oz);
    l->dx = select(hit, nx, l->dx), l->dy = select(hit, ny, l->dy), l->dz = select(hit, nz, l->dz);
    l->alive = ok;
}

// Out of line where a batch is several groups of lanes (the double kernels):
// GCC left it so before it had a dispersed variant, and the RGB trace is
// fastest that way (measured). The single-precision kernels' one group takes
// the body inline.
template <class D, class M, bool kDispersed, bool kMargins = false>
__attribute__((noinline)) void cross_toward_scene_lanes(const LensElement& e, const SurfaceScalars& f,
                                                        size_t surface, LaneGlass glass, int first,
                                                        LaneGroup<D, M>* l) {
    cross_toward_scene_lanes_body<D, M, kDispersed, kMargins>(e, f, surface, glass, first, l);
}

// trace_from_film_batch_portable's work for the whole batch, in groups of
// D::kLanes lanes side by side so that their latencies overlap. kMargins:
// margin (kLensBatch) gets each lane's least rim clearance (above), the rims
// stopping none.
template <class D, class M, bool kDispersed, bool kMargins = false>
inline void trace_from_film_lanes(const LensElement* elements, size_t count, LaneGlass glass, LensRayBatch* b,
                                  double* margin = nullptr) {
    constexpr int kWidth = D::kLanes;
    static_assert(kLensBatch % kWidth == 0, "whole groups of lanes");
    constexpr int kGroups = kLensBatch / kWidth;
    LaneGroup<D, M> lanes[kGroups];
    for (int g = 0; g < kGroups; ++g) {
        LaneGroup<D, M>& l = lanes[g];
        const int first = kWidth * g;
        l.ox = D::load(b->ox + first), l.oy = D::load(b->oy + first), l.oz = D::load(b->oz + first);
        l.dx = D::load(b->dx + first), l.dy = D::load(b->dy + first), l.dz = D::load(b->dz + first);
        l.alive = M::load(b->alive + first) & (l.dz < D(0.0));
        if constexpr (kMargins) l.margin = D(INFINITY);
    }
    for (size_t s = count; s-- > 0;) {
        const SurfaceScalars scalars = SurfaceScalars::of(elements[s], kSingleLanes<D>);
        bool any_alive = false;
        for (int g = 0; g < kGroups; ++g) {
            if constexpr (kGroups == 1)
                cross_toward_scene_lanes_body<D, M, kDispersed, kMargins>(elements[s], scalars, s, glass, kWidth * g,
                                                                          &lanes[g]);
            else
                cross_toward_scene_lanes<D, M, kDispersed, kMargins>(elements[s], scalars, s, glass, kWidth * g,
                                                                     &lanes[g]);
            any_alive |= any(lanes[g].alive);
        }
        if (!any_alive) break;
    }
    for (int g = 0; g < kGroups; ++g) {
        const LaneGroup<D, M>& l = lanes[g];
        const int first = kWidth * g;
        l.ox.store(b->ox + first), l.oy.store(b->oy + first), l.oz.store(b->oz + first);
        l.dx.store(b->dx + first), l.dy.store(b->dy + first), l.dz.store(b->dz + first);
        l.alive.store(b->alive + first);
        if constexpr (kMargins) l.margin.store(margin + first);
    }
}

}  // namespace lc
