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

// The largest of v[0..N), halving with fixed widths: GCC runs each step in lanes.
[[gnu::always_inline]] inline float largest(float (&v)[N]) {
    static_assert(N == 16, "four halvings");
    for (int i = 0; i < 8; ++i) v[i] = v[i + 8] > v[i] ? v[i + 8] : v[i];
    for (int i = 0; i < 4; ++i) v[i] = v[i + 4] > v[i] ? v[i + 4] : v[i];
    for (int i = 0; i < 2; ++i) v[i] = v[i + 2] > v[i] ? v[i + 2] : v[i];
    return v[1] > v[0] ? v[1] : v[0];
}

}  // namespace

bool packet_cull_enabled() {
    const char* text = std::getenv("LENSCOMPARE_PACKET_CULL");
    return !(text && std::strcmp(text, "0") == 0);  // as LENSCOMPARE_EMBREE_ROBUST (embree_packet.cpp)
}

LC_BUILT_PER_ISA bool capsule_of_segments(const RTCRayPacket& packet, const int* valid, const float light_m[3],
                                          SegmentCapsule* out) {
    int first = 0;  // the first valid lane's origin is the axis's start
    while (first < N && valid[first] == 0) ++first;
    if (first == N) return false;
    const float ax = packet.org_x[first], ay = packet.org_y[first], az = packet.org_z[first];
    const float lx = light_m[0], ly = light_m[1], lz = light_m[2];
    float farthest2[N];
    for (int i = 0; i < N; ++i) {  // branch-free, so that GCC runs it 16 wide
        const float ox = packet.org_x[i], oy = packet.org_y[i], oz = packet.org_z[i], t = packet.tfar[i];
        const float ex = ox + t * packet.dir_x[i] - lx, ey = oy + t * packet.dir_y[i] - ly,
                    ez = oz + t * packet.dir_z[i] - lz;
        const float mx = ox - ax, my = oy - ay, mz = oz - az;
        const float from_first2 = mx * mx + my * my + mz * mz, end_from_light2 = ex * ex + ey * ey + ez * ez;
        const float d2 = from_first2 > end_from_light2 ? from_first2 : end_from_light2;
        // Not finite (or NaN): an infinite radius, so that every primitive stays a candidate
        const float sure = d2 <= std::numeric_limits<float>::max() ? d2 : kInf;
        farthest2[i] = valid[i] != 0 ? sure : 0.0f;
    }
    out->a[0] = ax, out->a[1] = ay, out->a[2] = az;
    out->b[0] = lx, out->b[1] = ly, out->b[2] = lz;
    out->radius_m = std::sqrt(largest(farthest2));
    float size = 1.0f + out->radius_m;
    for (int a = 0; a < 3; ++a) size = std::max({size, 1.0f + std::fabs(out->a[a]), 1.0f + std::fabs(out->b[a])});
    out->size_m = size;
    return true;
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
