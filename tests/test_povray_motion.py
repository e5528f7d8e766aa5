"""Motion blur against POV-Ray's sub-frame average.

POV-Ray 3.7 has no motion blur; ``render_povray`` renders a moving scene as
the mean of K sub-frames at the centres of K equal parts of the shutter
(``lenscompare povray --time-samples K``), each written by ``scene_to_pov(...,
time_s=t)`` and rendered by POV-Ray 3.7.0.10 (Debian's ``povray``) with

    povray +Iscene.pov +Oout.exr +FE -D -V +Q9 -UA +W180 +H120 -A +WT2

and ``blur_samples N, N`` with N = spp / K. The native render integrates the
same shutter continuously (time a sample dimension). Kept small for CI.
"""

from __future__ import annotations

import math
import shutil
from dataclasses import replace

import numpy as np
import pytest

from lenscompare.cameras import camera_for
from lenscompare.image import write_exr
from lenscompare.metrics import measure_streak, ssim
from lenscompare.motion import geometry_at_s, subframe_times_s
from lenscompare.motion_path import longest_motion_path
from lenscompare.povray import render_povray, scene_to_pov
from lenscompare.povray.runner import (
    MAX_AUTO_TIME_SAMPLES,
    MAX_SUBFRAME_SPACING_PX,
    pinhole_subframes,
    run_povray,
    run_povray_frames,
    subframes_for,
)
from lenscompare.render import render
from lenscompare.scene import EmissiveMaterial, Sphere, load_scene

from helpers import REFERENCE_SCENES

pytestmark = pytest.mark.skipif(shutil.which("povray") is None, reason="POV-Ray (povray) is not installed")

SHUTTER_S = (0.0, 0.05)
LAMP = Sphere((0.9, 0.95, 3.0), 0.03, "probe", velocity=(4.0, 0.0, 0.0))  # in focus, about 17 px of travel


def moving_showcase():
    """The lit showcase (thin lens f/2.8, defocused foreground and background)
    with the in-focus red sphere and a small in-focus lamp moving sideways,
    the near blue sphere moving toward the camera, and the camera rising."""
    scene = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(180, 120))
    objects = list(scene.objects)
    objects[1] = replace(objects[1], velocity=(1.5, 0.0, 0.0))   # red, in focus
    objects[2] = replace(objects[2], velocity=(0.0, 0.0, -2.0))  # blue, before focus, approaching
    materials = {**scene.materials, "probe": EmissiveMaterial("probe", (6.0, 6.0, 6.0))}
    scene = replace(scene, objects=(*objects, LAMP), materials=materials)
    return scene.with_camera(velocity=(0.0, 0.2, 0.0)).with_render(shutter_s=SHUTTER_S)


def lamp_path_px(scene) -> tuple[np.ndarray, np.ndarray]:
    """The lamp's centre on the film when the shutter opens and closes (camera motion included)."""
    ends = []
    for t in SHUTTER_S:
        still = geometry_at_s(scene, t)
        camera = camera_for(still, "thin")
        ends.append(camera.project_px(camera.frame.camera_from_world(still.objects[-1].center)))
    return ends[0], ends[1]


def test_subframes_move_objects_with_their_texture_and_the_camera():
    scene = moving_showcase()
    text = scene_to_pov(scene, model="thin", spp=4, time_s=0.025)
    assert "texture { LC_Material1 } } translate <0.037500000000000006, 0, 0>" in text  # red: 1.5 m/s x 0.025 s
    assert "translate <0.1, 0, 0>" in text          # the lamp
    assert "location <0, 0.605, -0.5>" in text      # camera 0.6 m + 0.2 m/s x 0.025 s
    assert "POV-Ray has no motion blur" in text


def test_moving_lit_scene_matches_povray_subframes(tmp_path):
    """SSIM >= 0.97 and the lamp's streak within 2 % in both renders and of v
    T projected, with as many sub-frames as the default takes: copies of the
    longest streak at most 1 px apart."""
    scene = moving_showcase()
    native = render(scene, spp=256, sampler="sobol", seed=3, threads=2, progress=False)
    pov = render_povray(scene, spp=256, threads=2)
    streak_px = longest_motion_path(scene, camera_for(scene, "thin")).length_px
    assert pov.metadata["streak_px"] == streak_px and pov.metadata["time_samples"] == math.ceil(streak_px)
    assert pov.metadata["subframe_spacing_px"] <= MAX_SUBFRAME_SPACING_PX == 1.0
    similarity = ssim(native.pixels, pov.pixels, data_range=1.0)
    start, end = lamp_path_px(scene)
    expected_px = float(np.linalg.norm(end - start))
    a = measure_streak(native.pixels, start_px=start, end_px=end, margin_px=6)
    b = measure_streak(pov.pixels, start_px=start, end_px=end, margin_px=6)
    message = (f"SSIM {similarity:.4f}; streak native {a.length_px:.3f} px, POV-Ray {b.length_px:.3f} px, "
               f"v T projected {expected_px:.3f} px; reference {pov.metadata['renderer']} `{pov.metadata['command']}`")
    ok = (similarity >= 0.97 and abs(a.length_px - b.length_px) <= 0.02 * expected_px
          and abs(a.length_px - expected_px) <= 0.02 * expected_px
          and abs(b.length_px - expected_px) <= 0.02 * expected_px)
    if not ok:
        write_exr(tmp_path / "native.exr", native)
        write_exr(tmp_path / "povray.exr", pov)
    assert ok, message
    print(message)


def test_sub_frames_rendered_as_one_animation_are_the_separate_renders_bit_for_bit():
    """render_povray renders a moving scene's sub-frames as one POV-Ray
    animation (frame k includes sub-frame k's file): each frame must be the
    image a POV-Ray process of its own gives that sub-frame's text, bit for
    bit, and the render their mean, its trace time within its wall time."""
    scene = moving_showcase().with_camera(resolution=(48, 32))
    times = subframe_times_s(SHUTTER_S, 3).tolist()
    texts = [scene_to_pov(scene, model="thin", spp=2, time_s=t) for t in times]
    options = ["+FE", "-D", "-V", "+Q9", "-UA", "+W48", "+H32", "-A", "+WT2"]
    frames, result, _, command = run_povray_frames(texts, options)
    assert "+KFF3" in command
    assert result.stderr.count("Trace Time") == 3
    for text, frame in zip(texts, frames):
        alone, *_ = run_povray(text, options)
        assert frame is not None and np.array_equal(frame, alone)
    image = render_povray(scene, model="thin", spp=6, threads=2, time_samples=3)
    mean = (frames[0].astype(np.float64) + frames[1] + frames[2]) / 3
    assert np.array_equal(image.pixels, mean.astype(np.float32))
    assert image.metadata["time_samples"] == 3 and 0 < image.metadata["seconds"] <= image.metadata["wall_seconds"]


def test_default_subframes_keep_a_streaks_copies_within_a_pixel_and_within_bounds():
    assert subframes_for(0.0) == 1 and subframes_for(0.4) == 1  # a streak under a pixel: one frame
    assert subframes_for(6.63) == 7 and subframes_for(7.0) == 7 and subframes_for(30.2) == 31
    assert subframes_for(1e6) == subframes_for(math.inf) == MAX_AUTO_TIME_SAMPLES  # then copies lie further apart


def test_the_pinholes_sub_frames_waste_few_rays():
    # 256 spp over 14 frames would take 26 rays each (5 x 5 + 1; 364 in all); 16 frames take 17 (272).
    assert pinhole_subframes(14, 256) == 16 and pinhole_subframes(7, 256) == 7  # 7 x 37 = 259
    for least in (1, 3, 14, 40):
        for spp in (4, 64, 256, 1000):
            k = pinhole_subframes(least, spp)
            assert least <= k <= 2 * least  # copies never further apart than asked
    scene = moving_showcase().with_camera(resolution=(48, 32))
    image = render_povray(scene, model="pinhole", spp=64, threads=2)
    least = subframes_for(image.metadata["streak_px"])
    assert image.metadata["time_samples"] == pinhole_subframes(least, 64)
    assert 64 <= image.metadata["spp"] <= 72  # rays traced: within an eighth of those asked


def test_a_still_scene_is_one_frame_and_says_nothing_of_sub_frames():
    scene = moving_showcase().with_camera(resolution=(48, 32)).with_render(shutter_s=(0.0, 0.0))
    image = render_povray(scene, model="thin", spp=4, threads=2)
    assert "time_samples" not in image.metadata and "+KFF" not in image.metadata["command"]

