"""How far things travel across the film during the shutter, from the scene
alone (no rendering): the size of the planner's ``motion_blur`` effect, and
how many sub-frames POV-Ray's reference of a moving scene takes.

Each object's points (a sphere's centre, the corners of a box, rectangle or a
mesh's bounding box) move at the object's velocity relative to the camera's,
v_object - v_camera, so a moving camera streaks every still object. A point
on a straight line in space projects onto a straight line on the film, so its
path there is the segment between its images when the shutter opens and when
it closes (as long as it stays in front of the camera). An object counts when
its path enters the frame; occlusion is ignored, so the estimate can only be
too large (the planner errs toward simulating an effect).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .cameras import CameraFrame, CameraModel
from .native_scene import rectangle_quad
from .scene import Box, Mesh, Rectangle, Scene, Sphere

__all__ = ["MotionPath", "longest_motion_path"]

_TIME_STEPS = 33  # positions checked along each path for "in front and in frame"
_NEAR_M = 1e-6


@dataclass(frozen=True)
class MotionPath:
    """The longest path on the film.

    Attributes
    ----------
    length_px : float
        Its length, px.
    object_index : int
        Which of ``scene.objects``.
    start_px, end_px : ndarray
        Raster positions of the point when the shutter opens and closes.
    """

    length_px: float
    object_index: int
    start_px: np.ndarray
    end_px: np.ndarray


def _points_m(obj) -> np.ndarray:
    """Points of the object whose paths stand for it, (n, 3) m."""
    if isinstance(obj, Sphere):
        return np.asarray([obj.center], dtype=float)
    if isinstance(obj, Rectangle):
        return rectangle_quad(obj.corner, obj.edge1, obj.edge2)
    lo, hi = (obj.min, obj.max) if isinstance(obj, Box) else (obj.vertices_m.min(axis=0), obj.vertices_m.max(axis=0))
    return np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])],
                    dtype=float)  # the eight corners


def longest_motion_path(scene: Scene, camera: CameraModel) -> MotionPath | None:
    """The longest film path of any object point over the shutter, or None
    when nothing visible moves relative to the camera (or the shutter is an
    instant)."""
    open_s, close_s = scene.render.shutter_s
    if not close_s > open_s:
        return None
    frame = CameraFrame.of(scene.camera)
    width, height = camera.film.resolution
    v_camera = np.asarray(scene.camera.velocity, dtype=float)
    times = np.linspace(open_s, close_s, _TIME_STEPS)
    best: MotionPath | None = None
    for index, obj in enumerate(scene.objects):
        relative = np.asarray(obj.velocity, dtype=float) - v_camera
        if not relative.any():
            continue
        for p in _points_m(obj):
            # Camera space at each time: the camera frame at t = 0 seeing p + (v - v_c) t.
            xyz = frame.camera_from_world(p[None, :] + relative[None, :] * times[:, None])
            if not np.all(xyz[:, 2] > _NEAR_M):
                continue  # crosses the camera plane: no straight path on the film
            raster = camera.project_px(xyz)
            inside = ((raster[:, 0] >= 0) & (raster[:, 0] <= width) & (raster[:, 1] >= 0) & (raster[:, 1] <= height))
            if not inside.any():
                continue
            length = float(np.linalg.norm(raster[-1] - raster[0]))
            if best is None or length > best.length_px:
                best = MotionPath(length, index, raster[0], raster[-1])
    return best
