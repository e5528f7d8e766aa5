"""Pinhole camera: the thin lens with its aperture closed.

==================  =====  ====  ===========================================
Parameter           Type   Unit  Meaning
==================  =====  ====  ===========================================
focal_length_mm     float  mm    sets the film distance (or ``lens``: its EFL)
focus_distance      float  m     sets the film distance d' = f d / (d - f)
film_mm             pair   mm    film width and height
==================  =====  ====  ===========================================

The film distance is the thin lens's at the same focus, so pinhole and thin-lens
frames match and focusing changes the field of view (DESIGN.md).
"""

from __future__ import annotations

from dataclasses import dataclass

from .. import _native
from ..optics import focus_film_distance_mm
from .base import CameraModel, check_focus_reachable, scene_focal_length_mm
from .frame import CameraFrame, Film

__all__ = ["PinholeCamera"]


@dataclass(frozen=True, kw_only=True)
class PinholeCamera(CameraModel):
    model = "pinhole"

    @classmethod
    def from_scene(cls, scene) -> "PinholeCamera":
        f_mm = scene_focal_length_mm(scene, "pinhole")
        check_focus_reachable(scene, f_mm)
        return cls(frame=CameraFrame.of(scene.camera), film=Film.of(scene.camera),
                   focus_distance_m=scene.camera.focus_distance_m, focal_length_mm=f_mm,
                   film_distance_mm=focus_film_distance_mm(scene.camera.focus_distance_mm, f_mm))

    def native(self, *, disk_mapping: str = "concentric") -> "_native.PinholeCamera":
        """The native camera (``disk_mapping`` is unused: a pinhole has no lens)."""
        half_w, half_h = self.screen_half_extent
        return _native.PinholeCamera(*self.frame, self.film.width_px, self.film.height_px, half_w, half_h)
