"""The render loop asks the pinhole and the thin lens for kCameraBatch rays at
a time, made side by side in SIMD lanes (thin_lens_lanes.h); each batch must
give generate_ray's rays to the last bit, whatever the camera's frame."""

from __future__ import annotations

import numpy as np
import pytest

from lenscompare import _native
from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.scene import parse_scene

from helpers import camera_scene_text

N_SAMPLES = 10007  # not a whole number of batches: the last one is short
FRAMES = [((0.0, 0.0, 0.0), (0.0, 0.0, 1.0)),          # axis-aligned
          ((0.3, 1.7, -2.0), (-1.0, 0.25, 4.0)),       # tilted and off-origin
          ((-0.0, -0.0, -0.0), (0.0, -0.5, 1.0))]      # signed zeros in the origin


def _rays(generate, camera, raster, lens):
    n = len(raster)
    out = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)
    generate(camera, raster, lens, *out)
    return out


@pytest.mark.parametrize("model", ["pinhole", "thin"])
@pytest.mark.parametrize("position, look_at", FRAMES)
def test_batched_rays_are_generate_rays_bit_for_bit(model, position, look_at):
    scene = parse_scene(camera_scene_text(model=model, position=position, look_at=look_at, resolution=(360, 240)))
    camera = camera_for(scene, model).native()
    rng = np.random.default_rng(3)
    raster = (rng.random((N_SAMPLES, 2)) * [360, 240]).astype(np.float32)
    raster[:4] = [[0, 0], [360, 240], [180, 120], [359.99997, 0.5]]
    lens = rng.random((N_SAMPLES, 2)).astype(np.float32)
    one_at_a_time = _rays(_native.generate_rays, camera, raster, lens)
    batched = _rays(diagnostics.generate_rays_batched, camera, raster, lens)
    assert np.isfinite(one_at_a_time[1]).all() and (one_at_a_time[2] > 0).all()
    for a, b in zip(one_at_a_time, batched):
        assert a.tobytes() == b.tobytes()
