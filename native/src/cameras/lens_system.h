// Full lens system (Kolb et al. 1995; paper section 2.4): a film point, a point
// on the exit-pupil region behind the lens, and an exact Snell trace through
// every surface. Vignetted rays come back as nothing. The weight turns
// radiance into film irradiance (cos^4 and the sampled pupil area over the
// squared axial distance), divided by its value at the film centre for a
// uniform scene, so the centre of a uniform scene reads 1 (DESIGN.md).
#pragma once

#include <cmath>
#include <memory>
#include <vector>

#include "cameras/camera_ray.h"
#include "lens/exit_pupil.h"
#include "lens/lens_trace.h"
#include "scene.h"

namespace lc {

static_assert(kLensBatch == kCameraBatch, "generate_rays takes the render loop's whole camera batch");

struct LensSystemCamera {
    Frame world_from_camera;           // origin at the entrance-pupil centre
    std::vector<LensElement> elements; // scene side first, lens frame (mm)
    double film_z_mm;                  // film plane, lens frame
    double entrance_pupil_z_mm;        // lens-frame z of the camera origin
    double film_width_mm, film_height_mm;
    int width_px, height_px;
    std::shared_ptr<const ExitPupil> pupil;
    double inverse_centre_irradiance = 1.0;  // set by calibrate()
    LensTraceKernel trace_kernel = best_lens_trace_kernel();  // all give the same bits
    // Derived from the above once: a division per ray costs more than the
    // rest of the ray's set-up.
    double film_mm_per_px_x = film_width_mm / width_px, film_mm_per_px_y = film_height_mm / height_px;
    double inverse_axial2_per_mm2 = 1.0 / ((film_z_mm - pupil->plane_z_mm()) * (film_z_mm - pupil->plane_z_mm()));

    // Everything up to the trace; also used for the pass-rate statistics.
    // Returns false without tracing when the film point is outside the image circle.
    bool sample_lens_ray(Point2f raster_px, Point2f lens_sample, LensRay* ray, double* area_mm2) const {
        double x, y, r;
        film_point(raster_px, &x, &y, &r);
        PupilSample s;
        if (!pupil->sample(r, lens_sample, &s)) return false;
        *ray = aim(x, y, r, s);
        *area_mm2 = s.area_mm2;
        return true;
    }

    // Film point (lens frame, mm) of a raster position, and its distance from the axis.
    void film_point(Point2f raster_px, double* x, double* y, double* r) const {
        // The image is inverted on the film.
        *x = (0.5 * width_px - double(raster_px.x)) * film_mm_per_px_x;
        *y = (double(raster_px.y) - 0.5 * height_px) * film_mm_per_px_y;
        *r = std::sqrt(*x * *x + *y * *y);  // hypot's overflow guard costs a libm call per ray
    }

    // The ray from film point (x, y) toward a pupil sample drawn for the +x
    // ring, rotated to the film point's azimuth.
    LensRay aim(double x, double y, double r, const PupilSample& s) const {
        double inverse_r = r > 0.0 ? 1.0 / r : 0.0;
        double cos_phi = r > 0.0 ? x * inverse_r : 1.0, sin_phi = y * inverse_r;
        double px = cos_phi * s.x_mm - sin_phi * s.y_mm, py = sin_phi * s.x_mm + cos_phi * s.y_mm;
        Vec3d toward{px - x, py - y, pupil->plane_z_mm() - film_z_mm};
        return LensRay{{x, y, film_z_mm}, toward * (1.0 / std::sqrt(dot(toward, toward)))};
    }

    MaybeRay generate_ray(Point2f raster_px, Point2f lens_sample) const {
        // Sample a point of the exit-pupil region
        LensRay ray;
        double area_mm2;
        if (!sample_lens_ray(raster_px, lens_sample, &ray, &area_mm2)) return std::nullopt;
        double cos_theta = -ray.direction.z;
        // Trace the ray through the lens
        if (!trace_from_film(elements, &ray)) return std::nullopt;
        return camera_ray(ray, cos_theta, area_mm2);
    }

    // Lanes [0, n) of a batch set up for the trace, as sample_lens_ray does one
    // ray; lanes outside the image circle or past n are dead. The pupil
    // samples are kept for their areas.
    void sample_batch(const Point2f* raster_px, const Point2f* lens_sample, int n, LensRayBatch* batch,
                      PupilSample* pupil_samples) const {
        double x[kLensBatch], y[kLensBatch], r[kLensBatch];
        for (int i = 0; i < kLensBatch; ++i) film_point(raster_px[i < n ? i : 0], &x[i], &y[i], &r[i]);
        for (int i = 0; i < kLensBatch; ++i) {
            batch->alive[i] = i < n && pupil->sample(r[i], lens_sample[i], &pupil_samples[i]);
            if (!batch->alive[i]) pupil_samples[i] = PupilSample{0.0, 0.0, 0.0};
        }
        for (int i = 0; i < kLensBatch; ++i) {
            LensRay ray = aim(x[i], y[i], r[i], pupil_samples[i]);
            batch->ox[i] = ray.origin_mm.x, batch->oy[i] = ray.origin_mm.y, batch->oz[i] = ray.origin_mm.z;
            batch->dx[i] = ray.direction.x, batch->dy[i] = ray.direction.y, batch->dz[i] = ray.direction.z;
        }
    }

    // The same as generate_ray for up to kLensBatch samples at once, traced in
    // lockstep (the render loop uses this; results equal generate_ray's).
    void generate_rays(const Point2f* raster_px, const Point2f* lens_sample, int n, MaybeRay* out) const {
        LensRayBatch batch;
        PupilSample s[kLensBatch];
        sample_batch(raster_px, lens_sample, n, &batch, s);
        double cos_theta[kLensBatch];
        for (int i = 0; i < kLensBatch; ++i) cos_theta[i] = -batch.dz[i];
        trace_from_film_batch(elements, &batch, trace_kernel);
        for (int i = 0; i < n; ++i) {
            if (!batch.alive[i]) {
                out[i] = std::nullopt;
                continue;
            }
            LensRay ray{{batch.ox[i], batch.oy[i], batch.oz[i]}, {batch.dx[i], batch.dy[i], batch.dz[i]}};
            out[i] = camera_ray(ray, cos_theta[i], s[i].area_mm2);
        }
    }

    // A ray that left the lens -> the camera ray with its irradiance weight.
    CameraRay camera_ray(const LensRay& ray, double cos_theta, double area_mm2) const {
        // Film irradiance weight: cos^4 theta * A / Z^2, normalised at the centre
        double cos2 = cos_theta * cos_theta;
        double weight = cos2 * cos2 * area_mm2 * inverse_axial2_per_mm2 * inverse_centre_irradiance;
        // Lens frame (mm, +z toward the film) -> camera frame (m, +z toward the scene)
        Vec3d origin_camera{ray.origin_mm.x * 1e-3, ray.origin_mm.y * 1e-3,
                            (entrance_pupil_z_mm - ray.origin_mm.z) * 1e-3};
        Vec3d dir_camera{ray.direction.x, ray.direction.y, -ray.direction.z};
        return CameraRay{world_from_camera.world_from_camera_point(origin_camera),
                         world_from_camera.world_from_camera_vector(dir_camera), float(weight)};
    }
};

// Sets inverse_centre_irradiance so that a uniform scene of radiance 1 reads 1
// at the film centre: a stratified estimate over the centre ring's polygon.
void calibrate_centre_irradiance(LensSystemCamera* camera);

// Traced and passed counts for given samples (pass-rate statistics).
struct LensPassCounts {
    uint64_t samples = 0, traced = 0, passed = 0;
};
LensPassCounts count_lens_passes(const LensSystemCamera& camera, const Point2f* raster_px, const Point2f* lens,
                                 size_t n);

// Lens-only throughput: n random (film, pupil) samples traced through the
// lens on `threads` threads, no scene. Returns the seconds taken.
double measure_lens_throughput(const LensSystemCamera& camera, uint64_t n, int threads, LensPassCounts* counts);

}  // namespace lc
