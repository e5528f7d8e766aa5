// The lens-system camera: its set-up, done once per camera, and the film
// points and pupil picks of a batch (sample_batch), built per instruction set.
#include "cameras/lens_system.h"

#include "cpu_kernels.h"

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

namespace {

// LensSystemCamera::sample_batch's work, per instruction set.
LC_BUILT_PER_ISA void sample_lanes(const LensSystemCamera& c, const Point2f* raster_px, const Point2f* lens_sample,
                                   int n, LensRayBatch* batch, double* area_mm2) {
    LensAimBatch aim;
    // Film points first, in loops of their own: film_point's arithmetic,
    // with the square roots in a plain array loop that GCC vectorises
    // (two per instruction at the baseline), none waiting behind the
    // picks' branches.
    for (int i = 0; i < kLensBatch; ++i) {
        const Point2f p = raster_px[i < n ? i : 0];
        aim.film_x_mm[i] = (0.5 * c.width_px - double(p.x)) * c.film_mm_per_px_x;
        aim.film_y_mm[i] = (double(p.y) - 0.5 * c.height_px) * c.film_mm_per_px_y;
    }
    for (int i = 0; i < kLensBatch; ++i)
        aim.film_r_mm[i] = std::sqrt(aim.film_x_mm[i] * aim.film_x_mm[i] + aim.film_y_mm[i] * aim.film_y_mm[i]);
    for (int i = 0; i < kLensBatch; ++i) aim.u_radial[i] = double(lens_sample[i < n ? i : 0].x);
    c.pupil->pick_batch(aim.film_r_mm, lens_sample, n, &aim, area_mm2, batch->alive);
    aim_batch(aim, c.aim_planes(), batch, c.trace_kernel);
}

}  // namespace

FilmPlacement LensSystemCamera::film_placement() const {
    return {float(0.5 * width_px), float(0.5 * height_px), float(film_mm_per_px_x), float(film_mm_per_px_y)};
}

void LensSystemCamera::look_up_batch(const Point2f* raster_px, const Point2f* lens_sample, int n,
                                     LensRayBatch* batch, double* area_mm2) const {
    LensRaysF rays;
    look_up_rays(raster_px, lens_sample, n, &rays);
    for (int i = 0; i < kLensBatch; ++i) batch->ox[i] = double(rays.ox[i]);
    for (int i = 0; i < kLensBatch; ++i) batch->oy[i] = double(rays.oy[i]);
    for (int i = 0; i < kLensBatch; ++i) batch->oz[i] = double(rays.oz[i]);
    for (int i = 0; i < kLensBatch; ++i) batch->dx[i] = double(rays.dx[i]);
    for (int i = 0; i < kLensBatch; ++i) batch->dy[i] = double(rays.dy[i]);
    for (int i = 0; i < kLensBatch; ++i) batch->dz[i] = double(rays.dz[i]);
    for (int i = 0; i < kLensBatch; ++i) area_mm2[i] = double(rays.weight_mm2[i]);
    std::copy_n(rays.alive, kLensBatch, batch->alive);
}

void LensSystemCamera::look_up_rays(const Point2f* raster_px, const Point2f* lens_sample, int n,
                                    LensRaysF* rays) const {
    bool exact[kLensBatch];
    look_up_lens_rays(*ray_table, film_placement(), raster_px, lens_sample, n, rays, exact);
    bool any = false;
    for (int i = 0; i < kLensBatch; ++i) any |= exact[i];
    if (!any) return;
    // Traced in double, then rounded to float into their lanes: the rest of
    // the way is the table's.
    LensRayBatch traced;
    double area_mm2[kLensBatch];
    trace_lanes(raster_px, lens_sample, n, exact, &traced, area_mm2);
    for (int i = 0; i < n; ++i) {
        if (!exact[i]) continue;
        rays->alive[i] = traced.alive[i];
        if (!traced.alive[i]) continue;
        rays->ox[i] = float(traced.ox[i]), rays->oy[i] = float(traced.oy[i]), rays->oz[i] = float(traced.oz[i]);
        rays->dx[i] = float(traced.dx[i]), rays->dy[i] = float(traced.dy[i]), rays->dz[i] = float(traced.dz[i]);
        rays->weight_mm2[i] = float(area_mm2[i]);
    }
}

bool LensSystemCamera::look_up_ray_rows(const Point2f* raster_px, const Point2f* lens_sample, int n,
                                        CameraRayRows* rows, float* weight, bool* alive,
                                        const LensPencilCheck* check) const {
    LensRaysF rays;
    look_up_rays(raster_px, lens_sample, n, &rays);
    lens_to_world_rows(LensToWorldF(lens_to_world()), rays, rows, weight);
    for (int i = 0; i < kLensBatch; ++i) alive[i] = i < n && rays.alive[i];
    return !check || lens_rays_within(*check, rays, alive);
}

void LensSystemCamera::trace_lanes(const Point2f* raster_px, const Point2f* lens_sample, int n, const bool* which,
                                   LensRayBatch* batch, double* area_mm2) const {
    int lane[kLensBatch], m = 0;
    Point2f raster[kLensBatch], lens[kLensBatch];  // zeroed (Point2f's initialisers): only here, off the common path
    for (int i = 0; i < n; ++i)
        if (which[i]) lane[m] = i, raster[m] = raster_px[i], lens[m] = lens_sample[i], ++m;
    LensRayBatch traced;
    double traced_area_mm2[kLensBatch], cos_theta[kLensBatch];
    trace_exactly(raster, lens, m, &traced, traced_area_mm2, cos_theta);
    for (int j = 0; j < m; ++j) {
        const int i = lane[j];
        batch->alive[i] = traced.alive[j];
        if (!traced.alive[j]) continue;
        batch->ox[i] = traced.ox[j], batch->oy[i] = traced.oy[j], batch->oz[i] = traced.oz[j];
        batch->dx[i] = traced.dx[j], batch->dy[i] = traced.dy[j], batch->dz[i] = traced.dz[j];
        const double cos2 = cos_theta[j] * cos_theta[j];
        area_mm2[i] = cos2 * cos2 * traced_area_mm2[j];
    }
}

void LensSystemCamera::sample_batch(const Point2f* raster_px, const Point2f* lens_sample, int n, LensRayBatch* batch,
                                    double* area_mm2) const {
    sample_lanes(*this, raster_px, lens_sample, n, batch, area_mm2);
}

}  // namespace lc
