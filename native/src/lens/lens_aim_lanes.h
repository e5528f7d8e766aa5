// aim_one of lens_aim.h in SIMD lanes, for the kernels that include
// lens_trace_lanes.h (the same eight- or sixteen-lane types, the same rules:
// only templates, the same IEEE operations in the same order as the scalar
// code, so every kernel gives its bits).
#pragma once

#include "lens/lens_aim.h"

namespace lc {

template <class D, class M>
inline void aim_lanes(const LensAimBatch& in, AimPlanes planes, LensRayBatch* out) {
    constexpr int kWidth = D::kLanes;
    static_assert(kLensBatch % kWidth == 0, "whole groups of lanes");
    const D zero(0.0), one(1.0), film_z(planes.film_z_mm), tz(planes.pupil_plane_z_mm - planes.film_z_mm);
    for (int first = 0; first < kLensBatch; first += kWidth) {
        const D x = D::load(in.film_x_mm + first), y = D::load(in.film_y_mm + first), r = D::load(in.film_r_mm + first);
        const D s = sqrt(D::load(in.u_radial + first)), t = D::load(in.across + first);
        const D lx = D::load(in.centre_x_mm + first) +
                     s * ((one - t) * D::load(in.a_x_mm + first) + t * D::load(in.b_x_mm + first));
        const D ly = s * ((one - t) * D::load(in.a_y_mm + first) + t * D::load(in.b_y_mm + first));
        const M off_axis = r > zero;
        const D inverse_r = select(off_axis, one / r, zero);
        const D cos_phi = select(off_axis, x * inverse_r, one), sin_phi = y * inverse_r;
        const D px = cos_phi * lx - sin_phi * ly, py = sin_phi * lx + cos_phi * ly;
        const D tx = px - x, ty = py - y;
        const D inverse_length = one / sqrt(tx * tx + ty * ty + tz * tz);
        x.store(out->ox + first), y.store(out->oy + first), film_z.store(out->oz + first);
        (tx * inverse_length).store(out->dx + first), (ty * inverse_length).store(out->dy + first);
        (tz * inverse_length).store(out->dz + first);
    }
}

}  // namespace lc
