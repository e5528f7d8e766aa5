// A dispersive lens system's rays when each carries a band of the spectrum
// (render_tile_bands.h), the way the dispersive thin lens's do
// (thin_lens_bands.h), instead of a scene ray per traced hero wavelength.
//
// A sample's ray is traced at the d line from its film point x; the same
// ray, leaving the lens, came at 380 nm from film point x' (traced back
// through the glass). The glass makes the lens a one-parameter family in
// k(λ), the glasses' mean normalised dispersion (exactly so for glass given
// by an Abbe number: every index is then linear in 1 / λ²), and the film
// point at λ is taken on the line through the two: x + g (k(λ) - k_d),
// g = (x' - x) / (k_380 - k_d). As for the thin lens, each λ's film point
// wrapped back into the pixel is then uniform over it, and where it was
// wrapped by o pixels its ray is taken as the d-line ray from x - o aimed at
// the sample's own exit-pupil point (trace_split_rays): split_into_bands
// walks the segment, a ray per stretch of the spectrum landing in one pixel.
//
// Which wavelengths a ray carries: both traces let every ray through the
// rims and keep its least clearance (rim^2 - height^2) / rim^2, at d and at
// 380 nm; taken as linear in k too, the ray carries the stretch of the
// spectrum where it is positive. (Traced at d with the rims, a ray that
// passes in blue but not at d was never drawn: showcase lost 0.6 % of its
// blue channel wide open; weighting carriers at 380 and 780 nm by the ends a
// ray passes, as session 31 did, put it 0.8-1.5 % over in every channel.)
//
// Unlike the thin lens's this is an approximation, in four places: the film
// point off its line (the secondary spectrum's curve), the clearance off
// its line (where the rim that binds changes), g and the stretch taken as
// the same a pixel away (lateral colour changes across the image, so the
// wrap is not exactly uniform), and the split rays a pixel away carrying
// what their sample's ray carries. tests/test_lens_bands.py measures the
// whole against the traced wavelengths.
#include <algorithm>
#include <cmath>

#include "cameras/lens_system.h"
#include "cpu_kernels.h"
#include "double_lanes.h"
#include "lens/lens_band_table.h"
#include "rng.h"

namespace lc {
namespace {

// Rows of elements_by_nm (nm from 380) at the Fraunhofer lines.
constexpr size_t kRowF = 486 - 380, kRowD = 588 - 380, kRowC = 656 - 380;

// k(λ): the mean over the lens's glasses (the media behind its surfaces that
// disperse) of (n(λ) - n_d) / (n_F - n_C).
std::vector<double> band_parameter(const std::vector<std::vector<LensElement>>& by_nm) {
    if (by_nm.size() <= kRowC) return {};
    std::vector<double> k(by_nm.size(), 0.0);
    const std::vector<LensElement>&f = by_nm[kRowF], &d = by_nm[kRowD], &c = by_nm[kRowC];
    int glasses = 0;
    for (size_t e = 0; e < d.size(); ++e) {
        const double spread = f[e].n_film_side - c[e].n_film_side;
        if (!(std::fabs(spread) > 1e-12)) continue;
        ++glasses;
        for (size_t row = 0; row < by_nm.size(); ++row)
            k[row] += (by_nm[row][e].n_film_side - d[e].n_film_side) / spread;
    }
    if (glasses == 0) return {};
    for (double& v : k) v /= glasses;
    return k;
}

// Each sample's g, in raster pixels per unit of k (split_into_bands: raster
// x grows with its first argument, raster y against its second; the film is
// inverted), and the stretch [k_from, k_to) of k its rays carry: where the
// clearance, on its line in k, is positive. A sample with no way back at 380
// nm (known false: a miss, or total reflection) keeps its d path only; one
// that no wavelength gets through is marked dead in alive. Four lanes at a
// time without branches, built per instruction set: written per sample, with
// a branch on the slope's sign and a division in each, it was a tenth of a
// band render's time (perf, session 49, Zen 4), and GCC would not vectorise
// it (double_lanes.h). The same IEEE operations as per sample.
LC_BUILT_PER_ISA void clearance_stretches(int n, const bool* known, const double* shift_x_mm,
                                          const double* shift_y_mm, const double* slope, const double* margin_d,
                                          double px_per_mm_x, double px_per_mm_y, const DispersionRuns& runs,
                                          bool* alive, double* gx, double* gy, double* k_from, double* k_to) {
    const Double4 k_d = Double4{} + runs.reference(), k_lowest = Double4{} + runs.lowest();
    const Double4 k_highest = Double4{} + runs.highest(), zero{}, one = zero + 1.0;
    for (int first = 0; first < n; first += 4) {
        const Double4 s = lanes_of(slope, first, n), m = lanes_of(margin_d, first, n);
        const Mask4 was_alive = lanes_of(alive, first, n), is_known = lanes_of(known, first, n);
        const Mask4 on_line = was_alive & is_known;
        const Mask4 rising = s > zero, falling = s < zero, open = m > zero;
        // Where the clearance's line crosses 0 (used only where the slope is not 0).
        const Double4 cut = k_d - m / (rising | falling ? s : one);
        const Double4 from = rising & (k_lowest < cut) ? cut : k_lowest;  // std::max(k_lowest, cut)
        const Double4 falling_to = falling & (cut < k_highest) ? cut : k_highest;  // std::min(k_highest, cut)
        // A flat clearance (or a NaN slope): the whole spectrum, or none of it.
        const Double4 to = ~rising & ~falling & ~open ? from : falling_to;
        const Double4 lane_gx = on_line ? -lanes_of(shift_x_mm, first, n) * px_per_mm_x : zero;
        const Double4 lane_gy = on_line ? -lanes_of(shift_y_mm, first, n) * px_per_mm_y : zero;
        const Double4 lane_from = on_line ? from : k_lowest, lane_to = on_line ? to : k_highest;
        const Mask4 now_alive = was_alive & ((is_known & (to > from)) | (~is_known & open));
        store_lanes(lane_gx, first, n, gx), store_lanes(lane_gy, first, n, gy);
        store_lanes(lane_from, first, n, k_from), store_lanes(lane_to, first, n, k_to);
        store_lanes(now_alive, first, n, alive);
    }
}

// Where each of rays [0, n) crosses the plane to_pupil_mm from the film (its
// origins'): built per instruction set, where baseline x86-64 divides two
// samples at a time (callgrind, AVX2: 5.5 instructions a sample, now 3.6).
LC_BUILT_PER_ISA void pupil_points(int n, const LensRayBatch& rays, double to_pupil_mm, double* x_mm,
                                   double* y_mm) {
    for (int i = 0; i < n; ++i) {
        const double t = to_pupil_mm / rays.dz[i];
        x_mm[i] = rays.ox[i] + rays.dx[i] * t;
        y_mm[i] = rays.oy[i] + rays.dy[i] * t;
    }
}

}  // namespace

void LensSystemCamera::set_band_rays(bool on) {
    band_rays_on = on;
    if (!on || !disperses() || !band_parameter_by_nm.empty()) return;
    band_parameter_by_nm = band_parameter(elements_by_nm);
    band_parameter_runs = DispersionRuns(band_parameter_by_nm);
    reversed_blue_elements = reversed_lens(elements_by_nm.front());
    // Not through blades: the table turns one film azimuth's values to each film point's.
    const bool round =
        std::none_of(elements.begin(), elements.end(), [](const LensElement& e) { return e.blades > 0; });
    if (round)
        band_table = build_lens_band_table(elements, reversed_blue_elements,
                                           band_parameter_by_nm.front() - band_parameter_runs.reference(), *pupil,
                                           film_z_mm, kBandTableRadialCells, kBandTableAroundCells);
    if (pencils) band_pencils = LensPencils::of(*this, true);  // none where the d line's are none
}

bool LensSystemCamera::trace_open_aimed(int n, LensRayBatch* rays, const double* area_mm2, double* margin,
                                        CameraRayRows* rows, float* weight, bool* alive,
                                        const LensPencilCheck* check) const {
    double cos_theta[kLensBatch];
    for (int i = 0; i < kLensBatch; ++i) cos_theta[i] = -rays->dz[i];
    trace_from_film_batch_margins(elements, rays, margin, trace_kernel);
    to_rows(lens_to_world(), *rays, cos_theta, area_mm2, n, rows, weight, alive);
    return !check || lens_rays_within(*check, *rays, alive);
}

bool LensSystemCamera::band_rays(const Point2f* raster_px, const Point2f* lens_sample, int n, BandRays* out,
                                 const LensPencilCheck* check) const {
    // The band table's cells first: their cache misses then overlap the trace.
    TableCellLanes cells;
    if (band_table) locate_band_cells(*band_table, film_placement(), raster_px, lens_sample, n, &cells);
    LensRayBatch leaving;
    double margin_d[kLensBatch];
    sample_batch(raster_px, lens_sample, n, &leaving, out->sample_area_mm2);
    // Where each aimed ray crosses the exit-pupil plane: its split rays aim there too.
    pupil_points(n, leaving, pupil->plane_z_mm() - film_z_mm, out->sample_pupil_x_mm, out->sample_pupil_y_mm);
    trace_open_aimed(n, &leaving, out->sample_area_mm2, margin_d, &out->sample_rows, out->sample_weight,
                     out->sample_alive, nullptr);
    // How the film point (mm) and the clearance move per unit of k: from the
    // table, or traced back at 380 nm where it cannot answer.
    double shift_x_mm[kLensBatch], shift_y_mm[kLensBatch], slope[kLensBatch];
    bool known[kLensBatch] = {};
    if (band_table) look_up_band_shifts(*band_table, cells, n, shift_x_mm, shift_y_mm, slope, known);
    // Alive and not known: bytes compared (GCC vectorises it), then counted
    // (with && and a bool's |= it was 9 instructions a sample, callgrind).
    bool unknown[kLensBatch] = {};
    int unknown_count = 0;
    for (int i = 0; i < n; ++i) unknown[i] = out->sample_alive[i] > known[i];
    for (int i = 0; i < n; ++i) unknown_count += unknown[i];
    if (unknown_count > 0)  // a ray with no way back at 380 nm stays unknown: its d path only (below)
        trace_band_shifts(leaving, raster_px, n, margin_d, unknown, shift_x_mm, shift_y_mm, slope, known);
    double gx[kCameraBatch], gy[kCameraBatch], k_from[kCameraBatch], k_to[kCameraBatch];
    clearance_stretches(n, known, shift_x_mm, shift_y_mm, slope, margin_d, 1.0 / film_mm_per_px_x,
                        1.0 / film_mm_per_px_y, band_parameter_runs, out->sample_alive, gx, gy, k_from, k_to);
    // Checked once each ray's stretch of the spectrum is known: the rays no
    // wavelength passes never reach the scene, and the pencils hold only those
    // some band passes (band_pencils).
    const bool within = !check || lens_rays_within(*check, leaving, out->sample_alive);
    const int first_entry = out->count;
    // No whole points: whole_ray_rows reads sample_rows.
    split_into_bands(n, raster_px, gx, gy, band_parameter_runs, 1.0, 1.0, out, nullptr, k_from, k_to, false);
    // The new split rays: their sample's exit-pupil point and pick area;
    // those in their sample's own pixel are its ray, the others are still
    // to trace (trace_split_rays).
    const size_t count = size_t(out->count);
    if (out->entry_weight.size() < out->sample.size()) {
        const size_t room = out->sample.size();
        out->entry_ray.resize(6 * room), out->entry_weight.resize(room), out->entry_pupil.resize(3 * room);
        out->entry_alive.resize(room), out->entry_found.resize(room);
    }
    for (size_t at = size_t(first_entry); at < count; ++at) {
        const int i = out->sample[at];
        out->entry_pupil[3 * at] = out->sample_pupil_x_mm[i], out->entry_pupil[3 * at + 1] = out->sample_pupil_y_mm[i];
        out->entry_pupil[3 * at + 2] = out->sample_area_mm2[i];
        const Point2f p = out->raster_px[at];
        const bool own = p.x == raster_px[i].x && p.y == raster_px[i].y;
        out->entry_found[at] = own;
        if (!own) continue;
        for (int a = 0; a < 3; ++a)
            out->entry_ray[6 * at + size_t(a)] = out->sample_rows.origin[a][i],
                                            out->entry_ray[6 * at + 3 + size_t(a)] = out->sample_rows.direction[a][i];
        out->entry_weight[at] = out->sample_weight[i];
        out->entry_alive[at] = out->sample_alive[i];
    }
    return within;
}

void LensSystemCamera::trace_band_shifts(const LensRayBatch& leaving, const Point2f* raster_px, int n,
                                         const double* margin_d, const bool* which, double* shift_x_mm,
                                         double* shift_y_mm, double* slope, bool* known) const {
    LensRayBatch back;
    double margin_blue[kLensBatch];
    mirror_for_back_trace(leaving, &back);
    for (int i = 0; i < kLensBatch; ++i) back.alive[i] = back.alive[i] && i < n && which[i];
    trace_from_film_batch_margins(reversed_blue_elements, &back, margin_blue, trace_kernel);
    const double per_k = 1.0 / (band_parameter_by_nm.front() - band_parameter_runs.reference());
    for (int i = 0; i < n; ++i) {
        if (!back.alive[i]) continue;
        double x_mm, y_mm, r_mm, blue_x_mm, blue_y_mm;
        film_point(raster_px[i], &x_mm, &y_mm, &r_mm);
        back_traced_film_point(back, i, film_z_mm, &blue_x_mm, &blue_y_mm);
        shift_x_mm[i] = (blue_x_mm - x_mm) * per_k, shift_y_mm[i] = (blue_y_mm - y_mm) * per_k;
        slope[i] = (margin_blue[i] - margin_d[i]) * per_k;
        known[i] = true;
    }
}

bool LensSystemCamera::trace_split_rays(BandRays* rays, const LensPencilCheck* check) const {
    // The rays a pixel or more from their sample's, a whole batch at a time:
    // from their own film point toward their sample's exit-pupil point (the
    // same lens sample would aim elsewhere where the pupil's rings are
    // narrower than a pixel), weighed by its pick's area, each carrying what
    // its sample's ray carries.
    bool within = true;
    const size_t count = size_t(rays->count);
    const double to_pupil_mm = pupil->plane_z_mm() - film_z_mm;
    size_t at = 0;
    while (true) {
        LensRayBatch aimed;
        double area_mm2[kLensBatch];
        size_t entry[kLensBatch];
        int m = 0;
        for (; at < count && m < kLensBatch; ++at) {
            if (rays->entry_found[at]) continue;
            double x_mm, y_mm, r_mm;
            film_point(rays->raster_px[at], &x_mm, &y_mm, &r_mm);
            const double tx = rays->entry_pupil[3 * at] - x_mm, ty = rays->entry_pupil[3 * at + 1] - y_mm;
            const double inverse_length = 1.0 / std::sqrt(tx * tx + ty * ty + to_pupil_mm * to_pupil_mm);
            aimed.ox[m] = x_mm, aimed.oy[m] = y_mm, aimed.oz[m] = film_z_mm;
            aimed.dx[m] = tx * inverse_length, aimed.dy[m] = ty * inverse_length;
            aimed.dz[m] = to_pupil_mm * inverse_length;
            aimed.alive[m] = true;
            area_mm2[m] = rays->entry_pupil[3 * at + 2];
            entry[m++] = at;
        }
        if (m == 0) break;
        for (int i = m; i < kLensBatch; ++i) {
            aimed.ox[i] = aimed.oy[i] = 0.0, aimed.oz[i] = film_z_mm;
            aimed.dx[i] = aimed.dy[i] = 0.0, aimed.dz[i] = -1.0, aimed.alive[i] = false, area_mm2[i] = 0.0;
        }
        double margin[kLensBatch];
        CameraRayRows traced;
        float weight[kCameraBatch];
        bool alive[kCameraBatch];
        within &= trace_open_aimed(m, &aimed, area_mm2, margin, &traced, weight, alive, within ? check : nullptr);
        for (int t = 0; t < m; ++t) {
            const size_t e = entry[t];
            for (int a = 0; a < 3; ++a)
                rays->entry_ray[6 * e + size_t(a)] = traced.origin[a][t],
                                         rays->entry_ray[6 * e + 3 + size_t(a)] = traced.direction[a][t];
            rays->entry_weight[e] = weight[t], rays->entry_alive[e] = alive[t], rays->entry_found[e] = true;
        }
    }
    return within;
}

void LensSystemCamera::keep_band_carriers(const Point2f* raster_px, int n, LensRayBatch* leaving,
                                          const double* margin_d) const {
    bool alive[kCameraBatch] = {}, known[kLensBatch] = {};
    for (int i = 0; i < n; ++i) alive[i] = leaving->alive[i];
    double shift_x_mm[kLensBatch], shift_y_mm[kLensBatch], slope[kLensBatch];
    trace_band_shifts(*leaving, raster_px, n, margin_d, alive, shift_x_mm, shift_y_mm, slope, known);
    double gx[kCameraBatch], gy[kCameraBatch], k_from[kCameraBatch], k_to[kCameraBatch];
    clearance_stretches(n, known, shift_x_mm, shift_y_mm, slope, margin_d, 1.0 / film_mm_per_px_x,
                        1.0 / film_mm_per_px_y, band_parameter_runs, alive, gx, gy, k_from, k_to);
    for (int i = 0; i < n; ++i) leaving->alive[i] = alive[i];
}

void LensSystemCamera::whole_ray_rows(const BandRays& rays, CameraRayRows* out, BandRayWeights* weights) const {
    for (int r = 0; r < rays.whole_count; ++r) {
        const int i = rays.whole_sample[r];
        for (int a = 0; a < 3; ++a)
            out->origin[a][r] = rays.sample_rows.origin[a][i], out->direction[a][r] = rays.sample_rows.direction[a][i];
        weights->weight[r] = rays.sample_weight[i];
        weights->alive[r] = rays.sample_alive[i];
    }
    weights->used = true;
}

void LensSystemCamera::band_ray_rows(const BandRays& rays, int first, int n, CameraRayRows* out,
                                     BandRayWeights* weights) const {
    // trace_split_rays found them all; a vignetted one still goes to the
    // packet (it may close its sample's value), weight 0: given a finite ray,
    // the camera's axis.
    const Vec3d origin = world_from_camera.world_from_camera_point({0.0, 0.0, 0.0});
    const Vec3d forward = world_from_camera.world_from_camera_vector({0.0, 0.0, 1.0});
    for (int r = 0; r < n; ++r) {
        const size_t e = size_t(first + r);
        const bool alive = rays.entry_alive[e];
        const float* ray = &rays.entry_ray[6 * e];
        out->origin[0][r] = alive ? ray[0] : float(origin.x), out->origin[1][r] = alive ? ray[1] : float(origin.y);
        out->origin[2][r] = alive ? ray[2] : float(origin.z);
        out->direction[0][r] = alive ? ray[3] : float(forward.x);
        out->direction[1][r] = alive ? ray[4] : float(forward.y);
        out->direction[2][r] = alive ? ray[5] : float(forward.z);
        weights->weight[r] = alive ? rays.entry_weight[e] : 0.0f;
        weights->alive[r] = alive;
    }
    weights->used = true;
}

void LensSystemCamera::trace_open_from(const Point2f* raster_px, const Point2f* lens_sample, int n,
                                       LensRayBatch* leaving, double* margin_d, bool* alive) const {
    double area_mm2[kLensBatch];
    CameraRayRows rows;
    float weight[kCameraBatch];
    sample_batch(raster_px, lens_sample, n, leaving, area_mm2);
    trace_open_aimed(n, leaving, area_mm2, margin_d, &rows, weight, alive, nullptr);
}

void LensSystemCamera::band_shifts(const Point2f* raster_px, const Point2f* lens_sample, int n, bool from_table,
                                   double* shift_x_mm, double* shift_y_mm, double* slope, bool* known) const {
    LensRayBatch leaving;
    double margin_d[kLensBatch];
    bool alive[kCameraBatch];
    std::fill_n(known, n, false);
    trace_open_from(raster_px, lens_sample, n, &leaving, margin_d, alive);
    if (from_table) {
        if (band_table)
            look_up_band_shifts(*band_table, film_placement(), raster_px, lens_sample, n, shift_x_mm, shift_y_mm,
                                slope, known);
    } else {
        trace_band_shifts(leaving, raster_px, n, margin_d, alive, shift_x_mm, shift_y_mm, slope, known);
    }
    for (int i = 0; i < n; ++i) known[i] = known[i] && alive[i];
}

BandModelCheck LensSystemCamera::check_band_model(int film_cells, int samples_per_cell) const {
    // Film points on a grid over the film (jittered), lens samples drawn,
    // all fixed by a seed: each ray traced open at d and back at 380 nm
    // (band_rays' model, as its cells without the table) and back at each
    // test wavelength with the rims (film_points_from: the truth).
    constexpr float kTestNm[] = {400.0f, 450.0f, 500.0f, 550.0f, 620.0f, 700.0f, 780.0f};
    const double k_d = band_parameter_runs.reference();
    uint64_t state = 0x9E3779B97F4A7C15ull;
    auto next = [&]() {  // SplitMix64 to [0, 1)
        return float(double(mix64(state += 0x9E3779B97F4A7C15ull) >> 40) * 0x1.0p-24);
    };
    std::vector<Point2f> raster, lens;
    for (int cy = 0; cy < film_cells; ++cy)
        for (int cx = 0; cx < film_cells; ++cx)
            for (int k = 0; k < samples_per_cell; ++k) {
                raster.push_back({float((cx + next()) / film_cells * width_px),
                                  float((cy + next()) / film_cells * height_px)});
                lens.push_back({next(), next()});
            }
    BandModelCheck out;
    std::vector<double> film_error_px;
    for (size_t first = 0; first < raster.size(); first += kLensBatch) {
        const int n = int(std::min<size_t>(kLensBatch, raster.size() - first));
        const Point2f* batch_raster = raster.data() + first;
        LensRayBatch leaving;
        double margin_d[kLensBatch];
        double shift_x_mm[kLensBatch], shift_y_mm[kLensBatch], slope[kLensBatch];
        bool alive[kCameraBatch], known[kLensBatch] = {};
        trace_open_from(batch_raster, lens.data() + first, n, &leaving, margin_d, alive);
        trace_band_shifts(leaving, batch_raster, n, margin_d, alive, shift_x_mm, shift_y_mm, slope, known);
        bool elsewhere[kLensBatch] = {};  // passing at some test wavelength, not at d
        for (float nm : kTestNm) {
            int32_t row[kLensBatch];
            std::fill_n(row, kLensBatch, glass_row(nm));
            double truth_x_mm[kLensBatch], truth_y_mm[kLensBatch];
            bool passes[kLensBatch];
            film_points_from(leaving, row, truth_x_mm, truth_y_mm, passes);
            const double dk = band_parameter_by_nm[size_t(row[0])] - k_d;
            for (int i = 0; i < n; ++i) {
                if (!alive[i] || !known[i]) continue;
                const bool model = margin_d[i] + slope[i] * dk > 0.0;
                elsewhere[i] |= passes[i] && !(margin_d[i] > 0.0);
                out.passing += int(passes[i]);
                out.one_way += int(model != passes[i]);
                if (!passes[i]) continue;
                double x_mm, y_mm, r_mm;
                film_point(batch_raster[i], &x_mm, &y_mm, &r_mm);
                const double ex = (truth_x_mm[i] - (x_mm + shift_x_mm[i] * dk)) / film_mm_per_px_x;
                const double ey = (truth_y_mm[i] - (y_mm + shift_y_mm[i] * dk)) / film_mm_per_px_y;
                film_error_px.push_back(std::sqrt(ex * ex + ey * ey));
            }
        }
        for (int i = 0; i < n; ++i) out.rays += int(alive[i]), out.elsewhere += int(elsewhere[i]);
    }
    if (!film_error_px.empty()) {
        const size_t at = size_t(0.99 * double(film_error_px.size() - 1));
        std::nth_element(film_error_px.begin(), film_error_px.begin() + std::ptrdiff_t(at), film_error_px.end());
        out.film_p99_px = film_error_px[at];
    }
    return out;
}

}  // namespace lc
