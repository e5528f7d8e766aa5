// Raw Embree primary-ray throughput on a scene: the ceiling a camera model's
// render can approach. Pinhole rays, rtcIntersect1, no shading.
#pragma once

#include "cameras/pinhole.h"
#include "scene.h"

namespace lc {

struct RawThroughput {
    double seconds = 0;
    uint64_t rays = 0;
    uint64_t hits = 0;  // kept so the compiler cannot drop the queries
};

RawThroughput measure_raw_primary_throughput(const Scene& scene, const PinholeCamera& camera, int spp, int threads);

}  // namespace lc
