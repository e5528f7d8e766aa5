// What every camera model returns for one (film sample, lens sample).
#pragma once

#include <optional>
#include <type_traits>
#include <utility>

#include "vec.h"

namespace lc {

struct CameraRay {
    Vec3d origin;     // world space, metres
    Vec3d direction;  // world space, unit length
    float weight;     // radiance scale: 1 for pinhole/thin/thick
};

// A camera's generate_ray returns std::nullopt for a vignetted sample.
using MaybeRay = std::optional<CameraRay>;

// *ray = that ray, written in place: assigning a CameraRay temporary made GCC
// copy it through the stack in overlapping halves, a store-forwarding stall
// per ray (a third of the pinhole's render_tile under perf).
inline void set_ray(MaybeRay* ray, double ox, double oy, double oz, double dx, double dy, double dz, float weight) {
    CameraRay& r = ray->emplace();
    r.origin.x = ox, r.origin.y = oy, r.origin.z = oz;
    r.direction.x = dx, r.direction.y = dy, r.direction.z = dz;
    r.weight = weight;
}

// The render loop hands samples to a camera this many at a time, gathered
// across the pixels of a tile: the lens system's SIMD trace keeps several
// registers of rays in flight to hide the latency of its square roots.
constexpr int kCameraBatch = 32;

// A batch's rays in columns, as the cameras find them (world space, metres):
// the render loop takes them from here into its packets, with no MaybeRay
// per ray between (whose double fields, stored and at once reloaded for the
// float packet, cost a store-forwarding stall per ray).
struct CameraRayBatch {
    double origin[3][kCameraBatch], direction[3][kCameraBatch];
    float weight[kCameraBatch];
    bool alive[kCameraBatch];  // false: vignetted
};

// A batch's rays in single precision, in rows (origin x, y, z, then
// direction), as the render loop's packets take them.
struct CameraRayRows {
    float origin[3][kCameraBatch], direction[3][kCameraBatch];
};

// Rays [0, n) of rows into batch, widened to double (exactly), every one
// alive with weight 1.
inline void widen_rows(const CameraRayRows& rows, int n, CameraRayBatch* batch) {
    for (int a = 0; a < 3; ++a)
        for (int i = 0; i < n; ++i)
            batch->origin[a][i] = double(rows.origin[a][i]), batch->direction[a][i] = double(rows.direction[a][i]);
    for (int i = 0; i < n; ++i) batch->weight[i] = 1.0f, batch->alive[i] = true;
}

// Rays [0, n) of a batch one at a time, for the callers that take MaybeRay.
inline void maybe_rays(const CameraRayBatch& batch, int n, MaybeRay* out) {
    for (int i = 0; i < n; ++i) {
        if (!batch.alive[i]) {
            out[i] = std::nullopt;
            continue;
        }
        set_ray(&out[i], batch.origin[0][i], batch.origin[1][i], batch.origin[2][i], batch.direction[0][i],
                batch.direction[1][i], batch.direction[2][i], batch.weight[i]);
    }
}

// Cameras that find a batch's rays in columns say so with
// generate_ray_batch(raster, lens, n, out) (CameraRayBatch).
template <class Camera, class = void>
struct GeneratesRayBatches : std::false_type {};
template <class Camera>
struct GeneratesRayBatches<Camera, std::void_t<decltype(std::declval<const Camera&>().generate_ray_batch(
                                       nullptr, nullptr, 0, static_cast<CameraRayBatch*>(nullptr)))>>
    : std::true_type {};

// Cameras whose rays are found in single precision and all pass with weight 1
// (the thin lens, the pinhole, the thick lens) say so with generate_ray_rows(raster, lens, n,
// out) (CameraRayRows): the render loop then takes them straight into its
// packets, with no double batch between (its stores and reloads, and the
// rounding back to float, were a fifth of an empty scene's render_tile).
template <class Camera, class = void>
struct GeneratesRayRows : std::false_type {};
template <class Camera>
struct GeneratesRayRows<Camera, std::void_t<decltype(std::declval<const Camera&>().generate_ray_rows(
                                    nullptr, nullptr, 0, static_cast<CameraRayRows*>(nullptr)))>> : std::true_type {};

// Cameras whose rays are found in float rows but may be vignetted and carry
// a weight (the lens system) say so with generate_weighted_ray_rows(raster,
// lens, n, rows, weight, alive): the render loop takes those rows straight
// into its packets too.
template <class Camera, class = void>
struct GeneratesWeightedRayRows : std::false_type {};
template <class Camera>
struct GeneratesWeightedRayRows<Camera, std::void_t<decltype(std::declval<const Camera&>().generate_weighted_ray_rows(
                                            nullptr, nullptr, 0, static_cast<CameraRayRows*>(nullptr),
                                            static_cast<float*>(nullptr), static_cast<bool*>(nullptr)))>>
    : std::true_type {};

// Rays for n <= kCameraBatch samples, one MaybeRay each: through the
// camera's batch (the same bits as generate_ray) where it has one.
template <class Camera>
void camera_rays(const Camera& camera, const Point2f* raster_px, const Point2f* lens, int n, MaybeRay* out) {
    if constexpr (GeneratesRayBatches<Camera>::value) {
        CameraRayBatch batch;
        camera.generate_ray_batch(raster_px, lens, n, &batch);
        maybe_rays(batch, n, out);
    } else {
        for (int i = 0; i < n; ++i) out[i] = camera.generate_ray(raster_px[i], lens[i]);
    }
}

// Raster position -> direction in camera space for an ideal perspective
// projection: the film (width film_w, distance d' behind the lens) mapped in
// front of the lens at z = 1. Raster x grows right, raster y grows down.
struct FilmToScreen {
    int width_px = 1, height_px = 1;
    double screen_half_width = 1.0;   // (film width / 2) / film distance
    double screen_half_height = 1.0;  // (film height / 2) / film distance

    Vec3d direction(Point2f raster_px) const {
        double sx = (2.0 * raster_px.x / width_px - 1.0) * screen_half_width;
        double sy = (1.0 - 2.0 * raster_px.y / height_px) * screen_half_height;
        return {sx, sy, 1.0};
    }

    // direction's x and y in single precision, as the thin lens and the
    // pinhole find their rays (thin_lens_lanes.h): one rounding per step.
    void screen_point(Point2f raster_px, float* x, float* y) const {
        *x = (raster_px.x * float(2.0 / width_px) - 1.0f) * float(screen_half_width);
        *y = (1.0f - raster_px.y * float(2.0 / height_px)) * float(screen_half_height);
    }
};

}  // namespace lc
