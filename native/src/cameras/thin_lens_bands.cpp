#include "cameras/thin_lens_bands.h"

#include <algorithm>
#include <cmath>
#include <cstring>

#include "double_lanes.h"
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

// floor(v), exactly, for |v| < 2^51 (film coordinates in pixels; NaN and
// infinities pass through): v rounded to the nearest integer by adding and
// taking away 1.5 x 2^52, less one where that went up (baseline x86-64 has
// no rounding instruction to vectorise). A zero comes back +0 where
// std::floor keeps -0: nothing below tells them apart.
inline Double4 floor_lanes(Double4 v) {
    const Double4 magic = Double4{} + 0x1.8p52;
    const Double4 nearest = (v + magic) - magic;
    return nearest > v ? nearest - 1.0 : nearest;
}

// Split samples' segments of film points, x + g (k - k_ref) for k over
// [k_lowest, k_highest), one entry a sample: the first and last pixel
// columns and rows; where a segment crosses at most one pixel edge each way
// (near: a spread under a pixel, most split samples), the planes where it
// crosses them (k_first <= k_second, k_highest for an edge it does not
// cross), whether it crosses x's first, whether it crosses one edge only,
// over the whole spectrum (BandRoulette's case), and whether its first pixel
// is the sample's own. Masks are all ones where true.
struct SplitSegments {
    static constexpr int kRoom = kCameraBatch + 3;  // whole groups of four lanes
    double x_from[kRoom], x_to[kRoom], y_from[kRoom], y_to[kRoom], k_first[kRoom], k_second[kRoom];
    long long near[kRoom], x_first[kRoom], once_over_all[kRoom], own_first[kRoom];
};

// Entries [first, first + 4) of *out from the samples' columns at first,
// four lanes at a time: the IEEE operations the walk below made a sample at
// a time until session 52 (their chain of floors, divisions and clamps was
// most of split_into_bands), lane by lane, so the same bits.
inline void segments_lanes(int first, const double* x_px, const double* y_px, const double* gx_px,
                           const double* gy_px, const double* k_ref_at, const double* k_lowest_at,
                           const double* k_highest_at, double k_all_lowest, double k_all_highest,
                           SplitSegments* out) {
    // Whole groups of four read as they are (the columns are padded):
    // double_lanes.h's lanes_of, which tests each lane against a count, cost
    // 2.5 cycles a sample more here (rdtsc).
    auto lanes = [&](const double* v) {
        Double4 l;
        std::memcpy(&l, v + first, sizeof l);
        return l;
    };
    auto store = [&](auto value, auto* to) { std::memcpy(to + first, &value, sizeof value); };
    const Double4 x = lanes(x_px), y = lanes(y_px), gx = lanes(gx_px), gy = lanes(gy_px), k_ref = lanes(k_ref_at);
    const Double4 k_lowest = lanes(k_lowest_at), k_highest = lanes(k_highest_at), one = Double4{} + 1.0;
    const Double4 below = k_lowest - k_ref, above = k_highest - k_ref;
    const Double4 x_from = floor_lanes(x + gx * below), x_to = floor_lanes(x + gx * above);
    const Double4 y_from = floor_lanes(y + gy * below), y_to = floor_lanes(y + gy * above);
    const Double4 dx = x_to - x_from, dy = y_to - y_from;
    const Mask4 near = ((dx < 0.0 ? -dx : dx) <= 1.0) & ((dy < 0.0 ? -dy : dy) <= 1.0);
    // Where the segment crosses an edge between from and to: divided whatever
    // the test (by 1 where it crosses none), the choice a select.
    auto edge_k = [&](Double4 from, Double4 to, Double4 position, Double4 g) {
        const Mask4 crosses = to != from;
        const Double4 far = from < to ? to : from;  // std::max(from, to)
        const Double4 k = k_ref + (far - position) / (crosses ? g : one);
        const Double4 clamped = k < k_lowest ? k_lowest : (k_highest < k ? k_highest : k);  // std::clamp
        return crosses ? clamped : k_highest;
    };
    const Double4 kx = edge_k(x_from, x_to, x, gx), ky = edge_k(y_from, y_to, y, gy);
    const Double4 k_first = ky < kx ? ky : kx, k_second = kx < ky ? ky : kx;  // std::min, std::max
    store(x_from, out->x_from), store(x_to, out->x_to), store(y_from, out->y_from), store(y_to, out->y_to);
    store(k_first, out->k_first), store(k_second, out->k_second);
    store(near, out->near), store(Mask4(kx <= ky), out->x_first);
    store(Mask4(near & (k_second == k_highest) & (k_first > k_lowest) & (k_first < k_highest) &
                (k_lowest == k_all_lowest) & (k_highest == k_all_highest)),
          out->once_over_all);
    store(Mask4((x_from == floor_lanes(x)) & (y_from == floor_lanes(y))), out->own_first);
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
    // Every sample's test first, in a loop of its own without a branch (a
    // fifth of the samples split, at random: a branch on it was a third of
    // this function, and the test's floors in software most of the rest at
    // baseline x86-64, perf and callgrind; GCC keeps the loop scalar, and in
    // four lanes, as the segments below, it was no faster: docs/how-it-was-
    // made-fast.md, session 52); then each written as a whole sample, kept
    // only where it is one, and its index kept for the walk below where it
    // is not.
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
    // Each split sample's segment four lanes at a time, then the roulette's
    // draws: a sample it shades whole (55 % of the split samples on showcase
    // through the Double Gauss) goes to the whole samples, in order, and
    // skips the walk. Before, the walk found each sample's segment and drew
    // a sample at a time: split_into_bands 29.6-30.1 -> 22.3-23.8 cycles a
    // sample (rdtsc around it, the lens system's band render at 64 spp; the
    // dispersive thin lens's 28.7 -> 19.8-20.0). Drawn in a scalar pass
    // without a branch before the walk, it was no faster end to end.
    SplitSegments segments;
    {
        constexpr int kRoom = SplitSegments::kRoom;
        double x[kRoom], y[kRoom], gx[kRoom], gy[kRoom], k_ref[kRoom], k_lo[kRoom], k_hi[kRoom];
        for (int s = 0; s < split_count + 3; ++s) {  // padded with the first's
            const int i = split[s < split_count ? s : 0];
            x[s] = raster_px[i].x, y[s] = raster_px[i].y;
            gx[s] = lens_x_m[i] * x_scale, gy[s] = -lens_y_m[i] * y_scale;
            k_ref[s] = k_refs[i], k_lo[s] = k_from[i], k_hi[s] = k_to[i];
        }
        for (int s = 0; s < split_count; s += 4)
            segments_lanes(s, x, y, gx, gy, k_ref, k_lo, k_hi, k_all_lowest, k_all_highest, &segments);
    }
    // The walk's samples: their index in segments, and the roulette's q for those it keeps.
    int walked[kCameraBatch];
    float q_of[kCameraBatch];
    int walk_count = 0;
    for (int s = 0; s < split_count; ++s) {
        const int i = split[s];
        const float q = !out->roulette ? 1.0f
                                       : out->roulette->probability(segments.once_over_all[s] ? segments.k_first[s]
                                                                                              : k_all_lowest,
                                                                    segments.own_first[s] == 0);
        const bool dropped = (out->roulette != nullptr) & (segments.once_over_all[s] != 0) &
                             !(roulette_uniform(raster_px[i]) < q);
        write_whole(whole_count, i);
        whole_count += int(dropped);
        walked[walk_count] = s, q_of[walk_count] = q;
        walk_count += int(!dropped);
    }
    out->whole_count = whole_count;
    for (int w = 0; w < walk_count; ++w) {
        const int s = walked[w], i = split[s];
        const double x = raster_px[i].x, y = raster_px[i].y;
        const double k_lowest = k_from[i], k_highest = k_to[i];
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
        if (segments.near[s]) {
            // At most one edge each way: crossings' walk written out.
            out->reserve_more(3);
            const double x_from = segments.x_from[s], x_to = segments.x_to[s];
            const double y_from = segments.y_from[s], y_to = segments.y_to[s];
            const double k_first = segments.k_first[s], k_second = segments.k_second[s];
            const bool x_first = segments.x_first[s];
            if (out->roulette && segments.once_over_all[s]) {
                // Split once, over the whole spectrum, and kept by the roulette: the ray a pixel away weighed 1 / q.
                const double far_x = x_first ? x_to : x_from, far_y = x_first ? y_from : y_to;
                const bool own_below = segments.own_first[s];
                const float q = q_of[w], scale = 1.0f / q;
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
        // Several edges: crossings' lists walked in k order.
        const double k_ref = k_refs[i], gx = lens_x_m[i] * x_scale, gy = -lens_y_m[i] * y_scale;
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
