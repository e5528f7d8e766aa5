// What both binding files share: the array types Python hands over (C-contiguous,
// on the CPU, moved without copies) and how a ray goes back into them.
#pragma once

#include <nanobind/nanobind.h>
#include <nanobind/ndarray.h>

#include <cstddef>

#include "cameras/camera_ray.h"

namespace lc {

template <class T, nanobind::ssize_t... Shape>
using CArray = nanobind::ndarray<T, nanobind::shape<Shape...>, nanobind::c_contig, nanobind::device::cpu>;

// Row i of the output arrays: the ray, or zeros and weight 0 for a vignetted sample.
inline void store_ray(const MaybeRay& ray, size_t i, CArray<double, -1, 3>& origin, CArray<double, -1, 3>& direction,
                      CArray<float, -1>& weight) {
    Vec3d o = ray ? ray->origin : Vec3d{}, d = ray ? ray->direction : Vec3d{};
    origin(i, 0) = o.x, origin(i, 1) = o.y, origin(i, 2) = o.z;
    direction(i, 0) = d.x, direction(i, 1) = d.y, direction(i, 2) = d.z;
    weight(i) = ray ? ray->weight : 0.0f;
}

// The test and benchmark hooks, bound into the submodule m (bindings_diagnostics.cpp).
void bind_diagnostics(nanobind::module_& m);

}  // namespace lc
