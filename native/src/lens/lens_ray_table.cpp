#include "lens/lens_ray_table.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "cpu_kernels.h"
#include "lens/lens_aim.h"

namespace lc {

bool trace_with_margin(const std::vector<LensElement>& elements, LensRay* ray, double* margin) {
    if (!(ray->direction.z < 0.0)) return false;
    double least = INFINITY;
    for (auto e = elements.rbegin(); e != elements.rend(); ++e) {
        // The trace's own crossing without its rim tests; the hit point is then the origin.
        if (!cross_toward_scene(*e, ray, /*test_aperture=*/false)) return false;
        const Vec3d& p = ray->origin_mm;
        const double rim = e->semi_aperture_mm;
        least = std::min(least, rim > 0.0 ? (rim - std::sqrt(p.x * p.x + p.y * p.y)) / rim : -1.0);
        for (int k = 0; k < e->blades; ++k)
            least = std::min(least, (e->apothem_mm - (p.x * e->edge_normal_x[size_t(k)] +
                                                      p.y * e->edge_normal_y[size_t(k)])) / e->apothem_mm);
    }
    *margin = least;
    return true;
}

namespace {

// One node's values for a film point at (r, 0) and pupil sample (s, u).
void trace_node(const std::vector<LensElement>& elements, const ExitPupil& pupil, AimPlanes planes, int ring,
                double film_r_mm, double s, float u, float* out) {
    PupilPick pick;
    if (!pupil.pick_in_ring(ring, film_r_mm, u, &pick)) {  // outside the image circle: dead
        std::fill(out, out + kTableValues, 0.0f);
        out[kTableMargin] = -1.0f;
        return;
    }
    LensRay ray = aim_one(film_r_mm, 0.0, film_r_mm, s * s, pick, planes);
    const double cos_theta = -ray.direction.z;
    double margin;
    if (!trace_with_margin(elements, &ray, &margin)) {
        std::fill(out, out + kTableValues, std::numeric_limits<float>::quiet_NaN());
        return;
    }
    out[kTableOriginX] = float(ray.origin_mm.x);
    out[kTableOriginY] = float(ray.origin_mm.y);
    out[kTableOriginZ] = float(ray.origin_mm.z);
    out[kTableDirectionX] = float(ray.direction.x);
    out[kTableDirectionY] = float(ray.direction.y);
    out[kTableDirectionZ] = float(ray.direction.z);
    const double cos2 = cos_theta * cos_theta;
    out[kTableWeight] = float(cos2 * cos2 * pick.area_mm2);
    out[kTableMargin] = float(margin);
}

}  // namespace

std::shared_ptr<const LensRayTable> build_lens_ray_table(const std::vector<LensElement>& elements,
                                                         const ExitPupil& pupil, double film_z_mm,
                                                         int radial_cells, int around_cells) {
    auto table = std::make_shared<LensRayTable>();
    static_cast<LensTableGrid&>(*table) = LensTableGrid(pupil, radial_cells, around_cells);
    table->nodes.resize(table->node_count());
    const AimPlanes planes{film_z_mm, pupil.plane_z_mm()};
    table->for_each_node(pupil, [&](int ring, int end, double film_r_mm, double s, float u, size_t node) {
        trace_node(elements, pupil, planes, ring, film_r_mm, s, u, table->nodes[node].end[end]);
    });
    double radius2_mm2 = 0.0, z_lo = INFINITY, z_hi = -INFINITY;
    for (const LensTableNode& node : table->nodes)
        for (const float* v : node.end) {
            const double x = v[kTableOriginX], y = v[kTableOriginY], z = v[kTableOriginZ];
            if (!(std::isfinite(x) && std::isfinite(y) && std::isfinite(z))) continue;
            radius2_mm2 = std::max(radius2_mm2, x * x + y * y);
            z_lo = std::min(z_lo, z), z_hi = std::max(z_hi, z);
        }
    table->origin_radius_mm = std::sqrt(radius2_mm2);
    table->origin_z_lo_mm = z_lo <= z_hi ? z_lo : 0.0, table->origin_z_hi_mm = z_lo <= z_hi ? z_hi : 0.0;
    return table;
}

namespace {

// Eight floats as one value (GCC's vector extension): a node end's values, so
// that the interpolation is eight-wide arithmetic on any instruction set
// (two halves at the baseline), each lane IEEE float: the same bits on all.
typedef float Float8 __attribute__((vector_size(32), aligned(32)));

Float8 load8(const float* p) {
    Float8 v;
    __builtin_memcpy(&v, p, sizeof v);
    return v;
}

// A corner's values at film radius fraction fr between its ring's ends.
__attribute__((always_inline)) inline Float8 at_radius(const LensTableNode* node, Float8 fr) {
    const Float8 inner = load8(node->end[0]), outer = load8(node->end[1]);
    return inner + fr * (outer - inner);
}

// 8 lanes' values, value by value (out[q] lane k = lane[k][q]): a transpose.
__attribute__((always_inline)) inline void transpose8(const Float8* lane, Float8* out) {
    // Pairs, then quads, then halves (the classic three stages of unpacks).
    Float8 a[8], b[8];
    for (int k = 0; k < 8; k += 2) {
        a[k] = __builtin_shufflevector(lane[k], lane[k + 1], 0, 8, 1, 9, 4, 12, 5, 13);
        a[k + 1] = __builtin_shufflevector(lane[k], lane[k + 1], 2, 10, 3, 11, 6, 14, 7, 15);
    }
    for (int k = 0; k < 8; k += 4)
        for (int j = 0; j < 2; ++j) {
            b[k + j] = __builtin_shufflevector(a[k + j], a[k + j + 2], 0, 1, 8, 9, 4, 5, 12, 13);
            b[k + j + 2] = __builtin_shufflevector(a[k + j], a[k + j + 2], 2, 3, 10, 11, 6, 7, 14, 15);
        }
    // b[0], b[1], b[2], b[3] hold values (0, 4), (2, 6), (1, 5), (3, 7).
    constexpr int kFirstValue[4] = {0, 2, 1, 3};
    for (int j = 0; j < 4; ++j) {
        out[kFirstValue[j]] = __builtin_shufflevector(b[j], b[j + 4], 0, 1, 2, 3, 8, 9, 10, 11);
        out[kFirstValue[j] + 4] = __builtin_shufflevector(b[j], b[j + 4], 4, 5, 6, 7, 12, 13, 14, 15);
    }
}

}  // namespace

LC_BUILT_PER_ISA void look_up_lens_rays(const LensRayTable& table, FilmPlacement film, const Point2f* raster_px,
                                        const Point2f* lens_sample, int n, LensRaysF* out, bool* exact) {
    static_assert(kLensBatch % 8 == 0 && kTableValues == 8, "whole 8 x 8 transposes");
    const int around_nodes = table.around_nodes();
    TableCellLanes cells;
    find_table_cells(table, film, raster_px, lens_sample, n, &cells);
    const float *fr = cells.fr, *fs = cells.fs, *fu = cells.fu, *y_sign = cells.y_sign;
    const float *x = cells.x, *y = cells.y, *r = cells.r;
    const int* first_node = cells.first_node;
    // Each lane's four corners, eight values at once; then eight lanes'
    // values turned value by value. The batch's cache lines asked for first.
    alignas(32) float values[kTableValues][kLensBatch];
    const LensTableNode* nodes = table.nodes.data();
    prefetch_table_cells(nodes, cells, kLensBatch, around_nodes);
    for (int group = 0; group < kLensBatch; group += 8) {
        Float8 lane[8], by_value[8];
        for (int k = 0; k < 8; ++k) {
            const int i = group + k;
            const LensTableNode* n00 = nodes + first_node[i];
            const Float8 f_r = Float8{} + fr[i], f_u = Float8{} + fu[i], f_s = Float8{} + fs[i];
            const Float8 e00 = at_radius(n00, f_r), e01 = at_radius(n00 + 1, f_r);
            const Float8 e10 = at_radius(n00 + around_nodes, f_r), e11 = at_radius(n00 + around_nodes + 1, f_r);
            const Float8 near = e00 + f_u * (e01 - e00), far = e10 + f_u * (e11 - e10);
            lane[k] = near + f_s * (far - near);
        }
        transpose8(lane, by_value);
        // A failed corner's NaN kept in the margin only (it marks the lanes to trace).
        for (int q = 0; q < kTableMargin; ++q) by_value[q] = by_value[q] == by_value[q] ? by_value[q] : Float8{};
        for (int q = 0; q < kTableValues; ++q) __builtin_memcpy(&values[q][group], &by_value[q], sizeof(Float8));
    }
    // Which lanes pass, and which the caller traces (NaN: a failed corner).
    float keep[kLensBatch];  // 1: alive
    for (int i = 0; i < kLensBatch; ++i) {
        const bool valid = i < n;
        const float margin = values[kTableMargin][i];
        exact[i] = valid & (margin != margin);
        out->alive[i] = valid & (margin > 0.0f);
        keep[i] = out->alive[i] ? 1.0f : 0.0f;
    }
    // Rotated from +x to the film point's azimuth (as aim_one).
    for (int i = 0; i < kLensBatch; ++i) {
        // On the axis (r = 0) cos 1, sin 0, with no floating-point operation
        // under a condition (which GCC would not vectorise for AVX2).
        const float on_axis = r[i] > 0.0f ? 0.0f : 1.0f;
        const float inverse_r = 1.0f / (r[i] + on_axis);
        const float cos_phi = (x[i] + on_axis) * inverse_r, sin_phi = y[i] * inverse_r;
        const float ax = values[kTableDirectionX][i], ay = values[kTableDirectionY][i] * y_sign[i];
        const float az = values[kTableDirectionZ][i];
        const float inverse_length = 1.0f / std::sqrt(ax * ax + ay * ay + az * az);
        const float qx = values[kTableOriginX][i], qy = values[kTableOriginY][i] * y_sign[i];
        const float rx = cos_phi * qx - sin_phi * qy;
        const float ry = sin_phi * qx + cos_phi * qy;
        const float ux = (cos_phi * ax - sin_phi * ay) * inverse_length;
        const float uy = (sin_phi * ax + cos_phi * ay) * inverse_length;
        const float uz = az * inverse_length;
        // Dead lanes: (0, 0, 0) toward -z, weight 0 (finite values, no branch).
        out->ox[i] = rx * keep[i], out->oy[i] = ry * keep[i], out->oz[i] = values[kTableOriginZ][i] * keep[i];
        out->dx[i] = ux * keep[i], out->dy[i] = uy * keep[i], out->dz[i] = uz * keep[i] + (keep[i] - 1.0f);
        out->weight_mm2[i] = values[kTableWeight][i] * keep[i];
    }
}

}  // namespace lc
