"""What the camera models share: the camera frame and the focal length."""

from __future__ import annotations

import numpy as np

from ..errors import InputError

__all__ = ["camera_frame", "check_focus_reachable", "focal_length_mm", "require", "scene_prescription",
           "screen_half_extent"]


def camera_frame(camera):
    """World-from-camera frame: origin, right, up, forward (unit, world space).

    POV-Ray convention (left-handed, +y up): right = up x forward, so a camera
    looking along +z with up +y has right = +x.
    """
    origin = np.asarray(camera.position, dtype=float)
    forward = np.asarray(camera.look_at, dtype=float) - origin
    forward /= np.linalg.norm(forward)
    right = np.cross(np.asarray(camera.up, dtype=float), forward)
    right /= np.linalg.norm(right)
    up = np.cross(forward, right)
    return tuple(tuple(float(c) for c in v) for v in (origin, right, up, forward))


def require(scene, value, key: str, model: str):
    """``value``, or an InputError naming the camera key the model needs."""
    if value is None:
        raise InputError(scene.source, f"required for the {model} model", key=f"camera.{key}")
    return value


def focal_length_mm(scene, model: str) -> float:
    """The focal length a pinhole/thin/thick camera uses, mm.

    From ``camera.lens`` (its effective focal length) when the scene names a
    lens, so that the idealised models share the real lens; otherwise
    ``camera.focal_length_mm``.
    """
    camera = scene.camera
    if camera.lens is not None:
        from ..lenses import paraxial_data

        return paraxial_data(scene_prescription(scene, model)).effective_focal_length_mm
    return require(scene, camera.focal_length_mm, "focal_length_mm", model)


def scene_prescription(scene, model: str):
    """The prescription ``camera.lens`` names: a shipped name, or a path
    (relative paths are taken from the scene file's folder)."""
    from pathlib import Path

    from ..lenses import load_prescription, shipped_lens_names

    name = require(scene, scene.camera.lens, "lens", model)
    if name in shipped_lens_names() or Path(name).is_absolute():
        return load_prescription(name)
    return load_prescription(Path(scene.base_dir) / name)


def check_focus_reachable(scene, focal_length: float) -> None:
    if not scene.camera.focus_distance_m * 1000.0 > focal_length:
        raise InputError(scene.source, f"{scene.camera.focus_distance_m:g} m is not beyond the focal length "
                         f"{focal_length:g} mm", key="camera.focus_distance")


def screen_half_extent(scene, film_distance_mm: float) -> tuple[float, float]:
    """Half film width and height over the film distance (tangents of the half fields)."""
    film_w_mm, film_h_mm = scene.camera.film_mm
    return film_w_mm / 2.0 / film_distance_mm, film_h_mm / 2.0 / film_distance_mm
