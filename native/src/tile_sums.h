// A tile's per-pixel sums of weighted radiance (and of their squares, for the
// variance), added one packet of samples at a time.
#pragma once

#include <cstddef>

#include "vec.h"

namespace lc {

// Samples [0, n): each radiance[j] * weight[j] (in double) into the three
// sums at sums + 3 slot[j], and its square into squares likewise (squares
// may be null). A run of samples of one pixel sums in registers, in sample
// order; the three channels side by side in one vector, each with the same
// operations in the same order as one channel at a time, so the sums are
// the same bits on every instruction set.
void add_tile_samples(int n, const size_t* slot, const Vec3f* radiance, const float* weight, double* sums,
                      double* squares);

}  // namespace lc
