#include "lens/exit_pupil.h"

#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace lc {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kScanCells = 24;      // coarse grid that finds where light passes
constexpr int kMarchSteps = 48;     // outward steps per boundary search
constexpr int kBisections = 14;     // refinement of each boundary point
constexpr double kRelativeMargin = 1.01;   // polygon enlargement: covers chords and ring interpolation
// ... plus a fraction of the scan half-width: eight times what the bisection
// leaves (2.5e-6). It was 2e-4, more than the pupil itself behind a pinpoint
// stop (0.007 mm on the Double Gauss): at f/5000 22 % of the traced rays
// passed, and the centre's calibration (a midpoint rule over the polygon)
// read 1.4 % low; now 78 % pass and the flat field's centre reads 1.000.
constexpr double kAbsoluteMargin = 0.00002;
// Other glasses' pupils (a dispersive lens's ends of the spectrum) widen a
// ring's polygon only where they reach past the first's by more than this
// factor somewhere: wide open they reach 1 % past it, within the margins,
// and widening there anyway took the dispersive lens system 25 % longer to
// 1 % noise on showcase (bench/bench_spectral.py) for no change in colour.
constexpr double kOutgrown = 1.03;

struct Direction2 {
    double x, y;
};

// cos and sin of the polygon's angles, computed once.
const std::array<Direction2, kPupilAngles>& unit_directions() {
    static const std::array<Direction2, kPupilAngles> table = [] {
        std::array<Direction2, kPupilAngles> t{};
        for (int k = 0; k < kPupilAngles; ++k)
            t[size_t(k)] = {std::cos(2.0 * kPi * k / kPupilAngles), std::sin(2.0 * kPi * k / kPupilAngles)};
        return t;
    }();
    return table;
}

struct PupilGeometry {
    const std::vector<LensElement>* elements;
    int stop_index;
    double film_z_mm, plane_z_mm;

    LensRay ray_through(double film_x_mm, double px, double py) const {
        return {{film_x_mm, 0.0, film_z_mm}, normalize(Vec3d{px - film_x_mm, py, plane_z_mm - film_z_mm})};
    }

    bool passes(double film_x_mm, double px, double py) const {
        LensRay ray = ray_through(film_x_mm, px, py);
        return trace_from_film(*elements, &ray);
    }

    // Height at which a ray aimed at (px, 0) crosses the stop, rims ignored;
    // false if it never gets there.
    bool stop_height(double film_x_mm, double px, double* height) const {
        LensRay ray = ray_through(film_x_mm, px, 0.0);
        for (int i = int(elements->size()) - 1; i > stop_index; --i)
            if (!cross_toward_scene((*elements)[size_t(i)], &ray, false)) return false;
        double t;
        if (!intersect_surface((*elements)[size_t(stop_index)], ray, &t)) return false;
        *height = ray.origin_mm.x + t * ray.direction.x;
        return true;
    }
};

// g.passes for n plane points (film point film_x[i], plane point (px[i],
// py[i])) into out[i] (1: passes), through the double batch trace a batch at
// a time: the same answers bit for bit, several times faster than one ray at
// a time (building the pupil was a fifth of a default lens render's wall time).
void passes_batch(const PupilGeometry& g, size_t n, const double* film_x, const double* px, const double* py,
                  char* out) {
    const LensTraceKernel kernel = best_lens_trace_kernel();
    for (size_t first = 0; first < n; first += kLensBatch) {
        const size_t count = std::min(n - first, size_t(kLensBatch));
        LensRayBatch b;
        for (size_t lane = 0; lane < size_t(kLensBatch); ++lane) {
            const size_t i = first + std::min(lane, count - 1);
            const LensRay ray = g.ray_through(film_x[i], px[i], py[i]);
            b.ox[lane] = ray.origin_mm.x, b.oy[lane] = ray.origin_mm.y, b.oz[lane] = ray.origin_mm.z;
            b.dx[lane] = ray.direction.x, b.dy[lane] = ray.direction.y, b.dz[lane] = ray.direction.z;
            b.alive[lane] = lane < count;
        }
        trace_from_film_batch(*g.elements, &b, kernel, LensTracePrecision::Double);
        for (size_t lane = 0; lane < count; ++lane) out[first + lane] = b.alive[lane];
    }
}

// The secant method from the axis: quick, and enough wherever the rays
// aimed near the axis reach the stop.
bool chief_ray_by_secant(const PupilGeometry& g, double film_x, double scale_mm, double* plane_x) {
    double x0 = 0.0, x1 = 0.1 * scale_mm, h0, h1;
    if (!g.stop_height(film_x, x0, &h0) || !g.stop_height(film_x, x1, &h1)) return false;
    for (int i = 0; i < 50 && std::fabs(h1) > 1e-12 * scale_mm; ++i) {
        if (h1 == h0) return false;
        double x2 = x1 - h1 * (x1 - x0) / (h1 - h0);
        x0 = x1, h0 = h1, x1 = x2;
        if (!std::isfinite(x1) || !g.stop_height(film_x, x1, &h1)) return false;
    }
    *plane_x = x1;
    return std::fabs(h1) <= 1e-6 * scale_mm;
}

// A scan of the plane for a sign change of the stop height between two rays
// that both reach the stop, then bisection. Needed far off the axis of a lens
// with a steeply curved rear group: there the ray aimed at the axis misses a
// surface's sphere altogether and the secant never starts (the wide-angle lens
// rendered black beyond 24 degrees at f/11 before this).
bool chief_ray_by_bracket(const PupilGeometry& g, double film_x, double scale_mm, double* plane_x) {
    constexpr int kCells = 512;
    double x_prev = 0.0, h_prev = 0.0;
    bool have_prev = false;
    for (int i = 0; i <= kCells; ++i) {
        double x = -2.0 * scale_mm + 4.0 * scale_mm * i / kCells, h;
        if (!g.stop_height(film_x, x, &h)) {
            have_prev = false;
            continue;
        }
        if (have_prev && (h_prev < 0.0) != (h < 0.0)) {
            double lo = x_prev, h_lo = h_prev, hi = x;
            bool bracket_holds = true;
            for (int k = 0; k < 60 && bracket_holds; ++k) {
                double mid = 0.5 * (lo + hi), h_mid;
                if (!g.stop_height(film_x, mid, &h_mid)) bracket_holds = false;
                else if ((h_mid < 0.0) == (h_lo < 0.0)) lo = mid, h_lo = h_mid;
                else hi = mid;
            }
            double h_at;
            if (bracket_holds && g.stop_height(film_x, 0.5 * (lo + hi), &h_at) && std::fabs(h_at) <= 1e-6 * scale_mm) {
                *plane_x = 0.5 * (lo + hi);
                return true;
            }
        }
        x_prev = x, h_prev = h, have_prev = true;
    }
    return false;
}

// Where the chief ray (through the stop centre) from film_x crosses the
// sampling plane; false when it cannot be found. It finds the pupil even when
// the stop is so small that a scan misses it.
bool chief_ray_plane_x(const PupilGeometry& g, double film_x, double scale_mm, double* plane_x) {
    return chief_ray_by_secant(g, film_x, scale_mm, plane_x) || chief_ray_by_bracket(g, film_x, scale_mm, plane_x);
}

// For each (film_x[j], psi[j]): the largest distance from (cx[j], 0) along
// angle psi at which light from film_x still passes, or 0 when none does. A
// march outward, then bisection, every search in lockstep (passes_batch).
std::vector<double> boundary_distances(const PupilGeometry& g, const std::vector<double>& film_x,
                                       const std::vector<double>& psi, const std::vector<double>& cx,
                                       double max_distance) {
    const size_t searches = film_x.size();
    const double step = max_distance / kMarchSteps;
    std::vector<double> cos_psi(searches), sin_psi(searches);
    for (size_t j = 0; j < searches; ++j) cos_psi[j] = std::cos(psi[j]), sin_psi[j] = std::sin(psi[j]);
    // The march: kMarchSteps + 1 points per search.
    constexpr size_t kPoints = kMarchSteps + 1;
    std::vector<double> fx(searches * kPoints), px(searches * kPoints), py(searches * kPoints);
    std::vector<char> passed(searches * kPoints);
    for (size_t j = 0; j < searches; ++j)
        for (size_t i = 0; i < kPoints; ++i) {
            fx[j * kPoints + i] = film_x[j];
            px[j * kPoints + i] = cx[j] + double(i) * step * cos_psi[j];
            py[j * kPoints + i] = double(i) * step * sin_psi[j];
        }
    passes_batch(g, fx.size(), fx.data(), px.data(), py.data(), passed.data());
    std::vector<double> lo(searches), hi(searches);
    std::vector<size_t> open;  // the searches that found light, being bisected
    for (size_t j = 0; j < searches; ++j) {
        int last_pass = -1;
        for (size_t i = 0; i < kPoints; ++i)
            if (passed[j * kPoints + i]) last_pass = int(i);
        if (last_pass < 0) continue;
        lo[j] = last_pass * step, hi[j] = lo[j] + step;
        open.push_back(j);
    }
    std::vector<double> mid(open.size());
    fx.resize(open.size()), px.resize(open.size()), py.resize(open.size()), passed.resize(open.size());
    for (int round = 0; round < kBisections; ++round) {
        for (size_t o = 0; o < open.size(); ++o) {
            const size_t j = open[o];
            mid[o] = 0.5 * (lo[j] + hi[j]);
            fx[o] = film_x[j], px[o] = cx[j] + mid[o] * cos_psi[j], py[o] = mid[o] * sin_psi[j];
        }
        passes_batch(g, open.size(), fx.data(), px.data(), py.data(), passed.data());
        for (size_t o = 0; o < open.size(); ++o) (passed[o] ? lo[open[o]] : hi[open[o]]) = mid[o];
    }
    std::vector<double> distance(searches, 0.0);
    for (size_t j : open) distance[j] = hi[j];
    return distance;
}

// The tables a sample reads, from the radii and the CDF.
void finish_sampling_tables(PupilPolygon* poly) {
    const auto& unit = unit_directions();
    for (int k = 0; k < kPupilAngles; ++k) {
        const size_t a = size_t(k), b = size_t((k + 1) % kPupilAngles);
        FanTriangle& t = poly->fan[a];
        t.cdf_lo = k == 0 ? 0.0 : poly->cdf[a - 1];
        t.cdf_hi = poly->cdf[a];
        t.inverse_cdf_step = 1.0 / std::max(t.cdf_hi - t.cdf_lo, 1e-300);
        t.a_x_mm = poly->radius_mm[a] * unit[a].x, t.a_y_mm = poly->radius_mm[a] * unit[a].y;
        t.b_x_mm = poly->radius_mm[b] * unit[b].x, t.b_y_mm = poly->radius_mm[b] * unit[b].y;
    }
    int k = 0;
    for (int j = 0; j < kPupilGuideCells; ++j) {
        while (k < kPupilAngles - 1 && poly->cdf[size_t(k)] <= double(j) / kPupilGuideCells) ++k;
        poly->guide[size_t(j)] = uint8_t(k);
    }
}

// The distance from the origin along (cos psi, sin psi) to the boundary of
// the convex hull of points (x, y), which holds the origin; 0 if it is not
// reached (a hull of fewer than three points).
double hull_reach(const std::vector<Direction2>& hull, double cos_psi, double sin_psi) {
    double reach = 0.0;
    const size_t n = hull.size();
    for (size_t i = 0; n >= 3 && i < n; ++i) {
        const Direction2 a = hull[i], b = hull[(i + 1) % n];
        // origin + t (c, s) = a + u (b - a): Cramer's rule
        const double ex = b.x - a.x, ey = b.y - a.y;
        const double det = cos_psi * (-ey) - sin_psi * (-ex);
        if (std::fabs(det) < 1e-300) continue;
        const double t = (a.x * (-ey) - a.y * (-ex)) / det;
        const double u = (cos_psi * a.y - sin_psi * a.x) / det;
        if (t > 0.0 && u >= -1e-12 && u <= 1.0 + 1e-12) reach = std::max(reach, t);
    }
    return reach;
}

// The convex hull of points, counter-clockwise (Andrew's monotone chain).
std::vector<Direction2> convex_hull(std::vector<Direction2> points) {
    std::sort(points.begin(), points.end(),
              [](const Direction2& a, const Direction2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
    if (points.size() < 3) return points;
    auto cross = [](const Direction2& o, const Direction2& a, const Direction2& b) {
        return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
    };
    std::vector<Direction2> hull(2 * points.size());
    size_t k = 0;
    for (size_t i = 0; i < points.size(); ++i) {
        while (k >= 2 && cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
        hull[k++] = points[i];
    }
    for (size_t i = points.size() - 1, lower = k + 1; i-- > 0;) {
        while (k >= lower && cross(hull[k - 2], hull[k - 1], points[i]) <= 0.0) --k;
        hull[k++] = points[i];
    }
    hull.resize(k - 1);
    return hull;
}

PupilPolygon build_polygon(const std::vector<PupilGeometry>& glasses, const double film_radii[3],
                           double scan_half_mm) {
    const PupilGeometry& g = glasses.front();
    PupilPolygon poly;
    // Where does light pass at all? Centre of the passing scan points.
    constexpr size_t kScanPoints = 3 * kScanCells * kScanCells;
    std::vector<double> scan_film(kScanPoints), scan_x(kScanPoints), scan_y(kScanPoints);
    std::vector<char> scan_passed(kScanPoints);
    size_t n = 0;
    for (int r = 0; r < 3; ++r)
        for (int iy = 0; iy < kScanCells; ++iy)
            for (int ix = 0; ix < kScanCells; ++ix, ++n) {
                scan_film[n] = film_radii[r];
                scan_x[n] = -scan_half_mm + (ix + 0.5) * 2.0 * scan_half_mm / kScanCells;
                scan_y[n] = -scan_half_mm + (iy + 0.5) * 2.0 * scan_half_mm / kScanCells;
            }
    passes_batch(g, kScanPoints, scan_film.data(), scan_x.data(), scan_y.data(), scan_passed.data());
    double sum_x = 0.0;
    int count = 0;
    for (size_t i = 0; i < kScanPoints; ++i)
        if (scan_passed[i]) sum_x += scan_x[i], ++count;
    // Anchor: the chief ray of the middle radius when it gets through (it
    // finds tiny stops the scan misses), else the centre of the scan's hits.
    // When the chief rays of the ring's first and last radii get through too,
    // the centre follows them (a line through the two), so that a pupil
    // smaller than its move across the ring stays inside the polygon.
    double chief_x[3];
    bool chief_passes[3];
    for (int r = 0; r < 3; ++r)
        chief_passes[r] = chief_ray_plane_x(g, film_radii[r], scan_half_mm, &chief_x[r]) &&
                          g.passes(film_radii[r], chief_x[r], 0.0);
    poly.centre_r_mm = film_radii[1];
    if (chief_passes[1]) {
        poly.centre_x_mm = chief_x[1];
        if (chief_passes[0] && chief_passes[2] && film_radii[2] > film_radii[0])
            poly.centre_slope = (chief_x[2] - chief_x[0]) / (film_radii[2] - film_radii[0]);
    } else if (count > 0) {
        poly.centre_x_mm = sum_x / count;
    } else {
        return poly;  // outside the image circle
    }
    poly.empty = false;

    // Boundary per angle: the farthest passing point over the ring's radii,
    // each searched from where the centre lies for it.
    std::vector<double> search_film, search_psi, search_centre;
    for (int k = 0; k < kPupilAngles; ++k)
        for (int r = 0; r < 3; ++r) {
            search_film.push_back(film_radii[r]), search_psi.push_back(2.0 * kPi * k / kPupilAngles);
            search_centre.push_back(ExitPupil::centre_at(poly, film_radii[r]));
        }
    const std::vector<double> distance =
        boundary_distances(g, search_film, search_psi, search_centre, 2.0 * scan_half_mm);
    std::array<double, kPupilAngles> raw{};
    for (int k = 0; k < kPupilAngles; ++k)
        for (int r = 0; r < 3; ++r) raw[size_t(k)] = std::max(raw[size_t(k)], distance[size_t(3 * k + r)]);
    if (glasses.size() > 1) {
        // Every glass's boundary, each searched from its own chief ray where
        // that gets through (else from the first's centre), as points round
        // the first's centre at the same film radius; the polygon reaches the
        // hull of them all (pupils through round rims are convex).
        const auto& unit = unit_directions();
        std::vector<Direction2> points;
        for (int k = 0; k < kPupilAngles; ++k)
            for (int r = 0; r < 3; ++r) {
                const double d = distance[size_t(3 * k + r)];
                points.push_back({d * unit[size_t(k)].x, d * unit[size_t(k)].y});
            }
        for (size_t gi = 1; gi < glasses.size(); ++gi) {
            std::vector<double> centre(search_centre.size()), offset(3, 0.0);
            for (int r = 0; r < 3; ++r) {
                double x;
                if (chief_ray_plane_x(glasses[gi], film_radii[r], scan_half_mm, &x) &&
                    glasses[gi].passes(film_radii[r], x, 0.0))
                    offset[size_t(r)] = x - ExitPupil::centre_at(poly, film_radii[r]);
            }
            for (size_t j = 0; j < search_centre.size(); ++j) centre[j] = search_centre[j] + offset[j % 3];
            const std::vector<double> reach =
                boundary_distances(glasses[gi], search_film, search_psi, centre, 2.0 * scan_half_mm);
            for (int k = 0; k < kPupilAngles; ++k)
                for (int r = 0; r < 3; ++r) {
                    const double d = reach[size_t(3 * k + r)];
                    if (d > 0.0)
                        points.push_back({offset[size_t(r)] + d * unit[size_t(k)].x, d * unit[size_t(k)].y});
                }
        }
        const std::vector<Direction2> hull = convex_hull(points);
        std::array<double, kPupilAngles> reach{};
        bool outgrows = false;
        for (int k = 0; k < kPupilAngles; ++k) {
            reach[size_t(k)] = hull_reach(hull, unit[size_t(k)].x, unit[size_t(k)].y);
            outgrows |= reach[size_t(k)] > kOutgrown * raw[size_t(k)];
        }
        if (outgrows)
            for (int k = 0; k < kPupilAngles; ++k) raw[size_t(k)] = std::max(raw[size_t(k)], reach[size_t(k)]);
    }
    // Enlarge a little: covers the chords between sampled angles (0.12 % of
    // the radius for a convex region) and the boundary between the ring's radii.
    for (int k = 0; k < kPupilAngles; ++k)
        poly.radius_mm[size_t(k)] = raw[size_t(k)] * kRelativeMargin + kAbsoluteMargin * scan_half_mm;
    // Triangle fan areas -> CDF.
    double total = 0.0;
    double wedge = std::sin(2.0 * kPi / kPupilAngles) * 0.5;
    for (int k = 0; k < kPupilAngles; ++k) {
        total += wedge * poly.radius_mm[size_t(k)] * poly.radius_mm[size_t((k + 1) % kPupilAngles)];
        poly.cdf[size_t(k)] = total;
    }
    for (double& c : poly.cdf) c /= total;
    poly.cdf.back() = 1.0;
    finish_sampling_tables(&poly);
    poly.area_mm2 = total;
    return poly;
}

}  // namespace

PupilPolygon bounding_disk(double radius_mm) {
    PupilPolygon poly;
    poly.empty = false;
    poly.radius_mm.fill(radius_mm / std::cos(kPi / kPupilAngles));  // the 64-gon holds the disk
    for (int k = 0; k < kPupilAngles; ++k) poly.cdf[size_t(k)] = double(k + 1) / kPupilAngles;
    finish_sampling_tables(&poly);
    poly.area_mm2 = kPupilAngles * std::sin(2.0 * kPi / kPupilAngles) * 0.5 * poly.radius_mm[0] * poly.radius_mm[0];
    return poly;
}

ExitPupil::ExitPupil(const std::vector<LensElement>& elements, double max_film_radius_mm)
    : segments_(size_t(kPupilSegments)), plane_z_mm_(elements.back().vertex_z_mm),
      max_film_radius_mm_(max_film_radius_mm), segments_per_mm_(kPupilSegments / max_film_radius_mm) {}

ExitPupil ExitPupil::brute_force(const std::vector<LensElement>& elements, double max_film_radius_mm) {
    ExitPupil pupil(elements, max_film_radius_mm);
    std::fill(pupil.segments_.begin(), pupil.segments_.end(), bounding_disk(1.5 * elements.back().semi_aperture_mm));
    return pupil;
}

ExitPupil::ExitPupil(const std::vector<LensElement>& elements, int stop_index, double film_z_mm,
                     double max_film_radius_mm)
    : ExitPupil(std::vector<std::vector<LensElement>>{elements}, stop_index, film_z_mm, max_film_radius_mm) {}

ExitPupil::ExitPupil(const std::vector<std::vector<LensElement>>& glasses, int stop_index, double film_z_mm,
                     double max_film_radius_mm)
    : ExitPupil(glasses.front(), max_film_radius_mm) {
    const std::vector<LensElement>& elements = glasses.front();
    std::vector<PupilGeometry> geometries;
    for (const std::vector<LensElement>& glass : glasses)
        geometries.push_back(PupilGeometry{&glass, stop_index, film_z_mm, plane_z_mm_});
    // Light reaching the rear vertex plane lies within about the rear clear
    // aperture; the scan covers twice that to be safe.
    double largest = 0.0;
    for (const LensElement& e : elements) largest = std::max(largest, e.semi_aperture_mm);
    double scan_half_mm = std::max(2.0 * elements.back().semi_aperture_mm, 1e-3);
    scan_half_mm = std::min(scan_half_mm, 2.0 * largest);
    tbb::parallel_for(0, kPupilSegments, [&](int i) {
        double r0 = max_film_radius_mm_ * i / kPupilSegments;
        double r1 = max_film_radius_mm_ * (i + 1) / kPupilSegments;
        double radii[3] = {r0, 0.5 * (r0 + r1), r1};
        segments_[size_t(i)] = build_polygon(geometries, radii, scan_half_mm);
    });
}

}  // namespace lc
