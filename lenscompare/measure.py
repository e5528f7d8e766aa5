"""What a scene's images are measured for, per run: blur disks against
equation 5, distortion from a dot grid, relative illumination from a flat
field, and image similarity. The report and the checks both use these.

Each run's image carries the camera value it was rendered through
(``image.camera``): focal length, film distance, aperture and pixel pitch come
from there, never from a default.

A measurement that the image cannot support (a flat field of 3 x 2 pixels, a
dot grid with no dot inside the frame, a blur disk larger than the image) is
``None`` for that render or that sphere, never an exception: every scene the
schema accepts gets a report.
"""

from __future__ import annotations

import math

import numpy as np

from .cameras import CameraModel, LensSystemCamera
from .lenses import relative_illumination as relative_illumination_traced
from .lenses import traced_spot_diameter_mm
from .metrics import (
    ciede2000,
    distortion_percent,
    dot_centroids,
    find_point_sources,
    fit_radial_distortion,
    luminance,
    match_points,
    measure_blur_disk,
    psnr,
    relative_illumination,
    relative_rmse,
    rmse,
    ssim,
)
from .optics import circle_of_confusion_mm, second_moment_diameter_ratio
from .scene import EmissiveMaterial, Scene, Sphere
from .units import mm_from_m

__all__ = ["measure_blur_disks", "measure_distortion", "measure_vignetting", "compare_images"]


def _camera_of(run) -> CameraModel:
    camera = run.image.camera
    if camera is None:
        raise ValueError(f"run {run.label!r}: its image carries no camera value to measure against")
    return camera


def _emissive_spheres(scene: Scene) -> list[Sphere]:
    return [o for o in scene.objects if isinstance(o, Sphere)
            and isinstance(scene.materials[o.material], EmissiveMaterial)]


def measure_blur_disks(scene: Scene, runs) -> dict:
    """Blur-disk diameter of every emissive sphere, per render.

    Each row holds the measured second-moment diameter beside two expectations:
    equation 5 (``eq5_px``; the measurement's departure from it is
    ``departure_from_eq5_percent``) and the expectation for the model that
    rendered it (``expected_px``, ``error_percent``): equation 5 again for the
    pinhole, thin and thick lens, and a real-ray spot traced through the
    prescription at the same depth and field with the same second-moment
    definition for the lens system (:func:`lenscompare.lenses.traced_spot_diameter_mm`),
    whose blur departs from equation 5 through pupil vignetting and aberrations.
    """
    spheres = _emissive_spheres(scene)
    result = {"depth_m": [], "renders": {}}
    for run in runs:
        camera = _camera_of(run)
        xyz = camera.frame.camera_from_world([s.center for s in spheres])
        result["depth_m"] = xyz[:, 2].tolist()
        pitch = camera.pixel_pitch_mm
        # Centroids found in the image, paired with where each sphere projects.
        found = find_point_sources(run.image.pixels)
        projected = camera.project_px(xyz)
        rows = []
        for sphere, (x, y, z), proj in zip(spheres, xyz, projected):
            if not found:
                break
            source = min(found, key=lambda s: math.dist(s.centroid_px, proj))
            if math.dist(source.centroid_px, proj) > 0.05 * scene.camera.width_px:
                rows.append(None)
                continue
            # The pinhole has no aperture (diameter 0): no blur.
            eq5_px = circle_of_confusion_mm(mm_from_m(z), focus_distance_mm=camera.focus_distance_mm,
                                            focal_length_mm=camera.focal_length_mm,
                                            aperture_diameter_mm=camera.aperture_diameter_mm) / pitch
            sphere_px = 2.0 * sphere.radius * camera.image_scale_mm / z / pitch
            window_px = eq5_px + sphere_px + 4
            expected_px, expected_from = eq5_px, "equation 5"
            if isinstance(camera, LensSystemCamera):
                # The same window on the traced spot as on the image's.
                expected_px = traced_spot_diameter_mm(
                    camera.prescription, height_mm=mm_from_m(math.hypot(x, y)), distance_mm=mm_from_m(z),
                    film_z_mm=camera.film_z_mm, window_radius_mm=window_px * pitch) / pitch
                expected_from = f"real rays through {camera.prescription.name}"
            if camera.aperture_blades:
                # The blur takes the aperture's shape: an N-gon's second moment
                # (for the lens system a first-order scaling of the round stop's spot).
                expected_px *= second_moment_diameter_ratio(camera.aperture_blades)
                expected_from += f", {camera.aperture_blades}-blade aperture"
            try:
                disk = measure_blur_disk(run.image.pixels, center_px=source.centroid_px, window_radius_px=window_px,
                                         source_diameter_px=sphere_px)
            except ValueError:  # the image cannot hold this disk (e.g. a few pixels in all)
                rows.append(None)
                continue
            d = disk.second_moment_diameter_px
            rows.append({"depth_m": z, "field_deg": math.degrees(math.atan(math.hypot(x, y) / z)),
                         "measured_px": d, "encircled_energy_px": disk.encircled_energy_diameter_px,
                         "eq5_px": eq5_px, "departure_from_eq5_percent": _percent(d, eq5_px),
                         "expected_px": expected_px, "expected_from": expected_from,
                         "error_percent": _percent(d, expected_px)})
        result["renders"][run.label] = rows
    return result


def _percent(measured: float, expected: float) -> float | None:
    """Relative difference in percent; None where the expectation is too small to divide by."""
    return 100.0 * (measured / expected - 1.0) if expected > 1.0 else None


DISTORTION_DEFINITION = ("dot centroid against its paraxial image point (the paraxial chief ray through the "
                         "entrance-pupil centre on the rendered film: no fitted scale); at the scene's f-number the "
                         "centroid also holds any coma")


def measure_distortion(scene: Scene, runs) -> dict:
    """Radial distortion of a dot grid, per render, against the ideal projection.

    The ideal position of each dot is its paraxial image point,
    ``camera.image_scale_mm * tan(theta)`` from the centre; nothing is fitted,
    so distortion near the axis is not absorbed into the scale (see
    :data:`DISTORTION_DEFINITION`).
    """
    spheres = _emissive_spheres(scene)
    w, h = scene.camera.resolution
    centre = np.array([w / 2.0, h / 2.0])
    result = {"definition": DISTORTION_DEFINITION, "renders": {}}
    for run in runs:
        camera = _camera_of(run)
        xyz = camera.frame.camera_from_world([s.center for s in spheres])
        tan_xy = np.stack([xyz[:, 0] / xyz[:, 2], xyz[:, 1] / xyz[:, 2]], axis=-1)
        field_deg = np.degrees(np.arctan(np.hypot(tan_xy[:, 0], tan_xy[:, 1])))
        direction = tan_xy * [1.0, -1.0]  # raster y grows downward
        ideal_all = centre + direction * camera.image_scale_mm / camera.pixel_pitch_mm
        try:
            measured = dot_centroids(run.image.pixels)
            i_measured, i_ideal = match_points(measured, ideal_all, max_distance_px=0.03 * w)
        except ValueError:  # no dot grid this image can show
            result["renders"][run.label] = None
            continue
        m, ideal, fields = measured[i_measured], ideal_all[i_ideal], field_deg[i_ideal]
        # Dots the frame cuts have biased centroids: keep those well inside.
        margin = 0.02 * w
        inside = np.all((m > margin) & (m < np.array([w, h]) - margin), axis=1)
        m, ideal, fields = m[inside], ideal[inside], fields[inside]
        off_axis = fields > 4.0  # near the axis a centroid error of 0.05 px is a large percentage
        if off_axis.sum() < 3:
            result["renders"][run.label] = None
            continue
        try:
            radial = distortion_percent(m[off_axis], ideal[off_axis], center_px=centre)
            fit = fit_radial_distortion(m, ideal, center_px=centre, normalize_radius_px=float(np.hypot(*centre)))
        except ValueError:
            result["renders"][run.label] = None
            continue
        result["renders"][run.label] = {
            "field_deg": fields[off_axis].tolist(), "distortion_percent": np.asarray(radial.percent).tolist(),
            "k1": fit.k1, "k2": fit.k2, "dots_matched": int(len(m)), "dots_in_scene": int(len(spheres)),
            "max_abs_distortion_percent": float(np.nanmax(np.abs(radial.percent))),
            "f_number": camera.f_number,
        }
    return result


def measure_vignetting(scene: Scene, runs, *, traced: bool = True) -> dict:
    """Relative illumination against field angle from a flat-field render.

    For the lens system, ``traced`` holds the independent expectation at the
    same f-number: :func:`lenscompare.lenses.relative_illumination` (real rays,
    pupil area and cos factors) at a few field angles. ``traced=False`` leaves
    it out (about 0.7 s per lens-system run: a caller measuring many renders of
    one camera needs it once).
    """
    result = {"renders": {}}
    for run in runs:
        camera = _camera_of(run)
        try:
            bins = min(24, max(1, min(run.image.pixels.shape[:2]) // 2))  # 24, or fewer on a tiny image
            radius_px, ri = relative_illumination(run.image.pixels, n_bins=bins)
        except ValueError:  # not a flat field the metric can read (dark centre, a few pixels)
            result["renders"][run.label] = None
            continue
        field = np.degrees(np.arctan(np.asarray(radius_px) * camera.pixel_pitch_mm / camera.image_scale_mm))
        at = {}
        for angle in (10.0, 20.0):
            if field.max() >= angle:
                at[f"{angle:g}_deg"] = float(np.interp(angle, field, ri))
        entry = {"field_deg": field.tolist(), "relative_illumination": np.asarray(ri).tolist(), "at": at,
                 "f_number": camera.f_number}
        if traced and isinstance(camera, LensSystemCamera):
            angles = [a for a in (5.0, 10.0, 15.0, 20.0, 25.0) if a <= field.max()]
            entry["traced"] = {"field_deg": angles,
                               "relative_illumination": [relative_illumination_traced(camera.prescription, a,
                                                                                       samples_across=160)
                                                         for a in angles]}
        result["renders"][run.label] = entry
    return result


def compare_images(image_true: np.ndarray, image_test: np.ndarray) -> dict:
    """Similarity of two renders of one scene; data range from the reference."""
    data_range = float(image_true.max() - image_true.min()) or 1.0
    # White: the reference's brightest pixel (point-source scenes are mostly black).
    colour = ciede2000(image_true, image_test, white_luminance=float(max(luminance(image_true).max(), 1e-12)))
    return {"ssim": ssim(image_true, image_test, data_range=data_range),
            "psnr_db": psnr(image_true, image_test, data_range=data_range),
            "rmse": rmse(image_true, image_test), "relative_rmse": relative_rmse(image_true, image_test),
            "ciede2000_mean": colour.mean, "ciede2000_p95": colour.percentile_95, "data_range": data_range}
