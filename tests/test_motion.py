"""Motion blur: moving objects and cameras, against analytic truths.

A small emissive sphere crossing the view at constant depth and speed leaves a
streak whose half-plateau length is exactly its centre's projected path, v T
on the film (lenscompare.metrics.streak); its plateau is flat, and its height
is the sphere's radiance times the disk's area in the centre row over L. A
camera moving at -v sees the same streak. Zero velocities or a zero shutter
leave the static image untouched, bit for bit.
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from lenscompare.cameras import camera_for
from lenscompare.metrics import measure_streak
from lenscompare.render import render
from lenscompare.scene import load_scene, parse_scene

from helpers import REFERENCE_SCENES

WIDTH, HEIGHT = 200, 41          # odd height: the sphere's centre row is a pixel row
FILM_MM = (36.0, 36.0 * HEIGHT / WIDTH)
DEPTH_M, RADIUS_M = 4.0, 0.05    # about 7 px across at 50 mm
SPEED_M_PER_S, SHUTTER_S = 35.0, (0.0, 1.0 / 30.0)  # about 82 px
START_X_M = -0.58


def streak_scene(*, model: str = "thin", object_velocity=(SPEED_M_PER_S, 0.0, 0.0), camera_velocity=(0, 0, 0),
                 shutter=SHUTTER_S, extra: str = "") -> "Scene":
    text = f"""
[camera]
model = "{model}"
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, 1.0]
focal_length_mm = 50.0
f_number = 2.8
focus_distance = {DEPTH_M}
film_mm = [{FILM_MM[0]}, {FILM_MM[1]}]
resolution = [{WIDTH}, {HEIGHT}]
velocity = {list(map(float, camera_velocity))}
{extra}
[render]
shutter = {list(map(float, shutter))}

[materials.glow]
type = "emissive"
color = [1.0, 1.0, 1.0]

[[objects]]
type = "sphere"
center = [{START_X_M}, 0.0, {DEPTH_M}]
radius = {RADIUS_M}
material = "glow"
velocity = {list(map(float, object_velocity))}
"""
    return parse_scene(text, source="<streak>")


def projected_path_px(scene, model: str) -> tuple[np.ndarray, np.ndarray]:
    """The sphere centre's raster positions when the shutter opens and closes."""
    camera = camera_for(scene, model)
    sphere = scene.objects[0]
    ends = [np.asarray(sphere.center) + np.asarray(sphere.velocity) * t for t in scene.render.shutter_s]
    return tuple(camera.project_px(camera.frame.camera_from_world(p)) for p in ends)


def test_streak_length_and_flatness_match_v_t_projected():
    scene = streak_scene()
    # 1024 spp: the sphere covers a pixel for 1/12 of the shutter, about 90 of its samples
    image = render(scene, model="thin", spp=1024, sampler="sobol", seed=1, threads=2, progress=False)
    start, end = projected_path_px(scene, "thin")
    expected_px = float(np.linalg.norm(end - start))
    streak = measure_streak(image.pixels, start_px=start, end_px=end)
    assert expected_px > 75
    # Within 2 % or 0.5 px of v T projected
    assert abs(streak.length_px - expected_px) <= max(0.02 * expected_px, 0.5), (streak, expected_px)
    # Flat along its length: no ripple, no ramp
    assert streak.unevenness < 0.03 and abs(streak.tilt) < 0.03, streak
    # Its height: the disk's area in the centre row (px^2, 1 px high) over the path length
    radius_px = RADIUS_M / DEPTH_M * camera_for(scene, "thin").film_distance_mm / FILM_MM[0] * WIDTH
    y = np.linspace(-0.5, 0.5, 20001)
    strip_area = np.trapezoid(2.0 * np.sqrt(np.maximum(radius_px ** 2 - y ** 2, 0.0)), y)
    assert streak.plateau == pytest.approx(strip_area / expected_px, rel=0.04)


@pytest.mark.parametrize("model, extra", [("pinhole", ""), ("thin", ""), ("thick", "principal_plane_gap_mm = 8.0"),
                                          ("lens", 'lens = "dgauss.50mm"')])
def test_moving_camera_gives_the_moving_objects_streak(model, extra):
    """Every model: the camera at -v gives the streak of the object at +v."""
    object_moves = streak_scene(model=model, extra=extra)
    camera_moves = streak_scene(model=model, extra=extra, object_velocity=(0, 0, 0),
                                camera_velocity=(-SPEED_M_PER_S, 0.0, 0.0))
    a = render(object_moves, model=model, spp=32, sampler="sobol", seed=2, threads=2, progress=False).pixels
    b = render(camera_moves, model=model, spp=32, sampler="sobol", seed=2, threads=2, progress=False).pixels
    start, end = projected_path_px(object_moves, model)
    if model == "lens":  # the real lens's own projection: find the streak along the centre row
        start, end = np.array([5.0, HEIGHT / 2]), np.array([WIDTH - 5.0, HEIGHT / 2])
    sa = measure_streak(a, start_px=start, end_px=end)
    sb = measure_streak(b, start_px=start, end_px=end)
    assert sa.length_px > 75
    assert abs(sa.length_px - sb.length_px) < 0.5, (sa, sb)
    assert np.abs(a - b).max() < 0.02 * a.max()  # the same picture, up to float rounding of positions



@pytest.mark.parametrize("model, sample_wavelengths",
                         [("thin", False), ("thin", True), ("lens", False), ("lens", True)])
def test_a_moving_camera_through_a_dispersive_lens_gives_the_moving_objects_streak(model, sample_wavelengths):
    """Spectral renders through a lens with Abbe numbers (band rays and drawn
    wavelengths, the lens system's two traced, through either camera):
    the camera at -v gives the streak of the object at +v, each ray's origin
    moved where the camera is at its time."""
    lens = str(Path(__file__).parent / "data" / "lenses" / "dgauss_abbe.dat")
    object_moves = streak_scene(model=model).with_camera(lens=lens, focal_length_mm=None)
    camera_moves = streak_scene(model=model, object_velocity=(0, 0, 0), camera_velocity=(-SPEED_M_PER_S, 0.0, 0.0)
                                ).with_camera(lens=lens, focal_length_mm=None)
    kwargs = dict(model=model, spp=32, sampler="sobol", seed=2, threads=2, progress=False, spectral=True,
                  sample_wavelengths=sample_wavelengths)
    a, b = (render(scene, **kwargs).pixels for scene in (object_moves, camera_moves))
    start, end = np.array([5.0, HEIGHT / 2]), np.array([WIDTH - 5.0, HEIGHT / 2])
    sa, sb = (measure_streak(image, start_px=start, end_px=end) for image in (a, b))
    assert sa.length_px > 75
    assert abs(sa.length_px - sb.length_px) < 0.5, (sa, sb)
    assert np.abs(a - b).max() < 0.02 * a.max()

def test_zero_velocity_or_zero_shutter_is_the_static_image_bit_for_bit():
    static = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(96, 64))
    moving_objects = tuple(replace(o, velocity=(1.5, 0.2, -0.5)) for o in static.objects)
    cases = {
        "open shutter, nothing moves": static.with_render(shutter_s=(0.0, 0.05)),
        "closed shutter, everything moves": replace(static, objects=moving_objects).with_camera(velocity=(0.3, 0, 0)),
    }
    for model in ("pinhole", "thin", "lens"):
        kwargs = dict(model=model, spp=4, seed=5, threads=2, progress=False)
        lens = "dgauss.50mm" if model == "lens" else None
        reference = render(static.with_camera(lens=lens) if lens else static, **kwargs).pixels
        for name, scene in cases.items():
            scene = scene.with_camera(lens=lens) if lens else scene
            for sampler in ("jittered", "sobol"):
                a = render(scene, sampler=sampler, **kwargs).pixels
                b = render(static.with_camera(lens=lens) if lens else static, sampler=sampler, **kwargs).pixels
                assert a.tobytes() == b.tobytes(), (model, name, sampler)
        assert reference.max() > 0


def test_moving_render_is_finite_and_differs_from_the_static_one():
    static = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(96, 64))
    objects = list(static.objects)
    objects[1] = replace(objects[1], velocity=(3.0, 0.0, 0.0))  # the red sphere, in focus
    moving = replace(static, objects=tuple(objects)).with_render(shutter_s=(0.0, 0.05))
    a = render(static, spp=8, seed=1, threads=2, progress=False)
    b = render(moving, spp=8, seed=1, threads=2, progress=False)
    assert np.isfinite(b.pixels).all()
    assert np.abs(a.pixels - b.pixels).max() > 0.1
    assert b.metadata["motion"] == {"shutter_s": [0.0, 0.05], "samples_time": True,
                                    "camera_velocity_m_per_s": [0.0, 0.0, 0.0]}
    assert "motion" not in a.metadata


def test_checker_moves_with_its_object():
    """A checkered box moving at v seen by a camera moving at v (shutter
    closed at t = 0.5 s): the same picture as both at rest, so the texture
    travelled with the box."""
    static = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(96, 64))
    v = (0.7, 0.0, 0.4)
    together = replace(static, objects=tuple(replace(o, velocity=v) for o in static.objects))
    together = together.with_camera(velocity=v).with_render(shutter_s=(0.5, 0.5))
    kwargs = dict(model="pinhole", spp=4, seed=5, threads=2, progress=False)
    a, b = render(static, **kwargs).pixels, render(together, **kwargs).pixels
    # Lights stay put, so only shading may change slightly; the checker pattern must not slide.
    floor_rows = slice(40, 64)
    edges_a = np.abs(np.diff(a[floor_rows].mean(axis=2), axis=1)) > 0.1
    edges_b = np.abs(np.diff(b[floor_rows].mean(axis=2), axis=1)) > 0.1
    assert (edges_a == edges_b).mean() > 0.97


@pytest.mark.parametrize("moving", [(1, 2, 3), (0,), (0, 1, 2, 3, 4, 5, 6)], ids=["spheres", "floor", "everything"])
def test_barely_moving_objects_render_the_static_image(moving):
    """Objects moving by 50 pm over the shutter go through the motion-blurred
    geometry (its own Embree scene, asked only about rays through the
    movers' swept bounds) for camera and shadow rays alike; the image is the
    static one up to float rounding at edges. A ray wrongly culled would lose
    a sphere or its shadow."""
    static = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(120, 80))
    objects = tuple(replace(o, velocity=(1e-9, 0.0, 0.0)) if i in moving else o for i, o in enumerate(static.objects))
    barely = replace(static, objects=objects).with_render(shutter_s=(0.0, 0.05))
    kwargs = dict(model="thin", spp=16, sampler="sobol", seed=3, threads=2, progress=False)
    a, b = render(static, **kwargs), render(barely, **kwargs)
    assert b.metadata["motion"]["samples_time"]
    difference = np.abs(a.pixels - b.pixels).max(axis=2)
    assert (difference > 1e-3).mean() < 0.002, (difference > 1e-3).sum()
    assert difference.mean() < 1e-4
