"""Thin lens (paper section 2.2; Cook et al. 1984).

==================  =====  ====  ===========================================
Parameter           Type   Unit  Meaning
==================  =====  ====  ===========================================
focal_length_mm     float  mm    focal length f (or ``lens``: its EFL)
f_number            float  -     N; lens diameter f / N
focus_distance      float  m     plane of sharp focus, from the lens centre
film_mm             pair   mm    film width and height
aperture_blades     int    -     0: circular; N >= 3: regular N-gon, same
                                 area as the circle
aperture_rotation   float  deg   the polygon's turn (``_deg`` in the file)
==================  =====  ====  ===========================================

The film sits at d' = f d / (d - f) (eq. 4); ``camera.position`` is the lens
centre. The native camera gets the lens radius and the focus distance in scene
units (m), converted here.
"""

from __future__ import annotations

from dataclasses import dataclass

from .. import _native
from ..optics import aperture_diameter_mm, focus_film_distance_mm
from ..units import m_from_mm
from .base import CameraModel, check_focus_reachable, require, scene_focal_length_mm
from .frame import CameraFrame, Film

__all__ = ["ThinLensCamera", "DISK_MAPPING_CODES"]

DISK_MAPPING_CODES = {"polar": _native.DISK_POLAR, "concentric": _native.DISK_CONCENTRIC}


@dataclass(frozen=True, kw_only=True)
class ThinLensCamera(CameraModel):
    model = "thin"

    @classmethod
    def from_scene(cls, scene, *, model: str = "thin", **extra):
        f_mm = scene_focal_length_mm(scene, model)
        n = require(scene, scene.camera.f_number, "f_number", model)
        check_focus_reachable(scene, f_mm)
        return cls(frame=CameraFrame.of(scene.camera), film=Film.of(scene.camera),
                   focus_distance_m=scene.camera.focus_distance_m, focal_length_mm=f_mm,
                   film_distance_mm=focus_film_distance_mm(scene.camera.focus_distance_mm, f_mm),
                   f_number=n, aperture_diameter_mm=aperture_diameter_mm(f_mm, n),
                   aperture_blades=scene.camera.aperture_blades,
                   aperture_rotation_deg=scene.camera.aperture_rotation_deg, **extra)

    def native(self, *, disk_mapping: str = "concentric") -> "_native.ThinLensCamera":
        half_w, half_h = self.screen_half_extent
        return _native.ThinLensCamera(
            *self.frame, self.film.width_px, self.film.height_px, half_w, half_h,
            lens_radius_m=m_from_mm(self.aperture_diameter_mm / 2.0),
            focus_distance_m=self.focus_distance_m,
            disk_mapping=DISK_MAPPING_CODES[disk_mapping],
            aperture_blades=self.aperture_blades,
            aperture_rotation_deg=self.aperture_rotation_deg,
        )
