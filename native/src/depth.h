// The depth buffer of a pinhole camera: for each pixel, the distance along the
// view axis (m) of the nearest surface it sees, +inf where it sees nothing.
// The image-based depth of field (lenscompare/postfilter) reads it.
#pragma once

#include <cstdint>

#include "cameras/pinhole.h"
#include "scene.h"

namespace lc {

// A relative depth step to one of the 8 neighbours beyond this marks a silhouette pixel.
constexpr double kDepthEdgeJump = 0.05;
// Silhouette pixels trace this many rays across (a regular grid) and keep the nearest hit.
constexpr int kDepthEdgeGrid = 8;  // finds an object covering 1/64 of the pixel

// Fills depth_m (height x width, row 0 at the top): one ray through each pixel
// centre; then, where the depth jumps to a neighbour (a silhouette), the
// nearest hit of a kDepthEdgeGrid^2 grid of rays over the pixel, so that a
// pixel partly covered by an object takes that object's depth. Each pixel is
// computed alone in both passes: any thread count gives the same buffer.
// refine (optional, height x width): pixels that take the grid whatever their
// neighbours (objects too small for any pixel centre to hit).
void render_depth(const Scene& scene, const PinholeCamera& camera, int threads, float* depth_m,
                  const uint8_t* refine = nullptr);

}  // namespace lc
