"""Where a camera stands and what it sees: its world frame and its film."""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np

__all__ = ["CameraFrame", "Film"]

Vec3 = tuple[float, float, float]


class CameraFrame(NamedTuple):
    """World-from-camera frame: origin (m) and unit right, up, forward vectors.

    POV-Ray convention (left-handed, +y up): right = up x forward, so a camera
    looking along +z with up +y has right = +x.  A named tuple, so
    ``origin, right, up, forward = frame`` reads it.
    """

    origin: Vec3
    right: Vec3
    up: Vec3
    forward: Vec3

    @classmethod
    def of(cls, camera) -> "CameraFrame":
        """The frame of a scene's ``[camera]`` (position, look_at, up)."""
        origin = np.asarray(camera.position, dtype=float)
        forward = np.asarray(camera.look_at, dtype=float) - origin
        forward /= np.linalg.norm(forward)
        right = np.cross(np.asarray(camera.up, dtype=float), forward)
        right /= np.linalg.norm(right)
        up = np.cross(forward, right)
        return cls(*(tuple(float(c) for c in v) for v in (origin, right, up, forward)))

    def camera_from_world(self, points_m) -> np.ndarray:
        """World points (..., 3) -> camera space: x right, y up, z along the view, m."""
        p = np.asarray(points_m, dtype=float) - np.asarray(self.origin)
        return np.stack([p @ np.asarray(self.right), p @ np.asarray(self.up), p @ np.asarray(self.forward)],
                        axis=-1)


@dataclass(frozen=True)
class Film:
    """The film: its size in mm and in pixels (pixels are square)."""

    width_px: int
    height_px: int
    width_mm: float
    height_mm: float

    @classmethod
    def of(cls, camera) -> "Film":
        return cls(camera.width_px, camera.height_px, *camera.film_mm)

    @property
    def pixel_pitch_mm(self) -> float:
        return self.width_mm / self.width_px

    @property
    def half_diagonal_mm(self) -> float:
        return 0.5 * float(np.hypot(self.width_mm, self.height_mm))

    @property
    def resolution(self) -> tuple[int, int]:
        return (self.width_px, self.height_px)
