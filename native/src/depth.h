// The depth buffer of a pinhole camera: for each pixel, the distance along the
// view axis (m) of the first surface its centre ray hits, +inf where it hits
// nothing. The image-based depth of field (lenscompare/postfilter) reads it.
#pragma once

#include "cameras/pinhole.h"
#include "scene.h"

namespace lc {

// Fills depth_m (height x width, row 0 at the top) with one ray per pixel
// centre. Each pixel is computed alone, so any thread count gives the same buffer.
void render_depth(const Scene& scene, const PinholeCamera& camera, int threads, float* depth_m);

}  // namespace lc
