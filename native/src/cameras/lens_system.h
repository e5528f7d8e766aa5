// Full lens system (Kolb et al. 1995; paper section 2.4): a film point, a point
// on the exit-pupil region behind the lens, and an exact Snell trace through
// every surface. Vignetted rays come back as nothing. The weight turns
// radiance into film irradiance (cos^4 and the sampled pupil area over the
// squared axial distance), divided by its value at the film centre for a
// uniform scene, so the centre of a uniform scene reads 1 (DESIGN.md).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <memory>
#include <vector>

#include "cameras/camera_ray.h"
#include "cameras/lens_pencil.h"
#include "cameras/thin_lens_bands.h"
#include "lens/exit_pupil.h"
#include "lens/lens_aim.h"
#include "lens/lens_band_table.h"
#include "lens/lens_ray_table.h"
#include "lens/lens_reverse.h"
#include "lens/lens_to_world.h"
#include "lens/lens_trace.h"
#include "scene.h"
#include "spectral.h"
#include "spectral_bands.h"

namespace lc {

// The largest film radius the exit pupil's rings cover: the film corner's.
inline double film_corner_radius_mm(double film_width_mm, double film_height_mm) {
    return 0.5 * std::hypot(film_width_mm, film_height_mm);
}

// The elements with every bladed stop made round again (its circumscribed circle).
inline std::vector<LensElement> without_blades(std::vector<LensElement> elements) {
    for (LensElement& e : elements) e.blades = 0;
    return elements;
}

// Which mirror images of a film point the lens images as the mirror images
// of its rays (render_mirrored.h): bit 0 the film's x reflected (x -> -x), bit 1
// its y. A lens of round surfaces has both; a bladed stop only those its
// polygon is symmetric under.
inline unsigned lens_mirror_axes(const std::vector<LensElement>& elements) {
    unsigned axes = 3;
    for (const LensElement& e : elements)
        for (int k = 0; k < e.blades; ++k) {
            // Is edge k's normal, reflected, another edge's normal?
            const double nx = e.edge_normal_x[size_t(k)], ny = e.edge_normal_y[size_t(k)];
            bool x_found = false, y_found = false;
            for (int j = 0; j < e.blades; ++j) {
                const double mx = e.edge_normal_x[size_t(j)], my = e.edge_normal_y[size_t(j)];
                x_found |= std::fabs(mx + nx) < 1e-12 && std::fabs(my - ny) < 1e-12;
                y_found |= std::fabs(mx - nx) < 1e-12 && std::fabs(my + ny) < 1e-12;
            }
            if (!x_found) axes &= ~1u;
            if (!y_found) axes &= ~2u;
        }
    return axes;
}

static_assert(kLensBatch == kCameraBatch, "generate_ray_batch takes the render loop's whole camera batch");

// How well band_rays' model (lens_system_bands.cpp) holds for a camera:
// rays traced back at test wavelengths against the model's film points and
// passes (LensSystemCamera::check_band_model).
struct BandModelCheck {
    long passing = 0;   // rays x test wavelengths that pass the rims
    long one_way = 0;   // of those and the rest, how many the model passes and the trace not, or the reverse
    double film_p99_px = 0.0;  // the model's film point off the traced one, 99th percentile, pixels
    // Rays sampled (through every surface at d, rims aside), and of those the
    // ones passing at some test wavelength but not at d: the share of the
    // light a region sampled around the d pupil may miss (where the pupils
    // move apart more, behind small stops, the rays crossing outside it are
    // never drawn).
    long rays = 0, elsewhere = 0;
};

struct LensSystemCamera {
    Frame world_from_camera;           // origin at the entrance-pupil centre
    std::vector<LensElement> elements; // scene side first, lens frame (mm)
    double film_z_mm;                  // film plane, lens frame
    double entrance_pupil_z_mm;        // lens-frame z of the camera origin
    double film_width_mm, film_height_mm;
    int width_px, height_px;
    std::shared_ptr<const ExitPupil> pupil;
    double inverse_centre_irradiance = 1.0;  // set by calibrate()
    LensTraceKernel trace_kernel = best_lens_trace_kernel();  // all give the same bits; diagnostics may pick another
    // The batch trace (every render's) in single precision; the one-ray
    // generate_ray and generate_rays_at stay in double, the reference.
    LensTracePrecision trace_precision = LensTracePrecision::Single;
    // Spectral renders of a lens with dispersion: the elements with their
    // indices at each nm from 380 nm (set_dispersion); empty: no dispersion.
    std::vector<std::vector<LensElement>> elements_by_nm;
    LensDispersion dispersion;  // the same indices as eta tables, for the batch trace (set_dispersion)
    // The lens mirrored for back-tracing (lens_reverse.h) and its indices
    // per nm likewise (set_dispersion): film_points_from.
    std::vector<LensElement> reversed_elements;
    LensDispersion reversed_dispersion;
    // The measured bounds of its rays per film cell (lens_pencil.h; set
    // after calibration): null, the render's tiles test every own primitive.
    std::shared_ptr<const LensPencils> pencils;
    // The same for the band rays' open trace (LensPencils::of(camera, true);
    // set_band_rays): the d-line pencils above do not hold the rays a rim
    // stops at d but not in blue, and with them most tiles of a band render
    // left their cull (session 51: 85 fell back in showcase at 180x120).
    std::shared_ptr<const LensPencils> band_pencils;
    // The film mirrors whose rays are the traced rays' mirror images
    // (lens_mirror_axes; set with the elements): the render traces a quarter
    // of the samples and reflects them (render_mirrored.h). 0: every pixel
    // traces its own samples.
    unsigned mirror_axes = 0;
    // Spectral renders whose rays carry bands of the spectrum
    // (lens_system_bands.cpp; set_band_rays): the dispersion parameter k at
    // every nm from 380 nm, its runs, and whether the render takes them.
    std::vector<double> band_parameter_by_nm;
    DispersionRuns band_parameter_runs;
    std::vector<LensElement> reversed_blue_elements;  // reversed_lens of the 380 nm glass: the back-trace
    // The back-trace's shifts by look-up (lens_band_table.h); null: traced per sample.
    std::shared_ptr<const LensBandTable> band_table;
    static constexpr int kBandTableRadialCells = 16, kBandTableAroundCells = 32;
    bool band_rays_on = false;
    bool band_roulette_on = true;  // as ThinLensCamera's
    // The rays by table look-up (lens_ray_table.h) for the batch paths
    // (RGB, and spectral without dispersion: set_dispersion drops it);
    // null: every sample traced.
    std::shared_ptr<const LensRayTable> ray_table;
    // Derived from the above once: a division per ray costs more than the
    // rest of the ray's set-up.
    double film_mm_per_px_x = film_width_mm / width_px, film_mm_per_px_y = film_height_mm / height_px;
    double inverse_axial2_per_mm2 = 1.0 / ((film_z_mm - pupil->plane_z_mm()) * (film_z_mm - pupil->plane_z_mm()));

    AimPlanes aim_planes() const { return {film_z_mm, pupil->plane_z_mm()}; }

    // Everything up to the trace, one ray (the scalar reference of
    // sample_batch); also used for the pass-rate statistics. Returns false
    // without tracing when the film point is outside the image circle.
    bool sample_lens_ray(Point2f raster_px, Point2f lens_sample, LensRay* ray, double* area_mm2) const {
        double x, y, r;
        film_point(raster_px, &x, &y, &r);
        PupilPick pick;
        if (!pupil->pick(r, lens_sample.y, &pick)) return false;
        *ray = aim_one(x, y, r, double(lens_sample.x), pick, aim_planes());
        *area_mm2 = pick.area_mm2;
        return true;
    }

    // Film point (lens frame, mm) of a raster position, and its distance from the axis.
    void film_point(Point2f raster_px, double* x, double* y, double* r) const {
        // The image is inverted on the film.
        *x = (0.5 * width_px - double(raster_px.x)) * film_mm_per_px_x;
        *y = (double(raster_px.y) - 0.5 * height_px) * film_mm_per_px_y;
        *r = std::sqrt(*x * *x + *y * *y);  // hypot's overflow guard costs a libm call per ray
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

    bool disperses() const { return !elements_by_nm.empty(); }

    // Each surface's (scene side, film side) indices at every nm from 380 nm
    // (rows): the glass of spectral renders.
    void set_dispersion(std::vector<std::vector<LensElement>> by_nm) {
        elements_by_nm = std::move(by_nm);
        dispersion = LensDispersion::of(elements_by_nm);
        std::vector<std::vector<LensElement>> reversed_by_nm;
        reversed_by_nm.reserve(elements_by_nm.size());
        for (const std::vector<LensElement>& row : elements_by_nm) reversed_by_nm.push_back(reversed_lens(row));
        reversed_elements = reversed_lens(elements);
        reversed_dispersion = LensDispersion::of(reversed_by_nm);
        band_parameter_by_nm.clear(), band_table = nullptr, band_pencils = nullptr;  // set_band_rays builds them
        band_rays_on = false;
    }

    // Band rays (lens_system_bands.cpp, render_tile_bands.h): one ray per
    // sample carries every wavelength whose film point stays in its pixel.
    // on: whether spectral renders take them (a lens with dispersion only).
    void set_band_rays(bool on);
    bool carries_bands() const { return band_rays_on && disperses() && band_parameter_runs.fits(); }
    bool band_roulette() const { return band_roulette_on; }
    const DispersionRuns& band_runs() const { return band_parameter_runs; }
    const std::vector<double>& band_focus_table() const { return band_parameter_by_nm; }
    bool band_rays(const Point2f* raster_px, const Point2f* lens_sample, int n, BandRays* out,
                   const LensPencilCheck* check = nullptr) const;
    // The band rays' trace: lanes [0, n) of rays, aimed (pupil area_mm2
    // each), traced at the d line with the rims stopping none, margin
    // (kLensBatch) each ray's least rim clearance (lens_trace.h,
    // trace_from_film_batch_margins); rows, weight and alive as
    // generate_weighted_ray_rows', alive where the ray got through every
    // surface (whatever its margin). With check, whether all lie within its pencil.
    bool trace_open_aimed(int n, LensRayBatch* rays, const double* area_mm2, double* margin, CameraRayRows* rows,
                          float* weight, bool* alive, const LensPencilCheck* check) const;
    // Samples [0, n) picked and traced so (leaving: the rays leaving the
    // lens), for the band model's measures (check_band_model, band_shifts).
    void trace_open_from(const Point2f* raster_px, const Point2f* lens_sample, int n, LensRayBatch* leaving,
                         double* margin_d, bool* alive) const;
    // Lanes [0, n) of leaving (trace_open_from's, margin_d its clearances)
    // left alive only where some band of the spectrum passes, as band_rays
    // decides it but with the back-trace for the band table (the band
    // pencils' measure: LensPencils::of(camera, true)).
    void keep_band_carriers(const Point2f* raster_px, int n, LensRayBatch* leaving, const double* margin_d) const;
    // The split rays band_rays left to trace, all of rays' entries so far
    // (render_tile_bands.h pools them across batches: a batch's few, traced
    // alone, cost a whole trace of 32 lanes).
    static constexpr bool kPoolsSplitRays = true;
    bool trace_split_rays(BandRays* rays, const LensPencilCheck* check = nullptr) const;
    // band_rays' back-trace at 380 nm, traced (where the band table cannot
    // answer; and check_band_model's): lanes [0, n) of leaving (the open
    // trace at d, margin_d its clearances) with which[i] set: the film
    // point's shift (mm) and the clearance's slope per unit of k, known[i]
    // set where the ray got back through the lens (the others untouched).
    void trace_band_shifts(const LensRayBatch& leaving, const Point2f* raster_px, int n, const double* margin_d,
                           const bool* which, double* shift_x_mm, double* shift_y_mm, double* slope,
                           bool* known) const;
    // The whole samples' rays: their own rays, rays.sample_rows (or gathered, for a moving camera).
    static constexpr bool kWholeRaysInSampleRows = true;
    void whole_ray_rows(const BandRays& rays, CameraRayRows* out, BandRayWeights* weights) const;
    // The model against the trace on film_cells^2 jittered film points,
    // samples_per_cell lens samples each (after set_band_rays(true)).
    BandModelCheck check_band_model(int film_cells, int samples_per_cell) const;
    // Lanes [0, n) (n <= kLensBatch): band_rays' film shift per unit of k
    // (mm, lens frame) and clearance slope, from the band table (from_table)
    // or traced back at 380 nm; known false where the source cannot answer
    // or the ray is blocked at d (the diagnostics' measure of the table).
    void band_shifts(const Point2f* raster_px, const Point2f* lens_sample, int n, bool from_table,
                     double* shift_x_mm, double* shift_y_mm, double* slope, bool* known) const;
    void band_ray_rows(const BandRays& rays, int first, int n, CameraRayRows* out, BandRayWeights* weights) const;

    // Where on the film the rays of leaving came from at lane i's glass row
    // (row[i], of elements_by_nm): each traced back through the glass at that
    // wavelength, from where it left the lens (the batch trace's result: on
    // the first surface, toward the scene) to the film plane, in the batch
    // trace's precision. alive[i]: the ray gets back through every surface
    // at that wavelength (film_x_mm and film_y_mm then hold its film point,
    // lens frame; 0 otherwise). A dispersive lens only (set_dispersion).
    void film_points_from(const LensRayBatch& leaving, const int32_t* row, double* film_x_mm, double* film_y_mm,
                          bool* alive) const {
        LensRayBatch back;
        mirror_for_back_trace(leaving, &back);
        trace_from_film_batch(reversed_elements, LaneGlass{&reversed_dispersion, row}, &back, trace_kernel,
                              trace_precision);
        for (int i = 0; i < kLensBatch; ++i) {
            alive[i] = back.alive[i];
            film_x_mm[i] = film_y_mm[i] = 0.0;
            if (alive[i]) back_traced_film_point(back, i, film_z_mm, &film_x_mm[i], &film_y_mm[i]);
        }
    }

    // The ray at wavelength nm (indices of the nearest nm): the same film and
    // pupil sample traced through the glass at that wavelength, scalar (the
    // reference of generate_rays_at_batch). The pupil region is the design
    // wavelength's. A ray that meets total internal reflection at this
    // wavelength is blocked, like any other.
    MaybeRay generate_ray_at(Point2f raster_px, Point2f lens_sample, float nm) const {
        MaybeRay ray;
        generate_rays_at(raster_px, lens_sample, &nm, 1, &ray);
        return ray;
    }

    // The same sample at n wavelengths: one film point and pupil point, n traces.
    void generate_rays_at(Point2f raster_px, Point2f lens_sample, const float* nm, int n, MaybeRay* out) const {
        LensRay start;
        double area_mm2;
        const bool aimed = sample_lens_ray(raster_px, lens_sample, &start, &area_mm2);
        const double cos_theta = -start.direction.z;
        for (int k = 0; k < n; ++k) {
            out[k] = std::nullopt;
            if (!aimed) continue;
            LensRay ray = start;
            if (!trace_from_film(disperses() ? glass_at(nm[k]) : elements, &ray)) continue;
            out[k] = camera_ray(ray, cos_theta, area_mm2);
        }
    }

    // The elements with their indices at the nm nearest to nm.
    const std::vector<LensElement>& glass_at(float nm) const { return elements_by_nm[size_t(glass_row(nm))]; }

    // The row of elements_by_nm (and of dispersion) nearest to nm, halves
    // rounded up. A float's nm - 380 and its sum with 0.5 are exact in
    // double, and truncating a non-negative value is its floor, so this is
    // std::lround's row (which rounds halves away from zero: only below row
    // 0, clamped alike) without a libm call per lane.
    int32_t glass_row(float nm) const {
        const double shifted = double(nm) - 380.0 + 0.5;
        if (!(shifted >= 1.0)) return 0;  // below row 1, or NaN
        return int32_t(std::min(shifted, double(elements_by_nm.size() - 1)));
    }

    // generate_rays_at for up to kLensBatch samples at once: sample i at
    // wavelengths nm[i][0, traced), out[i][k] its ray at nm[i][k] (the same
    // bits as generate_rays_at), through generate_ray_batches_at.
    void generate_rays_at_batch(const Point2f* raster_px, const Point2f* lens_sample,
                                const float (*nm)[kHeroWavelengths], int n, int traced,
                                MaybeRay (*out)[kHeroWavelengths]) const {
        CameraRayBatch columns[kHeroWavelengths];
        generate_ray_batches_at(raster_px, lens_sample, nm, n, traced, columns);
        MaybeRay rays[kLensBatch];
        for (int k = 0; k < traced; ++k) {
            maybe_rays(columns[k], n, rays);
            for (int i = 0; i < n; ++i) out[i][k] = rays[i];
        }
    }

    // The same rays in columns: out[k] holds each sample's ray at its
    // wavelength nm[i][k], k < traced. The samples are aimed once, in
    // lockstep, then traced once per k, every lane through the glass at its
    // own wavelength, like generate_ray_batch's RGB trace.
    void generate_ray_batches_at(const Point2f* raster_px, const Point2f* lens_sample,
                                 const float (*nm)[kHeroWavelengths], int n, int traced, CameraRayBatch* out) const {
        const LensToWorld to_world = lens_to_world();
        trace_each_wavelength(raster_px, lens_sample, nm, n, traced, nullptr,
                              [&](int k, const LensRayBatch& batch, const double* cos_theta, const double* area_mm2) {
                                  to_columns(to_world, batch, cos_theta, area_mm2, n, &out[k]);
                                  return static_cast<const bool*>(out[k].alive);
                              });
    }

    // generate_ray_batches_at's rays rounded to float, as the spectral render
    // loop's packets take them: rows[k], weight[k] and alive[k] for the k-th
    // traced wavelength (no double columns between, as generate_weighted_ray_rows).
    // Given a tile's check (checked_pencil), whether every traced
    // wavelength's rays lie within its pencil (dispersion moves them off the
    // d-line rays it was measured with); true without one.
    bool generate_weighted_ray_rows_at(const Point2f* raster_px, const Point2f* lens_sample,
                                       const float (*nm)[kHeroWavelengths], int n, int traced, CameraRayRows* rows,
                                       float (*weight)[kCameraBatch], bool (*alive)[kCameraBatch],
                                       const LensPencilCheck* check = nullptr) const {
        const LensToWorld to_world = lens_to_world();
        return trace_each_wavelength(raster_px, lens_sample, nm, n, traced, check,
                                     [&](int k, const LensRayBatch& batch, const double* cos_theta,
                                         const double* area_mm2) {
                                         to_rows(to_world, batch, cos_theta, area_mm2, n, &rows[k], weight[k],
                                                 alive[k]);
                                         return static_cast<const bool*>(alive[k]);
                                     });
    }

    // Both forms above: the samples aimed once, then traced per wavelength k
    // and handed to emit(k, traced batch, cos theta, pupil area), which
    // returns the lanes alive; whether each k's lanes passed the check.
    template <class Emit>
    bool trace_each_wavelength(const Point2f* raster_px, const Point2f* lens_sample,
                               const float (*nm)[kHeroWavelengths], int n, int traced, const LensPencilCheck* check,
                               Emit emit) const {
        bool within = true;
        LensRayBatch aimed;
        double area_mm2[kLensBatch], cos_theta[kLensBatch];
        sample_batch(raster_px, lens_sample, n, &aimed, area_mm2);
        for (int i = 0; i < kLensBatch; ++i) cos_theta[i] = -aimed.dz[i];
        for (int k = 0; k < traced; ++k) {
            LensRayBatch batch = aimed;
            if (disperses()) {
                int32_t row[kLensBatch];
                for (int i = 0; i < kLensBatch; ++i) row[i] = i < n ? glass_row(nm[i][k]) : 0;
                trace_from_film_batch(elements, LaneGlass{&dispersion, row}, &batch, trace_kernel, trace_precision);
            } else {
                trace_from_film_batch(elements, &batch, trace_kernel, trace_precision);
            }
            const bool* alive = emit(k, batch, cos_theta, area_mm2);
            if (check && within) within = lens_rays_within(*check, batch, alive);
        }
        return within;
    }

    // Lanes [0, n) of a batch set up for the trace, as sample_lens_ray does one
    // ray: film points and pupil picks lane by lane (table look-ups), then the
    // aim, with its square roots and divisions, in SIMD. Lanes outside the
    // image circle or past n are dead.
    // (lens_system.cpp, built per instruction set as the trace is.)
    void sample_batch(const Point2f* raster_px, const Point2f* lens_sample, int n, LensRayBatch* batch,
                      double* area_mm2) const;

    // trace_batch through ray_table: look_up_rays' rays widened to double
    // (the diagnostics' batch path; the render takes the float rows of
    // look_up_ray_rows), area_mm2 each lane's cos^4 theta times pupil area.
    void look_up_batch(const Point2f* raster_px, const Point2f* lens_sample, int n, LensRayBatch* batch,
                       double* area_mm2) const;
    // Lanes [0, n)'s rays from ray_table in float (the lens frame), the
    // lanes the table cannot answer traced in double and rounded into theirs.
    void look_up_rays(const Point2f* raster_px, const Point2f* lens_sample, int n, LensRaysF* rays) const;
    // generate_weighted_ray_rows through ray_table: look_up_rays' rays to the
    // world in float (lens_to_world.h) and checked in float (lens_pencil.h).
    bool look_up_ray_rows(const Point2f* raster_px, const Point2f* lens_sample, int n, CameraRayRows* rows,
                          float* weight, bool* alive, const LensPencilCheck* check) const;
    // Where the film lies in raster pixels, for the look-up.
    FilmPlacement film_placement() const;
    // look_up_rays' traced lanes: lanes i < n with which[i] traced into
    // batch and area_mm2 (times cos^4 theta, as the table's weights).
    void trace_lanes(const Point2f* raster_px, const Point2f* lens_sample, int n, const bool* which,
                     LensRayBatch* batch, double* area_mm2) const;

    // Samples [0, n) aimed and traced in lockstep, with each lane's cos theta
    // at the film and pupil area: what both batch forms below start from.
    void trace_batch(const Point2f* raster_px, const Point2f* lens_sample, int n, LensRayBatch* batch,
                     double* area_mm2, double* cos_theta) const {
        if (ray_table) {
            look_up_batch(raster_px, lens_sample, n, batch, area_mm2);
            for (int i = 0; i < kLensBatch; ++i) cos_theta[i] = 1.0;  // area_mm2 holds cos^4 theta already
            return;
        }
        trace_exactly(raster_px, lens_sample, n, batch, area_mm2, cos_theta);
    }

    // trace_batch without a table: every lane aimed and traced.
    void trace_exactly(const Point2f* raster_px, const Point2f* lens_sample, int n, LensRayBatch* batch,
                       double* area_mm2, double* cos_theta) const {
        sample_batch(raster_px, lens_sample, n, batch, area_mm2);
        for (int i = 0; i < kLensBatch; ++i) cos_theta[i] = -batch->dz[i];
        trace_from_film_batch(elements, batch, trace_kernel, trace_precision);
    }

    // The same as generate_ray for up to kLensBatch samples at once, traced in
    // lockstep (results equal generate_ray's).
    void generate_ray_batch(const Point2f* raster_px, const Point2f* lens_sample, int n,
                            CameraRayBatch* out) const {
        LensRayBatch batch;
        double area_mm2[kLensBatch], cos_theta[kLensBatch];
        trace_batch(raster_px, lens_sample, n, &batch, area_mm2, cos_theta);
        to_columns(lens_to_world(), batch, cos_theta, area_mm2, n, out);
    }

    // generate_ray_batch's rays rounded to float, as the render loop's packets
    // take them (GeneratesWeightedRayRows): no double columns between.
    // Given a tile's check (checked_pencil), whether every ray lies within
    // its pencil; true without one.
    bool generate_weighted_ray_rows(const Point2f* raster_px, const Point2f* lens_sample, int n, CameraRayRows* rows,
                                    float* weight, bool* alive, const LensPencilCheck* check = nullptr) const {
        if (ray_table) return look_up_ray_rows(raster_px, lens_sample, n, rows, weight, alive, check);
        LensRayBatch batch;
        double area_mm2[kLensBatch], cos_theta[kLensBatch];
        trace_batch(raster_px, lens_sample, n, &batch, area_mm2, cos_theta);
        to_rows(lens_to_world(), batch, cos_theta, area_mm2, n, rows, weight, alive);
        return !check || lens_rays_within(*check, batch, alive);
    }

    // The pencil of the rays through raster rectangle [x0, x1] x [y0, y1]
    // (camera_pencil.h), measured, so with the check each traced batch must
    // pass for the cull to hold (render_tile, lens_pencil.h). False: no
    // pencil (none measured, or a cell of the rectangle has none).
    // A band render's (carries_bands) are the open trace's, over the
    // rectangle grown by a pixel each way: its split rays start up to a
    // pixel outside the tile.
    bool checked_pencil(double x0_px, double y0_px, double x1_px, double y1_px, CameraPencil* pencil,
                        LensPencilCheck* check) const {
        if (carries_bands())
            return band_pencils && band_pencils->tile(world_from_camera, entrance_pupil_z_mm, x0_px - 1.0,
                                                      y0_px - 1.0, x1_px + 1.0, y1_px + 1.0, pencil, check);
        if (!pencils || !pencils->tile(world_from_camera, entrance_pupil_z_mm, x0_px, y0_px, x1_px, y1_px, pencil,
                                       check))
            return false;
        bound_origins(pencil);
        return true;
    }

    // Sets pencil's box round every origin of this camera's batch rays (not a
    // band render's): a ray leaves from the first surface within its clear
    // aperture, or from the ray table's interpolated origins; in the world,
    // widened past the float rounding of both and of the world transform.
    // Per tile, so the boxes' faces behind the whole lens are culled once
    // (Scene::camera_candidates), not per packet from the rays' origins.
    void bound_origins(CameraPencil* pencil) const {
        const LensElement& first = elements.front();
        const double sag_mm = rim_sag_mm(first.curvature_per_mm, first.semi_aperture_mm);
        double radius_mm = first.semi_aperture_mm;
        double z_lo_mm = first.vertex_z_mm + std::min(0.0, sag_mm), z_hi_mm = first.vertex_z_mm + std::max(0.0, sag_mm);
        if (ray_table) {
            radius_mm = std::max(radius_mm, ray_table->origin_radius_mm);
            z_lo_mm = std::min(z_lo_mm, ray_table->origin_z_lo_mm);
            z_hi_mm = std::max(z_hi_mm, ray_table->origin_z_hi_mm);
        }
        if (!(std::isfinite(radius_mm) && std::isfinite(z_lo_mm) && std::isfinite(z_hi_mm))) return;
        const double slack_mm = 1e-4 * (1.0 + radius_mm + std::fabs(z_lo_mm) + std::fabs(z_hi_mm));
        radius_mm += slack_mm, z_lo_mm -= slack_mm, z_hi_mm += slack_mm;
        // Lens frame (mm, +z toward the film) -> camera frame (m, +z toward the scene): lens_to_world.h.
        const double mid_m = (entrance_pupil_z_mm - 0.5 * (z_lo_mm + z_hi_mm)) * 1e-3;
        const double half_depth_m = 0.5 * (z_hi_mm - z_lo_mm) * 1e-3, radius_m = radius_mm * 1e-3;
        const Frame& f = world_from_camera;
        const Vec3d centre = f.origin + f.forward * mid_m;
        const double c3[3] = {centre.x, centre.y, centre.z};
        const double right[3] = {f.right.x, f.right.y, f.right.z}, up[3] = {f.up.x, f.up.y, f.up.z};
        const double forward[3] = {f.forward.x, f.forward.y, f.forward.z};
        const double margin_m =
            1e-6 * (std::fabs(c3[0]) + std::fabs(c3[1]) + std::fabs(c3[2]) + radius_m + half_depth_m);
        for (int k = 0; k < 3; ++k) {
            const double reach_m = radius_m * std::sqrt(right[k] * right[k] + up[k] * up[k]) +
                                   half_depth_m * std::fabs(forward[k]) + margin_m;
            pencil->origins_lo_m[k] = c3[k] - reach_m, pencil->origins_hi_m[k] = c3[k] + reach_m;
        }
        pencil->origins_in_box = true;
    }

    // Traced lanes -> camera rays in world space with their weights; lanes
    // from n on and those the lens blocked are not alive.
    static void to_columns(const LensToWorld& to_world, const LensRayBatch& traced, const double* cos_theta,
                           const double* area_mm2, int n, CameraRayBatch* out) {
        WorldRayBatch world;
        lens_to_world_batch(to_world, traced, cos_theta, area_mm2, &world);
        for (int i = 0; i < kLensBatch; ++i) {
            out->origin[0][i] = world.ox[i], out->origin[1][i] = world.oy[i], out->origin[2][i] = world.oz[i];
            out->direction[0][i] = world.dx[i], out->direction[1][i] = world.dy[i];
            out->direction[2][i] = world.dz[i];
            out->weight[i] = float(world.weight[i]);
            out->alive[i] = i < n && traced.alive[i];
        }
    }

    // The same in float rows, as the packets take them: to_columns' rays and
    // weights rounded to float (the same bits), and which lanes are alive.
    static void to_rows(const LensToWorld& to_world, const LensRayBatch& traced, const double* cos_theta,
                        const double* area_mm2, int n, CameraRayRows* rows, float* weight, bool* alive) {
        lens_to_world_rows(to_world, traced, cos_theta, area_mm2, rows, weight);
        for (int i = 0; i < kLensBatch; ++i) alive[i] = i < n && traced.alive[i];
    }

    LensToWorld lens_to_world() const {
        return {world_from_camera, entrance_pupil_z_mm, inverse_axial2_per_mm2 * inverse_centre_irradiance};
    }

    // A ray that left the lens -> the camera ray with its irradiance weight.
    CameraRay camera_ray(const LensRay& ray, double cos_theta, double area_mm2) const {
        // Film irradiance weight: cos^4 theta * A / Z^2, normalised at the centre
        double cos2 = cos_theta * cos_theta;
        double weight = cos2 * cos2 * area_mm2 * (inverse_axial2_per_mm2 * inverse_centre_irradiance);
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

}  // namespace lc
