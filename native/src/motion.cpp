#include "motion.h"

#include <algorithm>
#include <cmath>

namespace lc {

// Lane by lane without branches, so that GCC runs the rays side by side, once
// per instruction set (target_clones picks the clone when the library loads):
// a branching test per ray, most of its time in mispredictions, cost as much
// as Embree's second traversal itself. Subtractions, multiplications and
// comparisons only: every clone makes the same decisions.
__attribute__((target_clones("default", "avx2", "avx512f"))) bool swept_boxes_met(
    const float* lo_hi, int n_boxes, const float* const origin[3], const float* const direction[3],
    const float* t_max, const int* active, int* hit) {
    constexpr int N = SweptBounds::kLanes;
    // The reciprocals once per ray, not once per box: a division costs as
    // much as the rest of a box's test.
    float inv[3][N];
    for (int a = 0; a < 3; ++a)
        for (int i = 0; i < N; ++i) inv[a][i] = 1.0f / direction[a][i];
    int met[N] = {};
    for (int k = 0; k < n_boxes; ++k) {
        const float* lo = lo_hi + 6 * k;
        const float* hi = lo + 3;
        float t0[N], t1[N];
        for (int i = 0; i < N; ++i) t0[i] = 0.0f, t1[i] = t_max[i];
        for (int a = 0; a < 3; ++a)
            for (int i = 0; i < N; ++i) {
                const float o = origin[a][i];
                const float t_lo = (lo[a] - o) * inv[a][i], t_hi = (hi[a] - o) * inv[a][i];
                float near = t_lo > t_hi ? t_hi : t_lo, far = t_lo > t_hi ? t_lo : t_hi;
                // Parallel to the slab: all of the segment inside it, or none.
                const bool parallel = direction[a][i] == 0.0f, within = o >= lo[a] && o <= hi[a];
                near = parallel ? (within ? -INFINITY : INFINITY) : near;
                far = parallel ? (within ? INFINITY : -INFINITY) : far;
                t0[i] = near > t0[i] ? near : t0[i];
                t1[i] = far < t1[i] ? far : t1[i];
            }
        for (int i = 0; i < N; ++i) met[i] |= t0[i] > t1[i] ? 0 : 1;
    }
    int any = 0;
    for (int i = 0; i < N; ++i) {
        hit[i] = active[i] && met[i] ? -1 : 0;
        any |= hit[i];
    }
    return any != 0;
}

// Each sphere where Embree puts it at the ray's time (its centre interpolated
// between open and close), against the ray's segment: the squared distance
// from the centre to the segment's nearest point, against the squared radius
// with margins for the rounding of both tests. NaN keeps the ray.
__attribute__((target_clones("default", "avx2", "avx512f"))) bool moving_spheres_met(
    const float* spheres, int n, const float* const origin[3], const float* const direction[3],
    const float* t_max, const float* time, const int* active, int* hit) {
    constexpr int N = SweptBounds::kLanes;
    float inv_dd[N];
    for (int i = 0; i < N; ++i)
        inv_dd[i] = 1.0f / (direction[0][i] * direction[0][i] + direction[1][i] * direction[1][i] +
                            direction[2][i] * direction[2][i]);
    // Rounding grows with the coordinates: each lane's origin, each sphere's centre.
    float origin_size[N];
    for (int i = 0; i < N; ++i) {
        const float x = std::fabs(origin[0][i]), y = std::fabs(origin[1][i]), z = std::fabs(origin[2][i]);
        origin_size[i] = x > y ? (x > z ? x : z) : (y > z ? y : z);
    }
    int met[N] = {};
    for (int k = 0; k < n; ++k) {
        const float* c = spheres + 7 * k;
        const float ex = c[3] - c[0], ey = c[4] - c[1], ez = c[5] - c[2], r = c[6];
        float centre_size = 1.0f;
        for (int a = 0; a < 6; ++a) centre_size = std::max(centre_size, std::fabs(c[a]));
        for (int i = 0; i < N; ++i) {
            const float dx = direction[0][i], dy = direction[1][i], dz = direction[2][i], u = time[i];
            const float wx = c[0] + u * ex - origin[0][i], wy = c[1] + u * ey - origin[1][i],
                        wz = c[2] + u * ez - origin[2][i];
            // Nearest point of the segment t in [0, t_max] to the centre
            float t = (wx * dx + wy * dy + wz * dz) * inv_dd[i];
            t = t > t_max[i] ? t_max[i] : t;
            t = t < 0.0f ? 0.0f : t;
            const float qx = wx - t * dx, qy = wy - t * dy, qz = wz - t * dz;
            const float distance2 = qx * qx + qy * qy + qz * qz;
            // A margin of some 300 float steps of the largest coordinates: Embree's
            // own test (the same distance, with an approximate reciprocal) may
            // meet a sphere a few steps outside it; but less than the lift off
            // a surface (scene_trace.cpp), so that shadow rays from a moving
            // sphere's own surface are not asked about it.
            const float reach = r * (1.0f + 2e-5f) + 2e-5f * (centre_size + origin_size[i]);
            met[i] |= distance2 > reach * reach ? 0 : 1;
        }
    }
    int any = 0;
    for (int i = 0; i < N; ++i) {
        hit[i] = active[i] && met[i] ? -1 : 0;
        any |= hit[i];
    }
    return any != 0;
}

}  // namespace lc
