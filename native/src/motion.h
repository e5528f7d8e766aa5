// Time as a dimension of the sample space (Cook et al. 1984; paper section 3):
// what moves during the shutter, and how a sample's time maps onto it.
//
// Every object and the camera move linearly from their positions at t = 0:
// p(t) = p + v t. A sample's time u in [0, 1) maps onto the shutter as
// t = open + u (close - open) seconds; Embree's ray time is u itself (each
// moving geometry holds two time steps, its positions at open and at close,
// and Embree interpolates between them: exact for linear motion).
#pragma once

#include <algorithm>
#include <cmath>
#include <vector>

#include "vec.h"

namespace lc {

struct SceneMotion {
    double open_s = 0.0, close_s = 0.0;  // shutter, seconds
    Vec3d camera_velocity_m_per_s{0.0, 0.0, 0.0};
    bool anything_moves = false;  // some velocity is non-zero (objects or camera)

    // A time per sample is drawn only when the shutter is open over an
    // interval and something moves; otherwise every sample sees t = open and
    // the render takes the static path, bit for bit.
    bool samples_time() const { return anything_moves && close_s > open_s; }

    // The camera's offset at time t, m; applied to every camera ray's origin
    // (a rigid translation of the whole camera, so any model).
    bool moves_camera() const {
        return camera_velocity_m_per_s.x != 0.0 || camera_velocity_m_per_s.y != 0.0 ||
               camera_velocity_m_per_s.z != 0.0;
    }

    double time_s(float u) const { return open_s + double(u) * (close_s - open_s); }
};

// Where the moving primitives can be during the shutter: one box per distinct
// velocity (an object's primitives share one), each the union of the
// primitives' bounds at open and at close (linear motion stays inside it).
// The render asks Embree about the moving geometry only for rays that pass
// through one of these boxes: each Embree scene costs a fixed amount per
// packet whatever it holds, and most rays never come near what moves.
class SweptBounds {
  public:
    // Grows the box of `velocity` by the point p (m) and a margin (m) round it.
    void add(const Vec3f& velocity, const float* p, float margin_m) {
        Box& b = box_of(velocity);
        for (int a = 0; a < 3; ++a) {
            b.lo[a] = std::min(b.lo[a], p[a] - margin_m);
            b.hi[a] = std::max(b.hi[a], p[a] + margin_m);
        }
    }

    // Pads each box for float rounding in Embree's own tests and, past
    // kMaxBoxes velocities, merges them into one (a test per box per ray).
    void finish() {
        if (boxes_.size() > kMaxBoxes) {
            Box all = boxes_[0];
            for (const Box& b : boxes_)
                for (int a = 0; a < 3; ++a) all.lo[a] = std::min(all.lo[a], b.lo[a]), all.hi[a] = std::max(all.hi[a], b.hi[a]);
            boxes_.assign(1, all);
        }
        for (Box& b : boxes_)
            for (int a = 0; a < 3; ++a) {
                const float pad = 1e-4f * std::max({std::fabs(b.lo[a]), std::fabs(b.hi[a]), 1.0f});
                b.lo[a] -= pad, b.hi[a] += pad;
            }
    }

    // Whether the segment origin + t direction, t in [0, t_max], can meet a
    // box (slab test; conservative: a NaN never culls).
    bool may_hit(const Vec3f& origin, const Vec3f& direction, float t_max) const {
        const float o[3] = {origin.x, origin.y, origin.z}, d[3] = {direction.x, direction.y, direction.z};
        // The reciprocals once per ray, not once per box: a division costs as
        // much as the rest of a box's test.
        const float inv[3] = {1.0f / d[0], 1.0f / d[1], 1.0f / d[2]};
        for (const Box& b : boxes_) {
            float t0 = 0.0f, t1 = t_max;
            bool inside = true;
            for (int a = 0; a < 3 && inside; ++a) {
                if (d[a] == 0.0f) {
                    inside = o[a] >= b.lo[a] && o[a] <= b.hi[a];
                    continue;
                }
                float near = (b.lo[a] - o[a]) * inv[a], far = (b.hi[a] - o[a]) * inv[a];
                if (near > far) std::swap(near, far);
                t0 = near > t0 ? near : t0;
                t1 = far < t1 ? far : t1;
                inside = !(t0 > t1);
            }
            if (inside) return true;
        }
        return false;
    }

    bool empty() const { return boxes_.empty(); }

  private:
    static constexpr size_t kMaxBoxes = 16;
    struct Box {
        Vec3f velocity;
        float lo[3], hi[3];
    };

    Box& box_of(const Vec3f& v) {
        for (Box& b : boxes_)
            if (b.velocity.x == v.x && b.velocity.y == v.y && b.velocity.z == v.z) return b;
        const float inf = INFINITY;
        boxes_.push_back(Box{v, {inf, inf, inf}, {-inf, -inf, -inf}});
        return boxes_.back();
    }

    std::vector<Box> boxes_;
};

}  // namespace lc
