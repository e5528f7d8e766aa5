"""Time as a dimension: what a scene moves during its shutter.

Objects and the camera move linearly from their positions at t = 0 (the scene
file's): p(t) = p + v t, for t over ``[render] shutter = [open, close]`` (s).
A render with motion blur integrates the image over the shutter, time being
one more dimension of each pixel sample (the native tracer; Cook et al. 1984).
POV-Ray has no motion blur, so its reference averages sub-frames at evenly
spaced times (:func:`subframe_times_s`).

Conventions: an equal open and close is an instantaneous exposure at that
time (no motion blur); zero velocities or a zero shutter give the static
image, bit for bit.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from .scene import Box, Rectangle, Scene, SceneObject, Sphere

__all__ = ["moves", "samples_time", "anything_has_velocity", "object_offset_m", "camera_offset_m",
           "camera_at_s", "subframe_times_s", "geometry_at_s"]


def _nonzero(velocity) -> bool:
    return any(v != 0.0 for v in velocity)


def anything_has_velocity(scene: Scene) -> bool:
    """True when the camera or any object has a non-zero velocity."""
    return _nonzero(scene.camera.velocity) or any(_nonzero(o.velocity) for o in scene.objects)


def samples_time(scene: Scene) -> bool:
    """True when a render must integrate over time: the shutter is open for
    an interval and something moves."""
    open_s, close_s = scene.render.shutter_s
    return close_s > open_s and anything_has_velocity(scene)


def moves(scene: Scene) -> bool:
    """True when the image differs from the static scene's: something moves,
    and the shutter is open over an interval or opens after t = 0."""
    return anything_has_velocity(scene) and any(t != 0.0 for t in scene.render.shutter_s)


def object_offset_m(obj: SceneObject, time_s: float) -> np.ndarray:
    """Where ``obj`` has moved by time ``time_s``: velocity * t, m."""
    return np.asarray(obj.velocity, dtype=float) * float(time_s)


def camera_offset_m(scene: Scene, time_s: float) -> np.ndarray:
    """Where the camera has moved by time ``time_s``: velocity * t, m."""
    return np.asarray(scene.camera.velocity, dtype=float) * float(time_s)


def camera_at_s(scene: Scene, time_s: float) -> Scene:
    """``scene`` with its camera moved to where it is at ``time_s`` (position
    and look-at point shift together, so the view direction stays)."""
    offset = camera_offset_m(scene, time_s)
    if not offset.any():
        return scene
    shift = lambda p: tuple(float(c) for c in np.asarray(p, dtype=float) + offset)  # noqa: E731
    return scene.with_camera(position=shift(scene.camera.position), look_at=shift(scene.camera.look_at))


def subframe_times_s(shutter_s: tuple[float, float], count: int) -> np.ndarray:
    """``count`` evenly spaced times over the shutter: the centres of ``count``
    equal intervals (a midpoint rule, so the sub-frame average has no half-
    interval bias at either end).

    Examples
    --------
    >>> subframe_times_s((0.0, 1.0), 4).tolist()
    [0.125, 0.375, 0.625, 0.875]
    """
    open_s, close_s = (float(t) for t in shutter_s)
    return open_s + (np.arange(count) + 0.5) / count * (close_s - open_s)


def _moved(obj: SceneObject, offset: np.ndarray) -> SceneObject:
    """``obj`` translated by ``offset`` (m), its velocity kept."""
    add = lambda p: tuple(float(c) for c in np.asarray(p, dtype=float) + offset)  # noqa: E731
    if isinstance(obj, Sphere):
        return replace(obj, center=add(obj.center))
    if isinstance(obj, Box):
        return replace(obj, min=add(obj.min), max=add(obj.max))
    if isinstance(obj, Rectangle):
        return replace(obj, corner=add(obj.corner))
    vertices = obj.vertices_m + offset
    vertices.flags.writeable = False
    return replace(obj, translate=add(obj.translate), vertices_m=vertices)


def geometry_at_s(scene: Scene, time_s: float) -> Scene:
    """A still snapshot of ``scene``'s geometry at ``time_s``: every object and
    the camera where they are then, no velocities, no shutter. For questions
    of geometry (bounds, distances, projections); a checker on a moving object
    would stay behind in it, so render the moving scene itself instead."""
    objects = tuple(replace(_moved(o, object_offset_m(o, time_s)), velocity=(0.0, 0.0, 0.0)) for o in scene.objects)
    moved = replace(camera_at_s(scene, time_s), objects=objects)
    return replace(moved.with_camera(velocity=(0.0, 0.0, 0.0)), render=replace(scene.render, shutter_s=(0.0, 0.0)))
