#include "lens/lens_band_table.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cpu_kernels.h"
#include "lens/lens_aim.h"

namespace lc {
namespace {

// One node's values for a film point at (r, 0) and pupil sample (s, u).
void trace_band_node(const std::vector<LensElement>& elements, const std::vector<LensElement>& blue_reversed,
                     double k_per_blue, const ExitPupil& pupil, AimPlanes planes, int ring, double film_r_mm, double s,
                     float u, float* out) {
    std::fill(out, out + 4, std::numeric_limits<float>::quiet_NaN());
    PupilPick pick;
    if (!pupil.pick_in_ring(ring, film_r_mm, u, &pick)) return;
    LensRay ray = aim_one(film_r_mm, 0.0, film_r_mm, s * s, pick, planes);
    double margin_d, margin_blue;
    if (!trace_with_margin(elements, &ray, &margin_d)) return;
    // Back toward the film through the lens at 380 nm (lens_reverse.h's mirrored frame).
    LensRay back;
    back.origin_mm = {ray.origin_mm.x, ray.origin_mm.y, -ray.origin_mm.z};
    back.direction = {-ray.direction.x, -ray.direction.y, ray.direction.z};
    if (!trace_with_margin(blue_reversed, &back, &margin_blue) || !(back.direction.z < 0.0)) return;
    const double t = (-planes.film_z_mm - back.origin_mm.z) / back.direction.z;
    const double x_mm = back.origin_mm.x + back.direction.x * t, y_mm = back.origin_mm.y + back.direction.y * t;
    out[kBandShiftX] = float((x_mm - film_r_mm) / k_per_blue);
    out[kBandShiftY] = float(y_mm / k_per_blue);
    // trace_with_margin's clearance is (rim - height) / rim; the render's
    // trace keeps (rim^2 - height^2) / rim^2 = m (2 - m) (lens_trace_lanes.h),
    // the least of either being the same surface's (no blades here).
    auto squared = [](double m) { return m * (2.0 - m); };
    out[kBandSlope] = float((squared(margin_blue) - squared(margin_d)) / k_per_blue);
    out[3] = 0.0f;
}

typedef float Float4 __attribute__((vector_size(16), aligned(16)));

Float4 load4(const float* p) {
    Float4 v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}

}  // namespace

std::shared_ptr<const LensBandTable> build_lens_band_table(const std::vector<LensElement>& elements,
                                                           const std::vector<LensElement>& blue_reversed,
                                                           double k_per_blue, const ExitPupil& pupil,
                                                           double film_z_mm, int radial_cells, int around_cells) {
    auto table = std::make_shared<LensBandTable>();
    static_cast<LensTableGrid&>(*table) = LensTableGrid(pupil, radial_cells, around_cells);
    table->nodes.resize(table->node_count());
    const AimPlanes planes{film_z_mm, pupil.plane_z_mm()};
    table->for_each_node(pupil, [&](int ring, int end, double film_r_mm, double s, float u, size_t node) {
        trace_band_node(elements, blue_reversed, k_per_blue, pupil, planes, ring, film_r_mm, s, u,
                        table->nodes[node].end[end]);
    });
    return table;
}

LC_BUILT_PER_ISA void locate_band_cells(const LensBandTable& table, FilmPlacement film, const Point2f* raster_px,
                                        const Point2f* lens_sample, int n, TableCellLanes* cells) {
    find_table_cells(table, film, raster_px, lens_sample, n, cells);  // as look_up_lens_rays
    prefetch_table_cells(table.nodes.data(), *cells, n, table.around_nodes());  // 0.6 MB: more than Zen 3's L2
}

LC_BUILT_PER_ISA void look_up_band_shifts(const LensBandTable& table, const TableCellLanes& cells, int n,
                                          double* shift_x_mm, double* shift_y_mm, double* slope, bool* valid) {
    const int around_nodes = table.around_nodes();
    const float *fr = cells.fr, *fs = cells.fs, *fu = cells.fu, *y_sign = cells.y_sign;
    const float *x = cells.x, *y = cells.y, *r = cells.r;
    const int* first_node = cells.first_node;
    float gx[kLensBatch], gy[kLensBatch], dm[kLensBatch];
    const BandTableNode* nodes = table.nodes.data();
    for (int i = 0; i < n; ++i) {
        const BandTableNode* n00 = nodes + first_node[i];
        const Float4 f_r = Float4{} + fr[i], f_u = Float4{} + fu[i], f_s = Float4{} + fs[i];
        auto at_radius = [&](const BandTableNode* node) {
            const Float4 inner = load4(node->end[0]), outer = load4(node->end[1]);
            return inner + f_r * (outer - inner);
        };
        const Float4 e00 = at_radius(n00), e01 = at_radius(n00 + 1);
        const Float4 e10 = at_radius(n00 + around_nodes), e11 = at_radius(n00 + around_nodes + 1);
        const Float4 near = e00 + f_u * (e01 - e00), far = e10 + f_u * (e11 - e10);
        const Float4 v = near + f_s * (far - near);
        gx[i] = v[kBandShiftX], gy[i] = v[kBandShiftY], dm[i] = v[kBandSlope];
    }
    for (int i = 0; i < n; ++i) {
        valid[i] = gx[i] == gx[i];
        // Turned from +x to the film point's azimuth (the axis: no turn).
        const float on_axis = r[i] > 0.0f ? 0.0f : 1.0f;
        const float inverse_r = 1.0f / (r[i] + on_axis);
        const float cos_phi = (x[i] + on_axis) * inverse_r, sin_phi = y[i] * inverse_r;
        const float ty = gy[i] * y_sign[i];
        shift_x_mm[i] = double(cos_phi * gx[i] - sin_phi * ty);
        shift_y_mm[i] = double(sin_phi * gx[i] + cos_phi * ty);
        slope[i] = double(dm[i]);
    }
}

void look_up_band_shifts(const LensBandTable& table, FilmPlacement film, const Point2f* raster_px,
                         const Point2f* lens_sample, int n, double* shift_x_mm, double* shift_y_mm, double* slope,
                         bool* valid) {
    TableCellLanes cells;
    locate_band_cells(table, film, raster_px, lens_sample, n, &cells);
    look_up_band_shifts(table, cells, n, shift_x_mm, shift_y_mm, slope, valid);
}

}  // namespace lc
