#include "lens/lens_band_table.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

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
    table->rings = kPupilSegments;
    table->radial_cells = radial_cells, table->around_cells = around_cells;
    table->rings_per_mm = pupil.segments_per_mm();
    table->nodes.resize(size_t(kPupilSegments) * size_t(radial_cells + 1) * size_t(table->around_nodes()));
    const AimPlanes planes{film_z_mm, pupil.plane_z_mm()};
    // Each node on its own: the same table whatever the threads.
    tbb::parallel_for(0, kPupilSegments, [&](int ring) {
        for (int end = 0; end < 2; ++end) {
            const double film_r_mm = double(ring + end) / table->rings_per_mm;
            for (int i = 0; i <= radial_cells; ++i)
                for (int j = 0; j < table->around_nodes(); ++j) {
                    float* out = table->nodes[table->node_index(ring, i, j)].end[end];
                    if (pupil.segment(ring).empty) {
                        std::fill(out, out + 4, std::numeric_limits<float>::quiet_NaN());
                        continue;
                    }
                    trace_band_node(elements, blue_reversed, k_per_blue, pupil, planes, ring, film_r_mm,
                                    double(i) / radial_cells, float(j) / float(around_cells), out);
                }
        }
    });
    return table;
}

void look_up_band_shifts(const LensBandTable& table, FilmPlacement film, const Point2f* raster_px,
                         const Point2f* lens_sample, int n, double* shift_x_mm, double* shift_y_mm, double* slope,
                         bool* valid) {
    const int last_ring = table.rings - 1;
    const int around_nodes = table.around_nodes();
    const int ring_nodes = (table.radial_cells + 1) * around_nodes;
    const int last_radial = table.radial_cells - 1, last_around = around_nodes - 2;
    const float rings_per_mm = float(table.rings_per_mm);
    const float radial_cells = float(table.radial_cells), around_cells = float(table.around_cells);
    // As look_up_lens_rays: the ring and cell, u.y folded onto its half, in
    // plain lane loops that GCC vectorises; the corners a lane at a time.
    float x[kLensBatch], y[kLensBatch], r[kLensBatch], fr[kLensBatch], fs[kLensBatch], fu[kLensBatch];
    float y_sign[kLensBatch];
    int first_node[kLensBatch];
    for (int i = 0; i < n; ++i) {
        x[i] = (film.centre_x_px - raster_px[i].x) * film.mm_per_px_x;
        y[i] = (raster_px[i].y - film.centre_y_px) * film.mm_per_px_y;
        r[i] = std::sqrt(x[i] * x[i] + y[i] * y[i]);
        const float ring_at = r[i] * rings_per_mm;
        const int ring = std::min(int(ring_at), last_ring);
        fr[i] = std::min(ring_at - float(ring), 1.0f);
        const float radial_at = std::sqrt(lens_sample[i].x) * radial_cells;
        const int radial = std::min(int(radial_at), last_radial);
        fs[i] = radial_at - float(radial);
        const float uy = lens_sample[i].y;
        y_sign[i] = 1.0f - 2.0f * float(uy > 0.5f);
        const float around_at = std::min(uy, 1.0f - uy) * around_cells;
        const int around = std::min(int(around_at), last_around);
        fu[i] = around_at - float(around);
        first_node[i] = ring * ring_nodes + radial * around_nodes + around;
    }
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

}  // namespace lc
