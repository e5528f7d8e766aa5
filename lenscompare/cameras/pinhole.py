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

from .. import _native
from ..optics import focus_film_distance_mm
from .common import camera_frame, check_focus_reachable, focal_length_mm, screen_half_extent

__all__ = ["build"]


def build(scene):
    f_mm = focal_length_mm(scene, "pinhole")
    check_focus_reachable(scene, f_mm)
    film_distance_mm = focus_film_distance_mm(scene.camera.focus_distance_m * 1000.0, f_mm)
    half_w, half_h = screen_half_extent(scene, film_distance_mm)
    origin, right, up, forward = camera_frame(scene.camera)
    camera = _native.PinholeCamera(origin, right, up, forward, scene.camera.width_px, scene.camera.height_px,
                                   half_w, half_h)
    return camera, {"focal_length_mm": f_mm, "film_distance_mm": film_distance_mm}
