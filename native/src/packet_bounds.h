// One bound round a whole packet of shadow rays, and the own primitives
// (sphere_lanes.h, quad_lanes.h) it may meet: a per-packet cull that runs
// before the kernels' per-lane culls.
//
// A packet's shadow rays start at nearby hits (a camera packet's samples lie
// in one or two pixels) and all end at one light, so every segment lies in
// one capsule: round the axis from one lane's origin to the light, as wide
// as the farthest diffuse lane's origin from that one (a ball made once per
// camera packet, surface_lanes, for every light), widened for the segments'
// ends short of the light. A primitive whose bounding ball lies farther from the axis than
// that radius plus a margin (1e-4 of the coordinates, far above any
// rounding), or whose plane leaves the whole capsule on one side, meets no
// lane: it is skipped after one test per packet, all primitives side by side
// in float lanes, instead of the kernels' per-lane culls, 16 lanes each. The
// cull only skips what cannot block, so the images are the same bit for bit.
#pragma once

#include <cstdint>
#include <vector>

#include "embree_packet.h"
#include "quad_lanes.h"
#include "shading_lanes.h"

namespace lc {

// Whether a scene built now culls per packet: LENSCOMPARE_PACKET_CULL=0 turns
// it off, for the tests that show it changes no image and the benchmarks that
// measure what it saves.
bool packet_cull_enabled();

struct SegmentCapsule {
    float a[3], b[3];  // the axis: the centre of the origins' ball, the light (m)
    float radius_m;    // every valid segment lies within this of the axis
    float size_m;      // 1 + the largest coordinate or radius: the margin's scale
};

// The capsule round a camera packet's shadow segments toward light_m (s
// after surface_lanes): the axis from the ball round the segments' origins
// to the light, as wide as that ball, widened by twice the ends' distance
// short of the light (1 - kShadowEnd of each segment's length, doubled for
// the rounding of o + t d), so one ball serves every light. A value not
// finite makes the radius infinite: every primitive stays a candidate.
SegmentCapsule capsule_toward(const SurfaceLanes& s, const float light_m[3]);
// The same round any ball of origins (centre, radius).
SegmentCapsule capsule_toward(const float centre_m[3], float ball_radius_m, const float light_m[3]);

// The own primitives as the cull takes them, in columns: a bounding ball
// each, and a quad's plane (its unit normal and offset n . v0; a sphere's
// normal is 0, so its plane test always passes). Padded with zeros to whole
// packets, so that near_capsule's loop takes whole vectors.
struct CullColumns {
    std::vector<float> x, y, z, radius, nx, ny, nz, offset;
    int count() const { return count_; }
    int padded_count() const { return int(x.size()); }
    // The own spheres (centre xyz, radius each), then the own quads.
    static CullColumns of_own(const std::vector<float>& spheres, const std::vector<OwnQuad>& quads);

  private:
    void pad();
    int count_ = 0;
};

// Bit k set: primitive k (k < 64) may meet a segment within the capsule (for
// of_own's columns: the spheres' candidates from bit 0, the quads' after them;
// is_candidate, sphere_lanes.h).
// Built per instruction set, run on the shading kernel's (shading_lanes.h;
// the same bits on each, as LENSCOMPARE_SHADING_KERNEL's test shows).
uint64_t near_capsule(ShadingKernel kernel, const SegmentCapsule& capsule, const CullColumns& primitives);

// A thread's last shadow cull per light, kept for the camera packets that
// follow: the candidates of the capsule from a ball round this one's origins
// to each light. A later packet whose origins' ball lies inside that ball has
// its segments inside those capsules (a capsule round a ball inside another,
// to the same light, lies inside the other's, widening included), so the
// candidates serve it as they are: a superset of its own, tested exactly as
// before, so the images are the same bit for bit. A camera packet's samples
// lie in one pixel, and a pixel's next packets fall mostly inside a ball
// three times as wide as the first's (peers_lit, thin lens, 64 spp, under
// callgrind: 1.302 G instructions without the cache, 1.243 G with balls
// twice as wide kept down to a quarter's packet, 1.221 G three times and a
// sixth, 1.218 G five times and a tenth).
class ShadowCullCache {
  public:
    static constexpr int kLights = 8;  // lights past these are culled packet by packet
    // Once per camera packet, before near: keeps the ball if s's ball lies
    // inside it (and is not much smaller), else takes a new one round s's.
    // scene: a number no other scene built in this process has.
    void take(uint64_t scene, const SurfaceLanes& s);
    // The candidates toward light (< kLights) of the packet take was given.
    uint64_t near(const SurfaceLanes& s, int light, const float light_m[3], ShadingKernel kernel,
                  const CullColumns& primitives);

  private:
    uint64_t scene_ = 0;  // whose candidates these are (0: none, or a ball not finite)
    double centre_m_[3] = {};
    float radius_m_ = 0.0f;
    unsigned known_ = 0;  // bit l: masks_[l] found for this ball
    uint64_t masks_[kLights] = {};
};

}  // namespace lc
