"""What a scene's images are measured for, per run: blur disks against
equation 5, distortion from a dot grid, relative illumination from a flat
field, and image similarity. The report and the checks both use these.

Each run's image carries the camera value it was rendered through
(``image.camera``): focal length, film distance, aperture and pixel pitch come
from there, never from a default.
"""

from __future__ import annotations

import math

import numpy as np

from .cameras import CameraModel
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
from .optics import circle_of_confusion_mm
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
    """Blur-disk diameter of every emissive sphere, per render, against eq. 5."""
    spheres = _emissive_spheres(scene)
    result = {"depth_m": [], "renders": {}}
    for run in runs:
        camera = _camera_of(run)
        xyz = camera.frame.camera_from_world([s.center for s in spheres])
        result["depth_m"] = xyz[:, 2].tolist()
        pitch, film_mm = camera.pixel_pitch_mm, camera.film_distance_mm
        # The pinhole has no aperture (diameter 0): no blur.
        expected_px = [circle_of_confusion_mm(mm_from_m(z), focus_distance_mm=camera.focus_distance_mm,
                                              focal_length_mm=camera.focal_length_mm,
                                              aperture_diameter_mm=camera.aperture_diameter_mm) / pitch
                       for z in xyz[:, 2]]
        # Centroids found in the image, paired with where each sphere projects.
        found = find_point_sources(run.image.pixels)
        projected = camera.project_px(xyz)
        rows = []
        for sphere, (x, y, z), proj, expected in zip(spheres, xyz, projected, expected_px):
            if not found:
                break
            source = min(found, key=lambda s: math.dist(s.centroid_px, proj))
            if math.dist(source.centroid_px, proj) > 0.05 * scene.camera.width_px:
                rows.append(None)
                continue
            sphere_px = 2.0 * sphere.radius * film_mm / z / pitch
            disk = measure_blur_disk(run.image.pixels, center_px=source.centroid_px,
                                     window_radius_px=expected + sphere_px + 4, source_diameter_px=sphere_px)
            d = disk.second_moment_diameter_px
            rows.append({"depth_m": z, "expected_px": expected, "measured_px": d,
                         "encircled_energy_px": disk.encircled_energy_diameter_px,
                         "error_percent": 100.0 * (d / expected - 1.0) if expected > 1.0 else None})
        result["renders"][run.label] = rows
    return result


def measure_distortion(scene: Scene, runs) -> dict:
    """Radial distortion of a dot grid, per render, against the ideal projection
    whose scale is fitted on the dots within 6 degrees of the axis."""
    spheres = _emissive_spheres(scene)
    w, h = scene.camera.resolution
    centre = np.array([w / 2.0, h / 2.0])
    result = {"renders": {}}
    for run in runs:
        camera = _camera_of(run)
        xyz = camera.frame.camera_from_world([s.center for s in spheres])
        tan_xy = np.stack([xyz[:, 0] / xyz[:, 2], xyz[:, 1] / xyz[:, 2]], axis=-1)
        field_deg = np.degrees(np.arctan(np.hypot(tan_xy[:, 0], tan_xy[:, 1])))
        direction = tan_xy * [1.0, -1.0]  # raster y grows downward
        measured = dot_centroids(run.image.pixels)
        guess = centre + direction * camera.film_distance_mm / camera.pixel_pitch_mm
        i_measured, i_ideal = match_points(measured, guess, max_distance_px=0.03 * w)
        m, d, fields = measured[i_measured], direction[i_ideal], field_deg[i_ideal]
        # Dots the frame cuts have biased centroids: keep those well inside.
        margin = 0.02 * w
        inside = np.all((m > margin) & (m < np.array([w, h]) - margin), axis=1)
        m, d, fields = m[inside], d[inside], fields[inside]
        inner = fields < 6.0
        if inner.sum() < 3:
            result["renders"][run.label] = None
            continue
        scale = float(np.sum((m[inner] - centre) * d[inner]) / np.sum(d[inner] * d[inner]))
        ideal = centre + d * scale
        off_axis = fields > 4.0  # near the axis a centroid error of 0.05 px is a large percentage
        radial = distortion_percent(m[off_axis], ideal[off_axis], center_px=centre)
        fit = fit_radial_distortion(m, ideal, center_px=centre, normalize_radius_px=float(np.hypot(*centre)))
        result["renders"][run.label] = {
            "field_deg": fields[off_axis].tolist(), "distortion_percent": np.asarray(radial.percent).tolist(),
            "k1": fit.k1, "k2": fit.k2, "dots_matched": int(len(m)), "dots_in_scene": int(len(spheres)),
            "max_abs_distortion_percent": float(np.nanmax(np.abs(radial.percent))),
        }
    return result


def measure_vignetting(scene: Scene, runs) -> dict:
    """Relative illumination against field angle from a flat-field render."""
    result = {"renders": {}}
    for run in runs:
        camera = _camera_of(run)
        radius_px, ri = relative_illumination(run.image.pixels, n_bins=24)
        field = np.degrees(np.arctan(np.asarray(radius_px) * camera.pixel_pitch_mm / camera.film_distance_mm))
        at = {}
        for angle in (10.0, 20.0):
            if field.max() >= angle:
                at[f"{angle:g}_deg"] = float(np.interp(angle, field, ri))
        result["renders"][run.label] = {"field_deg": field.tolist(), "relative_illumination": np.asarray(ri).tolist(),
                                        "at": at}
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
