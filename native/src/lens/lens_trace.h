// Exact ray trace through a rotationally symmetric lens system, in double
// precision. Lens frame (shared with lenscompare/lenses/trace.py): z along the
// optical axis, z = 0 at the first vertex, +z toward the film; mm.
//
// At every surface, film side first: intersect the sphere through the vertex
// (a plane for curvature 0) on the vertex-side cap; test the clear aperture;
// refract by Snell's law. No hit, a miss of the aperture, total internal
// reflection or a ray that turns back toward the film all block the ray.
#pragma once

#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

#include "aperture.h"
#include "vec.h"

namespace lc {

struct LensElement {
    double curvature_per_mm;  // 1/R, 0 for planes and the stop
    double vertex_z_mm;
    double semi_aperture_mm;
    double n_scene_side;      // index of the medium in front (scene side)
    double n_film_side;       // index of the medium behind (film side)
    bool is_stop;
    // An N-blade stop (set_polygon_stop): the hit point must also lie within
    // every edge, p . normal_k <= apothem; semi_aperture_mm is then the
    // polygon's circumradius, so the circle test lets every such point by.
    int blades = 0;
    double apothem_mm = 0.0;
    std::array<double, kMaxApertureBlades> edge_normal_x{}, edge_normal_y{};
};

// Makes e a regular N-blade stop of the area of its circle (aperture.h's
// orientation: a vertex on +y at rotation 0, counter-clockwise; the lens
// frame's x and y are the camera's).
inline void set_polygon_stop(LensElement* e, int blades, double rotation_deg) {
    const ApertureShape shape = ApertureShape::of(blades, rotation_deg);
    if (shape.blades == 0) return;
    constexpr double kPi = 3.14159265358979323846;
    const double circumradius = e->semi_aperture_mm * polygon_circumradius_same_area(blades);
    e->blades = blades;
    e->apothem_mm = circumradius * std::cos(kPi / blades);
    for (int k = 0; k < blades; ++k) {
        // Edge k, from vertex k to k + 1: its outward normal halfway between them.
        const double angle = shape.first_vertex_rad + kPi * (2 * k + 1) / blades;
        e->edge_normal_x[size_t(k)] = std::cos(angle);
        e->edge_normal_y[size_t(k)] = std::sin(angle);
    }
    e->semi_aperture_mm = circumradius;
}

// Within the polygon of a bladed stop (true for any other surface).
inline bool inside_blades(const LensElement& e, double x, double y) {
    for (int k = 0; k < e.blades; ++k)
        if (x * e.edge_normal_x[size_t(k)] + y * e.edge_normal_y[size_t(k)] > e.apothem_mm) return false;
    return true;
}

// The sag (mm, along +z from the vertex) of a surface of curvature c at
// height h from the axis; a hemisphere's depth where h reaches past its radius.
inline double rim_sag_mm(double curvature_per_mm, double height_mm) {
    const double c = curvature_per_mm, h = height_mm;
    return c == 0.0                 ? 0.0
           : std::fabs(c) * h >= 1.0 ? 1.0 / c
                                     : c * h * h / (1.0 + std::sqrt(1.0 - c * c * h * h));
}

struct LensRay {
    Vec3d origin_mm;
    Vec3d direction;  // unit
};

// Spheres at least this curved (|R| <= 10 m) take their near root as
// (s sqrt(disc) - b) R / 2, a multiplication, instead of k / q: the
// cancellation there costs at most a few eps |R| (~1e-12 mm), while the
// divider it frees is what the lens trace waits for. Flatter spheres keep the
// division, which loses no bits however small c is.
constexpr double kDirectRootMinCurvaturePerMm = 1e-4;

inline bool direct_near_root(double curvature_per_mm) {
    return std::fabs(curvature_per_mm) >= kDirectRootMinCurvaturePerMm;
}

// Roots this little behind the origin still count: a ray leaving one surface
// where the next touches it (cemented, zero thickness) starts on both.
constexpr double kBehindToleranceMm = 1e-9;
// The single-precision trace's (lens_trace_lanes.h): its hit points are off
// their surface by a few float steps of the lens-frame coordinates (~1e-5 mm
// at 100 mm), so a cemented neighbour can lie that far behind.
constexpr double kBehindToleranceSingleMm = 1e-3;

// The cosine of the angle of incidence (-n . d, n the normal of
// surface_normal) and its square, as intersect_surface finds them.
struct Incidence {
    double cos_i, cos2_i;
};

// Where the ray meets the surface's physical cap; false when it does not.
// With incidence: also the cosine there, which on a sphere comes from the
// quadratic's discriminant (see below) instead of a dot product at the hit
// point, so that refraction need not wait for the root.
inline bool intersect_surface(const LensElement& e, const LensRay& ray, double* t_out,
                              Incidence* incidence = nullptr) {
    const Vec3d& o = ray.origin_mm;
    const Vec3d& d = ray.direction;
    if (e.curvature_per_mm == 0.0) {
        if (d.z == 0.0) return false;
        double t = (e.vertex_z_mm - o.z) / d.z;
        if (!(t >= -kBehindToleranceMm)) return false;
        *t_out = t;
        if (incidence) *incidence = {-d.z, d.z * d.z};
        return true;
    }
    // Sphere of radius R centred at vertex + R on the axis, written with the
    // curvature c = 1/R so that nearly flat surfaces (R = 1e9) lose no bits:
    // c |p - C|^2 = R  <=>  c (x^2 + y^2 + (z - v)^2) - 2 (z - v) = 0.
    // With d a unit vector the t^2 coefficient is c itself, so one root is
    // q * R: one division per surface instead of two.
    const double c = e.curvature_per_mm;
    Vec3d p{o.x, o.y, o.z - e.vertex_z_mm};
    double b = 2.0 * (c * dot(p, d) - d.z);
    double k = c * dot(p, p) - 2.0 * p.z;
    double disc = b * b - 4.0 * c * k;
    if (!(disc >= 0.0)) return false;
    double sq = std::sqrt(disc);
    // Numerically stable pair of roots.
    double q = -0.5 * (b + std::copysign(sq, b));
    double t0 = q * (1.0 / c);
    double t1 = direct_near_root(c) ? (std::copysign(sq, b) - b) * (0.5 * (1.0 / c)) : q != 0.0 ? k / q : INFINITY;
    // cos_i = -n . d = c (p . d + t) - d.z = b / 2 + c t: half the quadratic's
    // slope at the root, +-sqrt(disc) / 2 (its sign: + at k / q, - at q / c),
    // and its square disc / 4.
    const double half_slope = 0.5 * std::copysign(sq, b);
    const bool swapped = t0 > t1;
    if (swapped) std::swap(t0, t1);
    for (int root = 0; root < 2; ++root) {
        const double t = root == 0 ? t0 : t1;
        if (!(t >= -kBehindToleranceMm) || !std::isfinite(t)) continue;
        // The physical cap is the half of the sphere on the vertex side:
        // c (z - v) < 1, i.e. z short of the centre.
        double z_rel = p.z + t * d.z;
        if (c * z_rel < 1.0) {
            *t_out = t;
            const bool at_k_over_q = (root == 0) == swapped;
            if (incidence) *incidence = {at_k_over_q ? half_slope : -half_slope, 0.25 * disc};
            return true;
        }
    }
    return false;
}

// Unit normal of the surface at p (lens frame), pointing toward the film for
// the vertex region.
inline Vec3d surface_normal(const LensElement& e, const Vec3d& p) {
    if (e.curvature_per_mm == 0.0) return {0.0, 0.0, 1.0};
    const double c = e.curvature_per_mm;
    // (C - p) / R = (0,0,1) - c (p - vertex): unit length because p lies on
    // the sphere (to rounding, which the refraction tolerates), and exact
    // even for tiny c.
    return {-c * p.x, -c * p.y, 1.0 - c * (p.z - e.vertex_z_mm)};
}

// Snell refraction of unit d at unit normal n (either orientation) from index
// n1 into n2, the incidence cosine -n . d and its square given; false on
// total internal reflection.
inline bool refract(const Vec3d& d, Vec3d n, Incidence incidence, double n1, double n2, Vec3d* out) {
    double cos_i = incidence.cos_i;
    if (cos_i < 0.0) {
        n = -n;
        cos_i = -cos_i;
    }
    double eta = n1 / n2;
    // x > 0 ? x : 0 rather than fmax: the same bits as the SIMD max instruction
    double sin2_i = 1.0 - incidence.cos2_i;
    double sin2_t = eta * eta * (sin2_i > 0.0 ? sin2_i : 0.0);
    if (sin2_t >= 1.0) return false;
    double cos_t = std::sqrt(1.0 - sin2_t);
    // Unit length to rounding already (unit d and n): no normalisation needed.
    *out = d * eta + n * (eta * cos_i - cos_t);
    return true;
}

// Cross one surface travelling toward the scene (-z); false when blocked.
// Without the aperture test it follows a ray the rims would stop (used to
// find chief rays).
inline bool cross_toward_scene(const LensElement& e, LensRay* ray, bool test_aperture = true) {
    double t;
    Incidence incidence;
    if (!intersect_surface(e, *ray, &t, &incidence)) return false;
    Vec3d p = ray->origin_mm + ray->direction * t;
    if (test_aperture && p.x * p.x + p.y * p.y > e.semi_aperture_mm * e.semi_aperture_mm) return false;
    if (test_aperture && !inside_blades(e, p.x, p.y)) return false;
    ray->origin_mm = p;
    if (e.is_stop || e.n_scene_side == e.n_film_side) return true;
    Vec3d refracted;
    if (!refract(ray->direction, surface_normal(e, p), incidence, e.n_film_side, e.n_scene_side, &refracted))
        return false;
    if (!(refracted.z < 0.0)) return false;  // turned back toward the film (pbrt-v3 #92)
    ray->direction = refracted;
    return true;
}

// Trace from the film side through every element to the scene side. On
// success the ray starts on the first surface and travels toward -z.
inline bool trace_from_film(const std::vector<LensElement>& elements, LensRay* ray) {
    if (!(ray->direction.z < 0.0)) return false;
    for (auto e = elements.rbegin(); e != elements.rend(); ++e)
        if (!cross_toward_scene(*e, ray)) return false;
    return true;
}

}  // namespace lc

namespace lc {

// A batch of rays traced in lockstep, structure of arrays, no branches that
// depend on the lane. GCC does not vectorise these portable loops; the SIMD
// kernels below do it by hand. Same operations in the same order as the
// scalar trace above: all give the same bits.
constexpr int kLensBatch = 32;

struct LensRayBatch {
    double ox[kLensBatch], oy[kLensBatch], oz[kLensBatch];
    double dx[kLensBatch], dy[kLensBatch], dz[kLensBatch];
    bool alive[kLensBatch];
};

// A lens with dispersion: every surface's eta = n_film_side / n_scene_side at
// every nm from 380 nm, for a batch whose lanes trace different wavelengths
// (one row of the table per lane, looked up per surface). The elements still
// give each surface's shape and aperture.
struct LensDispersion {
    // Per surface, whether it refracts (!is_stop and n_scene_side !=
    // n_film_side, as cross_toward_scene asks): at no nm, at every nm, or at
    // some (two glasses whose indices cross): only then is it asked per lane.
    enum class Bends : unsigned char { Never, Always, Some };
    size_t rows = 0;                   // nm in the table
    size_t row_stride = 0;             // the surfaces rounded up to a multiple of 4
    std::vector<Bends> bends;          // per surface
    bool any_some = false;             // a surface that refracts at some rows only
    // Row by row ([row * row_stride + surface], padding after the last
    // surface): a lane's surfaces side by side, so that laying a batch out
    // (lay_out_glass_lanes) reads whole vectors of them and transposes them.
    std::vector<double> eta;
    std::vector<double> bends_at;      // 1 where it refracts, 0 where not

    // From the elements at each nm (rows of elements_by_nm).
    static LensDispersion of(const std::vector<std::vector<LensElement>>& elements_by_nm) {
        LensDispersion d;
        d.rows = elements_by_nm.size();
        const size_t surfaces = d.rows ? elements_by_nm[0].size() : 0;
        d.row_stride = (surfaces + 3) / 4 * 4;
        d.bends.assign(surfaces, Bends::Never);
        d.eta.assign(d.row_stride * d.rows, 1.0);
        d.bends_at.assign(d.row_stride * d.rows, 0.0);
        for (size_t s = 0; s < surfaces; ++s) {
            size_t bending = 0;
            for (size_t w = 0; w < d.rows; ++w) {
                const LensElement& e = elements_by_nm[w][s];
                if (e.is_stop || e.n_scene_side == e.n_film_side) continue;
                d.eta[w * d.row_stride + s] = e.n_film_side / e.n_scene_side;  // refract()'s n1 / n2, the same bits
                d.bends_at[w * d.row_stride + s] = 1.0;
                ++bending;
            }
            d.bends[s] = bending == 0 ? Bends::Never : bending == d.rows ? Bends::Always : Bends::Some;
            d.any_some |= d.bends[s] == Bends::Some;
        }
        return d;
    }
};

// Per lane, which row of a LensDispersion it traces (nullptr: the elements'
// own indices, the same for every lane).
struct LaneGlass {
    const LensDispersion* dispersion;
    const int32_t* row;  // kLensBatch rows, each in [0, dispersion->rows)
    // The same indices laid out lane by lane for the SIMD kernels, which load
    // them (laid_out): [surface * kLensBatch + lane].
    const double* eta_lanes = nullptr;
    const double* bends_at_lanes = nullptr;
};

// eta_lanes[s * kLensBatch + i] = d.eta[row[i] * d.row_stride + s] for
// every surface s < d.row_stride, and bends_at_lanes likewise when d.any_some
// (lens_glass_lanes.cpp, built per instruction set).
void lay_out_glass_lanes(const LensDispersion& d, const int32_t* row, double* eta_lanes, double* bends_at_lanes);

// glass with its lanes' indices laid out, surface by surface, in buffers
// of this thread's: the SIMD kernels gathered them from the tables per
// surface instead, and a gather (microcoded on Zen 4) was a fifth of the
// dispersed single-precision trace's time (perf, session 13).
inline LaneGlass laid_out(LaneGlass glass) {
    thread_local std::vector<double> eta, bends_at;
    const LensDispersion& d = *glass.dispersion;
    eta.resize(d.row_stride * kLensBatch), bends_at.resize(d.row_stride * kLensBatch);
    lay_out_glass_lanes(d, glass.row, eta.data(), bends_at.data());
    glass.eta_lanes = eta.data(), glass.bends_at_lanes = bends_at.data();
    return glass;
}

inline void cross_toward_scene_batch(const LensElement& e, size_t surface, LaneGlass glass, LensRayBatch* b) {
    const double c = e.curvature_per_mm, v = e.vertex_z_mm;
    const double semi2 = e.semi_aperture_mm * e.semi_aperture_mm;
    // The surface type is the same for every lane: branch once, outside the
    // lane loops, so that each loop is straight-line code.
    double t[kLensBatch], cos_i[kLensBatch], cos2_i[kLensBatch];
    bool ok[kLensBatch];
    if (c == 0.0) {
        for (int i = 0; i < kLensBatch; ++i) {
            t[i] = (v - b->oz[i]) / b->dz[i];
            ok[i] = b->alive[i] & (b->dz[i] != 0.0) & (t[i] >= -kBehindToleranceMm);
            cos_i[i] = -b->dz[i], cos2_i[i] = b->dz[i] * b->dz[i];
        }
    } else {
        const double radius = 1.0 / c;
        const bool direct = direct_near_root(c);
        for (int i = 0; i < kLensBatch; ++i) {
            const double ox = b->ox[i], oy = b->oy[i], dx = b->dx[i], dy = b->dy[i], dz = b->dz[i];
            const double pz = b->oz[i] - v;
            const double bq = 2.0 * (c * (ox * dx + oy * dy + pz * dz) - dz);
            const double k = c * (ox * ox + oy * oy + pz * pz) - 2.0 * pz;
            const double disc = bq * bq - 4.0 * c * k;
            const double sq = std::sqrt(disc >= 0.0 ? disc : 0.0);
            const double q = -0.5 * (bq + std::copysign(sq, bq));
            const double t0 = q * radius;
            const double t1 = direct ? (std::copysign(sq, bq) - bq) * (0.5 * radius) : q != 0.0 ? k / q : INFINITY;
            const bool swap = t0 > t1;
            const double lo = swap ? t1 : t0, hi = swap ? t0 : t1;
            const bool lo_ok = (lo >= -kBehindToleranceMm) & (std::fabs(lo) < INFINITY) & (c * (pz + lo * dz) < 1.0);
            const bool hi_ok = (hi >= -kBehindToleranceMm) & (std::fabs(hi) < INFINITY) & (c * (pz + hi * dz) < 1.0);
            ok[i] = b->alive[i] & (disc >= 0.0) & (lo_ok | hi_ok);
            t[i] = lo_ok ? lo : hi;
            // intersect_surface's incidence cosine: + half the slope at k / q, - at q / c
            const double h = 0.5 * std::copysign(sq, bq);
            cos_i[i] = lo_ok ? (swap ? h : -h) : (swap ? -h : h);
            cos2_i[i] = 0.25 * disc;
        }
    }
    // Hit point and aperture test
    double px[kLensBatch], py[kLensBatch], pz[kLensBatch];
    bool hit[kLensBatch];
    for (int i = 0; i < kLensBatch; ++i) {
        px[i] = b->ox[i] + b->dx[i] * t[i], py[i] = b->oy[i] + b->dy[i] * t[i], pz[i] = b->oz[i] + b->dz[i] * t[i];
        hit[i] = ok[i];
        ok[i] = ok[i] & !(px[i] * px[i] + py[i] * py[i] > semi2);
    }
    for (int k = 0; k < e.blades; ++k) {
        const double nx = e.edge_normal_x[size_t(k)], ny = e.edge_normal_y[size_t(k)], a = e.apothem_mm;
        for (int i = 0; i < kLensBatch; ++i) ok[i] = ok[i] & !(px[i] * nx + py[i] * ny > a);
    }
    // Per lane: eta and whether the surface refracts there.
    double eta[kLensBatch];
    bool bends[kLensBatch];
    bool any_bends = false;
    if (glass.dispersion == nullptr) {
        const bool uniform = !(e.is_stop || e.n_scene_side == e.n_film_side);
        for (int i = 0; i < kLensBatch; ++i) eta[i] = e.n_film_side / e.n_scene_side, bends[i] = uniform;
        any_bends = uniform;
    } else if (glass.dispersion->bends[surface] != LensDispersion::Bends::Never) {
        const size_t stride = glass.dispersion->row_stride;
        for (int i = 0; i < kLensBatch; ++i) {
            eta[i] = glass.dispersion->eta[size_t(glass.row[i]) * stride + surface];
            bends[i] = glass.dispersion->bends_at[size_t(glass.row[i]) * stride + surface] != 0.0;
        }
        any_bends = true;
    }
    double nx[kLensBatch], ny[kLensBatch], nz[kLensBatch];
    if (!any_bends) {
        for (int i = 0; i < kLensBatch; ++i) nx[i] = b->dx[i], ny[i] = b->dy[i], nz[i] = b->dz[i];
    } else {
        for (int i = 0; i < kLensBatch; ++i) {
            const double dx = b->dx[i], dy = b->dy[i], dz = b->dz[i];
            // Normal (0,0,1) - c (p - vertex)
            const double mx = -c * px[i], my = -c * py[i], mz = 1.0 - c * (pz[i] - v);
            const double sin2_i = 1.0 - cos2_i[i];
            const double sin2_t = eta[i] * eta[i] * (sin2_i > 0.0 ? sin2_i : 0.0);
            const double cos_t = std::sqrt(sin2_t < 1.0 ? 1.0 - sin2_t : 0.0);
            // refract() turns the normal to face the ray (m and cos_i negated
            // when cos_i < 0); negating cos_t instead negates s: the same bits.
            const double s = eta[i] * cos_i[i] - (cos_i[i] < 0.0 ? -cos_t : cos_t);
            nx[i] = bends[i] ? dx * eta[i] + mx * s : dx;
            ny[i] = bends[i] ? dy * eta[i] + my * s : dy;
            nz[i] = bends[i] ? dz * eta[i] + mz * s : dz;
            // Total internal reflection, or a ray turned back toward the film (pbrt-v3 #92)
            ok[i] = ok[i] & (!bends[i] | ((sin2_t < 1.0) & (nz[i] < 0.0)));
        }
    }
    // Lanes without a hit keep their old values: nothing undefined travels on.
    // Lanes with one move on to it even if a later test stopped them (their
    // values are finite and never read), as the SIMD kernels do so that the
    // next surface need not wait for those tests.
    for (int i = 0; i < kLensBatch; ++i) {
        const bool h = hit[i];
        b->ox[i] = h ? px[i] : b->ox[i], b->oy[i] = h ? py[i] : b->oy[i], b->oz[i] = h ? pz[i] : b->oz[i];
        b->dx[i] = h ? nx[i] : b->dx[i], b->dy[i] = h ? ny[i] : b->dy[i], b->dz[i] = h ? nz[i] : b->dz[i];
        b->alive[i] = ok[i];
    }
}

inline void trace_from_film_batch_portable(const std::vector<LensElement>& elements, LaneGlass glass,
                                           LensRayBatch* b) {
    for (int i = 0; i < kLensBatch; ++i) b->alive[i] = b->alive[i] && b->dz[i] < 0.0;
    for (size_t s = elements.size(); s-- > 0;) {
        cross_toward_scene_batch(elements[s], s, glass, b);
        bool any = false;
        for (int i = 0; i < kLensBatch; ++i) any |= b->alive[i];
        if (!any) return;
    }
}

// The same trace in SIMD intrinsics (lens_trace_avx2.cpp, lens_trace_avx512.cpp,
// one template in lens_trace_lanes.h), bit for bit; each only on a CPU that
// has its instruction set.
void trace_from_film_batch_avx2(const std::vector<LensElement>& elements, LensRayBatch* b);
void trace_from_film_batch_avx512(const std::vector<LensElement>& elements, LensRayBatch* b);
void trace_from_film_batch_avx2(const std::vector<LensElement>& elements, LaneGlass glass, LensRayBatch* b);
void trace_from_film_batch_avx512(const std::vector<LensElement>& elements, LaneGlass glass, LensRayBatch* b);

// The render's trace (LensSystemCamera::trace_precision): the same template
// over float lanes (lens_trace_single_*.cpp), every kernel the same bits as
// the portable one. In float, hit points sit a few float steps of the
// lens-frame coordinates off their surface (1e-5 mm at 100 mm), so the rays
// leave the lens within 2.6e-5 mm and 8e-6 in direction of the double
// trace's (7.6e-5 near a critical angle; bench/check_lens_trace_single.py): a
// thousandth of a pixel's footprint, for 0.59-0.65 of the lens camera's time
// per ray (bench/bench_lens_rays_cpu.py). The double trace stays the
// reference of the analysis (lens info, pupils, focus) and of the tests that
// hold it to the Python trace within 1e-9 mm.
void trace_from_film_batch_single_portable(const std::vector<LensElement>& elements, LaneGlass glass,
                                           LensRayBatch* b);
void trace_from_film_batch_single_avx2(const std::vector<LensElement>& elements, LensRayBatch* b);
void trace_from_film_batch_single_avx512(const std::vector<LensElement>& elements, LensRayBatch* b);
void trace_from_film_batch_single_avx2(const std::vector<LensElement>& elements, LaneGlass glass, LensRayBatch* b);
void trace_from_film_batch_single_avx512(const std::vector<LensElement>& elements, LaneGlass glass,
                                         LensRayBatch* b);

// The single-precision trace with the rims stopping no ray, each lane's least
// clearance (rim^2 - height^2) / rim^2 over the surfaces into margin (> 0:
// the rims would pass it): the lens system's band rays (lens_system_bands.cpp).
void trace_from_film_batch_single_margins_portable(const std::vector<LensElement>& elements, LensRayBatch* b,
                                                    double* margin);
void trace_from_film_batch_single_margins_avx2(const std::vector<LensElement>& elements, LensRayBatch* b,
                                                double* margin);
void trace_from_film_batch_single_margins_avx512(const std::vector<LensElement>& elements, LensRayBatch* b,
                                                  double* margin);

enum class LensTraceKernel { Portable, Avx2, Avx512 };
enum class LensTracePrecision { Double, Single };
constexpr LensTraceKernel kLensTraceKernels[] = {LensTraceKernel::Portable, LensTraceKernel::Avx2,
                                                 LensTraceKernel::Avx512};

bool lens_trace_kernel_available(LensTraceKernel kernel);
LensTraceKernel best_lens_trace_kernel();  // the fastest this CPU runs
const char* lens_trace_kernel_name(LensTraceKernel kernel);

inline void trace_from_film_batch(const std::vector<LensElement>& elements, LensRayBatch* b,
                                  LensTraceKernel kernel, LensTracePrecision precision = LensTracePrecision::Double) {
    if (precision == LensTracePrecision::Single) {
        switch (kernel) {
            case LensTraceKernel::Avx512: trace_from_film_batch_single_avx512(elements, b); return;
            case LensTraceKernel::Avx2: trace_from_film_batch_single_avx2(elements, b); return;
            case LensTraceKernel::Portable:
                trace_from_film_batch_single_portable(elements, LaneGlass{nullptr, nullptr}, b);
                return;
        }
    }
    switch (kernel) {
        case LensTraceKernel::Avx512: trace_from_film_batch_avx512(elements, b); return;
        case LensTraceKernel::Avx2: trace_from_film_batch_avx2(elements, b); return;
        case LensTraceKernel::Portable:
            trace_from_film_batch_portable(elements, LaneGlass{nullptr, nullptr}, b);
            return;
    }
}

inline void trace_from_film_batch_margins(const std::vector<LensElement>& elements, LensRayBatch* b,
                                          double* margin, LensTraceKernel kernel) {
    switch (kernel) {
        case LensTraceKernel::Avx512: trace_from_film_batch_single_margins_avx512(elements, b, margin); return;
        case LensTraceKernel::Avx2: trace_from_film_batch_single_margins_avx2(elements, b, margin); return;
        case LensTraceKernel::Portable: trace_from_film_batch_single_margins_portable(elements, b, margin); return;
    }
}

// The same with each lane at its own wavelength: lane i refracts with the
// indices of row glass.row[i] of glass.dispersion (the scalar trace through
// that row's elements, bit for bit).
inline void trace_from_film_batch(const std::vector<LensElement>& elements, LaneGlass glass, LensRayBatch* b,
                                  LensTraceKernel kernel, LensTracePrecision precision = LensTracePrecision::Double) {
    glass = laid_out(glass);
    if (precision == LensTracePrecision::Single) {
        switch (kernel) {
            case LensTraceKernel::Avx512: trace_from_film_batch_single_avx512(elements, glass, b); return;
            case LensTraceKernel::Avx2: trace_from_film_batch_single_avx2(elements, glass, b); return;
            case LensTraceKernel::Portable: trace_from_film_batch_single_portable(elements, glass, b); return;
        }
    }
    switch (kernel) {
        case LensTraceKernel::Avx512: trace_from_film_batch_avx512(elements, glass, b); return;
        case LensTraceKernel::Avx2: trace_from_film_batch_avx2(elements, glass, b); return;
        case LensTraceKernel::Portable: trace_from_film_batch_portable(elements, glass, b); return;
    }
}

}  // namespace lc
