#include "motion.h"

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

// The squared distance from each ray's line to the nearest point of a
// capsule's axis, against the squared radius with a margin for the rounding
// of both (float cancellation grows with the squared distance to the axis);
// NaN keeps the ray.
__attribute__((target_clones("default", "avx2", "avx512f"))) void swept_spheres_met(
    const float* capsules, int n, const float* const origin[3], const float* const direction[3], int* hit) {
    constexpr int N = SweptBounds::kLanes;
    int met[N] = {};
    for (int k = 0; k < n; ++k) {
        const float* c = capsules + 7 * k;
        const float ex = c[3] - c[0], ey = c[4] - c[1], ez = c[5] - c[2], r = c[6];
        for (int i = 0; i < N; ++i) {
            const float dx = direction[0][i], dy = direction[1][i], dz = direction[2][i];
            const float wx = c[0] - origin[0][i], wy = c[1] - origin[1][i], wz = c[2] - origin[2][i];
            const float dd = dx * dx + dy * dy + dz * dz, ed = ex * dx + ey * dy + ez * dz;
            const float wd = wx * dx + wy * dy + wz * dz;
            // |w + s e|^2 - ((w + s e).d)^2 / dd is least over s in [0, 1] at s:
            const float a = (ex * ex + ey * ey + ez * ez) - ed * ed / dd;
            const float b = (wx * ex + wy * ey + wz * ez) - wd * ed / dd;
            float s = a > 0.0f ? -b / a : (b < 0.0f ? 1.0f : 0.0f);
            s = s > 1.0f ? 1.0f : (s < 0.0f ? 0.0f : s);
            const float qx = wx + s * ex, qy = wy + s * ey, qz = wz + s * ez;
            const float qq = qx * qx + qy * qy + qz * qz, qd = qx * dx + qy * dy + qz * dz;
            const float distance2 = qq - qd * qd / dd;
            const float limit = r * r * 1.0001f + 1e-5f * qq + 1e-12f;
            met[i] |= distance2 > limit ? 0 : 1;
        }
    }
    for (int i = 0; i < N; ++i) hit[i] = hit[i] && met[i] ? -1 : 0;
}

}  // namespace lc
