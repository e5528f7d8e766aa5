// Time as a dimension of the sample space (Cook et al. 1984; paper section 3):
// what moves during the shutter, and how a sample's time maps onto it.
//
// Every object and the camera move linearly from their positions at t = 0:
// p(t) = p + v t. A sample's time u in [0, 1) maps onto the shutter as
// t = open + u (close - open) seconds; Embree's ray time is u itself (each
// moving geometry holds two time steps, its positions at open and at close,
// and Embree interpolates between them: exact for linear motion).
#pragma once

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

}  // namespace lc
