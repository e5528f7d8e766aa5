#include "packet_bounds.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>

#include "cpu_kernels.h"
#include "near_line_lanes.h"

namespace lc {
namespace {

constexpr int N = kPacketSize;
// The margin, relative to the coordinates: the exact tests' own slack is a
// few float steps (1e-7 relative) and the kernels' float cull 1e-5.
constexpr float kRelativeMargin = 1e-4f;
constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

bool packet_cull_enabled() {
    const char* text = std::getenv("LENSCOMPARE_PACKET_CULL");
    return !(text && std::strcmp(text, "0") == 0);  // as LENSCOMPARE_EMBREE_ROBUST (embree_packet.cpp)
}

SegmentCapsule capsule_toward(const SurfaceLanes& s, const float light_m[3]) {
    return capsule_toward(s.from_centre_m, s.from_radius_m, light_m);
}

SegmentCapsule capsule_toward(const float centre_m[3], float ball_radius_m, const float light_m[3]) {
    SegmentCapsule out;
    const float cx = centre_m[0], cy = centre_m[1], cz = centre_m[2];
    const float lx = light_m[0], ly = light_m[1], lz = light_m[2];
    const float ax = lx - cx, ay = ly - cy, az = lz - cz;
    // Every origin lies within r of the centre, so within |axis| + r of the
    // light, and its segment ends (1 - kShadowEnd) of that short of it.
    const float reach_m = std::sqrt(ax * ax + ay * ay + az * az) + ball_radius_m;
    const float radius_m = ball_radius_m + 2.0f * (1.0f - kShadowEnd) * reach_m;
    out.a[0] = cx, out.a[1] = cy, out.a[2] = cz;
    out.b[0] = lx, out.b[1] = ly, out.b[2] = lz;
    out.radius_m = radius_m <= std::numeric_limits<float>::max() ? radius_m : kInf;  // NaN too
    float size = 1.0f + out.radius_m;
    for (int k = 0; k < 3; ++k) {
        const float ends = 1.0f + std::max(std::fabs(out.a[k]), std::fabs(out.b[k]));
        size = ends > size ? ends : size;
    }
    out.size_m = size;
    return out;
}

void ShadowCullCache::take(uint64_t scene, const SurfaceLanes& s) {
    const double dx = double(s.from_centre_m[0]) - centre_m_[0], dy = double(s.from_centre_m[1]) - centre_m_[1],
                 dz = double(s.from_centre_m[2]) - centre_m_[2];
    // Inside, with room for the rounding of this test (a relative 1e-6), and
    // not much smaller: a wide ball's candidates would serve the small ones
    // after it long after they stopped being worth it.
    const bool inside = scene == scene_ && radius_m_ <= 6.0f * s.from_radius_m + 1e-6f &&
                        std::sqrt(dx * dx + dy * dy + dz * dz) + double(s.from_radius_m) <= double(radius_m_) * (1.0 - 1e-6);
    if (inside) return;
    // A new ball three times as wide round this packet's origins (none to keep
    // when its radius is not finite: near then culls by the packet's own).
    const float wide_m = 3.0f * s.from_radius_m + 1e-6f;
    scene_ = wide_m <= std::numeric_limits<float>::max() ? scene : 0;
    known_ = 0, radius_m_ = wide_m;
    for (int a = 0; a < 3; ++a) centre_m_[a] = s.from_centre_m[a];
}

uint64_t ShadowCullCache::near(const SurfaceLanes& s, int light, const float light_m[3], ShadingKernel kernel,
                               const CullColumns& primitives) {
    if (scene_ == 0) return near_capsule(kernel, capsule_toward(s, light_m), primitives);
    if (!((known_ >> light) & 1u)) {
        const float centre[3] = {float(centre_m_[0]), float(centre_m_[1]), float(centre_m_[2])};
        masks_[light] = near_capsule(kernel, capsule_toward(centre, radius_m_, light_m), primitives);
        known_ |= 1u << light;
    }
    return masks_[light];
}

CullColumns CullColumns::of_own(const std::vector<float>& spheres, const std::vector<OwnQuad>& quads) {
    CullColumns c;
    for (size_t k = 0; k + 3 < spheres.size(); k += 4) {
        c.x.push_back(spheres[k]), c.y.push_back(spheres[k + 1]), c.z.push_back(spheres[k + 2]);
        c.radius.push_back(spheres[k + 3]);
        c.nx.push_back(0.0f), c.ny.push_back(0.0f), c.nz.push_back(0.0f), c.offset.push_back(0.0f);
    }
    for (const OwnQuad& q : quads) {
        c.x.push_back(q.bound[0]), c.y.push_back(q.bound[1]), c.z.push_back(q.bound[2]);
        c.radius.push_back(q.bound[3]);
        const float* unit = q.unit_normal;
        c.nx.push_back(unit[0]), c.ny.push_back(unit[1]), c.nz.push_back(unit[2]);
        c.offset.push_back(float(unit[0] * q.v0[0] + unit[1] * q.v0[1] + unit[2] * q.v0[2]));
    }
    c.pad();
    return c;
}

void CullColumns::pad() {
    count_ = int(x.size());
    const size_t padded = (x.size() + N - 1) / N * N;
    for (std::vector<float>* column : {&x, &y, &z, &radius, &nx, &ny, &nz, &offset}) column->resize(padded, 0.0f);
}

namespace {

template <class Set>
[[gnu::always_inline]] inline uint64_t near_capsule_body(Set set, const SegmentCapsule& capsule,
                                                         const CullColumns& p) {
    const float ax = capsule.a[0], ay = capsule.a[1], az = capsule.a[2];
    const float bx = capsule.b[0], by = capsule.b[1], bz = capsule.b[2];
    const float abx = bx - ax, aby = by - ay, abz = bz - az;
    const float ab2 = abx * abx + aby * aby + abz * abz;
    const float inverse_ab2 = ab2 > 0.0f ? 1.0f / ab2 : 0.0f;
    const float capsule_radius = capsule.radius_m, capsule_size = capsule.size_m;
    uint64_t mask = 0;
    // The columns come padded to whole packets (CullColumns::pad): N primitives side by side per step.
    for (int base = 0; base < std::min(p.padded_count(), 64); base += N) {
        const float* x = p.x.data() + base;
        const float* y = p.y.data() + base;
        const float* z = p.z.data() + base;
        const float* radius = p.radius.data() + base;
        const float* nx = p.nx.data() + base;
        const float* ny = p.ny.data() + base;
        const float* nz = p.nz.data() + base;
        const float* offset = p.offset.data() + base;
        alignas(64) int near[N];
        for (int j = 0; j < N; ++j) {
            const float px = x[j] - ax, py = y[j] - ay, pz = z[j] - az, r = radius[j];
            const float along = (px * abx + py * aby + pz * abz) * inverse_ab2;
            const float t = along < 0.0f ? 0.0f : (along > 1.0f ? 1.0f : along);
            const float qx = px - t * abx, qy = py - t * aby, qz = pz - t * abz;
            const float margin =
                kRelativeMargin * (capsule_size + std::fabs(x[j]) + std::fabs(y[j]) + std::fabs(z[j]) + r);
            const float reach = r + capsule_radius + margin;
            const bool far_from_axis = qx * qx + qy * qy + qz * qz > reach * reach;
            // The plane's signed distance at both ends of the axis (a sphere's: 0)
            const float side_a = nx[j] * ax + ny[j] * ay + nz[j] * az - offset[j];
            const float side_b = nx[j] * bx + ny[j] * by + nz[j] * bz - offset[j];
            const float wide = capsule_radius + margin;
            const bool one_side = ((side_a > wide) & (side_b > wide)) | ((side_a < -wide) & (side_b < -wide));
            near[j] = -int(!(far_from_axis | one_side));  // NaN: near
        }
        mask |= uint64_t(lanes::bits_set(set, near)) << base;
    }
    // Padding and primitives past 64 are no candidates of this mask (is_candidate tests those past 64).
    const int n = std::min(p.count(), 64);
    return n == 64 ? mask : mask & ((uint64_t(1) << n) - 1);
}

uint64_t near_capsule_default(const SegmentCapsule& c, const CullColumns& p) {
    return near_capsule_body(lanes::PortableSet{}, c, p);
}
[[gnu::target("avx2")]] uint64_t near_capsule_avx2(const SegmentCapsule& c, const CullColumns& p) {
    return near_capsule_body(lanes::Avx2Set{}, c, p);
}
[[gnu::target("avx512f")]] uint64_t near_capsule_avx512(const SegmentCapsule& c, const CullColumns& p) {
    return near_capsule_body(lanes::Avx512Set{}, c, p);
}

}  // namespace

uint64_t near_capsule(ShadingKernel kernel, const SegmentCapsule& capsule, const CullColumns& primitives) {
    switch (kernel) {
        case ShadingKernel::Avx512: return near_capsule_avx512(capsule, primitives);
        case ShadingKernel::Avx2: return near_capsule_avx2(capsule, primitives);
        default: return near_capsule_default(capsule, primitives);
    }
}

}  // namespace lc
