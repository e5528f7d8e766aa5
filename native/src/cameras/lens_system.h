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

    // Everything up to the trace; also used for the pass-rate statistics.
    // Returns false without tracing when the film point is outside the image circle.
    bool sample_lens_ray(Point2f raster_px, Point2f lens_sample, LensRay* ray, double* area_mm2) const {
        // Film point: the image is inverted on the film.
        double x = (0.5 - double(raster_px.x) / width_px) * film_width_mm;
        double y = (double(raster_px.y) / height_px - 0.5) * film_height_mm;
        double r = std::sqrt(x * x + y * y);  // hypot's overflow guard costs a libm call per ray
        PupilSample s;
        if (!pupil->sample(r, lens_sample, &s)) return false;
        // Rotate the pupil sample from the +x ring frame to the film point's azimuth.
        double cos_phi = r > 0.0 ? x / r : 1.0, sin_phi = r > 0.0 ? y / r : 0.0;
        double px = cos_phi * s.x_mm - sin_phi * s.y_mm, py = sin_phi * s.x_mm + cos_phi * s.y_mm;
        Vec3d p_film{x, y, film_z_mm};
        ray->origin_mm = p_film;
        ray->direction = normalize(Vec3d{px - x, py - y, pupil->plane_z_mm() - film_z_mm});
        *area_mm2 = s.area_mm2;
        return true;
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

    // The same for up to kLensBatch samples at once, traced in lockstep (the
    // render loop uses this; results equal generate_ray's).
    void generate_rays(const Point2f* raster_px, const Point2f* lens_sample, int n, MaybeRay* out) const {
        LensRayBatch batch;
        double area_mm2[kLensBatch], cos_theta[kLensBatch];
        for (int i = 0; i < kLensBatch; ++i) {
            LensRay ray{{0.0, 0.0, film_z_mm}, {0.0, 0.0, -1.0}};
            batch.alive[i] = i < n && sample_lens_ray(raster_px[i], lens_sample[i], &ray, &area_mm2[i]);
            cos_theta[i] = -ray.direction.z;
            batch.ox[i] = ray.origin_mm.x, batch.oy[i] = ray.origin_mm.y, batch.oz[i] = ray.origin_mm.z;
            batch.dx[i] = ray.direction.x, batch.dy[i] = ray.direction.y, batch.dz[i] = ray.direction.z;
        }
        trace_from_film_batch(elements, &batch, trace_kernel);
        for (int i = 0; i < n; ++i) {
            if (!batch.alive[i]) {
                out[i] = std::nullopt;
                continue;
            }
            LensRay ray{{batch.ox[i], batch.oy[i], batch.oz[i]}, {batch.dx[i], batch.dy[i], batch.dz[i]}};
            out[i] = camera_ray(ray, cos_theta[i], area_mm2[i]);
        }
    }

    // A ray that left the lens -> the camera ray with its irradiance weight.
    CameraRay camera_ray(const LensRay& ray, double cos_theta, double area_mm2) const {
        // Film irradiance weight: cos^4 theta * A / Z^2, normalised at the centre
        double axial_mm = film_z_mm - pupil->plane_z_mm();
        double cos2 = cos_theta * cos_theta;
        double weight = cos2 * cos2 * area_mm2 / (axial_mm * axial_mm) * inverse_centre_irradiance;
        // Lens frame (mm, +z toward the film) -> camera frame (m, +z toward the scene)
        Vec3d origin_camera{ray.origin_mm.x / 1000.0, ray.origin_mm.y / 1000.0,
                            (entrance_pupil_z_mm - ray.origin_mm.z) / 1000.0};
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
