// A dispersive thin lens's rays when each carries a band of wavelengths
// rather than a few drawn ones (render_tile_bands.h).
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

    int size() const { return count; }
    void clear() { count = 0, whole_count = 0; }
    // Room for m more entries.
    void reserve_more(int m) {
        const size_t needed = size_t(count + m);
        if (sample.size() >= needed) return;
        const size_t grown = std::max(needed, 2 * sample.size());
        sample.resize(grown), raster_px.resize(grown), lens_x_m.resize(grown), lens_y_m.resize(grown);
        k_lo.resize(grown), k_hi.resize(grown);
    }
};

// Samples [0, n) (n <= kCameraBatch; film point raster_px[i], lens point in
// m) into their rays, *out's whole samples and split rays (after clear()): 1 /
// focus over runs' range, the reference plane runs.reference(), x_scale and
// y_scale the raster pixels per screen unit (y against raster y).
void split_into_bands(int n, const Point2f* raster_px, const double* lens_x_m, const double* lens_y_m,
                      const DispersionRuns& runs, double x_scale, double y_scale, BandRays* out);

}  // namespace lc
