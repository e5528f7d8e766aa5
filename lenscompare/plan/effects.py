"""Each lens effect's size in the image, predicted from the scene and camera
alone. One function per effect; a new effect (dispersion, motion) adds one
here and one line in :data:`EFFECTS`."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..optics import circle_of_confusion_mm, focus_film_distance_mm
from ..scene import Scene
from .visible_depth import visible_depth_range_m

__all__ = ["Effect", "LensContext", "lens_context", "defocus", "principal_plane_gap", "distortion", "vignetting",
           "EFFECTS"]


@dataclass(frozen=True)
class Effect:
    name: str
    magnitude: float
    unit: str          # "px" or "%"
    detail: str
    needed_by: str     # the cheapest model that simulates it


@dataclass(frozen=True)
class LensContext:
    """What the effects are computed from: the camera's optics in mm."""

    focal_length_mm: float
    f_number: float | None        # None: no aperture given (a pinhole)
    film_distance_mm: float
    pitch_mm: float
    half_diagonal_mm: float
    prescription: object | None   # a lens system, when the scene names one


def lens_context(scene: Scene) -> LensContext:
    from ..cameras.common import focal_length_mm, scene_prescription

    camera = scene.camera
    prescription = scene_prescription(scene, "lens") if camera.lens else None
    f_mm = focal_length_mm(scene, "thin")
    f_number = camera.f_number
    if prescription is not None and f_number is None:
        from ..lenses import paraxial_data

        f_number = paraxial_data(prescription).f_number  # wide open
    film_w, film_h = camera.film_mm
    return LensContext(f_mm, f_number, focus_film_distance_mm(camera.focus_distance_m * 1000.0, f_mm),
                       film_w / camera.width_px, 0.5 * math.hypot(film_w, film_h), prescription)


def defocus(scene: Scene, ctx: LensContext) -> Effect:
    """Largest circle of confusion (eq. 5) over the depths visible in the frame."""
    film_w, film_h = scene.camera.film_mm
    depth = visible_depth_range_m(scene, tan_half_w=film_w / 2 / ctx.film_distance_mm,
                                  tan_half_h=film_h / 2 / ctx.film_distance_mm)
    if depth is None or ctx.f_number is None:
        why = "nothing in the frame" if depth is None else "no aperture (no f-number)"
        return Effect("defocus", 0.0, "px", why, "thin")
    coc = [circle_of_confusion_mm(z * 1000.0, focus_distance_mm=scene.camera.focus_distance_m * 1000.0,
                                  focal_length_mm=ctx.focal_length_mm,
                                  aperture_diameter_mm=ctx.focal_length_mm / ctx.f_number) for z in depth]
    worst = max(coc) / ctx.pitch_mm
    return Effect("defocus", worst, "px",
                  f"visible depths {depth[0]:.3g}-{depth[1]:.3g} m, focus {scene.camera.focus_distance_m:g} m, "
                  f"f/{ctx.f_number:.3g}", "thin")


def principal_plane_gap(scene: Scene, ctx: LensContext) -> Effect:
    """Thick against thin: with camera.position at H and focus measured from H
    (DESIGN.md) the gap moves the film, not the image, so its image shift is 0."""
    return Effect("thick_lens", 0.0, "px", "object-space rays are the thin lens's when position is H", "thick")


def _corner_field_deg(ctx: LensContext) -> float:
    return math.degrees(math.atan(ctx.half_diagonal_mm / ctx.film_distance_mm))


def distortion(scene: Scene, ctx: LensContext) -> Effect:
    """Chief-ray distortion at the film corner, as a shift in pixels."""
    if ctx.prescription is None:
        return Effect("distortion", 0.0, "px", "ideal lens (no prescription)", "lens")
    from ..lenses import chief_ray_distortion_percent, image_circle_radius_mm

    focus = scene.camera.focus_distance_m
    circle_mm = image_circle_radius_mm(ctx.prescription, focus_distance_m=focus)
    if circle_mm < ctx.half_diagonal_mm:
        shift = (ctx.half_diagonal_mm - circle_mm) / ctx.pitch_mm
        return Effect("distortion", shift, "px", f"film corners lie outside the {circle_mm:.3g} mm image circle",
                      "lens")
    angle = _corner_field_deg(ctx)
    try:
        percent = chief_ray_distortion_percent(ctx.prescription, angle, focus_distance_m=focus)
    except Exception:  # no chief ray at that angle: treat as far off the ideal
        return Effect("distortion", math.inf, "px", f"no chief ray at {angle:.3g} deg", "lens")
    shift = abs(percent) / 100.0 * ctx.half_diagonal_mm / ctx.pitch_mm
    return Effect("distortion", shift, "px", f"{percent:+.3g} % at the corner field {angle:.3g} deg", "lens")


def vignetting(scene: Scene, ctx: LensContext) -> Effect:
    """Relative-illumination drop at the film corner (natural falloff and vignetting), %."""
    if ctx.prescription is None:
        return Effect("vignetting", 0.0, "%", "ideal lens (no prescription)", "lens")
    from ..lenses import image_circle_radius_mm, relative_illumination

    if image_circle_radius_mm(ctx.prescription, focus_distance_m=scene.camera.focus_distance_m) < ctx.half_diagonal_mm:
        return Effect("vignetting", 100.0, "%", "film corners outside the image circle are black", "lens")
    angle = _corner_field_deg(ctx)
    ri = relative_illumination(ctx.prescription, angle, f_number=ctx.f_number, samples_across=120)
    return Effect("vignetting", 100.0 * (1.0 - ri), "%", f"relative illumination {ri:.3f} at {angle:.3g} deg",
                  "lens")


EFFECTS = (defocus, principal_plane_gap, distortion, vignetting)
