"""What the report measures on each scene, per model: blur disks against
equation 5, distortion from a dot grid, relative illumination from a flat
field, and image similarity between models and against POV-Ray."""

from __future__ import annotations

import math

import numpy as np

from ..cameras.common import camera_frame
from ..metrics import (
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
from ..optics import circle_of_confusion_mm
from ..scene import EmissiveMaterial, Scene, Sphere

__all__ = ["measure_blur_disks", "measure_distortion", "measure_vignetting", "compare_images"]


def _camera_points(scene: Scene, points):
    """World points -> camera-space (x right, y up, z along the view), metres."""
    origin, right, up, forward = (np.array(v) for v in camera_frame(scene.camera))
    p = np.asarray(points, dtype=float) - origin
    return np.stack([p @ right, p @ up, p @ forward], axis=-1)


def _emissive_spheres(scene: Scene) -> list[Sphere]:
    return [o for o in scene.objects if isinstance(o, Sphere)
            and isinstance(scene.materials[o.material], EmissiveMaterial)]


def _projection_distance_mm(info: dict) -> float:
    """Film distance that sets the image scale: from the lens (pinhole, thin,
    thick) or from the rear principal plane (lens system)."""
    return info.get("film_distance_from_rear_principal_plane_mm", info.get("film_distance_mm", 50.0))


def _pitch_mm(scene: Scene) -> float:
    return scene.camera.film_mm[0] / scene.camera.width_px


def _project_px(scene: Scene, camera_xyz, film_distance_mm: float) -> np.ndarray:
    """Ideal (pinhole) raster position of camera-space points for a film distance."""
    w, h = scene.camera.resolution
    film_w, film_h = scene.camera.film_mm
    x, y, z = camera_xyz[..., 0], camera_xyz[..., 1], camera_xyz[..., 2]
    return np.stack([(film_distance_mm * x / z / film_w + 0.5) * w, (0.5 - film_distance_mm * y / z / film_h) * h],
                    axis=-1)


def measure_blur_disks(scene: Scene, runs) -> dict:
    """Blur-disk diameter of every emissive sphere, per render, against eq. 5."""
    spheres = _emissive_spheres(scene)
    xyz = _camera_points(scene, [s.center for s in spheres])
    pitch = _pitch_mm(scene)
    result = {"depth_m": xyz[:, 2].tolist(), "renders": {}}
    for run in runs:
        info = run.image.metadata.get("camera", {})
        f_mm, n = info.get("focal_length_mm"), info.get("f_number")
        aperture_mm = f_mm / n if n else 0.0  # the pinhole: no aperture, no blur
        film_mm = _projection_distance_mm(info)
        expected_px = [circle_of_confusion_mm(z * 1000.0, focus_distance_mm=scene.camera.focus_distance_m * 1000.0,
                                              focal_length_mm=f_mm, aperture_diameter_mm=aperture_mm) / pitch
                       for z in xyz[:, 2]]
        # Centroids found in the image, paired with where each sphere projects.
        found = find_point_sources(run.image.pixels)
        projected = _project_px(scene, xyz, film_mm)
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
    xyz = _camera_points(scene, [s.center for s in spheres])
    tan_xy = np.stack([xyz[:, 0] / xyz[:, 2], xyz[:, 1] / xyz[:, 2]], axis=-1)
    field_deg = np.degrees(np.arctan(np.hypot(tan_xy[:, 0], tan_xy[:, 1])))
    w, h = scene.camera.resolution
    centre = np.array([w / 2.0, h / 2.0])
    direction = tan_xy * [1.0, -1.0]  # raster y grows downward
    result = {"renders": {}}
    for run in runs:
        measured = dot_centroids(run.image.pixels)
        info = run.image.metadata.get("camera", {})
        guess = centre + direction * _projection_distance_mm(info) / _pitch_mm(scene)
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
    pitch = _pitch_mm(scene)
    for run in runs:
        radius_px, ri = relative_illumination(run.image.pixels, n_bins=24)
        f_mm = _projection_distance_mm(run.image.metadata.get("camera", {}))
        field = np.degrees(np.arctan(np.asarray(radius_px) * pitch / f_mm))
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
