// The last step of a lens-system camera ray, for a whole batch: from the lens
// frame (mm) to the world (m), with the film-irradiance weight. The same
// arithmetic as LensSystemCamera::camera_ray, lane by lane.
#pragma once

#include "cameras/camera_ray.h"
#include "lens/lens_ray_table.h"
#include "lens/lens_trace.h"
#include "vec.h"

namespace lc {

struct LensToWorld {
    Frame world_from_camera;
    double entrance_pupil_z_mm;  // lens-frame z of the camera origin
    // cos^4 theta * area times this is the weight: 1 / Z^2 (Z the film to
    // sampling-plane distance) over the centre irradiance
    double weight_per_mm2;
};

struct WorldRayBatch {
    double ox[kLensBatch], oy[kLensBatch], oz[kLensBatch];
    double dx[kLensBatch], dy[kLensBatch], dz[kLensBatch];
    double weight[kLensBatch];
};

void lens_to_world_batch(const LensToWorld& t, const LensRayBatch& lens, const double* cos_theta,
                         const double* area_mm2, WorldRayBatch* out);

// The same rays rounded to float, straight into the render loop's rows, with
// their weights (the same bits as lens_to_world_batch's, rounded once at the
// end): no double columns between the trace and the packet.
void lens_to_world_rows(const LensToWorld& t, const LensRayBatch& lens, const double* cos_theta,
                        const double* area_mm2, CameraRayRows* rows, float* weight);

// The same step in single precision for the lens-ray table's rays
// (LensRaysF), which are float already: LensToWorld rounded to float once per
// batch, each lane's arithmetic in float in camera_ray's order (no FMA, so
// every instruction set gives the same bits). The world rays differ from the
// double step's by float rounding of the sum (under 1e-6 relative), far
// within the table's own interpolation error.
struct LensToWorldF {
    float origin[3], right[3], up[3], forward[3];
    float entrance_pupil_z_mm, weight_per_mm2;
    explicit LensToWorldF(const LensToWorld& t);
};

void lens_to_world_rows(const LensToWorldF& t, const LensRaysF& lens, CameraRayRows* rows, float* weight);

// The frame that takes a lens ray to the world as t takes its mirror image
// (mirror bit 0: the lens frame's x turned over, bit 1: y): right and up
// turned over instead. The same bits: each is a product's sign.
inline LensToWorld mirrored_frame(LensToWorld t, unsigned mirror) {
    if (mirror & 1u) t.world_from_camera.right = t.world_from_camera.right * -1.0;
    if (mirror & 2u) t.world_from_camera.up = t.world_from_camera.up * -1.0;
    return t;
}
inline LensToWorldF mirrored_frame(LensToWorldF t, unsigned mirror) {
    for (int a = 0; a < 3; ++a) {
        if (mirror & 1u) t.right[a] = -t.right[a];
        if (mirror & 2u) t.up[a] = -t.up[a];
    }
    return t;
}

}  // namespace lc
