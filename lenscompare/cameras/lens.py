"""Full lens system (Kolb et al. 1995; paper section 2.4).

==================  =====  ====  ===========================================
Parameter           Type   Unit  Meaning
==================  =====  ====  ===========================================
lens                str    -     shipped name (``dgauss.50mm``) or .dat path
f_number            float  -     optional: stops the lens down (never opens
                                 it beyond its own stop: refused)
focus_distance      float  m     plane of sharp focus, from the entrance
                                 pupil; the film moves (unit focusing)
film_mm             pair   mm    film width and height
==================  =====  ====  ===========================================

``camera.position`` is the centre of the entrance pupil, so all models share
one perspective centre. The native camera traces in the lens frame (mm, z = 0
at the first vertex, +z toward the film) and converts to metres once.
"""

from __future__ import annotations

import numpy as np

from .. import _native
from ..lenses import aperture_stop_index, film_distance_mm, paraxial_data, stopped_down
from .common import camera_frame, scene_prescription

__all__ = ["build", "lens_elements"]


def lens_elements(prescription) -> dict[str, np.ndarray]:
    """Per-surface arrays in the lens frame, as the native camera takes them."""
    surfaces = prescription.surfaces
    return {
        "curvature_per_mm": np.array([s.curvature_per_mm for s in surfaces], dtype=float),
        "vertex_z_mm": np.array(prescription.vertex_z_mm, dtype=float),
        "semi_aperture_mm": np.array([s.semi_aperture_mm for s in surfaces], dtype=float),
        "n_scene_side": np.array([prescription.n_before(i) for i in range(len(surfaces))], dtype=float),
        "n_film_side": np.array([s.n_after for s in surfaces], dtype=float),
        "is_stop": np.array([s.is_stop for s in surfaces], dtype=bool),
        "stop_index": aperture_stop_index(prescription),
    }


def build(scene):
    camera = scene.camera
    prescription = scene_prescription(scene, "lens")
    if camera.f_number is not None:
        prescription = stopped_down(prescription, camera.f_number, source=scene.source, key="camera.f_number")
    data = paraxial_data(prescription)
    film_distance = film_distance_mm(prescription, camera.focus_distance_m, source=scene.source,
                                     key="camera.focus_distance")
    film_z_mm = data.total_track_mm + film_distance
    origin, right, up, forward = camera_frame(camera)
    native = _native.LensSystemCamera(
        origin, right, up, forward, camera.width_px, camera.height_px, camera.film_mm[0], camera.film_mm[1],
        **lens_elements(prescription),
        film_z_mm=film_z_mm,
        entrance_pupil_z_mm=data.entrance_pupil_position_mm,
    )
    return native, {
        "lens": prescription.name,
        "lens_sha256": prescription.sha256,
        "focal_length_mm": data.effective_focal_length_mm,
        "f_number": data.f_number,
        "film_distance_mm": film_distance,  # from the last vertex
        "film_distance_from_rear_principal_plane_mm": film_z_mm - data.rear_principal_plane_mm,
        "entrance_pupil_position_mm": data.entrance_pupil_position_mm,
    }
