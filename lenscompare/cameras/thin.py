"""Thin lens (paper section 2.2; Cook et al. 1984).

==================  =====  ====  ===========================================
Parameter           Type   Unit  Meaning
==================  =====  ====  ===========================================
focal_length_mm     float  mm    focal length f (or ``lens``: its EFL)
f_number            float  -     N; lens diameter f / N
focus_distance      float  m     plane of sharp focus, from the lens centre
film_mm             pair   mm    film width and height
==================  =====  ====  ===========================================

The film sits at d' = f d / (d - f) (eq. 4); ``camera.position`` is the lens
centre. Millimetres become metres here, once: the native camera gets the lens
radius and the focus distance in scene units.
"""

from __future__ import annotations

from .. import _native
from ..optics import aperture_diameter_mm, focus_film_distance_mm
from .common import camera_frame, check_focus_reachable, focal_length_mm, require, screen_half_extent

__all__ = ["build", "DISK_MAPPING_CODES"]

DISK_MAPPING_CODES = {"polar": _native.DISK_POLAR, "concentric": _native.DISK_CONCENTRIC}


def build(scene, *, model: str = "thin"):
    camera = scene.camera
    f_mm = focal_length_mm(scene, model)
    n = require(scene, camera.f_number, "f_number", model)
    check_focus_reachable(scene, f_mm)
    film_distance_mm = focus_film_distance_mm(camera.focus_distance_m * 1000.0, f_mm)
    half_w, half_h = screen_half_extent(scene, film_distance_mm)
    aperture_mm = aperture_diameter_mm(f_mm, n)
    origin, right, up, forward = camera_frame(camera)
    native = _native.ThinLensCamera(
        origin, right, up, forward, camera.width_px, camera.height_px, half_w, half_h,
        lens_radius_m=aperture_mm / 2.0 / 1000.0,
        focus_distance_m=camera.focus_distance_m,
        disk_mapping=DISK_MAPPING_CODES[scene.render.disk_mapping],
    )
    return native, {"focal_length_mm": f_mm, "film_distance_mm": film_distance_mm,
                    "aperture_diameter_mm": aperture_mm, "f_number": n}
