// The lens aperture: the unit disk, or a regular N-blade diaphragm of the same
// area (DESIGN.md: camera.aperture_blades, camera.aperture_rotation_deg).
//
// Sampling the polygon keeps the samplers' stratification: the square goes to
// the disk as before (polar or concentric, samplers.h), and the disk point
// (r, theta) goes to the triangle fan of the N-gon: theta picks the fan
// triangle and, linearly, the point along its outer edge; r scales it toward
// the centre. Both steps preserve area (r^2 and the edge parameter are
// uniform on each triangle), the map is continuous across the triangles, and
// no sample is rejected.
//
// Orientation (the lens seen from behind, camera x right and y up; the same
// axes as the lens system's lens frame): vertex 0 points up (+y) at rotation
// 0; a positive rotation turns the polygon counter-clockwise. A point behind
// the plane of focus images the aperture upright; one in front of it,
// turned by 180 degrees.
#pragma once

#include <array>
#include <cmath>
#include <stdexcept>

#include "samplers.h"

namespace lc {

// lenscompare/scene.py refuses more blades; beyond a few dozen the diaphragm
// is a circle for any purpose.
constexpr int kMaxApertureBlades = 32;

// Circumradius of the regular N-gon whose area is that of the unit circle:
// N R^2 sin(2 pi / N) / 2 = pi.
inline double polygon_circumradius_same_area(int blades) {
    constexpr double kPi = 3.14159265358979323846;
    return std::sqrt(2.0 * kPi / (blades * std::sin(2.0 * kPi / blades)));
}

struct ApertureShape {
    int blades = 0;  // 0: the unit disk; N >= 3: the N-gon of area pi
    double first_vertex_rad = 0.0;
    // Vertices in units of the circle's radius, counter-clockwise; the last
    // repeats the first so that triangle k runs from vertex k to k + 1.
    std::array<double, kMaxApertureBlades + 1> vertex_x{}, vertex_y{};

    static ApertureShape circle() { return {}; }

    // blades 0: the circle; 3..kMaxApertureBlades: the polygon (Python checks first).
    static ApertureShape of(int blades, double rotation_deg) {
        if (blades == 0) return circle();
        if (blades < 3 || blades > kMaxApertureBlades) throw std::invalid_argument("aperture_blades out of range");
        return polygon(blades, rotation_deg * (3.14159265358979323846 / 180.0));
    }

    static ApertureShape polygon(int blades, double rotation_rad) {
        constexpr double kPi = 3.14159265358979323846;
        ApertureShape s;
        s.blades = blades;
        s.first_vertex_rad = 0.5 * kPi + rotation_rad;
        const double radius = polygon_circumradius_same_area(blades);
        for (int k = 0; k <= blades; ++k) {
            const double angle = s.first_vertex_rad + 2.0 * kPi * (k % blades) / blades;
            s.vertex_x[size_t(k)] = radius * std::cos(angle);
            s.vertex_y[size_t(k)] = radius * std::sin(angle);
        }
        return s;
    }

    // Unit-square sample -> point of the aperture (circle radius 1), uniform in area.
    void sample(Point2f u, DiskMapping mapping, double* x, double* y) const {
        if (blades == 0) {
            Point2f disk = map_to_disk(u, mapping);
            *x = disk.x, *y = disk.y;
            return;
        }
        constexpr double kTwoPi = 6.28318530717958647692;
        PolarDiskPoint p = map_to_disk_polar(u, mapping);
        double r = p.r, theta = p.theta;
        if (r < 0.0) r = -r, theta += 0.5 * kTwoPi;  // the concentric map's left and lower halves
        // Which fan triangle, and how far along its outer edge
        double turns = (theta - first_vertex_rad) * (1.0 / kTwoPi);
        turns -= std::floor(turns);
        double t = turns * blades;
        int k = int(t);
        if (k >= blades) k = blades - 1;  // turns rounded up to 1
        double along = t - k;
        const size_t i = size_t(k);
        *x = r * (vertex_x[i] + along * (vertex_x[i + 1] - vertex_x[i]));
        *y = r * (vertex_y[i] + along * (vertex_y[i + 1] - vertex_y[i]));
    }
};

}  // namespace lc
