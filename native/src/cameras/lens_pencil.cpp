#include "cameras/lens_pencil.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "cameras/lens_system.h"
#include "cpu_kernels.h"

namespace lc {
namespace {

// Film points per cell side at most (cells of 8 pixels or more): a render
// tile (16 pixels) then spans two or three cells each way.
constexpr int kMaxCells = 64;
constexpr int kMinCellPx = 8;
// Pupil samples per film point: rings at these radial samples (1: the
// polygon's edge), kAngles points round each, and the centre.
constexpr double kRings[] = {1.0, 0.95, 0.9, 0.8, 0.5};
constexpr int kAngles = 16;
// A cell's measured screen range is widened by this fraction of its extent
// each way (what lies between the sampled film and pupil points), and by
// kScreenPad; the rays' lateral reach by kRadiusMargin.
constexpr double kScreenWiden = 0.5, kScreenPad = 2e-4, kRadiusMargin = 0.05;
// How far past the front surface's rim the open pencils' plane reaches:
// a ray there has a clearance of 1 - 1.2^2 = -0.44, past what any band
// makes up on the shipped lenses (a ray beyond fails the check: the tile
// then tests every primitive).
constexpr double kOpenReach = 1.2;

struct SampledRay {
    double l_mm[2], slope[2];
};

}  // namespace

namespace {

// The test of both forms (traced rays, table rays) against M checks at once,
// in the rays' own precision T (the checks' bounds rounded to T once):
// within[m], whether every lane alive[m] marks, turned over as mirror m says
// (reflected_check), lies within checks[m] (null: a mirror with no check,
// answered true). The checks share their pencil plane, radius and focus (a
// LensPencils' own), so the rays' arithmetic is done once for all M.
// Division-free: each test multiplied through by w = -dz > 0. Flag as wide
// as T, so that the loop vectorises.
template <class T, class Flag, int M, class Rays>
__attribute__((always_inline)) inline void rays_within_all(const LensPencilCheck* const checks[M], const Rays& b,
                                                           const bool* const alive[M], bool within[M]) {
    const LensPencilCheck* any = nullptr;
    for (int m = 0; m < M; ++m) any = any ? any : checks[m];
    for (int m = 0; m < M; ++m) within[m] = true;
    if (!any) return;
    // The windows, each reflected for its mirror (a mirror with no check:
    // the whole screen, and none of its lanes checked).
    T lo[M][2], hi[M][2];
    Flag checked[M][kLensBatch];
    for (int m = 0; m < M; ++m) {
        const LensPencilCheck c = checks[m] ? reflected_check(*checks[m], unsigned(m)) : LensPencilCheck{};
        for (int a = 0; a < 2; ++a) {
            lo[m][a] = checks[m] ? T(c.screen_lo[a]) : -T(INFINITY);
            hi[m][a] = checks[m] ? T(c.screen_hi[a]) : T(INFINITY);
        }
        for (int i = 0; i < kLensBatch; ++i) checked[m][i] = checks[m] ? alive[m][i] : 0;
    }
    const T pencil_z_mm = T(any->pencil_z_mm), radius_mm = T(any->radius_mm), k_per_mm = T(any->k_per_mm);
    Flag outside[M] = {};
    for (int i = 0; i < kLensBatch; ++i) {
        const T w = -b.dz[i], z_mm = pencil_z_mm - b.oz[i];
        const T lw_x = b.ox[i] * w - z_mm * b.dx[i], lw_y = b.oy[i] * w - z_mm * b.dy[i];
        const T sw_x = b.dx[i] + k_per_mm * lw_x, sw_y = b.dy[i] + k_per_mm * lw_y;
        const T rw = radius_mm * w;
        // & rather than &&: no branches, so the loop vectorises
        const bool reach = (w > T(0)) & (z_mm >= T(0)) & (std::fabs(lw_x) <= rw) & (std::fabs(lw_y) <= rw);
        for (int m = 0; m < M; ++m) {
            const bool within_m = reach & (sw_x >= lo[m][0] * w) & (sw_x <= hi[m][0] * w) & (sw_y >= lo[m][1] * w) &
                                  (sw_y <= hi[m][1] * w);
            outside[m] |= checked[m][i] & Flag(!within_m);
        }
    }
    for (int m = 0; m < M; ++m) within[m] = outside[m] == 0;
}

// One check (mirror 0: no reflection).
template <class T, class Flag, class Rays>
__attribute__((always_inline)) inline bool rays_within(const LensPencilCheck& c, const Rays& b, const bool* alive) {
    const LensPencilCheck* checks[1] = {&c};
    const bool* lanes[1] = {alive};
    bool within[1];
    rays_within_all<T, Flag, 1>(checks, b, lanes, within);
    return within[0];
}

}  // namespace

LC_BUILT_PER_ISA bool lens_rays_within(const LensPencilCheck& c, const LensRayBatch& b, const bool* alive) {
    return rays_within<double, int64_t>(c, b, alive);
}

LC_BUILT_PER_ISA bool lens_rays_within(const LensPencilCheck& c, const LensRaysF& b, const bool* alive) {
    return rays_within<float, int32_t>(c, b, alive);
}

LC_BUILT_PER_ISA void lens_rays_within_mirrors(const LensPencilCheck* const checks[4], const LensRayBatch& b,
                                                const bool* const alive[4], bool within[4]) {
    rays_within_all<double, int64_t, 4>(checks, b, alive, within);
}

LC_BUILT_PER_ISA void lens_rays_within_mirrors(const LensPencilCheck* const checks[4], const LensRaysF& b,
                                                const bool* const alive[4], bool within[4]) {
    rays_within_all<float, int32_t, 4>(checks, b, alive, within);
}

std::shared_ptr<const LensPencils> LensPencils::of(const LensSystemCamera& camera, bool open) {
    auto p = std::make_shared<LensPencils>();
    // Every ray leaves from the front surface, within its semi-aperture: the
    // pencil plane a micron behind its cap (toward the film). The open
    // trace's rays may leave it a little beyond its rim (a band passes them
    // there): the cap to kOpenReach times the semi-aperture.
    const LensElement& front = camera.elements.front();
    const double sag_mm = rim_sag_mm(front.curvature_per_mm, front.semi_aperture_mm * (open ? kOpenReach : 1.0));
    p->pencil_z_mm_ = front.vertex_z_mm + std::max(sag_mm, 0.0) + 1e-3;
    // The ray table's interpolated origins may lie past the cap (its nodes
    // are traced without the rims, so a node past the rim leaves deeper in
    // the surface's sphere): the plane behind them all, else a live ray near
    // the rim fails the check and its tile tests every primitive from then on
    // (24 of 256 mirrored tiles of showcase from the table did).
    if (camera.ray_table && !open)
        p->pencil_z_mm_ = std::max(p->pencil_z_mm_, camera.ray_table->origin_z_hi_mm + 1e-3);

    p->columns_ = std::clamp(camera.width_px / kMinCellPx, 1, kMaxCells);
    p->rows_ = std::clamp(camera.height_px / kMinCellPx, 1, kMaxCells);
    p->cells_per_px_x_ = double(p->columns_) / camera.width_px;
    p->cells_per_px_y_ = double(p->rows_) / camera.height_px;

    // The pupil samples of one film point
    std::vector<Point2f> u;
    for (const double ring : kRings)
        for (int a = 0; a < kAngles; ++a) u.push_back({float(ring), (a + 0.5f) / kAngles});
    u.push_back({0.0f, 0.5f});

    // Each grid corner's rays that pass, as lateral point and slope on the pencil plane
    const int corners_x = p->columns_ + 1, corners_y = p->rows_ + 1;
    std::vector<std::vector<SampledRay>> rays(size_t(corners_x * corners_y));
    std::vector<bool> turns_back(rays.size(), false);
    Point2f raster[kLensBatch], lens[kLensBatch];
    for (int j = 0; j < corners_y; ++j)
        for (int i = 0; i < corners_x; ++i) {
            const size_t corner = size_t(j * corners_x + i);
            const Point2f film{float(i / p->cells_per_px_x_), float(j / p->cells_per_px_y_)};
            for (size_t first = 0; first < u.size(); first += kLensBatch) {
                const int n = int(std::min<size_t>(kLensBatch, u.size() - first));
                for (int k = 0; k < n; ++k) raster[k] = film, lens[k] = u[first + size_t(k)];
                LensRayBatch b;
                if (open) {  // (a split ray starts a pixel away: LensSystemCamera::checked_pencil)
                    double margin_d[kLensBatch];
                    bool alive[kCameraBatch];
                    camera.trace_open_from(raster, lens, n, &b, margin_d, alive);
                    camera.keep_band_carriers(raster, n, &b, margin_d);
                } else {
                    double area_mm2[kLensBatch], cos_theta[kLensBatch];
                    camera.trace_batch(raster, lens, n, &b, area_mm2, cos_theta);
                }
                for (int k = 0; k < n; ++k) {
                    if (!b.alive[k]) continue;
                    const double w = -b.dz[k];
                    if (!(w > 0.0)) {
                        turns_back[corner] = true;
                        continue;
                    }
                    const double z_mm = p->pencil_z_mm_ - b.oz[k];
                    SampledRay r;
                    r.slope[0] = b.dx[k] / w, r.slope[1] = b.dy[k] / w;
                    r.l_mm[0] = b.ox[k] - z_mm * r.slope[0], r.l_mm[1] = b.oy[k] - z_mm * r.slope[1];
                    rays[corner].push_back(r);
                }
            }
        }

    // k: the rays of the corner nearest the film centre most nearly share s
    // (least squares: their l against their slope).
    const std::vector<SampledRay>& centre = rays[size_t((corners_y / 2) * corners_x + corners_x / 2)];
    double l_slope = 0.0, l2 = 0.0;
    for (const SampledRay& r : centre)
        for (int a = 0; a < 2; ++a) l_slope += r.l_mm[a] * r.slope[a], l2 += r.l_mm[a] * r.l_mm[a];
    p->k_per_mm_ = l2 > 0.0 ? -l_slope / l2 : 0.0;

    double radius_mm = 0.0;
    for (const auto& corner_rays : rays)
        for (const SampledRay& r : corner_rays)
            radius_mm = std::max({radius_mm, std::fabs(r.l_mm[0]), std::fabs(r.l_mm[1])});
    p->radius_mm_ = radius_mm * (1.0 + kRadiusMargin) + 1e-3;

    // Each cell: the union of its four corners' screen points, widened
    p->cells_.resize(size_t(p->columns_ * p->rows_));
    for (int j = 0; j < p->rows_; ++j)
        for (int i = 0; i < p->columns_; ++i) {
            Cell& cell = p->cells_[size_t(j * p->columns_ + i)];
            cell.bounded = true;
            for (const int corner : {j * corners_x + i, j * corners_x + i + 1, (j + 1) * corners_x + i,
                                     (j + 1) * corners_x + i + 1}) {
                cell.bounded &= !turns_back[size_t(corner)];
                for (const SampledRay& r : rays[size_t(corner)])
                    for (int a = 0; a < 2; ++a) {
                        const double s = r.slope[a] + p->k_per_mm_ * r.l_mm[a];
                        cell.screen_lo[a] = std::min(cell.screen_lo[a], s);
                        cell.screen_hi[a] = std::max(cell.screen_hi[a], s);
                    }
            }
            for (int a = 0; a < 2; ++a) {
                if (cell.screen_lo[a] > cell.screen_hi[a]) continue;  // no corner ray passes: stays empty
                const double widen = kScreenWiden * (cell.screen_hi[a] - cell.screen_lo[a]) + kScreenPad;
                cell.screen_lo[a] -= widen, cell.screen_hi[a] += widen;
            }
        }
    return p;
}

std::shared_ptr<const LensPencils> LensPencils::collapsed() const {
    auto p = std::make_shared<LensPencils>(*this);
    for (Cell& cell : p->cells_)
        for (int a = 0; a < 2; ++a)
            if (cell.screen_lo[a] <= cell.screen_hi[a])
                cell.screen_lo[a] = cell.screen_hi[a] = 0.5 * (cell.screen_lo[a] + cell.screen_hi[a]);
    return p;
}

bool LensPencils::tile(const Frame& world_from_camera, double entrance_pupil_z_mm, double x0_px, double y0_px,
                       double x1_px, double y1_px, CameraPencil* pencil, LensPencilCheck* check) const {
    if (cells_.empty()) return false;
    const int i0 = std::clamp(int(std::floor(x0_px * cells_per_px_x_)), 0, columns_ - 1);
    const int i1 = std::clamp(int(std::ceil(x1_px * cells_per_px_x_)) - 1, i0, columns_ - 1);
    const int j0 = std::clamp(int(std::floor(y0_px * cells_per_px_y_)), 0, rows_ - 1);
    const int j1 = std::clamp(int(std::ceil(y1_px * cells_per_px_y_)) - 1, j0, rows_ - 1);
    LensPencilCheck c{pencil_z_mm_, radius_mm_, k_per_mm_, {INFINITY, INFINITY}, {-INFINITY, -INFINITY}};
    for (int j = j0; j <= j1; ++j)
        for (int i = i0; i <= i1; ++i) {
            const Cell& cell = cells_[size_t(j * columns_ + i)];
            if (!cell.bounded) return false;
            for (int a = 0; a < 2; ++a)
                c.screen_lo[a] = std::min(c.screen_lo[a], cell.screen_lo[a]),
                c.screen_hi[a] = std::max(c.screen_hi[a], cell.screen_hi[a]);
        }
    // No sampled ray passes anywhere in the tile: nothing to bound it by.
    if (!(c.screen_lo[0] <= c.screen_hi[0] && c.screen_lo[1] <= c.screen_hi[1])) return false;
    *check = c;
    CameraPencil& out = *pencil;
    out.world_from_camera = world_from_camera;
    out.world_from_camera.origin =
        world_from_camera.world_from_camera_point({0.0, 0.0, (entrance_pupil_z_mm - pencil_z_mm_) * 1e-3});
    out.lens_radius_m = radius_mm_ * 1e-3;
    out.inverse_focus_per_m = k_per_mm_ * 1e3;
    for (int a = 0; a < 2; ++a) out.screen_lo[a] = c.screen_lo[a], out.screen_hi[a] = c.screen_hi[a];
    out.origins_on_lens_disk = false;
    return true;
}

}  // namespace lc
