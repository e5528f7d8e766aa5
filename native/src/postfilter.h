// Image-based depth of field (Potmesil and Chakravarty 1981), the scatter
// step: every pixel of a pinhole image spreads its colour over its own blur
// disk (or the aperture's N-gon), and the spread layers are composited back
// to front, so that a nearer layer covers a farther one as an opaque object
// does (after Kraus and Strengert 2007). lenscompare/postfilter.py sizes each
// pixel's disk (eq. 5) and sorts the pixels into depth layers; this file only
// spreads and composites.
#pragma once

#include <cstdint>

#include "aperture.h"

namespace lc {

struct ScatterInput {
    int width_px = 0, height_px = 0;
    const float* rgb = nullptr;       // height x width x 3, the pinhole image
    const float* coc_px = nullptr;    // height x width: signed blur diameter, px; > 0 behind the plane of focus
    const int32_t* layer = nullptr;   // height x width: 0 the farthest layer ... n_layers - 1 the nearest
    int n_layers = 0;
    ApertureShape aperture;           // the blur's shape (unit circle radius)
    int sub_rows = 4;                 // each output row integrates the kernel at this many heights
    int threads = 0;                  // 0: all cores
};

// Writes the filtered image (height x width x 3) and each pixel's coverage
// (the composited weight before normalisation; < 1 where the frame's border
// or a gap left pixels short of neighbours). Each output row is computed
// alone, in a fixed order, so any thread count gives the same image.
void scatter_depth_of_field(const ScatterInput& in, float* out_rgb, float* out_coverage);

}  // namespace lc
