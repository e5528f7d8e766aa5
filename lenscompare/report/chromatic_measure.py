"""Lateral colour measured on a spectral render, for the report's chromatic section.

The report's prediction (:func:`lenscompare.plan.effects.lateral_color`) is the
chief-ray film height at F (486.13 nm) minus at C (656.27 nm) at the film
corner. To measure the same quantity, not a channel-weighted one, the scene
is replaced by a small chart of *monochromatic* dots (``wavelength_nm``,
:mod:`lenscompare.spectral`) on the plane of focus, seen through the scene's
lens system (its lens, f-number, focus distance and mode, film):

- F dots at :data:`FIELD_FRACTIONS` of the corner field along the two film
  diagonals on the camera's right, C dots at the same fields on its left
  (point-symmetric, so the lens, being rotationally symmetric, images them at
  the same heights);
- one spectral render of the lens system (both lines in one image, on a film
  :data:`FILM_MARGIN` wider than the scene's so the corner dot lies inside
  it, at :data:`SPP` samples and :data:`SEED`);
- the image's luminance split into its F half and its C half, the C half
  turned 180 degrees about the optical axis onto the F dots, and the two
  stacked as the blue and red channels of one image, which
  :func:`lenscompare.metrics.lateral_color` measures: its red-minus-blue
  radial shift is then C minus F.

Longitudinal colour is measured the same way: the planner's
(:func:`lenscompare.plan.effects.longitudinal_color`) is the diameter of the
F light's blur disk where the C light focuses (paraxial), so one F-line dot
on the axis is rendered through the lens system with the film moved to the C
line's paraxial image, on a small film around the axis, and its
second-moment diameter measured with :func:`lenscompare.metrics.measure_blur_disk`
(a uniform disk reads its diameter; the dot's own image is removed).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from ..cameras import camera_for
from ..cameras.frame import CameraFrame
from ..errors import InputError
from ..lenses import stopped_down
from ..lenses.chromatic import axial_image_z_mm, chief_ray_height_at_mm, lateral_color_mm, longitudinal_color_blur_mm
from ..lenses.glass import C_NM, D_NM, F_NM
from ..metrics import lateral_color, measure_blur_disk
from ..plan.effects import corner_field_deg, ideal_camera
from ..render import render
from ..scene import EmissiveMaterial, RenderSettings, Scene, Sphere

__all__ = ["LateralColorMeasurement", "measure_lateral_color", "measure_longitudinal_color", "FIELD_FRACTIONS", "FILM_MARGIN", "SPP", "SEED"]

FIELD_FRACTIONS = (0.7, 1.0)
"""Dot fields as fractions of the corner field angle: mid-field and the film corner (the prediction's)."""
AZIMUTHS_DEG = (-10.0, -5.0, 0.0, 5.0, 10.0)
"""Dot azimuths about each film diagonal, degrees: five dots per field and diagonal, averaged."""
FILM_MARGIN = 1.3
"""The measuring film's size over the scene's: the corner dot's image lies inside it."""
WIDTH_PX = 320
"""The measuring film's width, pixels (its own pitch; results are given in the scene's pixels)."""
DOT_DIAMETER_PX = 3.0
"""Each dot's geometric image diameter on the measuring film, pixels (centroids of smaller dots alias)."""
SPP = 256
"""Samples per pixel of the dot chart. Wide open the spots are large and their centroids noisy:
with hero wavelengths drawn, landscape.125mm at f/10.4 on dot_grid read -6.8 % of the chief ray at the
corner with 64 spp (seed 15), -2.4 to +2.6 % with 256 spp over seeds 1-3 and 15 (0.7 field: -2.8 to
-0.7 %), about 1.7 s a camera; since session 45 the lens system's rays carry bands of the spectrum
(no wavelength drawn): corner -0.7 to +0.1 %, 0.7 field -2.4 to -0.8 %, about 3.5 s a camera."""
SEED = 15
DISK_FILM_PX = 64
"""The longitudinal-colour render's square film, pixels; it spans DISK_FILM_SPAN disks."""
DISK_FILM_SPAN = 4.0
DISK_SOURCE_FRACTION = 0.15
"""The F dot's own image diameter over the predicted disk's (removed from the measurement)."""
DISK_SPP = 128
"""Samples per pixel of the disk render (landscape.125mm at f/10.4: 2.05 px at 32, 64 and 128 spp, traced 2.05 px)."""


@dataclass(frozen=True)
class LateralColorMeasurement:
    """Lateral colour of one scene's lens: measured on the render against the chief-ray prediction.

    Attributes
    ----------
    field_deg : tuple of float
        Field angles of the dots, degrees (the last is the corner field).
    measured_px : tuple of float
        F minus C image height measured at each field, the scene's pixels
        (mean over the dots at that field; NaN where a dot was not found).
    predicted_px : tuple of float
        The chief-ray F minus C height at each field, the scene's pixels
        (:func:`lenscompare.lenses.chromatic.lateral_color_mm`).
    seconds : float
        The measuring render's time.
    """

    field_deg: tuple[float, ...]
    measured_px: tuple[float, ...]
    predicted_px: tuple[float, ...]
    seconds: float

    @property
    def corner_px(self) -> float | None:
        """Magnitude measured at the film corner (the field the report's prediction uses); None if not found."""
        value = self.measured_px[-1]
        return None if not math.isfinite(value) else abs(value)


def _chart(scene: Scene, fields_deg, *, pitch_mm: float) -> Scene:
    """The measuring scene: the scene's camera on a wider film, F dots to the
    right and C dots to the left at ``fields_deg`` along the film diagonals,
    on the plane of focus, on black; spectral, through the lens system."""
    camera = scene.camera
    origin, right, up, forward = (np.asarray(v) for v in CameraFrame.of(camera))
    width_mm, height_mm = camera.film_mm
    diagonal_rad = math.atan2(height_mm, width_mm)
    distance_m = camera.focus_distance_m
    # Magnification about f / distance: a dot DOT_DIAMETER_PX wide on the film.
    focal_mm = camera_for(scene, "lens").paraxial.effective_focal_length_mm
    radius_m = 0.5 * DOT_DIAMETER_PX * pitch_mm * distance_m / focal_mm
    materials = {"f_line": EmissiveMaterial("f_line", (1.0, 1.0, 1.0), F_NM),
                 "c_line": EmissiveMaterial("c_line", (1.0, 1.0, 1.0), C_NM)}
    dots = []
    for field in fields_deg:
        offset_m = distance_m * math.tan(math.radians(field))
        for side, material in ((1.0, "f_line"), (-1.0, "c_line")):
            for vertical in (1.0, -1.0):
                for azimuth in AZIMUTHS_DEG:
                    angle = diagonal_rad + math.radians(azimuth)
                    toward = side * math.cos(angle) * right + vertical * math.sin(angle) * up
                    centre = origin + distance_m * forward + offset_m * toward
                    dots.append(Sphere(tuple(float(c) for c in centre), radius_m, material))
    width_px = WIDTH_PX
    height_px = 2 * round(0.5 * width_px * height_mm / width_mm)  # even: the axis on a pixel corner
    film = (width_mm * FILM_MARGIN, width_mm * FILM_MARGIN * height_px / width_px)
    return dataclasses.replace(
        scene.with_camera(model="lens", film_mm=film, resolution=(width_px, height_px), velocity=(0.0, 0.0, 0.0)),
        render=RenderSettings(spp=SPP, sampler="sobol", seed=SEED, spectral=True),
        background=(0.0, 0.0, 0.0), materials=materials, objects=tuple(dots), lights=())


def _f_and_turned_c(pixels: np.ndarray) -> np.ndarray:
    """Luminance of the F half (the bluer one) and of the C half turned 180
    degrees onto it, as an RGB image: red C, green their mean, blue F."""
    luminance = pixels @ np.array([0.2126, 0.7152, 0.0722])
    half = luminance.shape[1] // 2
    left, right = np.zeros_like(luminance), np.zeros_like(luminance)
    left[:, :half], right[:, half:] = luminance[:, :half], luminance[:, half:]
    blue_minus_red = pixels[..., 2] - pixels[..., 0]
    f_is_left = blue_minus_red[:, :half].sum() > blue_minus_red[:, half:].sum()
    f_image, c_image = (left, right) if f_is_left else (right, left)
    c_turned = c_image[::-1, ::-1]
    return np.stack([c_turned, 0.5 * (c_turned + f_image), f_image], axis=-1)


def _measurable_lens(scene: Scene):
    """The scene's lens when its colour can be measured: it disperses and the
    scene has a finite plane of focus to put the chart on; else None (and no render)."""
    lens = scene.camera.lens
    if lens is None or not lens.disperses or not math.isfinite(scene.camera.focus_distance_m):
        return None
    return lens


def measure_lateral_color(scene: Scene, *, threads: int | None = None) -> LateralColorMeasurement | None:
    """Render the scene's monochromatic dot chart and measure F minus C lateral colour.

    Parameters
    ----------
    scene : Scene
        A scene as the report renders it (its lens resolved).
    threads : int, optional
        Render threads (the image is the same whatever the count).

    Returns
    -------
    LateralColorMeasurement or None
        None, with no render, when the scene's lens does not disperse or the
        scene has no finite plane of focus to put the dots on.
    """
    lens = _measurable_lens(scene)
    if lens is None:
        return None
    system = camera_for(scene, "lens")
    ideal = ideal_camera(scene)
    corner_deg = corner_field_deg(scene, ideal)
    fields_deg = tuple(corner_deg * f for f in FIELD_FRACTIONS)
    pitch_mm = scene.camera.film_mm[0] * FILM_MARGIN / WIDTH_PX
    chart = _chart(scene, fields_deg, pitch_mm=pitch_mm)
    image = render(chart, threads=threads, progress=False)
    measured = lateral_color(_f_and_turned_c(image.pixels))
    scale = pitch_mm / ideal.pixel_pitch_mm  # measuring pixels -> the scene's pixels
    measured_px, predicted_px = [], []
    for field in fields_deg:
        try:
            predicted_mm = lateral_color_mm(lens, field, film_z_mm=system.film_z_mm,
                                            focus_distance_m=system.focus_distance_m)
        except InputError:  # no chief ray at F or C there
            predicted_mm = math.nan
        predicted_px.append(predicted_mm / ideal.pixel_pitch_mm)
        # The dots at this field: the two whose film radius is nearest the chief ray's (the d height).
        expected_radius_px = _d_radius_mm(system, field) / pitch_mm
        near = np.abs(measured.field_radius_px - expected_radius_px) < 0.5 * DOT_DIAMETER_PX + 2.0
        # lateral_color's red-minus-blue is C minus F here.
        measured_px.append(-float(np.mean(measured.radial_shift_px[near])) * scale if near.sum() == 2 * len(AZIMUTHS_DEG) else math.nan)
    return LateralColorMeasurement(fields_deg, tuple(measured_px), tuple(predicted_px),
                                   float(image.metadata["seconds"]))


def _d_radius_mm(system, field_deg: float) -> float:
    """Film height (mm) of the d chief ray at ``field_deg``: where to look for that field's dots."""
    return abs(chief_ray_height_at_mm(system.prescription, field_deg, wavelength_nm=D_NM,
                                      film_z_mm=system.film_z_mm, focus_distance_m=system.focus_distance_m))


def measure_longitudinal_color(scene: Scene, *, threads: int | None = None) -> tuple[float, float] | None:
    """Render an F-line dot on the axis with the film at the C focus and measure its blur disk.

    Parameters
    ----------
    scene : Scene
        A scene as the report renders it (its lens resolved).
    threads : int, optional
        Render threads (the image is the same whatever the count).

    Returns
    -------
    (float, float) or None
        Measured and predicted disk diameter, the scene's pixels; None, with
        no render, when the lens does not disperse, the scene has no finite
        plane of focus or no f-number, or the prediction is 0.
    """
    lens = _measurable_lens(scene)
    if lens is None:
        return None
    ideal = ideal_camera(scene)
    if ideal.f_number is None:
        return None
    predicted_mm = longitudinal_color_blur_mm(stopped_down(lens, ideal.f_number),
                                              focus_distance_m=scene.camera.focus_distance_m)
    if predicted_mm <= 0.0:
        return None
    side_mm = DISK_FILM_SPAN * predicted_mm
    pitch_mm = side_mm / DISK_FILM_PX
    camera = scene.camera
    origin, _, _, forward = (np.asarray(v) for v in CameraFrame.of(camera))
    distance_m = camera.focus_distance_m
    focal_mm = camera_for(scene, "lens").paraxial.effective_focal_length_mm
    source_mm = DISK_SOURCE_FRACTION * predicted_mm
    dot = Sphere(tuple(float(c) for c in origin + distance_m * forward), 0.5 * source_mm * distance_m / focal_mm,
                 "f_line")
    chart = dataclasses.replace(
        scene.with_camera(model="lens", film_mm=(side_mm, side_mm), resolution=(DISK_FILM_PX, DISK_FILM_PX),
                          velocity=(0.0, 0.0, 0.0)),
        render=RenderSettings(spp=DISK_SPP, sampler="sobol", seed=SEED, spectral=True),
        background=(0.0, 0.0, 0.0), materials={"f_line": EmissiveMaterial("f_line", (1.0, 1.0, 1.0), F_NM)},
        objects=(dot,), lights=())
    system = camera_for(chart, "lens")
    c_focus_mm = axial_image_z_mm(lens, wavelength_nm=C_NM, focus_distance_m=system.focus_distance_m)
    image = render(chart, camera=dataclasses.replace(system, film_z_mm=c_focus_mm),
                   threads=threads, progress=False)
    luminance = image.pixels @ np.array([0.2126, 0.7152, 0.0722])
    disk = measure_blur_disk(luminance, source_diameter_px=source_mm / pitch_mm)
    return disk.second_moment_diameter_px * pitch_mm / ideal.pixel_pitch_mm, predicted_mm / ideal.pixel_pitch_mm
