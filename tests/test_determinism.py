"""Same seed, same image, whatever the thread count."""

import numpy as np
import pytest

from lenscompare.render import render
from lenscompare.scene import load_scene

from helpers import REFERENCE_SCENES


@pytest.mark.parametrize("model", ["pinhole", "thin"])
@pytest.mark.parametrize("sampler", ["random", "jittered"])
def test_bit_identical_for_one_and_two_threads(model, sampler):
    scene = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(120, 80))
    one = render(scene, model=model, sampler=sampler, spp=8, seed=7, threads=1)
    two = render(scene, model=model, sampler=sampler, spp=8, seed=7, threads=2)
    assert one.pixels.tobytes() == two.pixels.tobytes()
    assert np.all(np.isfinite(one.pixels))


def test_seed_changes_the_noise_not_the_picture():
    scene = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(120, 80))
    a = render(scene, spp=16, seed=1, threads=2).pixels
    b = render(scene, spp=16, seed=2, threads=2).pixels
    assert a.tobytes() != b.tobytes()
    assert abs(a.mean() - b.mean()) < 0.01 * a.mean()


@pytest.mark.parametrize("sampler, adaptive", [("jittered", False), ("jittered", True), ("sobol", True)])
def test_lens_system_is_bit_identical_for_one_and_two_threads(sampler, adaptive):
    """The lens system's batched trace (32 rays in lockstep, gathered across a
    tile's pixels) and its exit-pupil tables must not make the image depend on
    how tiles fall to threads; nor must the adaptive passes (jittered draws a
    second set, sobol continues its sequences).

    Large enough (150 tiles, 0.3-0.7 s a render here) and rendered twice on two
    threads because a busy machine can leave the second thread asleep until a
    small render is done: then both renders ran on one thread and prove
    nothing. (Checked by making the lens weight depend on the thread index, on
    a loaded machine: 120 x 80 at 8 spp caught it in 1 trial of 8; this test
    caught it in 12 runs of 12.)"""
    scene = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(360, 240), lens="dgauss.50mm")
    one = render(scene, model="lens", sampler=sampler, spp=16, seed=7, threads=1, adaptive=adaptive)
    assert np.all(np.isfinite(one.pixels)) and one.pixels.max() > 0
    if adaptive:
        assert one.metadata["adaptive"]["pixels_refined"] > 0
    for _ in range(2):
        two = render(scene, model="lens", sampler=sampler, spp=16, seed=7, threads=2, adaptive=adaptive)
        assert one.pixels.tobytes() == two.pixels.tobytes()
        if adaptive:
            assert one.metadata["adaptive"] == two.metadata["adaptive"]


@pytest.mark.parametrize("sampler", ["jittered", "sobol", "regular", "poisson"])
def test_moving_scene_is_bit_identical_for_one_and_two_threads(sampler):
    """Time samples come from each pixel's own streams too: a moving scene
    (objects and the camera, through the thin lens) does not depend on threads."""
    from dataclasses import replace

    scene = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(resolution=(120, 80), velocity=(0.2, 0, 0))
    scene = replace(scene, objects=tuple(replace(o, velocity=(1.0, 0.5, -1.0)) if i in (1, 2) else o
                                         for i, o in enumerate(scene.objects))).with_render(shutter_s=(0.0, 0.04))
    one = render(scene, model="thin", sampler=sampler, spp=8, seed=7, threads=1)
    two = render(scene, model="thin", sampler=sampler, spp=8, seed=7, threads=2)
    assert one.pixels.tobytes() == two.pixels.tobytes()
    assert np.all(np.isfinite(one.pixels))
