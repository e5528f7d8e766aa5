// From film points and picked pupil triangles to the rays that enter the lens
// (lens frame, mm): the per-ray set-up before the trace, done for a whole
// batch in lane loops so that its square roots and divisions run in SIMD
// (lens_aim_lanes.h) like the trace's. The scalar aim_one is the reference
// every kernel matches bit for bit.
#pragma once

#include <cmath>

#include "lens/lens_trace.h"

namespace lc {

// The fan triangle of the exit-pupil polygon a sample landed in (for a film
// point on +x), and the sample's place in it: the pupil point is
// centre + sqrt(u_radial) * ((1 - across) * a + across * b).
struct PupilPick {
    double centre_x_mm;
    double a_x_mm, a_y_mm, b_x_mm, b_y_mm;  // the triangle's outer vertices, from the centre
    double across;                           // 0 at a, 1 at b
    double area_mm2;                         // the polygon's area (uniform density 1 / area)
};

// A batch's film points and picks, structure of arrays.
struct LensAimBatch {
    double film_x_mm[kLensBatch], film_y_mm[kLensBatch], film_r_mm[kLensBatch];
    double u_radial[kLensBatch];
    double centre_x_mm[kLensBatch];
    double a_x_mm[kLensBatch], a_y_mm[kLensBatch], b_x_mm[kLensBatch], b_y_mm[kLensBatch];
    double across[kLensBatch];
};

// Film and sampling-plane positions along the axis.
struct AimPlanes {
    double film_z_mm, pupil_plane_z_mm;
};

// The ray from film point (x, y) at distance r from the axis toward the pick,
// rotated from +x to the film point's azimuth.
inline LensRay aim_one(double x, double y, double r, double u_radial, const PupilPick& p, AimPlanes planes) {
    const double s = std::sqrt(u_radial), t = p.across;
    const double lx = p.centre_x_mm + s * ((1.0 - t) * p.a_x_mm + t * p.b_x_mm);
    const double ly = s * ((1.0 - t) * p.a_y_mm + t * p.b_y_mm);
    const double inverse_r = r > 0.0 ? 1.0 / r : 0.0;
    const double cos_phi = r > 0.0 ? x * inverse_r : 1.0, sin_phi = y * inverse_r;
    const double px = cos_phi * lx - sin_phi * ly, py = sin_phi * lx + cos_phi * ly;
    const double tx = px - x, ty = py - y, tz = planes.pupil_plane_z_mm - planes.film_z_mm;
    const double inverse_length = 1.0 / std::sqrt(tx * tx + ty * ty + tz * tz);
    return LensRay{{x, y, planes.film_z_mm}, {tx * inverse_length, ty * inverse_length, tz * inverse_length}};
}

inline void aim_batch_portable(const LensAimBatch& in, AimPlanes planes, LensRayBatch* out) {
    for (int i = 0; i < kLensBatch; ++i) {
        const PupilPick p{in.centre_x_mm[i], in.a_x_mm[i], in.a_y_mm[i], in.b_x_mm[i], in.b_y_mm[i], in.across[i], 0.0};
        const LensRay ray = aim_one(in.film_x_mm[i], in.film_y_mm[i], in.film_r_mm[i], in.u_radial[i], p, planes);
        out->ox[i] = ray.origin_mm.x, out->oy[i] = ray.origin_mm.y, out->oz[i] = ray.origin_mm.z;
        out->dx[i] = ray.direction.x, out->dy[i] = ray.direction.y, out->dz[i] = ray.direction.z;
    }
}

// The same in SIMD (lens_trace_avx2.cpp, lens_trace_avx512.cpp).
void aim_batch_avx2(const LensAimBatch& in, AimPlanes planes, LensRayBatch* out);
void aim_batch_avx512(const LensAimBatch& in, AimPlanes planes, LensRayBatch* out);

// Origins and directions of every lane of out; alive is left alone.
inline void aim_batch(const LensAimBatch& in, AimPlanes planes, LensRayBatch* out, LensTraceKernel kernel) {
    switch (kernel) {
        case LensTraceKernel::Avx512: aim_batch_avx512(in, planes, out); return;
        case LensTraceKernel::Avx2: aim_batch_avx2(in, planes, out); return;
        case LensTraceKernel::Portable: aim_batch_portable(in, planes, out); return;
    }
}

}  // namespace lc
