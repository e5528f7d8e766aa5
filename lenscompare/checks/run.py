"""Running checks: each returns whether it held, what was measured, and why."""

from __future__ import annotations

import time
from dataclasses import dataclass

from ..errors import LensCompareError
from ..experiment import Run
from ..cameras import camera_for
from ..image import Image, read_exr
from ..lenses import load_prescription
from ..lenses.info import lens_info
from ..measure import measure_blur_disks
from ..mitsuba import render_mitsuba
from ..metrics import ciede2000, luminance, relative_rmse, ssim
from ..povray import render_povray
from ..render import render
from ..scene import load_scene
from ..verdict import Tolerances, judge_image
from .config import Check, lens_argument

__all__ = ["CheckResult", "run_check"]


@dataclass(frozen=True)
class CheckResult:
    check: Check
    passed: bool
    message: str
    measured: dict
    seconds: float


def run_check(check: Check, *, threads: int | None = None) -> CheckResult:
    start = time.perf_counter()
    try:
        passed, message, measured = _RUNNERS[check.type](check, threads)
    except LensCompareError as error:  # a broken input inside a check is that check's failure
        passed, message, measured = False, str(error), {}
    return CheckResult(check, passed, message, measured, time.perf_counter() - start)


def _blur_equation5(check: Check, threads):
    o = check.options
    scene = load_scene(check.path("scene"))
    if o["image"] is not None:  # a renderer's own image of the scene, measured as ours would be
        image = _outside_image(check, scene, o["model"])
    else:
        image = render(scene, model=o["model"], spp=int(o["spp"]), threads=threads, progress=False)
    # The report's measurement, on one render.
    rows = measure_blur_disks(scene, [Run(scene, o["model"], "native", image)])["renders"][o["model"]]
    errors = [r["error_percent"] for r in rows if r and r["expected_px"] >= o["min_expected_px"]]
    if not errors:
        return False, "no blur disk large enough to measure", {}
    worst = max(errors, key=abs)
    ok = abs(worst) <= o["tolerance_percent"]
    return ok, f"largest blur-disk error {worst:+.2f} % (limit {o['tolerance_percent']:g} %)", {
        "errors_percent": errors}


def _outside_image(check: Check, scene, model):
    pixels = read_exr(check.path("image")).pixels
    w, h = scene.camera.resolution
    if pixels.shape[:2] != (h, w):
        raise InputError(str(check.path("image")), f"image is {pixels.shape[1]}x{pixels.shape[0]}, the scene "
                         f"renders {w}x{h}")
    return Image(pixels, {"model": model}, camera=camera_for(scene, model))


def _measure(check: Check, threads):
    o = check.options
    scene = load_scene(check.path("scene"))
    tolerances = Tolerances(**{k: float(o[k]) for k in Tolerances.__dataclass_fields__})
    verdicts = judge_image(scene, read_exr(check.path("image")), model=o["model"], tolerances=tolerances,
                           source=str(check.path("image")), threads=threads)
    failed = [v for v in verdicts if not v.passed]
    message = "; ".join(f"{v.measurement}: {v.message}" for v in (failed or verdicts))
    return not failed, message, {v.measurement: v.passed for v in verdicts}


def _povray_ssim(check: Check, threads):
    o = check.options
    scene = load_scene(check.path("scene"))
    native = render(scene, model=o["model"], spp=int(o["spp"]), threads=threads, progress=False).pixels
    reference = render_povray(scene, model=o["model"], spp=int(o["povray_spp"]), threads=threads).pixels
    data_range = float(reference.max() - reference.min()) or 1.0
    value = ssim(reference, native, data_range=data_range)
    rel = relative_rmse(reference, native)
    return value >= o["min_ssim"], f"SSIM {value:.4f} (min {o['min_ssim']:g}), relative RMSE {rel:.4f}", {
        "ssim": value, "relative_rmse": rel}


def _mitsuba_agreement(check: Check, threads):
    """Mitsuba's render against the native one (SSIM) and, where the scene has
    emissive spheres blurred beyond ``min_expected_px``, Mitsuba's blur disks
    against equation 5."""
    o = check.options
    scene = load_scene(check.path("scene"))
    native = render(scene, model=o["model"], spp=int(o["spp"]), threads=threads, progress=False).pixels
    image = render_mitsuba(scene, model=o["model"], spp=int(o["mitsuba_spp"]))
    value = ssim(image.pixels, native, data_range=float(image.pixels.max() - image.pixels.min()) or 1.0)
    ok, message, measured = value >= o["min_ssim"], f"SSIM {value:.4f} (min {o['min_ssim']:g})", {"ssim": value}
    rows = measure_blur_disks(scene, [Run(scene, o["model"], "mitsuba", image)])["renders"].get(
        f"{o['model']} (Mitsuba)", [])
    errors = [r["error_percent"] for r in rows if r and r["expected_px"] >= o["min_expected_px"]]
    if errors:
        worst = max(errors, key=abs)
        ok = ok and abs(worst) <= o["tolerance_percent"]
        message += f"; Mitsuba blur disks: largest error {worst:+.2f} % of eq. 5 (limit {o['tolerance_percent']:g} %)"
        measured["blur_errors_percent"] = errors
    return ok, message, measured


def _lens_paraxial(check: Check, threads):
    o = check.options
    info = lens_info(load_prescription(lens_argument(check)))  # the quantity was checked when the config loaded
    value = float(info[o["quantity"]])
    expected = float(o["expected"])
    rel = abs(value - expected) / abs(expected) if expected else abs(value)
    return rel <= o["relative_tolerance"], (f"{o['quantity']} = {value:.9g} against {expected:.9g} "
                                             f"(relative {rel:.2e}, limit {o['relative_tolerance']:g})"), {
        "value": value, "relative_error": rel}


def _image_matches(check: Check, threads):
    o = check.options
    theirs = read_exr(check.path("image")).pixels
    scene = load_scene(check.path("scene"))
    ours = render(scene, model=o["model"], spp=int(o["spp"]), threads=threads, progress=False).pixels
    if theirs.shape != ours.shape:
        return False, f"image is {theirs.shape[1]}x{theirs.shape[0]}, the scene renders {ours.shape[1]}x{ours.shape[0]}", {}
    data_range = float(ours.max() - ours.min()) or 1.0
    s = ssim(ours, theirs, data_range=data_range)
    de = ciede2000(ours, theirs, white_luminance=float(max(luminance(ours).max(), 1e-12))).mean
    ok = s >= o["min_ssim"] and de <= o["max_delta_e"]
    return ok, f"SSIM {s:.4f} (min {o['min_ssim']:g}), mean ΔE00 {de:.3f} (max {o['max_delta_e']:g})", {
        "ssim": s, "ciede2000_mean": de}


_RUNNERS = {"blur_equation5": _blur_equation5, "povray_ssim": _povray_ssim, "mitsuba_agreement": _mitsuba_agreement,
            "measure": _measure,
            "lens_paraxial": _lens_paraxial,
            "image_matches": _image_matches}
