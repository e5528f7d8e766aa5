#include "lens/lens_to_world.h"

namespace lc {

// A plain loop over the batch, which GCC vectorises once per instruction set
// (target_clones picks the clone when the library loads). Only multiplies
// and adds, no FMA (-ffp-contract=off): every clone gives camera_ray's bits.
__attribute__((target_clones("default", "avx2", "avx512f"))) void lens_to_world_batch(
    const LensToWorld& t, const LensRayBatch& lens, const double* cos_theta, const double* area_mm2,
    WorldRayBatch* out) {
    for (int i = 0; i < kLensBatch; ++i) {
        const double cos2 = cos_theta[i] * cos_theta[i];
        out->weight[i] = cos2 * cos2 * area_mm2[i] * t.weight_per_mm2;
        // Lens frame (mm, +z toward the film) -> camera frame (m, +z toward the scene)
        const double cx = lens.ox[i] * 1e-3, cy = lens.oy[i] * 1e-3, cz = (t.entrance_pupil_z_mm - lens.oz[i]) * 1e-3;
        const double vx = lens.dx[i], vy = lens.dy[i], vz = -lens.dz[i];
        const Frame& f = t.world_from_camera;
        out->ox[i] = f.origin.x + f.right.x * cx + f.up.x * cy + f.forward.x * cz;
        out->oy[i] = f.origin.y + f.right.y * cx + f.up.y * cy + f.forward.y * cz;
        out->oz[i] = f.origin.z + f.right.z * cx + f.up.z * cy + f.forward.z * cz;
        out->dx[i] = f.right.x * vx + f.up.x * vy + f.forward.x * vz;
        out->dy[i] = f.right.y * vx + f.up.y * vy + f.forward.y * vz;
        out->dz[i] = f.right.z * vx + f.up.z * vy + f.forward.z * vz;
    }
}

}  // namespace lc
