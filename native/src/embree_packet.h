// The width of the ray packets the render loop hands Embree, and the packet
// types and calls of that width. Sixteen: Embree's 16-wide kernels are the
// native ones on AVX-512 CPUs (RTC_DEVICE_PROPERTY_NATIVE_RAY16_SUPPORTED),
// and elsewhere Embree splits a 16-wide packet into the packets its ISA has,
// giving each ray the same hit (bench/bench_peers.py measures what it buys).
#pragma once

#include <embree3/rtcore.h>

namespace lc {

constexpr int kPacketSize = 16;
constexpr int kPacketAlignment = 64;  // Embree asks packets and masks aligned to their width in bytes

using RTCRayHitPacket = RTCRayHit16;
using RTCRayPacket = RTCRay16;

inline void intersect_packet(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayHitPacket* rays) {
    rtcIntersect16(valid, scene, context, rays);
}

inline void occluded_packet(const int* valid, RTCScene scene, RTCIntersectContext* context, RTCRayPacket* rays) {
    rtcOccluded16(valid, scene, context, rays);
}

// Device configuration: LENSCOMPARE_EMBREE_ISA (sse2, sse4.2, avx, avx2,
// avx512) caps the instruction set Embree's kernels use, so tests can compare
// the images of each; unset, Embree picks the CPU's best. Returns the config
// string for rtcNewDevice (nullptr: defaults).
const char* embree_device_config();
// The scene flags for geometry with edges (quads, triangles): RTC_SCENE_FLAG_ROBUST,
// which keeps rays from slipping between primitives that share an edge, unless
// LENSCOMPARE_EMBREE_ROBUST=0 (Mitsuba 3's setting; for measuring what robust
// traversal costs: bench/bench_peers.py).
RTCSceneFlags embree_edge_flags();

}  // namespace lc
