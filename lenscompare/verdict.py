"""Any renderer's image of a scene, judged: the scene's measurements with pass/fail.

This is how a renderer's camera is validated (``lenscompare measure IMAGE.exr
--scene SCENE.toml``, and ``check`` configs with ``image = "..."``): the image
is measured as a native render would be (:mod:`lenscompare.measure`), against
the expectation of the camera model it claims to show, built from the scene
alone by ``camera_for(scene, model)``. Each measurement gives one verdict that
names the quantity that failed:

=============  ================================================================
measurement    passes when
=============  ================================================================
blur_disks     every emissive sphere's blur-disk diameter (second moment) is
               within ``blur_tolerance_percent`` of equation 5 (the lens system:
               of its real-ray spot) where that is at least ``min_blur_px``;
               and (ideal models) every disk's centroid lies within
               ``projection_tolerance_px`` of the sphere centre's projection
distortion    ideal models: the largest |radial distortion| of the dot grid is
               at most ``distortion_tolerance_percent``; the lens system: each
               dot within that of the chief-ray trace through the prescription
vignetting    relative illumination at 10° and 20° within
               ``vignetting_tolerance`` of 1 (pinhole and thin lens give
               radiance: no falloff) or of the real-ray trace (lens system)
similarity    SSIM against a native render of the scene (same model, the
               scene's spp) at least ``min_ssim``
=============  ================================================================
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from . import measure
from .cameras import LensSystemCamera, camera_for
from .errors import InputError
from .experiment import Run
from .image import Image
from .lenses import chief_ray_distortion_percent
from .metrics import find_point_sources, ssim
from .render import render
from .scene import EmissiveMaterial, Scene, Sphere

__all__ = ["Tolerances", "Verdict", "judge_image"]


@dataclass(frozen=True)
class Tolerances:
    """What ``measure`` and the checks accept (keyword names match the options and config keys)."""

    blur_tolerance_percent: float = 2.0
    min_blur_px: float = 4.0
    projection_tolerance_px: float = 0.25
    distortion_tolerance_percent: float = 0.2
    vignetting_tolerance: float = 0.02
    min_ssim: float = 0.97


@dataclass(frozen=True)
class Verdict:
    """One measurement's outcome: its name, whether it held, one line saying why, the numbers."""

    measurement: str
    passed: bool
    message: str
    details: dict = field(default_factory=dict)


def judge_image(scene: Scene, image: Image | np.ndarray, *, model: str | None = None,
                tolerances: Tolerances = Tolerances(), source: str = "image", threads: int | None = None
                ) -> list[Verdict]:
    """Run the scene's ``measure`` list on ``image`` and judge each.

    Parameters
    ----------
    scene : Scene
        The scene the image claims to show.
    image : Image or ndarray
        Linear RGB, (h, w, 3), row 0 at the top, the scene's resolution.
    model : str, optional
        The camera model the image claims (default: the scene's).
    tolerances : Tolerances
    source : str
        The image's name, for messages.

    Raises
    ------
    InputError
        The image's size is not the scene's resolution (naming ``source``).
    """
    pixels = np.asarray(image.pixels if isinstance(image, Image) else image, dtype=np.float32)
    w, h = scene.camera.resolution
    if pixels.ndim != 3 or pixels.shape[:2] != (h, w) or pixels.shape[2] < 3:
        raise InputError(source, f"image is {pixels.shape[1]}x{pixels.shape[0]}, but {scene.source} renders "
                         f"{w}x{h} (camera.resolution)")
    model = model or scene.camera.model
    camera = camera_for(scene, model)
    run = Run(scene, model, "image", Image(pixels[..., :3], {"model": model}, camera=camera))
    judges = {"blur_disks": _blur, "distortion": _distortion, "vignetting": _vignetting, "similarity": _similarity}
    return [judges[name](scene, run, tolerances, threads) for name in scene.measure]


def _emissive_spheres(scene):
    return [o for o in scene.objects if isinstance(o, Sphere)
            and isinstance(scene.materials[o.material], EmissiveMaterial)]


def _blur(scene, run, t: Tolerances, threads) -> Verdict:
    rows = measure.measure_blur_disks(scene, [run])["renders"][run.label]
    judged = [r for r in rows if r and r["expected_px"] >= t.min_blur_px]
    failures = []
    worst = max(judged, key=lambda r: abs(r["error_percent"]), default=None)
    if worst is not None and abs(worst["error_percent"]) > t.blur_tolerance_percent:
        failures.append(f"blur-disk diameter at {worst['depth_m']:.3g} m: {worst['measured_px']:.2f} px against "
                        f"{worst['expected_px']:.2f} px from {worst['expected_from']} ({worst['error_percent']:+.1f} %, "
                        f"limit {t.blur_tolerance_percent:g} %)")
    details = {"rows": rows, "judged": len(judged)}
    camera = run.image.camera
    if not isinstance(camera, LensSystemCamera):
        offset = _projection_offsets_px(scene, run)
        details["projection_offset_px"] = offset
        found = [d for d in offset if d is not None]
        if found and max(found) > t.projection_tolerance_px:
            failures.append(f"projection: a point source's centroid is {max(found):.2f} px from where the scene "
                            f"projects it (limit {t.projection_tolerance_px:g} px)")
        if len(found) < len(offset):
            failures.append(f"projection: {len(offset) - len(found)} of {len(offset)} point sources not found "
                            "where the scene projects them")
    if worst is None and not failures:
        return Verdict("blur_disks", False, f"no blur disk of at least {t.min_blur_px:g} px to measure", details)
    if failures:
        return Verdict("blur_disks", False, "; ".join(failures), details)
    return Verdict("blur_disks", True, f"{len(judged)} blur disks within {t.blur_tolerance_percent:g} % of "
                   f"{worst['expected_from']} (largest {worst['error_percent']:+.2f} %); centroids within "
                   f"{max(details.get('projection_offset_px') or [0.0]):.3f} px of the projection", details)


def _projection_offsets_px(scene, run) -> list[float | None]:
    """Per emissive sphere: distance from its projected centre to the nearest source centroid, px."""
    camera = run.image.camera
    spheres = _emissive_spheres(scene)
    projected = camera.project_px(camera.frame.camera_from_world([s.center for s in spheres]))
    found = [s.centroid_px for s in find_point_sources(run.image.pixels)]
    limit = 0.02 * scene.camera.width_px
    offsets = []
    for p in projected:
        d = min((math.dist(c, p) for c in found), default=math.inf)
        offsets.append(d if d <= limit else None)
    return offsets


def _distortion(scene, run, t: Tolerances, threads) -> Verdict:
    entry = measure.measure_distortion(scene, [run])["renders"][run.label]
    if entry is None:
        return Verdict("distortion", False, "too few dots found off the axis to measure distortion")
    camera = run.image.camera
    measured = np.asarray(entry["distortion_percent"])
    if isinstance(camera, LensSystemCamera):
        expected = np.array([chief_ray_distortion_percent(camera.prescription, f,
                                                          focus_distance_m=camera.focus_distance_m)
                             for f in entry["field_deg"]])
        against = f"the chief-ray trace through {camera.prescription.name}"
    else:
        expected, against = np.zeros_like(measured), "0 (an ideal camera does not distort)"
    error = np.abs(measured - expected)
    i = int(np.nanargmax(error))
    details = {**entry, "expected_percent": expected.tolist()}
    message = (f"radial distortion at {entry['field_deg'][i]:.1f}°: {measured[i]:+.3f} % against {against}: "
               f"off by {error[i]:.3f} % (limit {t.distortion_tolerance_percent:g} %), {entry['dots_matched']} dots")
    return Verdict("distortion", bool(error[i] <= t.distortion_tolerance_percent), message, details)


def _vignetting(scene, run, t: Tolerances, threads) -> Verdict:
    entry = measure.measure_vignetting(scene, [run])["renders"][run.label]
    traced = entry.get("traced")
    failures, parts = [], []
    for key, value in entry["at"].items():
        angle = float(key.split("_")[0])
        expected = float(np.interp(angle, traced["field_deg"], traced["relative_illumination"])) if traced else 1.0
        parts.append(f"{angle:g}°: {value:.3f} against {expected:.3f}")
        if abs(value - expected) > t.vignetting_tolerance:
            failures.append(f"relative illumination at {angle:g}°: {value:.3f} against {expected:.3f} "
                            f"(limit ±{t.vignetting_tolerance:g})")
    if not parts:
        return Verdict("vignetting", False, "the image reaches no 10° field to measure relative illumination at",
                       entry)
    if failures:
        return Verdict("vignetting", False, "; ".join(failures), entry)
    return Verdict("vignetting", True, "relative illumination " + ", ".join(parts), entry)


def _similarity(scene, run, t: Tolerances, threads) -> Verdict:
    ours = render(scene, camera=run.image.camera, threads=threads, progress=False).pixels
    theirs = run.image.pixels
    value = ssim(ours, theirs, data_range=float(ours.max() - ours.min()) or 1.0)
    return Verdict("similarity", bool(value >= t.min_ssim),
                   f"SSIM {value:.4f} against a native {run.model} render at {scene.render.spp} spp "
                   f"(min {t.min_ssim:g})", {"ssim": value})
