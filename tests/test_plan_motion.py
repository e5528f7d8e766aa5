"""The planner's motion_blur size against streaks measured on renders.

Three scenes of small emissive spheres (measurable streaks): an oblique
motion with a depth component, a camera panning past a still, defocused
sphere, and a near, defocused sphere with a shutter that opens late. The
prediction (longest projected path over the shutter, from the scene alone)
must be within 10 % of the half-plateau streak length measured on a 256-spp
native render; the search window is 30 % longer than the prediction on either
side, so a wrong prediction would show.
"""

from __future__ import annotations

import numpy as np
import pytest

from lenscompare.metrics import measure_streak
from lenscompare.plan import plan_scene, render_planned
from lenscompare.plan.effects import ideal_camera
from lenscompare.motion_path import longest_motion_path
from lenscompare.render import render
from lenscompare.scene import parse_scene


def scene_text(*, f_number, focus_m, center, velocity=(0, 0, 0), camera_velocity=(0, 0, 0),
               shutter=(0.0, 1 / 30), radius=0.04) -> str:
    vec = lambda v: "[" + ", ".join(repr(float(c)) for c in v) + "]"  # noqa: E731
    return f"""
[camera]
model = "thin"
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, 1.0]
focal_length_mm = 50.0
f_number = {f_number}
focus_distance = {focus_m}
resolution = [240, 160]
velocity = {vec(camera_velocity)}

[render]
shutter = {vec(shutter)}

[materials.glow]
type = "emissive"
color = [1.0, 1.0, 1.0]

[[objects]]
type = "sphere"
center = {vec(center)}
radius = {radius}
material = "glow"
velocity = {vec(velocity)}
"""


SCENES = {
    "oblique, in focus": dict(f_number=2.8, focus_m=4.0, center=(-0.45, -0.25, 4.0), velocity=(24.0, 12.0, -20.0)),
    "camera pans past a defocused sphere": dict(f_number=4.0, focus_m=4.0, center=(0.3, 0.35, 2.5),
                                                camera_velocity=(0.0, 12.0, 0.0)),
    "near, defocused, late shutter": dict(f_number=4.0, focus_m=4.0, center=(-0.35, 0.05, 1.5), radius=0.02,
                                          velocity=(12.0, -3.0, 0.0), shutter=(0.01, 0.05)),
}


def predicted_and_measured(name: str) -> tuple[float, float]:
    scene = parse_scene(scene_text(**SCENES[name]), source=f"<{name}>")
    effect = plan_scene(scene, measure_costs=False).effects["motion_blur"]
    path = longest_motion_path(scene, ideal_camera(scene))
    assert path.length_px == effect.magnitude and "objects[0] (sphere)" in effect.detail
    image = render(scene, spp=256, sampler="sobol", seed=4, threads=2, progress=False)
    margin = 0.3 * path.length_px + 6
    streak = measure_streak(image.pixels, start_px=path.start_px, end_px=path.end_px, margin_px=margin)
    return effect.magnitude, streak.length_px


@pytest.mark.parametrize("name", SCENES)
def test_motion_blur_prediction_within_10_percent_of_the_measured_streak(name):
    predicted, measured = predicted_and_measured(name)
    assert predicted > 20
    assert abs(predicted - measured) <= 0.10 * measured, (predicted, measured)


def test_still_scene_or_instant_shutter_needs_no_motion_blur():
    still = parse_scene(scene_text(f_number=2.8, focus_m=4.0, center=(0, 0, 4.0)), source="<still>")
    instant = parse_scene(scene_text(f_number=2.8, focus_m=4.0, center=(0, 0, 4.0), velocity=(5, 0, 0),
                                     shutter=(0.02, 0.02)), source="<instant>")
    for scene, why in ((still, "nothing visible moves"), (instant, "an instant")):
        effect = plan_scene(scene, measure_costs=False).effects["motion_blur"]
        assert effect.magnitude == 0 and why in effect.detail


def test_auto_renders_a_tiny_motion_as_the_mid_shutter_instant():
    """Under the tolerance the planner leaves motion blur out: the image is
    the still scene at the middle of the shutter."""
    slow = parse_scene(scene_text(f_number=2.8, focus_m=4.0, center=(0, 0, 4.0), velocity=(0.05, 0, 0)),
                       source="<slow>")
    image = render_planned(slow, spp=4, seed=1, threads=2, progress=False)
    plan = image.metadata["plan"]["effects"]["motion_blur"]
    assert 0 < plan["magnitude"] < 0.5 and not plan["needed"]
    mid = slow.with_render(shutter_s=(1 / 60, 1 / 60))
    assert np.array_equal(image.pixels, render(mid, model=image.metadata["model"], spp=4, seed=1, threads=2,
                                               progress=False).pixels)
