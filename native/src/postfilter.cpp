#include "postfilter.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace lc {
namespace {

// Where the kernel of a pixel crosses one height: [left, right] in px from
// the pixel centre, or left > right when it does not reach that height.
struct Chord {
    double left, right;
};

// The aperture's image on the raster (y down), radius_px the circle's radius:
// behind the plane of focus upright in the picture, in front turned by 180
// degrees (aperture.h).
Chord chord_at(const ApertureShape& shape, double radius_px, bool behind_focus, double y_px) {
    const double ay = (behind_focus ? -y_px : y_px) / radius_px;  // aperture y is up
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    if (shape.blades == 0) {
        if (std::fabs(ay) >= 1.0) return {1.0, -1.0};
        hi = std::sqrt(1.0 - ay * ay), lo = -hi;
    } else {
        for (int k = 0; k < shape.blades; ++k) {
            const double x0 = shape.vertex_x[size_t(k)], y0 = shape.vertex_y[size_t(k)];
            const double x1 = shape.vertex_x[size_t(k) + 1], y1 = shape.vertex_y[size_t(k) + 1];
            if (std::min(y0, y1) > ay || std::max(y0, y1) < ay) continue;
            const double x = y1 == y0 ? x0 : x0 + (ay - y0) * (x1 - x0) / (y1 - y0);
            lo = std::min({lo, x, y1 == y0 ? x1 : x}), hi = std::max({hi, x, y1 == y0 ? x1 : x});
        }
        if (!(lo < hi)) return {1.0, -1.0};
    }
    // In front of the focus the picture's x is mirrored too (the 180-degree turn).
    return behind_focus ? Chord{lo * radius_px, hi * radius_px} : Chord{-hi * radius_px, -lo * radius_px};
}

// Largest |x| of the unit aperture: the kernel's reach sideways in radii.
double horizontal_reach(const ApertureShape& shape) {
    if (shape.blades == 0) return 1.0;
    double reach = 0.0;
    for (int k = 0; k < shape.blades; ++k) reach = std::max(reach, std::fabs(shape.vertex_x[size_t(k)]));
    return reach;
}

// Largest |y| of the unit aperture: the kernel's reach up and down in radii.
double vertical_reach(const ApertureShape& shape) {
    if (shape.blades == 0) return 1.0;
    double reach = 0.0;
    for (int k = 0; k < shape.blades; ++k) reach = std::max(reach, std::fabs(shape.vertex_y[size_t(k)]));
    return reach;
}

// Per-axis second moment of the unit aperture over its radius squared: 1/4 for
// the circle, R^2 (2 + cos(2 pi / N)) / 12 for the N-gon of circumradius R.
double axis_moment(const ApertureShape& shape) {
    if (shape.blades == 0) return 0.25;
    const double r2 = shape.vertex_x[0] * shape.vertex_x[0] + shape.vertex_y[0] * shape.vertex_y[0];
    return r2 * (2.0 + std::cos(2.0 * 3.14159265358979323846 / shape.blades)) / 12.0;
}

// Rows above and below its own that a pixel's kernel reaches.
int reach_rows(double radius_px, double reach) { return int(std::ceil(radius_px * reach + 0.5)); }

// Adds weight times the box-filtered coverage of [left, right) (raster x, px)
// to the difference buffers of one row: after a running sum, pixel i holds
// the length of [left, right) inside [i, i + 1).
void add_span(double left, double right, double weight, const float* rgb, int width, double* diff) {
    left = std::clamp(left, 0.0, double(width)), right = std::clamp(right, 0.0, double(width));
    if (!(right > left)) return;
    const int a = int(left), b = int(right);
    const double fa = left - a, fb = right - b;
    const double w[4] = {weight * rgb[0], weight * rgb[1], weight * rgb[2], weight};
    double* da = diff + 4 * size_t(a);
    double* db = diff + 4 * size_t(b);
    for (int c = 0; c < 4; ++c) {
        da[c] += w[c] * (1.0 - fa), da[4 + c] += w[c] * fa;
        db[c] += w[c] * (fb - 1.0), db[4 + c] -= w[c] * fb;
    }
}

// The radius each pixel's kernel is drawn with, so that its spread on the
// pixel grid adds exactly the aperture's second moment (eq. 5's diameter)
// whatever its size. Drawn on the grid (box-filtered over the output pixels,
// centred on a pixel centre) a kernel's variance is not its own: under half a
// pixel it adds nothing, far above it adds 1/12 px^2 per axis, which the
// pinhole's own pixel already holds. A table of the grid variance against the
// drawn radius, inverted: a 1 px blur then spreads a little into the
// neighbours, as the thin lens's does, instead of staying sharp.
class KernelRadius {
  public:
    KernelRadius(const ApertureShape& shape, int sub_rows) : shape_(shape), moment_(axis_moment(shape)) {
        const double reach = vertical_reach(shape);
        double previous = 0.0;
        for (int i = 0; i <= kSteps; ++i) {
            const double radius = i * kStep;
            previous = std::max(previous, grid_variance(radius, reach, sub_rows));  // kept monotonic
            variance_[size_t(i)] = previous;
        }
    }

    // Radius to draw for a signed blur diameter; 0 (the pixel kept whole) below kSharpPx.
    double operator()(double coc_px) const {
        const double r = 0.5 * std::fabs(coc_px);
        if (2.0 * r < kSharpPx) return 0.0;
        const double target = moment_ * r * r;  // the aperture's per-axis variance, px^2
        if (target >= variance_[kSteps]) return std::sqrt(std::max(target - 1.0 / 12.0, 0.0) / moment_);
        const double* first = variance_;
        const size_t i = size_t(std::upper_bound(first, first + kSteps + 1, target) - first);  // variance_[i] > target
        if (i == 0) return 0.0;
        const double lo = variance_[i - 1], hi = variance_[i];
        return ((i - 1) + (hi > lo ? (target - lo) / (hi - lo) : 0.0)) * kStep;
    }

  private:
    static constexpr int kSteps = 512;
    static constexpr double kStep = 1.0 / 64.0;  // radii 0..8 px; beyond, variance = moment r^2 + 1/12
    static constexpr double kSharpPx = 0.01;      // a blur this small keeps the pixel bit for bit

    // Per-axis variance (mean of x and y) of a kernel of this radius centred on a pixel, on the grid.
    double grid_variance(double radius, double reach, int sub_rows) const {
        if (radius <= 0.0) return 0.0;
        const int rows = reach_rows(radius, reach);
        std::vector<double> column(2 * size_t(rows) + 3, 0.0);
        double total = 0.0, sum_yy = 0.0, sum_xx = 0.0;
        for (int dy = -rows; dy <= rows; ++dy)
            for (int k = 0; k < sub_rows; ++k) {
                const Chord c = chord_at(shape_, radius, true, dy + (k + 0.5) / sub_rows - 0.5);
                if (!(c.right > c.left)) continue;
                // Coverage of pixel columns i (centre i, the kernel's centre at 0).
                for (int i = -rows - 1; i <= rows + 1; ++i) {
                    const double overlap = std::min(c.right, i + 0.5) - std::max(c.left, i - 0.5);
                    if (overlap <= 0.0) continue;
                    total += overlap, sum_yy += overlap * dy * dy, sum_xx += overlap * double(i) * i;
                }
            }
        return total > 0.0 ? 0.5 * (sum_xx + sum_yy) / total : 0.0;
    }

    ApertureShape shape_;
    double moment_;
    double variance_[kSteps + 1];
};

}  // namespace

void scatter_depth_of_field(const ScatterInput& in, float* out_rgb, float* out_coverage) {
    const int width = in.width_px, height = in.height_px, layers = in.n_layers, sub_rows = in.sub_rows;
    const size_t pixels = size_t(width) * size_t(height);
    const double reach = vertical_reach(in.aperture), across = horizontal_reach(in.aperture);
    const KernelRadius kernel_radius_px(in.aperture, sub_rows);

    // Each layer's pixels by row (compressed rows), in row-major order.
    std::vector<size_t> start(size_t(layers) * size_t(height) + 1, 0);
    for (size_t p = 0; p < pixels; ++p) ++start[size_t(in.layer[p]) * size_t(height) + p / size_t(width) + 1];
    for (size_t i = 1; i < start.size(); ++i) start[i] += start[i - 1];
    std::vector<int32_t> column(pixels);
    {
        std::vector<size_t> next(start.begin(), start.end() - 1);
        for (size_t p = 0; p < pixels; ++p)
            column[next[size_t(in.layer[p]) * size_t(height) + p / size_t(width)]++] = int32_t(p % size_t(width));
    }
    // Each pixel's drawn radius and reach, once (not per output row it reaches).
    std::vector<double> radius_px(pixels);
    std::vector<int> reach_px(pixels);
    std::vector<int> layer_reach(size_t(layers), 0);
    for (size_t p = 0; p < pixels; ++p) {
        radius_px[p] = kernel_radius_px(in.coc_px[p]);
        reach_px[p] = reach_rows(radius_px[p], reach);
        int& r = layer_reach[size_t(in.layer[p])];
        r = std::max(r, reach_px[p]);
    }

    tbb::task_arena arena(in.threads > 0 ? in.threads : tbb::task_arena::automatic);
    arena.execute([&] {
        // Each pixel's kernel sum on the grid, so that it spreads exactly its
        // own colour (0: smaller than a sub-row spacing, kept in its pixel).
        std::vector<double> inverse_area(pixels, 0.0);
        tbb::parallel_for(tbb::blocked_range<size_t>(0, pixels), [&](const tbb::blocked_range<size_t>& range) {
            for (size_t p = range.begin(); p < range.end(); ++p) {
                const double radius = radius_px[p];
                const bool behind = in.coc_px[p] > 0.0f;
                const int rows = reach_px[p];
                double area = 0.0;
                for (int dy = -rows; dy <= rows && radius > 0.0; ++dy)
                    for (int k = 0; k < sub_rows; ++k) {
                        const Chord c = chord_at(in.aperture, radius, behind, dy + (k + 0.5) / sub_rows - 0.5);
                        if (c.right > c.left) area += (c.right - c.left) / sub_rows;
                    }
                inverse_area[p] = area > 0.0 ? 1.0 / area : 0.0;
            }
        });

        tbb::parallel_for(tbb::blocked_range<int>(0, height), [&](const tbb::blocked_range<int>& rows) {
            std::vector<double> diff(4 * (size_t(width) + 2)), colour(3 * size_t(width)), coverage(size_t(width), 0.0);
            for (int y = rows.begin(); y < rows.end(); ++y) {
                std::fill(colour.begin(), colour.end(), 0.0);
                std::fill(coverage.begin(), coverage.end(), 0.0);
                for (int l = 0; l < layers; ++l) {  // back to front
                    bool touched = false;
                    int lo_x = 0, hi_x = 0;  // the diff entries this layer's spans wrote: [lo_x, hi_x)
                    const int from = std::max(0, y - layer_reach[size_t(l)]);
                    const int to = std::min(height - 1, y + layer_reach[size_t(l)]);
                    for (int ys = from; ys <= to; ++ys) {
                        const size_t row = size_t(l) * size_t(height) + size_t(ys);
                        for (size_t i = start[row]; i < start[row + 1]; ++i) {
                            const int x = column[i];
                            const size_t p = size_t(ys) * size_t(width) + size_t(x);
                            const float* rgb = in.rgb + 3 * p;
                            const int dy = y - ys;
                            if (!touched) touched = true, lo_x = width, hi_x = 0;
                            if (inverse_area[p] == 0.0) {  // a point: stays in its pixel
                                if (dy == 0) {
                                    add_span(x, x + 1.0, 1.0, rgb, width, diff.data());
                                    lo_x = std::min(lo_x, x), hi_x = std::max(hi_x, x + 3);
                                }
                                continue;
                            }
                            if (std::abs(dy) > reach_px[p]) continue;
                            const double radius = radius_px[p];
                            // add_span writes entries floor(left) .. floor(right) + 1.
                            const int span_reach = int(std::ceil(radius * across)) + 1;
                            lo_x = std::min(lo_x, std::max(0, x - span_reach));
                            hi_x = std::max(hi_x, std::min(width + 2, x + span_reach + 2));
                            const bool behind = in.coc_px[p] > 0.0f;
                            const double weight = inverse_area[p] / sub_rows;
                            for (int k = 0; k < sub_rows; ++k) {
                                const Chord c = chord_at(in.aperture, radius, behind, dy + (k + 0.5) / sub_rows - 0.5);
                                if (c.right > c.left)
                                    add_span(x + 0.5 + c.left, x + 0.5 + c.right, weight, rgb, width, diff.data());
                            }
                        }
                    }
                    if (!touched || hi_x <= lo_x) continue;
                    // The layer's row, then "over" what lies behind it; only where its
                    // spans reached (elsewhere the running sum is exactly 0: nothing to add).
                    double sum[4] = {0.0, 0.0, 0.0, 0.0};
                    const int end_x = std::min(hi_x, width);
                    for (int x = lo_x; x < end_x; ++x) {
                        for (int c = 0; c < 4; ++c) sum[c] += diff[4 * size_t(x) + size_t(c)];
                        double alpha = sum[3];
                        if (!(alpha > 1e-9)) continue;
                        // Overlapping kernels may sum past 1: the layer is then opaque there.
                        const double scale = alpha > 1.0 ? 1.0 / alpha : 1.0;
                        alpha *= scale;
                        // What lies behind, normalised by the weight it received: the
                        // holes that this layer's own objects left in it (and the frame's
                        // border) filled from their surroundings, so that a blurred rim
                        // shows the background round it rather than black.
                        double* behind = &colour[3 * size_t(x)];
                        const double behind_weight = coverage[size_t(x)];
                        const double fill = behind_weight > 0.0 ? 1.0 / behind_weight : 0.0;
                        for (int c = 0; c < 3; ++c) behind[c] = sum[c] * scale + (1.0 - alpha) * behind[c] * fill;
                        coverage[size_t(x)] = alpha + (1.0 - alpha) * (behind_weight > 0.0 ? 1.0 : 0.0);
                    }
                    std::fill(diff.begin() + 4 * size_t(lo_x), diff.begin() + 4 * size_t(hi_x), 0.0);
                }
                // Normalised by the weight that arrived: at the frame's border, and
                // where the nearest layers left a hole with nothing behind it.
                for (int x = 0; x < width; ++x) {
                    const size_t p = size_t(y) * size_t(width) + size_t(x);
                    const double a = coverage[size_t(x)];
                    for (int c = 0; c < 3; ++c) out_rgb[3 * p + size_t(c)] = a > 0.0 ? float(colour[3 * size_t(x) + size_t(c)] / a) : 0.0f;
                    out_coverage[p] = float(a);
                }
            }
        });
    });
}

}  // namespace lc
