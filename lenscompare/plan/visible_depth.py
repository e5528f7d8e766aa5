"""The depth range of the geometry the camera actually sees, from the scene
alone (no rendering): every object is clipped against the view frustum.

Occlusion is ignored, so the range can only be too wide (the planner errs
toward simulating an effect, never toward dropping a visible one).
"""

from __future__ import annotations

import math

import numpy as np

from ..cameras import CameraFrame
from ..native_scene import box_quads, rectangle_quad
from ..scene import Box, Mesh, Scene, Sphere

__all__ = ["visible_depth_range_m"]

_NEAR_M = 1e-6


def _frustum_planes(tan_half_w: float, tan_half_h: float) -> list[np.ndarray]:
    """Inward normals (camera space) of the four side planes and the near plane, as (n, d): n.p + d >= 0."""
    return [np.array([1.0, 0.0, tan_half_w, 0.0]), np.array([-1.0, 0.0, tan_half_w, 0.0]),
            np.array([0.0, 1.0, tan_half_h, 0.0]), np.array([0.0, -1.0, tan_half_h, 0.0]),
            np.array([0.0, 0.0, 1.0, -_NEAR_M])]


def _clip_polygon(points: list[np.ndarray], plane: np.ndarray) -> list[np.ndarray]:
    """Sutherland-Hodgman: the part of a convex polygon on the inner side of a plane."""
    out = []
    for i, current in enumerate(points):
        previous = points[i - 1]
        d_cur, d_prev = plane[:3] @ current + plane[3], plane[:3] @ previous + plane[3]
        if d_cur >= 0:
            if d_prev < 0:
                out.append(previous + (current - previous) * (d_prev / (d_prev - d_cur)))
            out.append(current)
        elif d_prev >= 0:
            out.append(previous + (current - previous) * (d_prev / (d_prev - d_cur)))
    return out


def visible_depth_range_m(scene: Scene, *, tan_half_w: float, tan_half_h: float) -> tuple[float, float] | None:
    """Smallest and largest depth (m, along the view axis) of anything inside the
    frame, or None when nothing is.

    Parameters
    ----------
    tan_half_w, tan_half_h : float
        Tangents of the half fields of view (film half-size over film distance).
    """
    origin, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    to_camera = np.stack([right, up, forward])
    planes = _frustum_planes(tan_half_w, tan_half_h)
    lo, hi = math.inf, -math.inf

    for obj in scene.objects:
        if isinstance(obj, Sphere):
            c = to_camera @ (np.asarray(obj.center) - origin)
            # Inside the frustum enlarged by the radius (a sphere touches a plane when its distance is < r).
            if all(p[:3] @ c + p[3] >= -obj.radius * np.linalg.norm(p[:3]) for p in planes):
                lo, hi = min(lo, max(c[2] - obj.radius, _NEAR_M)), max(hi, c[2] + obj.radius)
            continue
        if isinstance(obj, Mesh):  # its bounding box: the depth range can only grow, as with occlusion
            faces = box_quads(obj.vertices_m.min(axis=0), obj.vertices_m.max(axis=0) + 1e-9)
        elif isinstance(obj, Box):
            faces = box_quads(obj.min, obj.max)
        else:
            faces = [rectangle_quad(obj.corner, obj.edge1, obj.edge2)]
        for face in faces:
            polygon = [to_camera @ (corner - origin) for corner in face]
            for plane in planes:
                polygon = _clip_polygon(polygon, plane)
                if not polygon:
                    break
            if polygon:
                depths = [p[2] for p in polygon]
                lo, hi = min(lo, min(depths)), max(hi, max(depths))
    return None if lo == math.inf else (lo, hi)
