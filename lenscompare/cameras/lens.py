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
aperture_blades     int    -     0: round stop; N >= 3: the stop a regular
                                 N-gon of its circle's area
aperture_rotation   float  deg   the polygon's turn (``_deg`` in the file)
focus_mode          str    -     "paraxial": film at the paraxial image of
                                 the focus plane (default); "best": at the
                                 smallest on-axis RMS spot of a point on it
                                 at the working aperture (contrast autofocus)
==================  =====  ====  ===========================================

``camera.position`` is the centre of the entrance pupil, so all models share
one perspective centre. The native camera traces in the lens frame (mm, z = 0
at the first vertex, +z toward the film) and converts to metres once.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import _native
from ..lenses import (
    ParaxialData,
    Prescription,
    aperture_stop_index,
    best_focus_film_z_mm,
    film_distance_mm,
    paraxial_data,
    paraxial_image_scale_mm,
    stopped_down,
)
from .base import CameraModel, require
from .frame import CameraFrame, Film

__all__ = ["LensSystemCamera", "lens_elements"]

def lens_elements(prescription: Prescription) -> dict[str, np.ndarray]:
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


@dataclass(frozen=True, kw_only=True)
class LensSystemCamera(CameraModel):
    """A real lens, stopped down to the scene's f-number and focused by moving the film.

    Attributes (beyond :class:`CameraModel`)
    ----------------------------------------
    prescription : Prescription
        The lens as rendered (its stop closed to ``f_number``).
    paraxial : ParaxialData
        First-order data of that prescription.
    film_z_mm : float
        Film position, mm from the first vertex toward the film.
    paraxial_scale_mm : float
        Film height per unit tangent of the field angle (paraxial chief ray
        through the entrance pupil): the ideal projection distortion is
        measured against. Not the film distance from H' unless focused at
        infinity (0.16 % apart for the Double Gauss at 2 m).
    focus_mode : str
        ``"paraxial"`` or ``"best"`` (see the table above).
    focus_shift_mm : float
        Film position minus the paraxial image of the focus plane, mm (0 in
        paraxial mode; negative: the film moved toward the lens).
    """

    model = "lens"
    prescription: Prescription
    paraxial: ParaxialData
    film_z_mm: float
    paraxial_scale_mm: float
    focus_mode: str = "paraxial"
    focus_shift_mm: float = 0.0

    @classmethod
    def from_scene(cls, scene) -> "LensSystemCamera":
        camera = scene.camera
        prescription = require(scene, camera.lens, "lens", "lens")
        if camera.f_number is not None:
            prescription = stopped_down(prescription, camera.f_number, source=scene.source, key="camera.f_number")
        data = paraxial_data(prescription)
        paraxial_z_mm = data.total_track_mm + film_distance_mm(prescription, camera.focus_distance_m,
                                                               source=scene.source, key="camera.focus_distance")
        film_z_mm = paraxial_z_mm
        if camera.focus_mode == "best":  # the prescription is already at the working aperture
            film_z_mm = best_focus_film_z_mm(prescription, focus_distance_m=camera.focus_distance_m)
        return cls(frame=CameraFrame.of(camera), film=Film.of(camera), focus_distance_m=camera.focus_distance_m,
                   focal_length_mm=data.effective_focal_length_mm,
                   film_distance_mm=film_z_mm - data.rear_principal_plane_mm,
                   f_number=data.f_number, aperture_diameter_mm=data.entrance_pupil_diameter_mm,
                   prescription=prescription, paraxial=data, film_z_mm=film_z_mm,
                   paraxial_scale_mm=paraxial_image_scale_mm(prescription, film_z_mm),
                   focus_mode=camera.focus_mode, focus_shift_mm=film_z_mm - paraxial_z_mm,
                   aperture_blades=camera.aperture_blades, aperture_rotation_deg=camera.aperture_rotation_deg)

    @property
    def image_scale_mm(self) -> float:
        return self.paraxial_scale_mm

    def native_numbers(self) -> dict[str, float]:
        """Numbers beyond :class:`CameraModel`'s that the native camera reads (checked finite)."""
        return {"film position (mm)": self.film_z_mm,
                "entrance pupil position (mm)": self.paraxial.entrance_pupil_position_mm}

    @property
    def working_f_number(self) -> float:
        """Film distance from the paraxial exit pupil over its diameter."""
        return (self.film_z_mm - self.paraxial.exit_pupil_position_mm) / self.paraxial.exit_pupil_diameter_mm

    @property
    def film_distance_from_last_vertex_mm(self) -> float:
        return self.film_z_mm - self.paraxial.total_track_mm

    def native(self, *, disk_mapping: str = "concentric") -> "_native.LensSystemCamera":
        """The native camera; ``disk_mapping`` is unused (the exit-pupil sampler
        maps lens samples itself)."""
        return _native.LensSystemCamera(
            *self.frame, self.film.width_px, self.film.height_px, self.film.width_mm, self.film.height_mm,
            **lens_elements(self.prescription),
            film_z_mm=self.film_z_mm,
            entrance_pupil_z_mm=self.paraxial.entrance_pupil_position_mm,
            aperture_blades=self.aperture_blades,
            aperture_rotation_deg=self.aperture_rotation_deg,
        )

    def to_json(self) -> dict:
        return {**super().to_json(), "lens": self.prescription.name, "lens_sha256": self.prescription.sha256,
                "film_distance_from_last_vertex_mm": self.film_distance_from_last_vertex_mm,
                "entrance_pupil_position_mm": self.paraxial.entrance_pupil_position_mm,
                "focus_mode": self.focus_mode, "focus_shift_from_paraxial_mm": self.focus_shift_mm}
