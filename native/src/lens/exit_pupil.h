// Where to aim rays from the film so that almost all of them get through the
// lens: for each of kPupilSegments rings of film radius, a star-shaped
// polygon on a plane at the rear vertex that holds every pupil point through
// which light from that ring passes (found by tracing), slightly enlarged.
// Sampling it uniformly wastes only the margin, unlike pbrt-v4's bounding
// boxes (55-73 % of traced rays pass). Rotational symmetry: each polygon is
// built for film points on +x and rotated to the film point's azimuth.
#pragma once

#include <algorithm>
#include <array>
#include <cstdint>
#include <vector>

#include "lens/lens_aim.h"
#include "lens/lens_trace.h"
#include "vec.h"

namespace lc {

constexpr int kPupilSegments = 64;
constexpr int kPupilAngles = 64;
// A power of two: u * cells is exact. 1024, not 128: with 64 triangles a cell
// then seldom holds a CDF step, so the search after the guide seldom loops and
// its branch is predicted (the same picks; 3.5x fewer mispredicted branches in
// sample_batch under callgrind, +8 % lens camera rays per CPU-second).
constexpr int kPupilGuideCells = 1024;

// What a sample that lands in fan triangle k reads, in one cache line
// instead of five separate tables (the same picks; no speed change measured).
struct alignas(64) FanTriangle {
    double cdf_lo, cdf_hi;     // cdf[k - 1] (0 for k = 0) and cdf[k]
    double inverse_cdf_step;   // 1 / (cdf_hi - cdf_lo)
    double a_x_mm, a_y_mm;     // boundary point k from the centre
    double b_x_mm, b_y_mm;     // boundary point k + 1 from the centre
};

struct PupilPolygon {
    bool empty = true;          // no light from this film ring: outside the image circle
    // The polygon's centre (on the x axis by symmetry) moves with the film
    // radius r as the chief ray does: centre_x_mm + centre_slope * (r -
    // centre_r_mm). Behind a small stop the pupil is smaller than its move
    // across one ring (f/1000 on the Double Gauss: 0.05 mm wide, moving 0.15
    // mm), and a fixed centre missed it (images black or wrongly calibrated).
    double centre_x_mm = 0.0;
    double centre_slope = 0.0;  // mm on the plane per mm of film radius
    double centre_r_mm = 0.0;   // the film radius centre_x_mm belongs to
    std::array<double, kPupilAngles> radius_mm{};  // boundary distance from the centre per angle
    std::array<double, kPupilAngles> cdf{};        // triangle-area CDF for sampling
    // Derived from the above once, so that a sample needs no division:
    std::array<FanTriangle, kPupilAngles> fan{};
    // guide[j]: the first triangle whose CDF exceeds j / kPupilGuideCells, where
    // the search for u in [j, j + 1) / cells starts (a binary search's
    // unpredictable branches cost more than the rest of the sample).
    std::array<uint8_t, kPupilGuideCells> guide{};
    double area_mm2 = 0.0;
};

class ExitPupil {
  public:
    ExitPupil() = default;
    // stop_index: the aperture stop (its centre anchors each polygon).
    ExitPupil(const std::vector<LensElement>& elements, int stop_index, double film_z_mm,
              double max_film_radius_mm);
    // The same through several glasses (a dispersive lens's elements at the
    // design wavelength first, then at the spectrum's ends): each ring's
    // polygon holds the pupils of all of them, which behind a small stop lie
    // apart (lateral colour moves the chief ray), round the first's centre.
    ExitPupil(const std::vector<std::vector<LensElement>>& glasses, int stop_index, double film_z_mm,
              double max_film_radius_mm);
    // A disk of 1.5 rear semi-apertures for every ring instead of the traced
    // polygons, the reference the tight sampler is tested against (diagnostics).
    static ExitPupil brute_force(const std::vector<LensElement>& elements, double max_film_radius_mm);

    // The fan triangle of the polygon for a film point at radius r that u_y
    // falls in, by area, and where across it (u_y reused: u.x alone then sets
    // the distance from the centre, so radial strata stay as fine as the
    // sampler's). With sqrt(u.x) along, aim_one gives a uniform sample of the
    // polygon. False when the ring is outside the image circle.
    bool pick(double film_radius_mm, float u_y, PupilPick* out) const {
        return pick_in_ring(segment_index(film_radius_mm), film_radius_mm, u_y, out);
    }

    // pick for the lanes of a batch at once, into aim's pick columns and
    // area_mm2; lanes from n on and those outside the image circle come back
    // not alive, with zeros. The same picks as pick, in two passes so that the
    // lanes' table loads (the guide, then the triangle) need not wait on one
    // another (perf put the pick's time just after those loads; the passes
    // did not measurably change it).
    void pick_batch(const double* film_r_mm, const Point2f* lens_sample, int n, LensAimBatch* aim,
                    double* area_mm2, bool* alive) const {
        const PupilPolygon* polygon[kLensBatch];
        double u[kLensBatch];
        int start[kLensBatch];
        for (int i = 0; i < kLensBatch; ++i) {
            polygon[i] = &segments_[size_t(segment_index(film_r_mm[i]))];
            u[i] = double(lens_sample[i < n ? i : 0].y);
            alive[i] = i < n && !polygon[i]->empty;
            start[i] = guide_start(*polygon[i], u[i]);
        }
        for (int i = 0; i < kLensBatch; ++i) {
            const PupilPolygon& poly = *polygon[i];
            const FanTriangle& t = poly.fan[size_t(triangle_past(poly, u[i], start[i]))];
            const bool a = alive[i];
            aim->centre_x_mm[i] = a ? centre_at(poly, film_r_mm[i]) : 0.0;
            aim->a_x_mm[i] = a ? t.a_x_mm : 0.0, aim->a_y_mm[i] = a ? t.a_y_mm : 0.0;
            aim->b_x_mm[i] = a ? t.b_x_mm : 0.0, aim->b_y_mm[i] = a ? t.b_y_mm : 0.0;
            aim->across[i] = a ? across(t, u[i]) : 0.0;
            area_mm2[i] = a ? poly.area_mm2 : 0.0;
        }
    }

    // pick within ring `segment`'s polygon whatever ring film radius r falls
    // in: the ray table (lens_ray_table.h) samples each ring's map up to both
    // its ends. False when the ring is outside the image circle.
    bool pick_in_ring(int segment, double film_radius_mm, float u_y, PupilPick* out) const {
        const PupilPolygon& poly = segments_[size_t(segment)];
        if (poly.empty) return false;
        const double u = double(u_y);
        const FanTriangle& t = poly.fan[size_t(triangle_past(poly, u, guide_start(poly, u)))];
        *out = PupilPick{centre_at(poly, film_radius_mm), t.a_x_mm, t.a_y_mm, t.b_x_mm, t.b_y_mm, across(t, u),
                         poly.area_mm2};
        return true;
    }

    // Rings per mm of film radius.
    double segments_per_mm() const { return segments_per_mm_; }

    // Which of the kPupilSegments rings a film radius falls in.
    int segment_index(double film_radius_mm) const {
        const int i = int(film_radius_mm * segments_per_mm_);
        return std::clamp(i, 0, kPupilSegments - 1);
    }

    double plane_z_mm() const { return plane_z_mm_; }
    const PupilPolygon& segment(int i) const { return segments_[size_t(i)]; }

    // Where the polygon's centre lies for a film point at radius r.
    static double centre_at(const PupilPolygon& poly, double film_radius_mm) {
        return poly.centre_x_mm + poly.centre_slope * (film_radius_mm - poly.centre_r_mm);
    }

  private:
    // Where the search for the fan triangle u falls in starts: the guide's
    // first triangle whose CDF exceeds u's cell.
    static int guide_start(const PupilPolygon& poly, double u) {
        return poly.guide[size_t(std::min(int(u * kPupilGuideCells), kPupilGuideCells - 1))];
    }
    // The first k from start on with cdf[k] > u (std::upper_bound's answer).
    // The first step without a branch (whether a cell's CDF step lies below u
    // is a coin toss the predictor loses); further steps are rare.
    static int triangle_past(const PupilPolygon& poly, double u, int start) {
        int k = start;
        k += int((k < kPupilAngles - 1) & (poly.fan[size_t(k)].cdf_hi <= u));
        while (k < kPupilAngles - 1 && poly.fan[size_t(k)].cdf_hi <= u) ++k;
        return k;
    }
    // Where across triangle t u falls: 0 at its vertex a, 1 at b.
    static double across(const FanTriangle& t, double u) {
        return std::clamp((u - t.cdf_lo) * t.inverse_cdf_step, 0.0, 1.0);
    }

    // The rings' common set-up: the plane at the rear vertex and the radius lookup.
    ExitPupil(const std::vector<LensElement>& elements, double max_film_radius_mm);

    std::vector<PupilPolygon> segments_;
    double plane_z_mm_ = 0.0;
    double max_film_radius_mm_ = 1.0;
    double segments_per_mm_ = kPupilSegments;  // kPupilSegments / max_film_radius_mm_
};

}  // namespace lc
