"""Each lens effect's size in the image, predicted from the scene and camera
alone. One function per effect; a new effect (dispersion, motion) adds one
here and one line in :data:`EFFECTS`."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..cameras import CameraModel, camera_for
from ..cameras.base import lens_f_number
from ..errors import InputError
from ..lenses import (
    chief_ray_distortion_percent,
    field_at_film_height_deg,
    image_circle_radius_mm,
    lateral_color_mm,
    longitudinal_color_blur_mm,
    point_source_spot_mm,
    pupil_relative_illumination,
    stopped_down,
    spot_diameter_mm,
)
from ..motion_path import longest_motion_path
from ..optics import circle_of_confusion_mm
from ..optics.diffraction import REFERENCE_WAVELENGTH_NM, airy_diameter_mm
from ..scene import Scene
from ..units import mm_from_m
from .spot_window import settled_window_px
from .visible_depth import visible_depth_range_m

__all__ = ["Effect", "ideal_camera", "defocus", "principal_plane_gap", "aberrations", "aberration_spot_px",
           "corner_field_deg", "distortion", "vignetting", "lateral_color", "longitudinal_color", "diffraction",
           "motion_blur", "EFFECTS", "COLOR_EFFECTS"]

# Effects only a spectral render shows (wavelength sampled, the glass
# dispersing): an RGB render of any model leaves them out.
COLOR_EFFECTS = ("lateral_color", "longitudinal_color")


@dataclass(frozen=True)
class Effect:
    name: str
    magnitude: float
    unit: str          # "px" or "%"
    detail: str
    needed_by: str     # the cheapest part that simulates it: a model, or "composite" (cameras/composite.py)


def ideal_camera(scene: Scene) -> CameraModel:
    """The camera the effects are sized against: the thin lens at the scene's
    f-number (its lens's own, wide open, when the scene gives none), or the
    pinhole when there is no aperture at all."""
    f_number = lens_f_number(scene)
    if f_number is None:
        return camera_for(scene, "pinhole")
    return camera_for(scene.with_camera(f_number=f_number), "thin")


def defocus(scene: Scene, camera: CameraModel) -> Effect:
    """Largest circle of confusion (eq. 5) over the depths visible in the frame."""
    tan_half_w, tan_half_h = camera.screen_half_extent
    depth = visible_depth_range_m(scene, tan_half_w=tan_half_w, tan_half_h=tan_half_h)
    if depth is None or camera.f_number is None:
        why = "nothing in the frame" if depth is None else "no aperture (no f-number)"
        return Effect("defocus", 0.0, "px", why, "thin")
    coc = [circle_of_confusion_mm(mm_from_m(z), focus_distance_mm=camera.focus_distance_mm,
                                  focal_length_mm=camera.focal_length_mm,
                                  aperture_diameter_mm=camera.aperture_diameter_mm) for z in depth]
    worst = max(coc) / camera.pixel_pitch_mm
    return Effect("defocus", worst, "px",
                  f"visible depths {depth[0]:.3g}-{depth[1]:.3g} m, focus {scene.camera.focus_distance_m:g} m, "
                  f"f/{camera.f_number:.3g}", "thin")


def principal_plane_gap(scene: Scene, camera: CameraModel) -> Effect:
    """Thick against thin: with camera.position at H and focus measured from H
    (DESIGN.md) the gap moves the film, not the image, so its image shift is 0."""
    return Effect("thick_lens", 0.0, "px", "object-space rays are the thin lens's when position is H", "thick")


def corner_field_deg(scene: Scene, camera: CameraModel) -> float:
    """Field angle (deg) of the light that reaches the film corner: the real
    chief ray's, which a distorting lens takes from another field than the
    paraxial corner field (fisheye on 18 x 12 mm: 61.5 deg, not 47); the
    paraxial one when no chief ray reaches the corner."""
    paraxial = camera.corner_field_deg
    real = field_at_film_height_deg(scene.camera.lens, camera.film.half_diagonal_mm,
                                    focus_distance_m=scene.camera.focus_distance_m, start_deg=paraxial)
    return paraxial if real is None else real


def aberration_spot_px(system, field_deg: float) -> float | None:
    """Second-moment diameter (px) of the lens system's spot of a point on the
    plane of focus at ``field_deg`` from the axis, on the camera's own film
    (its focus mode's position); None when no ray of it gets through.

    Real rays through the prescription at the working aperture
    (:func:`lenscompare.lenses.point_source_spot_mm`, a 160 x 160 grid fitted
    to the beam), measured in the window of :mod:`.spot_window`.  The second
    moment is the one the blur-disk metric measures on images, and for a
    uniform disk it is the disk's diameter: aberrations and defocus (eq. 5)
    are sized on one scale.
    """
    distance_mm = system.focus_distance_mm
    on_film, weight = point_source_spot_mm(system.prescription, height_mm=distance_mm * math.tan(math.radians(field_deg)),
                                           distance_mm=distance_mm, film_z_mm=system.film_z_mm)
    if len(weight) == 0:
        return None
    pitch = system.pixel_pitch_mm
    _, diameter = settled_window_px(
        lambda window_px: spot_diameter_mm(on_film, weight, window_radius_mm=window_px * pitch) / pitch)
    return diameter


def aberrations(scene: Scene, camera: CameraModel) -> Effect:
    """RMS spot diameter (second moment, px) of the lens system at the plane of
    focus, on axis and at the film corner: the blur a perfect lens would not
    have there. Only the full lens system simulates it."""
    lens = scene.camera.lens
    if lens is None:
        return Effect("aberrations", 0.0, "px", "ideal lens (no prescription)", "lens")
    system = camera_for(scene, "lens")  # the scene's f-number and focus mode (an InputError names the key)
    where = f"{system.focus_mode} focus at f/{system.f_number:.3g}"
    axis = aberration_spot_px(system, 0.0)
    if axis is None:  # refused earlier by the trace (no axial ray); kept 0-safe
        return Effect("aberrations", 0.0, "px", f"no ray reaches the film centre ({where})", "lens")
    # The field imaged at the corner; none when no chief ray reaches it (a
    # direct test: image_circle_radius_mm scans for minutes on a bare singlet).
    angle = field_at_film_height_deg(lens, system.film.half_diagonal_mm, focus_distance_m=system.focus_distance_m,
                                     start_deg=system.corner_field_deg)
    corner = None if angle is None else aberration_spot_px(system, angle)
    if corner is None:
        return Effect("aberrations", axis, "px", f"spot {axis:.3g} px on axis; no light reaches the film corner "
                      f"{system.film.half_diagonal_mm:.3g} mm off the axis: outside the image circle ({where})", "lens")
    return Effect("aberrations", max(axis, corner), "px",
                  f"spot {axis:.3g} px on axis, {corner:.3g} px at the corner field {angle:.3g} deg ({where})", "lens")


def distortion(scene: Scene, camera: CameraModel) -> Effect:
    """Chief-ray distortion at the film corner, as a shift in pixels."""
    lens = scene.camera.lens
    if lens is None:
        return Effect("distortion", 0.0, "px", "ideal lens (no prescription)", "composite")
    focus = scene.camera.focus_distance_m
    circle_mm = image_circle_radius_mm(lens, focus_distance_m=focus)
    if circle_mm < camera.film.half_diagonal_mm:
        shift = (camera.film.half_diagonal_mm - circle_mm) / camera.pixel_pitch_mm
        return Effect("distortion", shift, "px", f"film corners lie outside the {circle_mm:.3g} mm image circle",
                      "composite")
    angle = camera.corner_field_deg
    try:
        percent = chief_ray_distortion_percent(lens, angle, focus_distance_m=focus)
    except Exception:  # no chief ray at that angle: treat as far off the ideal
        return Effect("distortion", math.inf, "px", f"no chief ray at {angle:.3g} deg", "composite")
    shift = abs(percent) / 100.0 * camera.film.half_diagonal_mm / camera.pixel_pitch_mm
    return Effect("distortion", shift, "px", f"{percent:+.3g} % at the corner field {angle:.3g} deg", "composite")


def vignetting(scene: Scene, camera: CameraModel) -> Effect:
    """Relative-illumination drop at the film corner (natural falloff and vignetting), %."""
    lens = scene.camera.lens
    if lens is None:
        return Effect("vignetting", 0.0, "%", "ideal lens (no prescription)", "composite")
    if image_circle_radius_mm(lens, focus_distance_m=scene.camera.focus_distance_m) < camera.film.half_diagonal_mm:
        return Effect("vignetting", 100.0, "%", "film corners outside the image circle are black", "composite")
    angle = corner_field_deg(scene, camera)
    ri = pupil_relative_illumination(stopped_down(lens, camera.f_number), angle)
    # A corner brighter than the centre (a fisheye stopped down) is as far
    # from the ideal image as a darker one: the size is the departure.
    return Effect("vignetting", abs(100.0 * (1.0 - ri)), "%",
                  f"relative illumination {ri:.3f} at {angle:.3g} deg (the field imaged at the film corner)",
                  "composite")


def _no_dispersion(scene: Scene) -> str:
    """Why a scene's lens shows no colour ("" when it disperses)."""
    lens = scene.camera.lens
    if lens is None:
        return "ideal lens (no prescription)"
    if not lens.disperses:
        return f"{lens.name} does not disperse (no Abbe number or glass in its 5th column)"
    return ""


def lateral_color(scene: Scene, camera: CameraModel) -> Effect:
    """Chief-ray film height at F (486.13 nm) minus at C (656.27 nm) at the
    film corner, px: the field imaged at the corner (in d light), the object
    on the plane of focus, the film where the lens system puts it. The thin
    and thick lens derived from a prescription have none (they keep only its
    focal shift); the composite's distortion map per wavelength simulates it
    in a spectral render, as the lens system does by tracing."""
    why = _no_dispersion(scene)
    if why:
        return Effect("lateral_color", 0.0, "px", why, "composite")
    lens = scene.camera.lens
    system = camera_for(scene, "lens")
    angle = corner_field_deg(scene, camera)
    try:
        shift_mm = lateral_color_mm(lens, angle, film_z_mm=system.film_z_mm, focus_distance_m=system.focus_distance_m)
    except InputError:  # no chief ray there at F or C: outside the image circle
        return Effect("lateral_color", 0.0, "px", f"no chief ray at the corner field {angle:.3g} deg", "composite")
    return Effect("lateral_color", abs(shift_mm) / camera.pixel_pitch_mm, "px",
                  f"F minus C chief-ray height {1000 * shift_mm:+.3g} um at the corner field {angle:.3g} deg "
                  f"({lens.name}, {system.focus_mode} focus)", "composite")


def longitudinal_color(scene: Scene, camera: CameraModel) -> Effect:
    """Blur-disk diameter of the F light where the C light focuses, px: the
    F-C focus difference of the plane of focus seen through the scene's
    f-number (paraxial, :func:`lenscompare.lenses.chromatic.longitudinal_color_blur_mm`).
    The thin lens derived from the prescription simulates it (its focal
    length per wavelength)."""
    why = _no_dispersion(scene)
    if why or camera.f_number is None:
        return Effect("longitudinal_color", 0.0, "px", why or "no aperture (no f-number)", "thin")
    lens = scene.camera.lens
    blur_mm = longitudinal_color_blur_mm(stopped_down(lens, camera.f_number),
                                         focus_distance_m=scene.camera.focus_distance_m)
    return Effect("longitudinal_color", blur_mm / camera.pixel_pitch_mm, "px",
                  f"F disk {1000 * blur_mm:.3g} um at the C focus, f/{camera.f_number:.3g}, "
                  f"focus {scene.camera.focus_distance_m:g} m ({lens.name})", "thin")


def diffraction(scene: Scene, camera: CameraModel) -> Effect:
    """Airy-disk diameter 2.44 λ N_w at 550 nm, in pixels (DESIGN.md). Any
    model can carry it: the PSF is applied to the image after the render
    (lenscompare.diffraction), so it asks for no dearer model."""
    n_w = camera.working_f_number
    if n_w is None:
        return Effect("diffraction", 0.0, "px", "no aperture (no f-number)", "pinhole")
    diameter = airy_diameter_mm(REFERENCE_WAVELENGTH_NM, n_w) / camera.pixel_pitch_mm
    return Effect("diffraction", diameter, "px",
                  f"Airy disk {1000 * airy_diameter_mm(REFERENCE_WAVELENGTH_NM, n_w):.3g} um at 550 nm, "
                  f"working f/{n_w:.3g}, pixel {1000 * camera.pixel_pitch_mm:.3g} um", "pinhole")


def motion_blur(scene: Scene, camera: CameraModel) -> Effect:
    """Longest projected path, over the shutter, of any visible object relative
    to the camera (so the camera's own motion too), px. Every model samples
    time, so the cheapest carries it."""
    open_s, close_s = scene.render.shutter_s
    path = longest_motion_path(scene, camera)
    if path is None:
        why = ("the shutter is an instant" if not close_s > open_s else
               "nothing visible moves relative to the camera")
        return Effect("motion_blur", 0.0, "px", why, "pinhole")
    obj = scene.objects[path.object_index]
    moved_by = "its own and the camera's motion" if any(scene.camera.velocity) and any(obj.velocity) else (
        "the camera's motion" if any(scene.camera.velocity) else "its own motion")
    return Effect("motion_blur", path.length_px, "px",
                  f"objects[{path.object_index}] ({type(obj).__name__.lower()}) travels {path.length_px:.3g} px "
                  f"by {moved_by} over the {1000 * (close_s - open_s):.3g} ms shutter", "pinhole")


EFFECTS = (defocus, principal_plane_gap, aberrations, distortion, vignetting, lateral_color, longitudinal_color,
           diffraction, motion_blur)
