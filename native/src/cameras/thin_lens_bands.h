// A dispersive thin lens's rays when each carries a band of wavelengths
// rather than a few drawn ones (render_tile_bands.h). The lens system's band
// rays (lens_system_bands.cpp) are split here too, along the film points of a
// dispersion parameter instead of planes of focus.
//
// A thin lens of focal length f(λ) sends lens point p toward its own plane
// of focus k(λ) = 1 / focus, so wavelength λ's ray from film point x is the
// ray at a reference plane k_ref (the d line's: DispersionRuns::reference)
// from x - p (k(λ) - k_ref) (screen units;
// ThinLensCamera::generate_rays_sharing). Take the reference ray's film point
// x uniform over the pixel: each λ's own film point x + p (k(λ) - k_ref),
// wrapped back into the pixel (a shift modulo the pixel), is uniform over it
// too, so each λ is sampled as its own camera would sample it. Where that
// point needed no wrap its ray is the reference ray; where it was wrapped by
// a whole number of pixels o, it is the reference ray from x - o. As k runs
// over its range the unwrapped point runs along a segment, and every stretch
// of k in which the segment stays in one pixel is one ray carrying those
// wavelengths: one ray for the whole spectrum unless the segment crosses a
// pixel's edge.
#pragma once

#include <algorithm>
#include <cstdint>
#include <vector>

#include "cameras/camera_ray.h"
#include "spectral_bands.h"
#include "vec.h"

namespace lc {

struct LensPencilCheck;  // lens_pencil.h: the lens system's measured pencil

// A batch's rays. The samples whose every wavelength lands in their own
// pixel (most of them) are one ray each carrying the whole spectrum: their
// indices in the batch, film points and lens points (m) in whole_*, the first
// whole_count entries, as a camera that does not disperse would take them
// (render_tile_bands.h shades them so, never touching a band). The others'
// rays, one entry per ray, in sample order: sample (its index in the batch),
// the reference ray's film point, the lens point, and the band of planes of
// focus it carries, 1 / focus in [k_lo, k_hi). Entries [0, count) hold them;
// the columns only grow, so a batch writes them by index.
struct BandRays {
    int whole_count = 0;
    int whole_sample[kCameraBatch];
    Point2f whole_raster_px[kCameraBatch];
    float whole_lens_x_m[kCameraBatch], whole_lens_y_m[kCameraBatch];

    int count = 0;
    std::vector<int> sample;
    std::vector<Point2f> raster_px;
    std::vector<float> lens_x_m, lens_y_m;
    std::vector<double> k_lo, k_hi;
    std::vector<double> x_edges, y_edges;  // split_into_bands' scratch
    // Each ray's weight's factor and its whole-spectrum part (its map is its
    // band's plus entry_whole_part times the whole's): 1 and 0 but where the
    // roulette (set unless the camera's band_roulette is off) kept a split
    // sample (BandRoulette, spectral_bands.h).
    std::vector<float> entry_scale, entry_whole_part;
    const BandRoulette* roulette = nullptr;

    // A camera whose rays may be vignetted and carry a weight (the lens
    // system) traces every sample's own ray in band_rays, kept here for
    // whole_ray_rows; and the split rays': a stretch in the sample's own
    // pixel is its ray, copied at once, the others are traced later (from
    // their film point toward the sample's exit-pupil point), many samples'
    // together (trace_split_rays: render_tile_bands.h pools the split samples).
    CameraRayRows sample_rows;
    float sample_weight[kCameraBatch];
    bool sample_alive[kCameraBatch];
    double sample_pupil_x_mm[kCameraBatch], sample_pupil_y_mm[kCameraBatch], sample_area_mm2[kCameraBatch];
    std::vector<double> entry_pupil;  // 3 a ray: its sample's exit-pupil point (x, y, mm) and pick area (mm^2)
    std::vector<float> entry_ray;  // 6 a ray: origin, direction (world, float)
    std::vector<float> entry_weight;
    std::vector<char> entry_alive, entry_found;  // found: its ray is in entry_ray (false: still to trace)

    int size() const { return count; }
    void clear() { count = 0, whole_count = 0; }
    // Room for m more entries.
    void reserve_more(int m) {
        const size_t needed = size_t(count + m);
        if (sample.size() >= needed) return;
        const size_t grown = std::max(needed, 2 * sample.size());
        sample.resize(grown), raster_px.resize(grown), lens_x_m.resize(grown), lens_y_m.resize(grown);
        k_lo.resize(grown), k_hi.resize(grown), entry_scale.resize(grown), entry_whole_part.resize(grown);
    }
};

// Each ray's weight and whether it passed, for a camera that vignettes (the
// lens system). used false: every ray passes with weight 1 (the thin lens).
struct BandRayWeights {
    bool used = false;
    float weight[kCameraBatch];
    bool alive[kCameraBatch];
};

// Samples [0, n) (n <= kCameraBatch; film point raster_px[i], lens point in
// m) into their rays, *out's whole samples and split rays (after clear()): 1 /
// focus over runs' range (or each sample's own part of it, [k_from, k_to):
// where a lens system's ray passes its rims), the reference plane
// runs.reference() (or each sample's own, k_ref_by_sample), x_scale and
// y_scale the raster pixels per screen unit (y against raster y). A sample
// whose stretch is empty is written as whole. whole_points false: the whole
// samples' film and lens points (whole_raster_px, whole_lens_*) are not
// written, for a camera that keeps their rays as traced (the lens system:
// sample_rows).
void split_into_bands(int n, const Point2f* raster_px, const double* lens_x_m, const double* lens_y_m,
                      const DispersionRuns& runs, double x_scale, double y_scale, BandRays* out,
                      const double* k_ref_by_sample = nullptr, const double* k_from_by_sample = nullptr,
                      const double* k_to_by_sample = nullptr, bool whole_points = true);

}  // namespace lc
