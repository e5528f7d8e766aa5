// The lens-system camera's set-up, done once per camera (not per ray).
#include "cameras/lens_system.h"

namespace lc {

void calibrate_centre_irradiance(LensSystemCamera* camera) {
    camera->inverse_centre_irradiance = 1.0;
    // Midpoint rule: 128 steps from the pupil centre outward (u.x) times 1024
    // steps round it (u.y: 16 across each of the 64 fan triangles).
    constexpr int kRadial = 128, kAround = 1024;
    Point2f centre{float(camera->width_px) * 0.5f, float(camera->height_px) * 0.5f};
    double sum = 0.0;
    for (int j = 0; j < kAround; ++j)
        for (int i = 0; i < kRadial; ++i) {
            Point2f u{(i + 0.5f) / kRadial, (j + 0.5f) / kAround};
            MaybeRay ray = camera->generate_ray(centre, u);
            if (ray) sum += ray->weight;
        }
    double irradiance = sum / (double(kRadial) * kAround);
    camera->inverse_centre_irradiance = irradiance > 0.0 ? 1.0 / irradiance : 0.0;
}

}  // namespace lc
