"""What every camera model shares, as one frozen value built once from a scene.

A camera value holds the derived geometry (focal length, film distance,
aperture, pixel pitch, frame) that the native tracer, the POV-Ray exporter,
the planner and the measurements all read, so none of them derives it again.
Lengths in mm unless the name says ``_m``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from ..errors import InputError
from ..lenses import paraxial_data
from ..limits import MAX_F_NUMBER, MIN_F_NUMBER
from ..units import mm_from_m
from .frame import CameraFrame, Film

__all__ = ["CameraModel", "require", "scene_focal_length_mm", "check_focus_reachable", "check_camera_numbers",
           "lens_f_number"]


@dataclass(frozen=True, kw_only=True)
class CameraModel:
    """Geometry shared by every model.

    Attributes
    ----------
    frame : CameraFrame
        World position (the entrance-pupil centre) and orientation.
    film : Film
        Film size in mm and pixels.
    focus_distance_m : float
        Plane of sharp focus, from ``frame.origin`` along the view axis, m.
    focal_length_mm : float
        Focal length (the lens system's effective focal length).
    film_distance_mm : float
        From the rear principal plane (the thin lens itself; H' of a thick
        lens or a lens system) to the film: it sets the image scale.
    f_number : float or None
        Working aperture; None for the pinhole.
    aperture_diameter_mm : float
        Entrance-pupil diameter f / N; 0 for the pinhole.
    aperture_blades : int
        0: a circular aperture; N >= 3: a regular N-gon diaphragm of the
        circle's area.
    aperture_rotation_deg : float
        The polygon's turn, counter-clockwise seen from behind the lens
        (camera x right, y up); a vertex points up at 0.
    """

    model: ClassVar[str]
    frame: CameraFrame
    film: Film
    focus_distance_m: float
    focal_length_mm: float
    film_distance_mm: float
    f_number: float | None = None
    aperture_diameter_mm: float = 0.0
    aperture_blades: int = 0
    aperture_rotation_deg: float = 0.0

    @property
    def working_f_number(self) -> float | None:
        """Film distance over the exit-pupil diameter, which sets the size of
        the diffraction PSF on the film: N (1 + |m|) for the ideal lenses
        (pupils at the lens, magnification m); None without an aperture."""
        if self.f_number is None:
            return None
        return self.film_distance_mm / self.aperture_diameter_mm

    @property
    def focus_distance_mm(self) -> float:
        return mm_from_m(self.focus_distance_m)

    @property
    def pixel_pitch_mm(self) -> float:
        return self.film.pixel_pitch_mm

    @property
    def image_scale_mm(self) -> float:
        """Film height per unit tangent of the field angle seen from
        ``frame.origin``: the ideal (paraxial) projection. The film distance
        for the ideal models; the lens system overrides it."""
        return self.film_distance_mm

    @property
    def screen_half_extent(self) -> tuple[float, float]:
        """Tangents of the half fields: half film width and height over the film distance."""
        return (self.film.width_mm / 2.0 / self.film_distance_mm, self.film.height_mm / 2.0 / self.film_distance_mm)

    @property
    def corner_field_deg(self) -> float:
        """Field angle of the film corner (ideal projection), degrees."""
        return math.degrees(math.atan(self.film.half_diagonal_mm / self.image_scale_mm))

    def project_px(self, camera_xyz_m) -> np.ndarray:
        """Ideal (pinhole) raster position of camera-space points, (..., 2) px, y down."""
        xyz = np.asarray(camera_xyz_m, dtype=float)
        x, y, z = xyz[..., 0], xyz[..., 1], xyz[..., 2]
        w, h = self.film.resolution
        scale = self.image_scale_mm
        return np.stack([(scale * x / z / self.film.width_mm + 0.5) * w,
                         (0.5 - scale * y / z / self.film.height_mm) * h], axis=-1)

    def to_json(self) -> dict:
        """The derived quantities, for image metadata and reports."""
        info = {"model": self.model, "focal_length_mm": self.focal_length_mm,
                "film_distance_mm": self.film_distance_mm, "image_scale_mm": self.image_scale_mm,
                "focus_distance_m": self.focus_distance_m,
                "pixel_pitch_mm": self.pixel_pitch_mm}
        if self.f_number is not None:
            info.update(f_number=self.f_number, aperture_diameter_mm=self.aperture_diameter_mm,
                        aperture_blades=self.aperture_blades, aperture_rotation_deg=self.aperture_rotation_deg,
                        working_f_number=self.working_f_number)
        return info


def require(scene, value, key: str, model: str):
    """``value``, or an InputError naming the camera key the model needs."""
    if value is None:
        raise InputError(scene.source, f"required for the {model} model", key=f"camera.{key}")
    return value


def scene_focal_length_mm(scene, model: str) -> float:
    """The focal length a pinhole/thin/thick camera uses, mm: the effective
    focal length of ``camera.lens`` when the scene names one (so the idealised
    models share the real lens), else ``camera.focal_length_mm``."""
    lens = scene.camera.lens
    if lens is not None:
        return paraxial_data(lens).effective_focal_length_mm
    return require(scene, scene.camera.focal_length_mm, "focal_length_mm", model)


def check_focus_reachable(scene, focal_length_mm: float) -> None:
    """A thin lens focuses only beyond its focal length (eq. 4)."""
    if not mm_from_m(scene.camera.focus_distance_m) > focal_length_mm:
        raise InputError(scene.source, f"{scene.camera.focus_distance_m:g} m is not beyond the focal length "
                         f"{focal_length_mm:g} mm", key="camera.focus_distance")


def lens_f_number(scene) -> float | None:
    """The f-number the ideal models take for ``scene``: its own, else its
    lens's wide open (paraxial, from the lens's stop), else None.

    Raises
    ------
    InputError
        Naming ``camera.lens``, when the lens's own stop is faster than any
        lens in air: the elements before it magnify it (an entrance pupil
        wider than the front element), and ``camera.f_number`` stops it down.
    """
    lens = scene.camera.lens
    if scene.camera.f_number is not None or lens is None:
        return scene.camera.f_number
    data = paraxial_data(lens)
    if not data.f_number >= MIN_F_NUMBER:
        pupil_mm, front_mm = data.entrance_pupil_diameter_mm, 2.0 * lens.surfaces[0].semi_aperture_mm
        wider = f", wider than its front element ({front_mm:.4g} mm)" if pupil_mm > front_mm else ""
        raise InputError(scene.source, f"lens {lens.name} ({lens.source}): its stop images to an entrance pupil "
                         f"{pupil_mm:.4g} mm across{wider}: f/{data.f_number:.3g}, faster than any lens in air "
                         f"(f/{MIN_F_NUMBER:g}); set camera.f_number to stop it down", key="camera.lens")
    return data.f_number


def check_camera_numbers(camera: CameraModel, scene) -> CameraModel:
    """``camera``, after checking that every number the native tracer and
    POV-Ray will read from it is finite (and positive where it must be).

    The scene's keys are bounded one by one (:mod:`lenscompare.limits`); this
    checks what they combine into, so that nothing non-finite reaches Embree
    whatever the combination.

    Raises
    ------
    InputError
        Naming the scene file, ``camera`` and the quantity that came out
        unusable.
    """
    if camera.f_number is not None and not camera.f_number >= MIN_F_NUMBER:  # values set in code, not by a file
        if scene.camera.f_number is None and scene.camera.lens is not None:
            lens_f_number(scene)  # the lens's own stop: refused naming the lens
        raise InputError(scene.source, f"f/{camera.f_number:g} is faster than any lens in air (f/{MIN_F_NUMBER:g})",
                         key="camera.f_number")
    if camera.f_number is not None and not camera.f_number <= MAX_F_NUMBER:
        raise InputError(scene.source, f"f/{camera.f_number:g} is slower than the slowest stop rendered "
                         f"(f/{MAX_F_NUMBER:g})", key="camera.f_number")
    half_width, half_height = camera.screen_half_extent
    values = {"focal length (mm)": (camera.focal_length_mm, True),
              "film distance (mm)": (camera.film_distance_mm, True),
              "image scale (mm)": (camera.image_scale_mm, True),
              "aperture diameter (mm)": (camera.aperture_diameter_mm, False),
              "tangent of the half field (width)": (half_width, True),
              "tangent of the half field (height)": (half_height, True)}
    for name, extra in getattr(camera, "native_numbers", dict)().items():
        values[name] = (extra, False)
    for name, (value, positive) in values.items():
        if not (math.isfinite(value) and (value > 0 if positive else True)):
            raise InputError(scene.source, f"the {camera.model} camera's {name} comes out as {value:g} from these "
                             f"camera values (expected a finite{' positive' if positive else ''} number)",
                             key="camera")
    return camera
