// The lens-system camera's set-up, done once per camera (not per ray).
#include "cameras/lens_system.h"

namespace lc {

void calibrate_centre_irradiance(LensSystemCamera* camera) {
    camera->inverse_centre_irradiance = 1.0;
    // Midpoint rule: 128 steps from the pupil centre outward (u.x) times 1024
    // steps round it (u.y: 16 across each of the 64 fan triangles).
    constexpr int kRadial = 128, kAround = 1024;
    // A batch at a time through the double trace: generate_ray's rays, bit for
    // bit, several times faster than one at a time.
    const LensTracePrecision render_precision = camera->trace_precision;
    camera->trace_precision = LensTracePrecision::Double;
    static_assert(kRadial % kCameraBatch == 0, "whole batches, each within one step round");
    Point2f raster[kCameraBatch], u[kCameraBatch];
    for (Point2f& p : raster) p = {float(camera->width_px) * 0.5f, float(camera->height_px) * 0.5f};
    MaybeRay rays[kCameraBatch];
    double sum = 0.0;
    for (int j = 0; j < kAround; ++j)
        for (int first = 0; first < kRadial; first += kCameraBatch) {
            for (int k = 0; k < kCameraBatch; ++k) u[k] = {(first + k + 0.5f) / kRadial, (j + 0.5f) / kAround};
            camera_rays(*camera, raster, u, kCameraBatch, rays);
            for (const MaybeRay& ray : rays)
                if (ray) sum += ray->weight;
        }
    camera->trace_precision = render_precision;
    double irradiance = sum / (double(kRadial) * kAround);
    camera->inverse_centre_irradiance = irradiance > 0.0 ? 1.0 / irradiance : 0.0;
}

}  // namespace lc
