#include "lens/lens_to_world.h"

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

}  // namespace lc
