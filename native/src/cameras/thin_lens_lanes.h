// The thin lens's arithmetic for a whole batch of samples at once (the render
// loop hands a camera kCameraBatch of them): one sample's ray is a chain of a
// square root and three divisions in double precision, which leaves the core
// waiting on their latency; side by side in SIMD lanes those overlap.
#pragma once

#include "cameras/camera_ray.h"
#include "samplers.h"
#include "vec.h"

namespace lc {

// Lens points and film points (screen units, z = 1) to world rays, lane by
// lane, with exactly the operations of ThinLensCamera::ray_from_lens_point in
// its order (no fused multiply-adds): the same bits as one ray at a time, on
// every instruction set. origin_m and direction are [3][n] (x, y, z rows).
void thin_lens_rays_lanes(int n, const double* screen_x, const double* screen_y, const double* lens_x_m,
                          const double* lens_y_m, double inverse_focus_per_m, const Frame& world_from_camera,
                          double* const origin_m[3], double* const direction[3]);

// Raster points to screen points (z = 1), lane by lane: film.direction's x
// and y for each, with its operations (two divisions each, in SIMD here).
void screen_points_lanes(int n, const FilmToScreen& film, const Point2f* raster_px, double* screen_x,
                         double* screen_y);

// Lens samples to points of the unit disk by the concentric map, lane by
// lane: concentric_disk (samplers.h) for each, so the same bits as map_to_disk.
void concentric_disk_lanes(int n, const Point2f* lens_sample, double* disk_x, double* disk_y);

}  // namespace lc
