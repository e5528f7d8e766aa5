#include "shading_lanes.h"

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <initializer_list>
#include <limits>

#include "near_line_lanes.h"

namespace lc {
namespace {

constexpr int N = kPacketSize;

// (0.1 mm)^2: the smallest squared distance an inverse-square light falls off over
// (lenscompare.povray.export.INVERSE_SQUARE_FADE_DISTANCE_M squared).
constexpr float kNearestFalloffM2 = 1e-8f;

// Checker parity at the texture point (t in m) of cubes of size_m: parity of
// floor(t / size + 0.001) summed over the axes (scene.h, checker_is_odd).
// The parity of the integral sum is read as sum / 2 not being whole, which is
// exact for every double (above 2^53 all are even), so no lane needs the
// int64 conversion AVX-512F lacks; NaN counts as even, as that conversion made it.
[[gnu::always_inline]] inline bool checker_odd(float tx, float ty, float tz, float size_m) {
    constexpr double kTolerance = 0.001;
    const double size = size_m;
    const double sum = std::floor(double(tx) / size + kTolerance) + std::floor(double(ty) / size + kTolerance) +
                       std::floor(double(tz) / size + kTolerance);
    const double half = sum * 0.5;
    return (half != std::floor(half)) & (half == half);
}

// The largest of |x|, |y|, |z| and 1, compared in std::max's order.
[[gnu::always_inline]] inline float coordinate_size(float x, float y, float z) {
    float m = std::fabs(x);
    m = m < std::fabs(y) ? std::fabs(y) : m;
    m = m < std::fabs(z) ? std::fabs(z) : m;
    return m < 1.0f ? 1.0f : m;
}

// Habits that keep GCC's lane loops vector (checked with -fopt-info-vec):
// every value computed on every lane, then selected (the shadow set-up as
// arithmetic into local arrays, then a loop of selects: in one loop GCC moved
// the arithmetic under the condition and kept the loop scalar); one loop over
// the lanes with the channels written out (inside a loop over channels GCC
// unrolls the lanes and shuffles them together); __restrict on every array.

// The rows as plain pointers, so that the lane loop indexes them directly.
struct Columns {
    const float* start[3];
    const float* color[3];
    const float* checker_color[3];
    const float* checker_size_m;
    const int* diffuse;
};

[[gnu::always_inline]] inline void gather_body(const Columns& t, const int* __restrict material,
                                               SurfaceLanes& __restrict s, float (&__restrict rgb)[3][kPacketSize]) {
    // A packet is one pixel's samples at 16 spp and more, so mostly of one
    // material: then each value is loaded once and broadcast.
    int mixed = 0;
    for (int i = 0; i < N; ++i) mixed |= material[i] ^ material[0];
    if (mixed == 0) {
        const int k = material[0];
        const int diffuse = t.diffuse[k];
        const float size_m = t.checker_size_m[k];
        const float start[3] = {t.start[0][k], t.start[1][k], t.start[2][k]};
        const float color[3] = {t.color[0][k], t.color[1][k], t.color[2][k]};
        const float checker[3] = {t.checker_color[0][k], t.checker_color[1][k], t.checker_color[2][k]};
        for (int i = 0; i < N; ++i) {
            s.diffuse[i] = diffuse, s.checker_size_m[i] = size_m;
            rgb[0][i] = start[0], rgb[1][i] = start[1], rgb[2][i] = start[2];
            s.color[0][i] = color[0], s.color[1][i] = color[1], s.color[2][i] = color[2];
            s.checker_color[0][i] = checker[0], s.checker_color[1][i] = checker[1], s.checker_color[2][i] = checker[2];
        }
        return;
    }
    // Loaded into vector registers lane by lane (GCC 12 emulates the
    // gathers), then stored whole: the kernels after it read them without
    // waiting for sixteen narrow stores to land.
    for (int i = 0; i < N; ++i) {
        const int k = material[i];
        s.diffuse[i] = t.diffuse[k];
        s.checker_size_m[i] = t.checker_size_m[k];
        rgb[0][i] = t.start[0][k], rgb[1][i] = t.start[1][k], rgb[2][i] = t.start[2][k];
        s.color[0][i] = t.color[0][k], s.color[1][i] = t.color[1][k], s.color[2][i] = t.color[2][k];
        s.checker_color[0][i] = t.checker_color[0][k], s.checker_color[1][i] = t.checker_color[1][k];
        s.checker_color[2][i] = t.checker_color[2][k];
    }
}

[[gnu::always_inline]] inline void surface_body(const RTCRayHitPacket& __restrict camera,
                                                SurfaceLanes& __restrict s) {
    const RTCRay16& ray = camera.ray;
    const RTCHit16& hit = camera.hit;
    for (int i = 0; i < N; ++i) {
        const float t = ray.tfar[i];
        s.p[0][i] = ray.org_x[i] + ray.dir_x[i] * t;
        s.p[1][i] = ray.org_y[i] + ray.dir_y[i] * t;
        s.p[2][i] = ray.org_z[i] + ray.dir_z[i] * t;
        const float gx = hit.Ng_x[i], gy = hit.Ng_y[i], gz = hit.Ng_z[i];
        const float length = std::sqrt(gx * gx + gy * gy + gz * gz);
        const float nx = gx / length, ny = gy / length, nz = gz / length;
        // Two-sided: shade the side the ray sees
        const bool away = nx * ray.dir_x[i] + ny * ray.dir_y[i] + nz * ray.dir_z[i] > 0.0f;
        s.n[0][i] = away ? -nx : nx;
        s.n[1][i] = away ? -ny : ny;
        s.n[2][i] = away ? -nz : nz;
    }
    // The checker is read where the point was at t = 0 (p - shift on a moving lane).
    float texture[3][N];
    for (int i = 0; i < N; ++i) {
        const bool moving = s.moving[i] != 0;
        texture[0][i] = moving ? s.p[0][i] - s.shift_m[0][i] : s.p[0][i];
        texture[1][i] = moving ? s.p[1][i] - s.shift_m[1][i] : s.p[1][i];
        texture[2][i] = moving ? s.p[2][i] - s.shift_m[2][i] : s.p[2][i];
    }
    // The shadow rays' origins, lifted off the surface by an offset that grows
    // with the coordinates as float spacing does, and the ball round the
    // diffuse lanes' (every light's shadow packet starts from them).
    for (int i = 0; i < N; ++i) {
        const float px = s.p[0][i], py = s.p[1][i], pz = s.p[2][i];
        const float offset = 1e-4f * coordinate_size(px, py, pz);
        s.from_m[0][i] = px + s.n[0][i] * offset;
        s.from_m[1][i] = py + s.n[1][i] * offset;
        s.from_m[2][i] = pz + s.n[2][i] * offset;
    }
    int first = 0;
    while (first < N - 1 && s.diffuse[first] == 0) ++first;
    const float cx = s.from_m[0][first], cy = s.from_m[1][first], cz = s.from_m[2][first];
    float farthest2[N];
    for (int i = 0; i < N; ++i) {
        const float dx = s.from_m[0][i] - cx, dy = s.from_m[1][i] - cy, dz = s.from_m[2][i] - cz;
        const float d2 = dx * dx + dy * dy + dz * dz;
        // Not finite (or NaN): an infinite radius, so that every primitive stays a candidate
        const float sure = d2 <= std::numeric_limits<float>::max() ? d2 : INFINITY;
        farthest2[i] = s.diffuse[i] != 0 ? sure : 0.0f;
    }
    s.from_centre_m[0] = cx, s.from_centre_m[1] = cy, s.from_centre_m[2] = cz;
    s.from_radius_m = std::sqrt(lanes::largest_of_16(farthest2));
    int odd[N];
    // A lane without a checker divides by 0; the select below discards it.
    for (int i = 0; i < N; ++i) odd[i] = checker_odd(texture[0][i], texture[1][i], texture[2][i], s.checker_size_m[i]);
    for (int i = 0; i < N; ++i) {
        const bool checker = (s.checker_size_m[i] > 0.0f) & (odd[i] != 0);
        s.albedo[0][i] = checker ? s.checker_color[0][i] : s.color[0][i];
        s.albedo[1][i] = checker ? s.checker_color[1][i] : s.color[1][i];
        s.albedo[2][i] = checker ? s.checker_color[2][i] : s.color[2][i];
    }
}

[[gnu::always_inline]] inline bool shadow_body(const float light_m[3], bool inverse_square,
                                               const SurfaceLanes& __restrict s, const float* __restrict time,
                                               ShadowLanes& __restrict shadow, RTCRayPacket& __restrict packet) {
    const float lx = light_m[0], ly = light_m[1], lz = light_m[2];
    int valid[N];
    float to_light[3][N], inverse_d2[N];
    for (int i = 0; i < N; ++i) {
        const float px = s.p[0][i], py = s.p[1][i], pz = s.p[2][i];
        const float nx = s.n[0][i], ny = s.n[1][i], nz = s.n[2][i];
        const float tx = lx - px, ty = ly - py, tz = lz - pz;
        const float d2 = tx * tx + ty * ty + tz * tz;
        const float cos_theta = (nx * tx + ny * ty + nz * tz) / std::sqrt(d2);
        shadow.cos_theta[i] = cos_theta;
        // Not where the light is behind the surface (or the lane degenerate)
        valid[i] = (s.diffuse[i] != 0) & (cos_theta > 0.0f) ? -1 : 0;
        // 1 / d^2, at most 1 / (0.1 mm)^2 (POV-Ray's export caps it there too): a surface at
        // the light itself stays finite.
        // (The division before the select: GCC keeps a division under a condition scalar.)
        const float inverse = 1.0f / d2;
        inverse_d2[i] = d2 < kNearestFalloffM2 ? 1.0f / kNearestFalloffM2 : inverse;
        // From the origin lifted off the surface (surface_lanes), the segment
        // to the light as it is, not normalised (every occlusion test takes
        // any direction's length): t in [0, 1) short of the light.
        // Normalising it was a square root and three divisions per lane, half
        // of this loop's time (perf).
        to_light[0][i] = lx - s.from_m[0][i], to_light[1][i] = ly - s.from_m[1][i], to_light[2][i] = lz - s.from_m[2][i];
    }
    int any = 0;
    for (int i = 0; i < N; ++i) {
        // An idle lane holds a harmless ray: Embree's narrower kernels (SSE, AVX)
        // split the packet and check the rays of every lane they are handed.
        const bool traced = valid[i] != 0;
        packet.org_x[i] = traced ? s.from_m[0][i] : 0.0f;
        packet.org_y[i] = traced ? s.from_m[1][i] : 0.0f;
        packet.org_z[i] = traced ? s.from_m[2][i] : 0.0f;
        packet.dir_x[i] = traced ? to_light[0][i] : 0.0f;
        packet.dir_y[i] = traced ? to_light[1][i] : 0.0f;
        packet.dir_z[i] = traced ? to_light[2][i] : 1.0f;
        packet.tnear[i] = 0.0f;
        packet.tfar[i] = traced ? kShadowEnd : 0.0f;
        packet.time[i] = traced ? time[i] : 0.0f;  // the shadow at the same instant
        packet.mask[i] = 0xFFFFFFFFu;
        packet.id[i] = unsigned(i);
        packet.flags[i] = 0;
        shadow.valid[i] = valid[i];
        shadow.falloff[i] = traced ? (inverse_square ? inverse_d2[i] : 1.0f) : 0.0f;
        any |= valid[i];
    }
    return any != 0;
}

[[gnu::always_inline]] inline void add_light_body(const float intensity[3], const SurfaceLanes& __restrict s,
                                                  const ShadowLanes& __restrict shadow,
                                                  const float* __restrict shadow_tfar,
                                                  float (&__restrict rgb)[3][kPacketSize]) {
    const float red = intensity[0], green = intensity[1], blue = intensity[2];
    // One loop over the lanes, the channels written out: nested in a loop over
    // channels, GCC unrolls the lanes and shuffles them back together.
    for (int i = 0; i < N; ++i) {
        const bool lit = (shadow.valid[i] != 0) & (shadow_tfar[i] != -INFINITY);
        const float scale = shadow.cos_theta[i] * shadow.falloff[i];
        const float r = rgb[0][i], g = rgb[1][i], b = rgb[2][i];
        const float r_lit = r + s.albedo[0][i] * red * scale, g_lit = g + s.albedo[1][i] * green * scale,
                    b_lit = b + s.albedo[2][i] * blue * scale;
        // A select, not + 0: a sum of -0 and +0 would change a zero's sign
        rgb[0][i] = lit ? r_lit : r;
        rgb[1][i] = lit ? g_lit : g;
        rgb[2][i] = lit ? b_lit : b;
    }
}

// out[k] = m[k][0] in[0] + m[k][1] in[1] + m[k][2] in[2] on every lane.
[[gnu::always_inline]] inline void map_colour_body(const float (&m)[3][3], const float (&__restrict in)[3][kPacketSize],
                                                   float (&__restrict out)[3][kPacketSize]) {
    // One loop over the lanes, the channels written out (as add_light_body):
    // nested in a loop over channels, GCC stored the first two channels' rows
    // a quarter at a time (16-byte stores), and add_light_body's whole-row
    // loads of them then waited for those stores to reach the cache (a load
    // spanning several stores is not forwarded from them).
    const float r0 = m[0][0], r1 = m[0][1], r2 = m[0][2], g0 = m[1][0], g1 = m[1][1], g2 = m[1][2];
    const float b0 = m[2][0], b1 = m[2][1], b2 = m[2][2];
    for (int i = 0; i < N; ++i) {
        const float c0 = in[0][i], c1 = in[1][i], c2 = in[2][i];
        out[0][i] = r0 * c0 + r1 * c1 + r2 * c2;
        out[1][i] = g0 * c0 + g1 * c1 + g2 * c2;
        out[2][i] = b0 * c0 + b1 * c1 + b2 * c2;
    }
}

// The bodies compiled once per instruction set (the target attribute), as sphere_lanes.cpp does.
// (__restrict here too: the bodies' own are lost when they are inlined.)
#define LC_SHADING_KERNELS(SUFFIX, TARGET)                                                                     \
    TARGET void gather_##SUFFIX(const Columns& t, const int* __restrict material, SurfaceLanes& __restrict s, \
                                float (&__restrict rgb)[3][kPacketSize]) {                                   \
        gather_body(t, material, s, rgb);                                                                    \
    }                                                                                                        \
    TARGET void surface_##SUFFIX(const RTCRayHitPacket& __restrict camera, SurfaceLanes& __restrict s) {     \
        surface_body(camera, s);                                                                             \
    }                                                                                                        \
    TARGET bool shadow_##SUFFIX(const float light_m[3], bool inverse_square, const SurfaceLanes& __restrict s, \
                                const float* __restrict time, ShadowLanes& __restrict shadow,                \
                                RTCRayPacket& __restrict packet) {                                           \
        return shadow_body(light_m, inverse_square, s, time, shadow, packet);                                \
    }                                                                                                        \
    TARGET void add_light_##SUFFIX(const float intensity[3], const SurfaceLanes& __restrict s,               \
                                   const ShadowLanes& __restrict shadow, const float* __restrict shadow_tfar, \
                                   float (&__restrict rgb)[3][kPacketSize]) {                                \
        add_light_body(intensity, s, shadow, shadow_tfar, rgb);                                              \
    }                                                                                                        \
    TARGET void map_colour_##SUFFIX(const float (&m)[3][3], const float (&__restrict in)[3][kPacketSize],     \
                                    float (&__restrict out)[3][kPacketSize]) {                               \
        map_colour_body(m, in, out);                                                                         \
    }
LC_SHADING_KERNELS(default, )
LC_SHADING_KERNELS(avx2, [[gnu::target("avx2")]])
LC_SHADING_KERNELS(avx512, [[gnu::target("avx512f")]])
#undef LC_SHADING_KERNELS

bool available(ShadingKernel kernel) {
    switch (kernel) {
        case ShadingKernel::Avx2: return __builtin_cpu_supports("avx2");
        case ShadingKernel::Avx512: return __builtin_cpu_supports("avx512f");
        default: return true;
    }
}

const char* name_of(ShadingKernel kernel) {
    switch (kernel) {
        case ShadingKernel::Avx2: return "avx2";
        case ShadingKernel::Avx512: return "avx512";
        default: return "default";
    }
}

}  // namespace

ShadingKernel shading_kernel() {
    static const ShadingKernel chosen = [] {
        const char* wanted = std::getenv("LENSCOMPARE_SHADING_KERNEL");
        ShadingKernel best = ShadingKernel::Default;
        for (ShadingKernel k : {ShadingKernel::Default, ShadingKernel::Avx2, ShadingKernel::Avx512}) {
            if (!available(k)) continue;
            if (wanted && *wanted && std::strcmp(wanted, name_of(k)) == 0) return k;
            best = k;
        }
        return best;  // unset, or a kernel this CPU cannot run: the fastest it can
    }();
    return chosen;
}

const char* shading_kernel_name(ShadingKernel kernel) { return name_of(kernel); }

void gather_lanes(ShadingKernel kernel, const MaterialColumns& table, const int* material, SurfaceLanes& s,
                  float (&rgb)[3][kPacketSize]) {
    const Columns t{{table.start[0].data(), table.start[1].data(), table.start[2].data()},
                    {table.color[0].data(), table.color[1].data(), table.color[2].data()},
                    {table.checker_color[0].data(), table.checker_color[1].data(), table.checker_color[2].data()},
                    table.checker_size_m.data(),
                    table.diffuse.data()};
    switch (kernel) {
        case ShadingKernel::Avx512: return gather_avx512(t, material, s, rgb);
        case ShadingKernel::Avx2: return gather_avx2(t, material, s, rgb);
        default: return gather_default(t, material, s, rgb);
    }
}

void surface_lanes(ShadingKernel kernel, const RTCRayHitPacket& camera, SurfaceLanes& s) {
    switch (kernel) {
        case ShadingKernel::Avx512: return surface_avx512(camera, s);
        case ShadingKernel::Avx2: return surface_avx2(camera, s);
        default: return surface_default(camera, s);
    }
}

bool shadow_lanes(ShadingKernel kernel, const float light_m[3], bool inverse_square, const SurfaceLanes& s,
                  const float* time, ShadowLanes& shadow, RTCRayPacket& packet) {
    switch (kernel) {
        case ShadingKernel::Avx512: return shadow_avx512(light_m, inverse_square, s, time, shadow, packet);
        case ShadingKernel::Avx2: return shadow_avx2(light_m, inverse_square, s, time, shadow, packet);
        default: return shadow_default(light_m, inverse_square, s, time, shadow, packet);
    }
}

void add_light_lanes(ShadingKernel kernel, const float intensity[3], const SurfaceLanes& s,
                     const ShadowLanes& shadow, const float* shadow_tfar, float (&rgb)[3][kPacketSize]) {
    switch (kernel) {
        case ShadingKernel::Avx512: return add_light_avx512(intensity, s, shadow, shadow_tfar, rgb);
        case ShadingKernel::Avx2: return add_light_avx2(intensity, s, shadow, shadow_tfar, rgb);
        default: return add_light_default(intensity, s, shadow, shadow_tfar, rgb);
    }
}

void map_colour_lanes(ShadingKernel kernel, const float (&m)[3][3], const float (&in)[3][kPacketSize],
                      float (&out)[3][kPacketSize]) {
    switch (kernel) {
        case ShadingKernel::Avx512: return map_colour_avx512(m, in, out);
        case ShadingKernel::Avx2: return map_colour_avx2(m, in, out);
        default: return map_colour_default(m, in, out);
    }
}

}  // namespace lc
