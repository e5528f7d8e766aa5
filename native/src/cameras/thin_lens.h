// Thin lens (Cook et al. 1984; paper section 2.2): a point on the lens
// aperture (a disk, or an N-blade polygon of the same area: aperture.h),
// aimed through the film point's image on the plane of focus.
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "aperture.h"
#include "cameras/camera_pencil.h"
#include "cameras/camera_ray.h"
#include "cameras/thin_lens_bands.h"
#include "cameras/thin_lens_lanes.h"
#include "samplers.h"
#include "spectral.h"
#include "spectral_bands.h"

namespace lc {

struct ThinLensCamera {
    Frame world_from_camera;  // origin at the lens centre
    FilmToScreen film;        // from the film distance d' = f d / (d - f)
    double lens_radius_m;     // f / (2 N): the circle's, whatever the aperture's shape
    double focus_distance_m;  // along the view axis
    DiskMapping disk_mapping;
    ApertureShape aperture = ApertureShape::circle();
    // Spectral renders of a lens with dispersion: 1 / (plane of focus at λ), 1/m,
    // every nm from 380 nm, from the lens's focal length at λ with the film
    // where it is (lenscompare/render_spectral.py); empty: no dispersion.
    std::vector<double> inverse_focus_per_m_by_nm;
    DispersionRuns dispersion_runs;  // that table's rising and falling stretches

    bool disperses() const { return !inverse_focus_per_m_by_nm.empty(); }

    void set_dispersion(std::vector<double> inverse_focus_per_m) {
        dispersion_runs = DispersionRuns(inverse_focus_per_m);
        inverse_focus_per_m_by_nm = std::move(inverse_focus_per_m);
    }

    // Whether its rays can each carry a band of wavelengths (thin_lens_bands.h,
    // render_tile_bands.h): a lens that disperses, its plane of focus turning
    // back at most kMaxBandRuns - 1 times over the spectrum.
    bool carries_bands() const { return disperses() && dispersion_runs.fits(); }
    // Russian roulette on a split sample's ray a pixel away (BandRoulette,
    // spectral_bands.h); off: every split sample's rays traced.
    bool band_roulette_on = true;
    bool band_roulette() const { return band_roulette_on; }
    const DispersionRuns& band_runs() const { return dispersion_runs; }
    // The table the bands' integrals are read over (Scene::focus_band_integrals).
    const std::vector<double>& band_focus_table() const { return inverse_focus_per_m_by_nm; }

    // Samples [0, n)'s rays (n <= kCameraBatch), each carrying the whole spectrum or a band of planes of
    // focus (thin_lens_bands.h), into out (cleared). (check: the lens system's; a derived pencil needs none.)
    bool band_rays(const Point2f* raster_px, const Point2f* lens_sample, int n, BandRays* out,
                   const LensPencilCheck* /*check*/ = nullptr) const {
        double lens_x[kCameraBatch], lens_y[kCameraBatch];
        lens_points(lens_sample, n, lens_x, lens_y);
        split_into_bands(n, raster_px, lens_x, lens_y, dispersion_runs, film_px_per_screen_x(),
                         film_px_per_screen_y(), out);
        return true;
    }

    // The whole samples' rays of band_rays' in float: each the ray at the
    // reference plane of focus from its film point (all pass, weight 1).
    void whole_ray_rows(const BandRays& rays, CameraRayRows* out, BandRayWeights* weights) const {
        float screen_x[kCameraBatch], screen_y[kCameraBatch];
        screen_points_lanes(rays.whole_count, film, rays.whole_raster_px, screen_x, screen_y);
        thin_lens_rays_lanes(rays.whole_count, screen_x, screen_y, rays.whole_lens_x_m, rays.whole_lens_y_m,
                             dispersion_runs.reference(), FrameF::of(world_from_camera), out);
        weights->used = false;
    }

    // The split samples' rays [first, first + n) of band_rays' (n <=
    // kCameraBatch) in float, as whole_ray_rows'.
    void band_ray_rows(const BandRays& rays, int first, int n, CameraRayRows* out, BandRayWeights* weights) const {
        float screen_x[kCameraBatch], screen_y[kCameraBatch];
        screen_points_lanes(n, film, rays.raster_px.data() + first, screen_x, screen_y);
        thin_lens_rays_lanes(n, screen_x, screen_y, rays.lens_x_m.data() + first, rays.lens_y_m.data() + first,
                             dispersion_runs.reference(), FrameF::of(world_from_camera), out);
        weights->used = false;
    }

    MaybeRay generate_ray(Point2f raster_px, Point2f lens_sample) const {
        return generate_ray_focused(raster_px, lens_sample, 1.0 / focus_distance_m);
    }

    // A batch of n <= kCameraBatch samples (render_tile.h): the aperture's map
    // sample by sample, the rest side by side (thin_lens_lanes.h), in single
    // precision: generate_ray's rays to float rounding (the same lens points).
    void generate_ray_rows(const Point2f* raster_px, const Point2f* lens_sample, int n, CameraRayRows* out) const {
        float screen_x[kCameraBatch], screen_y[kCameraBatch];
        float lens_x_m[kCameraBatch], lens_y_m[kCameraBatch];
        if (aperture.blades == 0 && disk_mapping == DiskMapping::Concentric) {
            concentric_disk_lanes(n, lens_sample, lens_radius_m, lens_x_m, lens_y_m);
        } else {
            for (int i = 0; i < n; ++i) {
                double x, y;
                aperture.sample(lens_sample[i], disk_mapping, &x, &y);
                lens_x_m[i] = float(x * lens_radius_m), lens_y_m[i] = float(y * lens_radius_m);
            }
        }
        screen_points_lanes(n, film, raster_px, screen_x, screen_y);
        thin_lens_rays_lanes(n, screen_x, screen_y, lens_x_m, lens_y_m, 1.0 / focus_distance_m,
                             FrameF::of(world_from_camera), out);
    }

    // generate_ray_rows' rays widened to double, for the callers that take a CameraRayBatch.
    void generate_ray_batch(const Point2f* raster_px, const Point2f* lens_sample, int n,
                            CameraRayBatch* out) const {
        CameraRayRows rows;
        generate_ray_rows(raster_px, lens_sample, n, &rows);
        widen_rows(rows, n, out);
    }

    // Its rays through raster rectangle [x0, x1] x [y0, y1] (camera_pencil.h).
    // A lens that disperses sends each wavelength toward its own plane of
    // focus, k = 1 / focus in [k_lo, k_hi]: with k = k_mid + dk, |dk| <= half,
    // a ray l (1 - k z) + s z is l (1 - k_mid z) + (s - l dk) z, the ray at
    // k_mid from a screen point at most R half from s (R: the farthest lens
    // point), so the pencil at k_mid through the rectangle widened by R half
    // holds every wavelength's rays (generate_shared_ray_rows' wrapped film
    // points stay in their pixel, so in the rectangle).
    bool pencil(double x0_px, double y0_px, double x1_px, double y1_px, CameraPencil* out) const {
        const double reach = aperture.blades == 0 ? 1.0 : polygon_circumradius_same_area(aperture.blades);
        const double radius_m = lens_radius_m * reach;
        if (!disperses()) {
            *out = pencil_of(world_from_camera, film, radius_m, 1.0 / focus_distance_m, x0_px, y0_px, x1_px, y1_px);
            return true;
        }
        const double half = 0.5 * (dispersion_runs.highest() - dispersion_runs.lowest());
        *out = pencil_of(world_from_camera, film, radius_m, dispersion_runs.middle(), x0_px, y0_px, x1_px, y1_px);
        for (int axis = 0; axis < 2; ++axis) {
            out->screen_lo[axis] -= radius_m * half;
            out->screen_hi[axis] += radius_m * half;
        }
        return true;
    }

    // The ray at wavelength nm: a thin lens of focal length f(λ) keeps the
    // chief ray through its centre, so only the plane of focus moves.
    MaybeRay generate_ray_at(Point2f raster_px, Point2f lens_sample, float nm) const {
        if (!disperses()) return generate_ray(raster_px, lens_sample);
        return generate_ray_focused(raster_px, lens_sample, inverse_focus_per_m_at(nm));
    }

    // 1 / (plane of focus at nm), 1/m (linear between whole nm); needs disperses().
    double inverse_focus_per_m_at(float nm) const {
        double inverse_focus;
        inverse_focus_lanes(1, inverse_focus_per_m_by_nm, &nm, &inverse_focus);
        return inverse_focus;
    }

    void generate_rays_at(Point2f raster_px, Point2f lens_sample, const float* nm, int n, MaybeRay* out) const {
        for (int k = 0; k < n; ++k) out[k] = generate_ray_at(raster_px, lens_sample, nm[k]);
    }

    // A sample's rays at its four wavelengths, sharing one where it can:
    // out[k] is wavelength k's ray; shares[k] says it is out[0], the hero's.
    // Every wavelength's thin lens sends a lens point toward its own plane of
    // focus, so the ray wavelength k traces from film point
    //     x_k = x_0 + p_lens (1/focus_k - 1/focus_0)     (screen units)
    // is the hero's ray from x_0. Given the lens point, x_0 is uniform over the
    // pixel, and so is x_k wrapped back into it (a shift modulo the pixel):
    // each wavelength draws film and lens points as its own camera would, and
    // where x_k needs no wrap its ray is the hero's and is traced once.
    void generate_rays_sharing(Point2f raster_px, Point2f lens_sample, const float* nm, MaybeRay* out,
                               bool* shares) const {
        double ax, ay;
        aperture.sample(lens_sample, disk_mapping, &ax, &ay);
        const double lens_x = lens_radius_m * ax, lens_y = lens_radius_m * ay;
        const double inverse_focus_0 = inverse_focus_per_m_at(nm[0]);
        out[0] = ray_from_lens_point(raster_px, lens_x, lens_y, inverse_focus_0);
        shares[0] = true;
        for (int k = 1; k < kHeroWavelengths; ++k) {
            const double inverse_focus = inverse_focus_per_m_at(nm[k]);
            const double shift = inverse_focus - inverse_focus_0;
            Point2f wrapped;
            shifted_film_points_lanes(1, &raster_px, &lens_x, &lens_y, &shift, film_px_per_screen_x(),
                                      film_px_per_screen_y(), &shares[k], &wrapped);
            out[k] = shares[k] ? out[0] : ray_from_lens_point(wrapped, lens_x, lens_y, inverse_focus);
        }
    }

    // generate_rays_sharing for samples [0, n) at once, as the spectral
    // render loop takes them: the same lens points, shares and wrapped film
    // points (in double, as there), the rays in single precision side by side
    // (thin_lens_lanes.h), generate_rays_sharing's to float rounding as
    // generate_ray_rows' are generate_ray's. rows[k] holds every sample's ray
    // at its wavelength k (k = 0 the hero's); own[k][i] says whether sample i
    // traces it: always the hero's, a secondary's where it does not share.
    void generate_shared_ray_rows(const Point2f* raster_px, const Point2f* lens_sample, const HeroWavelengths* w,
                                  int n, CameraRayRows* rows, bool (*own)[kCameraBatch]) const {
        float lens_x_m[kCameraBatch], lens_y_m[kCameraBatch], inverse_focus[kCameraBatch], nm[kCameraBatch];
        float screen_x[kCameraBatch], screen_y[kCameraBatch];
        double lens_x[kCameraBatch], lens_y[kCameraBatch], inverse_focus_0[kCameraBatch];
        double inverse_focus_k[kCameraBatch], shift[kCameraBatch];
        bool stays[kCameraBatch];
        Point2f wrapped[kCameraBatch];
        lens_points(lens_sample, n, lens_x, lens_y);
        for (int i = 0; i < n; ++i) {
            lens_x_m[i] = float(lens_x[i]), lens_y_m[i] = float(lens_y[i]);
            nm[i] = w[i].nm[0];
            own[0][i] = true;
        }
        inverse_focus_lanes(n, inverse_focus_per_m_by_nm, nm, inverse_focus_0);
        for (int i = 0; i < n; ++i) inverse_focus[i] = float(inverse_focus_0[i]);
        const FrameF frame = FrameF::of(world_from_camera);
        screen_points_lanes(n, film, raster_px, screen_x, screen_y);
        thin_lens_rays_lanes_focused(n, screen_x, screen_y, lens_x_m, lens_y_m, inverse_focus, frame, &rows[0]);
        const double x_scale = film_px_per_screen_x(), y_scale = film_px_per_screen_y();
        for (int k = 1; k < kHeroWavelengths; ++k) {
            for (int i = 0; i < n; ++i) nm[i] = w[i].nm[k];
            inverse_focus_lanes(n, inverse_focus_per_m_by_nm, nm, inverse_focus_k);
            for (int i = 0; i < n; ++i) shift[i] = inverse_focus_k[i] - inverse_focus_0[i];
            shifted_film_points_lanes(n, raster_px, lens_x, lens_y, shift, x_scale, y_scale, stays, wrapped);
            bool any_own = false;
            for (int i = 0; i < n; ++i) {
                own[k][i] = !stays[i];
                any_own |= own[k][i];
                inverse_focus[i] = float(inverse_focus_k[i]);
            }
            if (!any_own) continue;  // rows[k] unread
            screen_points_lanes(n, film, wrapped, screen_x, screen_y);
            thin_lens_rays_lanes_focused(n, screen_x, screen_y, lens_x_m, lens_y_m, inverse_focus, frame, &rows[k]);
        }
    }

    // Lens samples [0, n) to lens points (m, camera frame) in double: aperture.sample's points.
    void lens_points(const Point2f* lens_sample, int n, double* lens_x_m, double* lens_y_m) const {
        if (aperture.blades == 0 && disk_mapping == DiskMapping::Concentric) {
            concentric_disk_lanes_double(n, lens_sample, lens_radius_m, lens_x_m, lens_y_m);
        } else {
            for (int i = 0; i < n; ++i) {
                double ax, ay;
                aperture.sample(lens_sample[i], disk_mapping, &ax, &ay);
                lens_x_m[i] = lens_radius_m * ax, lens_y_m[i] = lens_radius_m * ay;
            }
        }
    }

    // Raster pixels per screen unit (z = 1): x, and y (against raster y).
    double film_px_per_screen_x() const { return 0.5 * film.width_px / film.screen_half_width; }
    double film_px_per_screen_y() const { return 0.5 * film.height_px / film.screen_half_height; }

    MaybeRay generate_ray_focused(Point2f raster_px, Point2f lens_sample, double inverse_focus_per_m) const {
        // Sample point on lens
        double ax, ay;
        aperture.sample(lens_sample, disk_mapping, &ax, &ay);
        return ray_from_lens_point(raster_px, lens_radius_m * ax, lens_radius_m * ay, inverse_focus_per_m);
    }

    // The ray from lens point (x, y) (m, camera frame) through the film point's
    // image on the plane of focus 1 / inverse_focus_per_m away. In double: the
    // reference the batch's single-precision rays are tested against.
    MaybeRay ray_from_lens_point(Point2f raster_px, double lens_x_m, double lens_y_m,
                                 double inverse_focus_per_m) const {
        Vec3d p_lens{lens_x_m, lens_y_m, 0.0};
        // Ray from the lens point through the film point's image on the plane of
        // focus, film.direction * focus_distance; written divided by the focus
        // distance (normalize does not mind the scale), so that any finite focus
        // distance, 1e300 m too, stays finite.
        Vec3d dir_camera = normalize(film.direction(raster_px) - p_lens * inverse_focus_per_m);
        return CameraRay{world_from_camera.world_from_camera_point(p_lens),
                         world_from_camera.world_from_camera_vector(dir_camera), 1.0f};
    }
};

}  // namespace lc
