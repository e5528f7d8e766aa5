#include "cameras/thin_lens_bands.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "rng.h"

namespace lc {
namespace {

// Where the film point x + g (k - k_ref) crosses a pixel edge as k rises from
// k_lowest to k_highest: those k, rising, into *at, and the first pixel.
// Returns the step each crossing makes (+1 or -1).
int crossings(double x, double g, double k_ref, double k_lowest, double k_highest, std::vector<double>* at,
              double* first_pixel) {
    at->clear();
    const double from = x + g * (k_lowest - k_ref), to = x + g * (k_highest - k_ref);
    *first_pixel = std::floor(from);
    if (g > 0.0) {
        for (double edge = std::floor(from) + 1.0; edge <= std::floor(to); edge += 1.0)
            at->push_back(k_ref + (edge - x) / g);
        return 1;
    }
    if (g < 0.0) {
        for (double edge = std::floor(from); edge > std::floor(to); edge -= 1.0) at->push_back(k_ref + (edge - x) / g);
        return -1;
    }
    return 0;
}

// A uniform number in [0, 1) for a sample's roulette (BandRoulette), hashed
// from its film point's bits: the same for any thread count, and as free of
// its geometry as a hash is.
float roulette_uniform(Point2f raster_px) {
    uint32_t x, y;
    std::memcpy(&x, &raster_px.x, sizeof x), std::memcpy(&y, &raster_px.y, sizeof y);
    return float(mix64((uint64_t(x) << 32) | y) >> 40) * 0x1.0p-24f;
}

}  // namespace

// Per instruction set (target_clones): baseline x86-64 has no rounding
// instruction, and its floor in software was most of this function (perf).
__attribute__((target_clones("default", "avx2", "avx512f"))) void split_into_bands(
    int n, const Point2f* raster_px, const double* lens_x_m, const double* lens_y_m, const DispersionRuns& runs,
    double x_scale, double y_scale, BandRays* out, const double* k_ref_by_sample, const double* k_from_by_sample,
    const double* k_to_by_sample, bool whole_points) {
    const double k_all_lowest = runs.lowest(), k_all_highest = runs.highest();
    // Each sample's stretch of k (a lens system's ray passes its rims over part of the spectrum only).
    double k_from[kCameraBatch], k_to[kCameraBatch];
    if (k_from_by_sample) std::copy_n(k_from_by_sample, n, k_from), std::copy_n(k_to_by_sample, n, k_to);
    else std::fill_n(k_from, n, k_all_lowest), std::fill_n(k_to, n, k_all_highest);
    double k_refs[kCameraBatch];
    if (k_ref_by_sample) std::copy_n(k_ref_by_sample, n, k_refs);
    else std::fill_n(k_refs, n, runs.reference());
    // Every sample's test first, in a loop of its own that GCC vectorises (a
    // fifth of the samples split, at random: a branch on it was a third of
    // this function, and the test's scalar floors most of the rest, perf and
    // callgrind); then each written as a whole sample, kept only where it is
    // one, and its index kept for the walk below where it is not.
    bool whole[kCameraBatch];
    for (int i = 0; i < n; ++i) {
        const double x = raster_px[i].x, y = raster_px[i].y;
        const double below = k_from[i] - k_refs[i], above = k_to[i] - k_refs[i];
        // Screen x grows with raster x, screen y against raster y (FilmToScreen).
        const double gx = lens_x_m[i] * x_scale, gy = -lens_y_m[i] * y_scale;
        // Whole: the whole spectrum in one pixel; or none of it (the camera then marks it vignetted).
        whole[i] = ((std::floor(x + gx * below) == std::floor(x + gx * above)) &
                    (std::floor(y + gy * below) == std::floor(y + gy * above)) & (k_from[i] == k_all_lowest) &
                    (k_to[i] == k_all_highest)) |
                   !(k_to[i] > k_from[i]);
    }
    // Sample i as whole sample w.
    auto write_whole = [&](int w, int i) {
        out->whole_sample[w] = i;
        if (!whole_points) return;
        out->whole_raster_px[w] = raster_px[i];
        out->whole_lens_x_m[w] = float(lens_x_m[i]), out->whole_lens_y_m[w] = float(lens_y_m[i]);
    };
    int split[kCameraBatch];
    int whole_count = 0, split_count = 0;
    for (int i = 0; i < n; ++i) {
        write_whole(whole_count, i);
        whole_count += int(whole[i]);
        split[split_count] = i;
        split_count += int(!whole[i]);
    }
    out->whole_count = whole_count;
    for (int s = 0; s < split_count; ++s) {
        const int i = split[s];
        const double x = raster_px[i].x, y = raster_px[i].y;
        const double k_ref = k_refs[i], k_lowest = k_from[i], k_highest = k_to[i];
        const double below = k_lowest - k_ref, above = k_highest - k_ref;
        const double gx = lens_x_m[i] * x_scale, gy = -lens_y_m[i] * y_scale;
        const double pixel_x = std::floor(x), pixel_y = std::floor(y);
        auto emit_one = [&](double cell_x, double cell_y, double k_from, double k_to, float scale = 1.0f,
                            float whole_part = 0.0f) {
            if (!(k_to > k_from)) return;  // a corner: no wavelength lands there
            const size_t at = size_t(out->count++);
            out->sample[at] = i;
            out->raster_px[at] = {float(x - (cell_x - pixel_x)), float(y - (cell_y - pixel_y))};
            out->lens_x_m[at] = float(lens_x_m[i]), out->lens_y_m[at] = float(lens_y_m[i]);
            out->k_lo[at] = k_from, out->k_hi[at] = k_to;
            out->entry_scale[at] = scale, out->entry_whole_part[at] = whole_part;
        };
        const double x_from = std::floor(x + gx * below), x_to = std::floor(x + gx * above);
        const double y_from = std::floor(y + gy * below), y_to = std::floor(y + gy * above);
        if (std::fabs(x_to - x_from) <= 1.0 && std::fabs(y_to - y_from) <= 1.0) {
            // At most one edge each way (a spread under a pixel): crossings' walk written out.
            out->reserve_more(3);
            auto edge_k = [&](double from, double to, double position, double g) {
                return to != from ? std::clamp(k_ref + (std::max(from, to) - position) / g, k_lowest, k_highest)
                                  : k_highest;
            };
            const double kx = edge_k(x_from, x_to, x, gx), ky = edge_k(y_from, y_to, y, gy);
            const double k_first = std::min(kx, ky), k_second = std::max(kx, ky);
            const bool x_first = kx <= ky;
            // Split once, over the whole spectrum: roulette on the ray a pixel away. (The tests
            // joined by & rather than &&, one branch for all: callgrind 70.8 -> 70.3 a sample.)
            const bool once_over_all = (k_second == k_highest) & (k_first > k_lowest) & (k_first < k_highest) &
                                       (k_lowest == k_all_lowest) & (k_highest == k_all_highest);
            if (out->roulette && once_over_all) {
                const double far_x = x_first ? x_to : x_from, far_y = x_first ? y_from : y_to;
                const bool own_below = (x_from == pixel_x) & (y_from == pixel_y);
                const float q = out->roulette->probability(k_first, !own_below);
                if (!(roulette_uniform(raster_px[i]) < q)) {  // shaded whole
                    write_whole(out->whole_count++, i);
                    continue;
                }
                const float scale = 1.0f / q;
                emit_one(x_from, y_from, k_lowest, k_first, scale, own_below ? q - 1.0f : 0.0f);
                emit_one(far_x, far_y, k_first, k_highest, scale, own_below ? 0.0f : q - 1.0f);
                continue;
            }
            emit_one(x_from, y_from, k_lowest, k_first);
            if (x_first) emit_one(x_to, y_from, k_first, k_second);
            else emit_one(x_from, y_to, k_first, k_second);
            emit_one(x_to, y_to, k_second, k_highest);
            continue;
        }
        double cell_x, cell_y;
        const int step_x = crossings(x, gx, k_ref, k_lowest, k_highest, &out->x_edges, &cell_x);
        const int step_y = crossings(y, gy, k_ref, k_lowest, k_highest, &out->y_edges, &cell_y);
        const std::vector<double>&x_edges = out->x_edges, &y_edges = out->y_edges;
        out->reserve_more(int(x_edges.size() + y_edges.size()) + 1);
        auto emit = [&](double k_from, double k_to) { emit_one(cell_x, cell_y, k_from, k_to); };
        // Walk the two lists of edges in k order, a ray per stretch between them.
        double k = k_lowest;
        size_t ix = 0, iy = 0;
        while (ix < x_edges.size() || iy < y_edges.size()) {
            const bool x_next = iy == y_edges.size() || (ix < x_edges.size() && x_edges[ix] <= y_edges[iy]);
            const double edge = std::clamp(x_next ? x_edges[ix] : y_edges[iy], k, k_highest);
            emit(k, edge);
            k = edge;
            if (x_next) cell_x += step_x, ++ix;
            else cell_y += step_y, ++iy;
        }
        emit(k, k_highest);
    }
}

}  // namespace lc
