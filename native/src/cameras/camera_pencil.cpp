#include "cameras/camera_pencil.h"

#include <algorithm>
#include <cmath>

namespace lc {

bool CameraPencil::may_meet_ball(const float centre_m[3], float radius_m) const {
    const Frame& f = world_from_camera;
    const Vec3d d{double(centre_m[0]) - sweep_mid_m.x - f.origin.x, double(centre_m[1]) - sweep_mid_m.y - f.origin.y,
                  double(centre_m[2]) - sweep_mid_m.z - f.origin.z};
    const double x = dot(d, f.right), y = dot(d, f.up), z = dot(d, f.forward);
    // Far above the float rounding of the rays' origins (relative to the
    // lens centre's coordinates and the camera's offset), directions and the screen points.
    const double scale_m = length(d) + double(radius_m) + std::fabs(f.origin.x) + std::fabs(f.origin.y) +
                           std::fabs(f.origin.z) + lens_radius_m + length(sweep_mid_m) + sweep_half_m;
    const double r = double(radius_m) + sweep_half_m + 1e-5 * scale_m;
    if (!std::isfinite(x + y + z + r + scale_m)) return true;
    if (z + r < 0.0) return false;  // wholly behind the lens
    const double depth[2] = {std::max(z - r, 0.0), z + r};
    const double lateral[2] = {x, y};
    for (int a = 0; a < 2; ++a) {
        double lo = INFINITY, hi = -INFINITY;
        for (const double at : depth) {
            const double blur = lens_radius_m * std::fabs(1.0 - inverse_focus_per_m * at);
            lo = std::min(lo, screen_lo[a] * at - blur);
            hi = std::max(hi, screen_hi[a] * at + blur);
        }
        if (lateral[a] - r > hi || lateral[a] + r < lo) return false;
    }
    return true;
}

}  // namespace lc
