// Where to aim rays from the film so that almost all of them get through the
// lens: for each of kPupilSegments rings of film radius, a star-shaped
// polygon on a plane at the rear vertex that holds every pupil point through
// which light from that ring passes (found by tracing), slightly enlarged.
// Sampling it uniformly wastes only the margin, unlike pbrt-v4's bounding
// boxes (55-73 % of traced rays pass). Rotational symmetry: each polygon is
// built for film points on +x and rotated to the film point's azimuth.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include "lens/lens_trace.h"
#include "vec.h"

namespace lc {

constexpr int kPupilSegments = 64;
constexpr int kPupilAngles = 64;
constexpr int kPupilGuideCells = 128;  // a power of two: u * cells is exact

struct PupilPolygon {
    bool empty = true;          // no light from this film ring: outside the image circle
    double centre_x_mm = 0.0;   // polygon centre (on the x axis by symmetry)
    std::array<double, kPupilAngles> radius_mm{};  // boundary distance from the centre per angle
    std::array<double, kPupilAngles> cdf{};        // triangle-area CDF for sampling
    // guide[j]: the first triangle whose CDF exceeds j / kPupilGuideCells, where
    // the search for u in [j, j + 1) / cells starts (a binary search's
    // unpredictable branches cost more than the rest of the sample).
    std::array<uint8_t, kPupilGuideCells> guide{};
    double area_mm2 = 0.0;
};

struct PupilSample {
    double x_mm, y_mm;  // point on the sampling plane, film point on +x
    double area_mm2;    // area of the polygon sampled (uniform density 1/area)
};

class ExitPupil {
  public:
    ExitPupil() = default;
    // brute_force: a disk of 1.5 rear semi-apertures for every ring instead of
    // the traced polygons, the reference the tight sampler is tested against.
    // stop_index: the aperture stop (its centre anchors each polygon).
    ExitPupil(const std::vector<LensElement>& elements, int stop_index, double film_z_mm,
              double max_film_radius_mm, bool brute_force = false);

    // Uniform sample of the polygon for a film point at radius r; false when
    // the ring is outside the image circle.
    bool sample(double film_radius_mm, Point2f u, PupilSample* out) const;

    double plane_z_mm() const { return plane_z_mm_; }
    const PupilPolygon& segment(int i) const { return segments_[size_t(i)]; }
    int segment_index(double film_radius_mm) const;

  private:
    std::vector<PupilPolygon> segments_;
    double plane_z_mm_ = 0.0;
    double max_film_radius_mm_ = 1.0;
};

}  // namespace lc
