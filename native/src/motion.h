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
    // The camera's offset at shutter time u, m (render_tile.h, move_origins).
    Vec3d camera_offset_m(float u) const { return camera_velocity_m_per_s * time_s(u); }
};

// The lane-wise test behind SweptBounds::may_hit (motion.cpp): n_boxes boxes
// as lo xyz, hi xyz each, against SweptBounds::kLanes rays.
bool swept_boxes_met(const float* lo_hi, int n_boxes, const float* const origin[3], const float* const direction[3],
                     const float* t_max, const int* active, int* hit);

// The same for n moving spheres (centre at open xyz, centre at close xyz,
// radius, m, each), each where it is at the ray's own time in [0, 1).
bool moving_spheres_met(const float* spheres, int n, const float* const origin[3], const float* const direction[3],
                        const float* t_max, const float* time, const int* active, int* hit);

// Where the moving primitives can be during the shutter: one box per distinct
// velocity (an object's primitives share one), each the union of the
// primitives' bounds at open and at close (linear motion stays inside it).
// The render asks Embree about the moving geometry only for rays that pass
// through one of these boxes: each Embree scene costs a fixed amount per
// packet whatever it holds, and most rays never come near what moves.
//
// When only spheres move (at most kMaxSpheres of them), each ray is tested
// against the spheres themselves where they are at its time instead: a box
// round a sphere's path holds corners and times the sphere never reaches, and
// most shadow rays that passed the boxes (from a moving sphere's own surface,
// or from the floor beneath it) met no sphere.
class SweptBounds {
  public:
    // A vertex of a moving quad or triangle at open or close (m).
    void add_vertex(const Vec3f& velocity, const float* p) {
        grow(velocity, p, 0.0f);
        only_spheres_ = false;
    }

    // A moving sphere: its centre at open and at close (m), its radius (m).
    void add_sphere(const Vec3f& velocity, const float* centre_open, const float* centre_close, float radius_m) {
        grow(velocity, centre_open, radius_m);
        grow(velocity, centre_close, radius_m);
        spheres_.insert(spheres_.end(), {centre_open[0], centre_open[1], centre_open[2], centre_close[0],
                                           centre_close[1], centre_close[2], radius_m});
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
        lo_hi_.clear();
        for (const Box& b : boxes_) lo_hi_.insert(lo_hi_.end(), {b.lo[0], b.lo[1], b.lo[2], b.hi[0], b.hi[1], b.hi[2]});
        if (!only_spheres_ || spheres_.size() > 7 * kMaxSpheres) spheres_.clear();
    }

    // How many rays may_hit tests at once: the render's packet width (embree_packet.h).
    static constexpr int kLanes = 16;

    // Which of kLanes rays (SoA: origins, directions, segments t in [0, t_max],
    // shutter times in [0, 1)) may meet what moves: lanes with active[i] set
    // get -1 in hit[i] where they may, the rest 0. Returns whether any may.
    // The moving spheres at each ray's time when only spheres move, else the
    // swept boxes (a slab test; a direction component of exactly 0 tests the
    // origin against that slab instead). Conservative: a NaN never culls (motion.cpp).
    bool may_hit(const float* const origin[3], const float* const direction[3], const float* t_max,
                 const float* time, const int* active, int* hit) const {
        if (!spheres_.empty())
            return moving_spheres_met(spheres_.data(), int(spheres_.size() / 7), origin, direction, t_max, time,
                                      active, hit);
        return swept_boxes_met(lo_hi_.data(), int(lo_hi_.size() / 6), origin, direction, t_max, active, hit);
    }

    bool empty() const { return boxes_.empty(); }

  private:
    static constexpr size_t kMaxBoxes = 16, kMaxSpheres = 16;
    struct Box {
        Vec3f velocity;
        float lo[3], hi[3];
    };

    // Grows the box of `velocity` by the point p (m) and a margin (m) round it.
    void grow(const Vec3f& velocity, const float* p, float margin_m) {
        Box& b = box_of(velocity);
        for (int a = 0; a < 3; ++a) {
            b.lo[a] = std::min(b.lo[a], p[a] - margin_m);
            b.hi[a] = std::max(b.hi[a], p[a] + margin_m);
        }
    }

    Box& box_of(const Vec3f& v) {
        for (Box& b : boxes_)
            if (b.velocity.x == v.x && b.velocity.y == v.y && b.velocity.z == v.z) return b;
        const float inf = INFINITY;
        boxes_.push_back(Box{v, {inf, inf, inf}, {-inf, -inf, -inf}});
        return boxes_.back();
    }

    std::vector<Box> boxes_;
    std::vector<float> lo_hi_;  // per box: lo xyz, hi xyz (m), after finish()
    std::vector<float> spheres_;  // per sphere: centre at open xyz, at close xyz, radius (m)
    bool only_spheres_ = true;
};

}  // namespace lc
