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
