// Per-pixel sample sets over the camera's sample space: film (2D) + lens (2D).
// A sampler fills all of a pixel's samples at once; the render loop then hands
// them to the camera one by one. Dispatch on the sampler kind happens once per
// pixel, never per sample. New samplers add an enum value and one function.
#pragma once

#include <cstdint>

#include "vec.h"

namespace lc {

enum class SamplerKind : int { Random = 0, Jittered = 1 };

// Square -> unit disk mappings for lens samples.
enum class DiskMapping : int { Polar = 0, Concentric = 1 };

// Fills film[0..spp) and lens[0..spp) with points in [0,1)^2 for one pixel.
// The same (seed, pixel_index) always gives the same points.
void fill_pixel_samples(SamplerKind kind, uint64_t seed, uint64_t pixel_index, int spp,
                        Point2f* film, Point2f* lens);

// Strata of the jittered sampler: nx * ny == spp, nx the largest divisor of spp
// not above sqrt(spp) (8x8 for 64, 16x8 for 128; a prime spp gets 1 x spp).
void jittered_strata(int spp, int* nx, int* ny);

// Unit-square sample -> point in the unit disk, area-preserving.
Point2f map_to_disk(Point2f u, DiskMapping mapping);

}  // namespace lc
