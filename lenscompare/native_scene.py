"""Scene objects -> the flat arrays the native tracer builds its Embree scene from.

Spheres stay exact (Embree sphere points); a box becomes its six faces, marked
as one closed solid (``quad_solid``: the render then skips the faces a ray
cannot meet first, native/src/solid_faces.h), and a rectangle one quad; meshes go in as one Embree triangle geometry (all meshes'
vertices in one buffer, indices offset).

Motion: when anything has a velocity, each primitive's velocity (and each
mesh vertex's) goes along with the shutter and the camera's velocity; the
native scene then gives moving primitives Embree time steps
(native/src/scene.cpp). A scene where nothing moves passes no velocities at
all, so its Embree scene is the static one, bit for bit.
"""

from __future__ import annotations

import numpy as np

from . import _native
from .motion import anything_has_velocity
from .scene import Box, DiffuseMaterial, EmissiveMaterial, Mesh, Rectangle, Scene, Sphere

__all__ = ["build_native_scene", "box_quads", "rectangle_quad"]


def rectangle_quad(corner, edge1, edge2) -> np.ndarray:
    """The four corners, in order round the parallelogram, shape (4, 3)."""
    c, e1, e2 = (np.asarray(v, dtype=float) for v in (corner, edge1, edge2))
    return np.array([c, c + e1, c + e1 + e2, c + e2])


def box_quads(lo, hi) -> np.ndarray:
    """The six faces of an axis-aligned box, shape (6, 4, 3)."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    size = hi - lo
    ex, ey, ez = np.diag(size)
    return np.array([
        rectangle_quad(lo, ey, ez), rectangle_quad(lo + ex, ey, ez),  # -x, +x
        rectangle_quad(lo, ex, ez), rectangle_quad(lo + ey, ex, ez),  # -y, +y
        rectangle_quad(lo, ex, ey), rectangle_quad(lo + ez, ex, ey),  # -z, +z
    ])


def build_native_scene(scene: Scene) -> "_native.Scene":
    """Build the Embree scene for ``scene`` (a BVH build: milliseconds for our scenes)."""
    names = list(scene.materials)
    index = {name: i for i, name in enumerate(names)}
    spheres, sphere_material, quads, quad_material, quad_solid = [], [], [], [], []
    mesh_vertices, mesh_triangles, triangle_material, n_vertices = [], [], [], 0
    sphere_velocity, quad_velocity, vertex_velocity = [], [], []
    for obj in scene.objects:
        if isinstance(obj, Sphere):
            spheres.append([*obj.center, obj.radius])
            sphere_material.append(index[obj.material])
            sphere_velocity.append(obj.velocity)
        elif isinstance(obj, Box):
            faces = box_quads(obj.min, obj.max)
            quads.extend(faces)
            quad_material.extend([index[obj.material]] * len(faces))
            quad_solid.extend([len(quads)] * len(faces))  # one id per box: a closed convex solid
            quad_velocity.extend([obj.velocity] * len(faces))
        elif isinstance(obj, Rectangle):
            quads.append(rectangle_quad(obj.corner, obj.edge1, obj.edge2))
            quad_material.append(index[obj.material])
            quad_solid.append(-1)
            quad_velocity.append(obj.velocity)
        elif isinstance(obj, Mesh):
            mesh_vertices.append(obj.vertices_m)
            mesh_triangles.append(obj.triangles + n_vertices)
            triangle_material.append(np.full(len(obj.triangles), index[obj.material], dtype=np.int32))
            vertex_velocity.append(np.broadcast_to(np.asarray(obj.velocity, dtype=float), obj.vertices_m.shape))
            n_vertices += len(obj.vertices_m)

    kinds, colors, emissions, checker_colors, checker_sizes = [], [], [], [], []
    for name in names:
        m = scene.materials[name]
        if isinstance(m, EmissiveMaterial):
            kinds.append(_native.MATERIAL_EMISSIVE)
            colors.append(m.color)
            emissions.append((0.0, 0.0, 0.0))
            checker_colors.append((0.0, 0.0, 0.0))
            checker_sizes.append(0.0)
        elif isinstance(m, DiffuseMaterial):
            kinds.append(_native.MATERIAL_DIFFUSE)
            colors.append(m.color)
            emissions.append(m.emission)
            checker_colors.append(m.checker.color if m.checker else (0.0, 0.0, 0.0))
            checker_sizes.append(m.checker.size_m if m.checker else 0.0)

    def f32(values, shape):
        return np.ascontiguousarray(np.asarray(values, dtype=np.float32).reshape(shape))

    def i32(values):
        return np.ascontiguousarray(np.asarray(values, dtype=np.int32).reshape(-1))

    # Nothing moving: no velocities at all, the static scene's exact arrays.
    motion = {}
    if anything_has_velocity(scene):
        motion = dict(sphere_velocity=f32(sphere_velocity, (-1, 3)), quad_velocity=f32(quad_velocity, (-1, 3)),
                      vertex_velocity=f32(np.concatenate(vertex_velocity) if vertex_velocity else [], (-1, 3)),
                      shutter_s=tuple(float(t) for t in scene.render.shutter_s),
                      camera_velocity=tuple(float(v) for v in scene.camera.velocity))
    return _native.Scene(
        f32(spheres, (-1, 4)), i32(sphere_material),
        f32(quads, (-1, 4, 3)), i32(quad_material),
        i32(kinds), f32(colors, (-1, 3)), f32(emissions, (-1, 3)), f32(checker_colors, (-1, 3)),
        f32(checker_sizes, (-1,)),
        f32([l.position for l in scene.lights], (-1, 3)), f32([l.color for l in scene.lights], (-1, 3)),
        tuple(float(c) for c in scene.background),
        i32([l.falloff == "inverse_square" for l in scene.lights]),
        f32(np.concatenate(mesh_vertices) if mesh_vertices else [], (-1, 3)),
        np.ascontiguousarray(np.concatenate(mesh_triangles) if mesh_triangles else np.zeros((0, 3)), dtype=np.int32),
        i32(np.concatenate(triangle_material) if triangle_material else []),
        quad_solid=i32(quad_solid),
        **motion,
    )
