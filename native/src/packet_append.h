// The live rows of a run of kPacketSize camera rays appended to a packet in
// whole vectors (AVX-512's compress), in order, instead of a ray at a time:
// a lens system's vignetted rays leave the packets' counts off the runs'
// starts, and from then on every ray went one by one (perf: RayPacket's
// queue a twentieth of a lens render from the table). The same rays in the
// same lanes as the ray-at-a-time queue, so the same images.
#pragma once

#include <cstddef>
#include <cstdint>

#include "cameras/camera_ray.h"
#include "scene.h"

namespace lc {

// Whether this CPU runs append_live_rows (AVX-512 F, BMI2), and the shading kernel
// (LENSCOMPARE_SHADING_KERNEL) asks for AVX-512 code.
bool packet_append_available();

// Bit j set where alive[j] (j < kPacketSize).
uint32_t live_bits(const bool* alive);

// Rows [at, at + kPacketSize) of rows whose bits are in *live, each with its
// shutter time, weight (null: 1) and slot, after batch->count's queued ones:
// as many as the packet has room for, lowest bits first; those taken leave
// *live and count in batch->count.
void append_live_rows(const CameraRayRows& rows, int at, const float* time_u, const float* weight,
                      const size_t* slot, uint32_t* live, RayBatch* batch, float* batch_weight,
                      size_t* batch_slot);

}  // namespace lc
