#include "lens/lens_to_world.h"

#include "cpu_kernels.h"

namespace lc {
namespace {

// One lane of the lens frame (mm, +z toward the film) -> the world (m):
// camera_ray's arithmetic, shared by both batch forms below.
struct WorldLane {
    double ox, oy, oz, dx, dy, dz, weight;
};

inline WorldLane world_lane(const LensToWorld& t, const LensRayBatch& lens, const double* cos_theta,
                            const double* area_mm2, int i) {
    WorldLane w;
    const double cos2 = cos_theta[i] * cos_theta[i];
    w.weight = cos2 * cos2 * area_mm2[i] * t.weight_per_mm2;
    // Lens frame (mm, +z toward the film) -> camera frame (m, +z toward the scene)
    const double cx = lens.ox[i] * 1e-3, cy = lens.oy[i] * 1e-3, cz = (t.entrance_pupil_z_mm - lens.oz[i]) * 1e-3;
    const double vx = lens.dx[i], vy = lens.dy[i], vz = -lens.dz[i];
    const Frame& f = t.world_from_camera;
    w.ox = f.origin.x + f.right.x * cx + f.up.x * cy + f.forward.x * cz;
    w.oy = f.origin.y + f.right.y * cx + f.up.y * cy + f.forward.y * cz;
    w.oz = f.origin.z + f.right.z * cx + f.up.z * cy + f.forward.z * cz;
    w.dx = f.right.x * vx + f.up.x * vy + f.forward.x * vz;
    w.dy = f.right.y * vx + f.up.y * vy + f.forward.y * vz;
    w.dz = f.right.z * vx + f.up.z * vy + f.forward.z * vz;
    return w;
}

}  // namespace

// A plain loop over the batch, which GCC vectorises once per instruction set
// (target_clones picks the clone when the library loads). Only multiplies
// and adds, no FMA (-ffp-contract=off): every clone gives camera_ray's bits.
__attribute__((target_clones("default", "avx2", "avx512f"))) void lens_to_world_batch(
    const LensToWorld& t, const LensRayBatch& lens, const double* cos_theta, const double* area_mm2,
    WorldRayBatch* out) {
    for (int i = 0; i < kLensBatch; ++i) {
        const WorldLane w = world_lane(t, lens, cos_theta, area_mm2, i);
        out->ox[i] = w.ox, out->oy[i] = w.oy, out->oz[i] = w.oz;
        out->dx[i] = w.dx, out->dy[i] = w.dy, out->dz[i] = w.dz;
        out->weight[i] = w.weight;
    }
}

__attribute__((target_clones("default", "avx2", "avx512f"))) void lens_to_world_rows(
    const LensToWorld& t, const LensRayBatch& lens, const double* cos_theta, const double* area_mm2,
    CameraRayRows* rows, float* weight) {
    for (int i = 0; i < kLensBatch; ++i) {
        const WorldLane w = world_lane(t, lens, cos_theta, area_mm2, i);
        rows->origin[0][i] = float(w.ox), rows->origin[1][i] = float(w.oy), rows->origin[2][i] = float(w.oz);
        rows->direction[0][i] = float(w.dx), rows->direction[1][i] = float(w.dy);
        rows->direction[2][i] = float(w.dz);
        weight[i] = float(w.weight);
    }
}

LensToWorldF::LensToWorldF(const LensToWorld& t) {
    const Frame& f = t.world_from_camera;
    const Vec3d* axes[4] = {&f.origin, &f.right, &f.up, &f.forward};
    float* rows[4] = {origin, right, up, forward};
    for (int a = 0; a < 4; ++a)
        rows[a][0] = float(axes[a]->x), rows[a][1] = float(axes[a]->y), rows[a][2] = float(axes[a]->z);
    entrance_pupil_z_mm = float(t.entrance_pupil_z_mm);
    weight_per_mm2 = float(t.weight_per_mm2);
}

LC_BUILT_PER_ISA void lens_to_world_rows(const LensToWorldF& t, const LensRaysF& lens, CameraRayRows* rows,
                                         float* weight) {
    // The frame in locals and the arrays restrict: the stores below might
    // otherwise alias them, and GCC would not vectorise the loop over the lanes.
    const float o0 = t.origin[0], o1 = t.origin[1], o2 = t.origin[2];
    const float r0 = t.right[0], r1 = t.right[1], r2 = t.right[2];
    const float u0 = t.up[0], u1 = t.up[1], u2 = t.up[2];
    const float f0 = t.forward[0], f1 = t.forward[1], f2 = t.forward[2];
    const float pupil_z_mm = t.entrance_pupil_z_mm, per_mm2 = t.weight_per_mm2;
    const float *__restrict ox = lens.ox, *__restrict oy = lens.oy, *__restrict oz = lens.oz;
    const float *__restrict dx = lens.dx, *__restrict dy = lens.dy, *__restrict dz = lens.dz;
    const float* __restrict weight_mm2 = lens.weight_mm2;
    float *__restrict wx = rows->origin[0], *__restrict wy = rows->origin[1], *__restrict wz = rows->origin[2];
    float *__restrict vx_out = rows->direction[0], *__restrict vy_out = rows->direction[1],
          *__restrict vz_out = rows->direction[2];
    float* __restrict w = weight;
    for (int i = 0; i < kLensBatch; ++i) {
        w[i] = weight_mm2[i] * per_mm2;
        // Lens frame (mm, +z toward the film) -> camera frame (m, +z toward the scene)
        const float cx = ox[i] * 1e-3f, cy = oy[i] * 1e-3f, cz = (pupil_z_mm - oz[i]) * 1e-3f;
        const float vx = dx[i], vy = dy[i], vz = -dz[i];
        wx[i] = o0 + r0 * cx + u0 * cy + f0 * cz;
        wy[i] = o1 + r1 * cx + u1 * cy + f1 * cz;
        wz[i] = o2 + r2 * cx + u2 * cy + f2 * cz;
        vx_out[i] = r0 * vx + u0 * vy + f0 * vz;
        vy_out[i] = r1 * vx + u1 * vy + f1 * vz;
        vz_out[i] = r2 * vx + u2 * vy + f2 * vz;
    }
}

}  // namespace lc
