// The thin lens's arithmetic for a whole batch of samples at once (the render
// loop hands a camera kCameraBatch of them), side by side in SIMD lanes, in
// single precision: the rays go to Embree as floats, and in double the
// batch's square roots and divisions, with the concentric map's, were a fifth
// of an empty scene's thin-lens render (perf). The cameras' one-ray
// generate_ray stays in double: the reference the batch is tested against
// (tests/test_camera_batches.py), as the lens system's trace is.
#pragma once

#include <cmath>
#include <vector>

#include "cameras/camera_ray.h"
#include "samplers.h"
#include "vec.h"

namespace lc {

// A camera frame's origin and axes rounded to float.
struct FrameF {
    float origin[3], right[3], up[3], forward[3];

    static FrameF of(const Frame& f) {
        return {{float(f.origin.x), float(f.origin.y), float(f.origin.z)},
                {float(f.right.x), float(f.right.y), float(f.right.z)},
                {float(f.up.x), float(f.up.y), float(f.up.z)},
                {float(f.forward.x), float(f.forward.y), float(f.forward.z)}};
    }
};

// The ray from lens point (lens_x_m, lens_y_m, 0) (camera frame) through the
// image of screen point (screen_x, screen_y, 1) on the plane of focus, in
// world space: ThinLensCamera::ray_from_lens_point in single precision (the
// direction is screen point - lens point * inverse_focus, normalised, so that
// any focus distance, 1e300 m too, stays finite). The pinhole is lens point 0.
[[gnu::always_inline]] inline void thin_lens_ray(float screen_x, float screen_y, float lens_x_m, float lens_y_m,
                                                 float inverse_focus_per_m, const FrameF& f, float origin_m[3],
                                                 float direction[3]) {
    const float dx = screen_x - lens_x_m * inverse_focus_per_m;
    const float dy = screen_y - lens_y_m * inverse_focus_per_m;
    const float inverse_length = 1.0f / std::sqrt(dx * dx + dy * dy + 1.0f);
    const float ux = dx * inverse_length, uy = dy * inverse_length;
    for (int k = 0; k < 3; ++k) {
        origin_m[k] = f.origin[k] + f.right[k] * lens_x_m + f.up[k] * lens_y_m;
        direction[k] = f.right[k] * ux + f.up[k] * uy + f.forward[k] * inverse_length;
    }
}

// thin_lens_ray for lanes [0, n): screen points and lens points (metres)
// to world rays, into rows [0, n) of out.
void thin_lens_rays_lanes(int n, const float* screen_x, const float* screen_y, const float* lens_x_m,
                          const float* lens_y_m, double inverse_focus_per_m, const FrameF& world_from_camera,
                          CameraRayRows* out);

// The same with each lane's own plane of focus (a dispersive thin lens's
// wavelengths): inverse_focus_per_m[i] for lane i, already in float.
void thin_lens_rays_lanes_focused(int n, const float* screen_x, const float* screen_y, const float* lens_x_m,
                                  const float* lens_y_m, const float* inverse_focus_per_m,
                                  const FrameF& world_from_camera, CameraRayRows* out);

// A dispersive thin lens's planes of focus, lane by lane: 1 / (plane of focus
// at nm[i]) from inverse_focus_per_m_by_nm (linear between whole nm from 380 nm,
// ThinLensCamera::inverse_focus_per_m_at's arithmetic).
void inverse_focus_lanes(int n, const std::vector<double>& inverse_focus_per_m_by_nm, const float* nm,
                         double* inverse_focus_per_m);

// Where a wavelength's film point lies, lane by lane, for
// ThinLensCamera::generate_shared_ray_rows: raster point + lens point x shift
// x scale (y against raster y), whether it stays in the raster point's pixel,
// and that point wrapped back into the pixel.
void shifted_film_points_lanes(int n, const Point2f* raster_px, const double* lens_x_m, const double* lens_y_m,
                               const double* shift_per_m, double x_scale, double y_scale, bool* stays,
                               Point2f* wrapped_px);

// Raster points to screen points (z = 1), lane by lane: film.screen_point for each.
void screen_points_lanes(int n, const FilmToScreen& film, const Point2f* raster_px, float* screen_x,
                         float* screen_y);

// Lens samples to points of the disk of radius radius_m by the concentric
// map, lane by lane: concentric_disk (samplers.h) for each, scaled in double
// and rounded to float, so the same bits as map_to_disk times the radius.
void concentric_disk_lanes(int n, const Point2f* lens_sample, double radius_m, float* disk_x_m, float* disk_y_m);

// The same points in double, before the rounding: radius_m times
// concentric_disk's point (ThinLensCamera::generate_rays_sharing's lens point).
void concentric_disk_lanes_double(int n, const Point2f* lens_sample, double radius_m, double* disk_x_m,
                                  double* disk_y_m);

}  // namespace lc
