"""The render loop asks the pinhole and the thin lens for kCameraBatch rays at
a time, made side by side in SIMD lanes in single precision
(thin_lens_lanes.h); each batch must give generate_ray's rays (double, the
reference) to float rounding, whatever the camera's frame."""

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


# A float's relative rounding (2^-24). The batch's coordinates come within
# 2.7 of them of the reference (measured, these frames); a bug would not.
FLOAT_EPS = 2.0 ** -24
ROUNDINGS = 6


@pytest.mark.parametrize("model", ["pinhole", "thin"])
@pytest.mark.parametrize("position, look_at", FRAMES)
def test_batched_rays_are_generate_rays_to_float_rounding(model, position, look_at):
    scene = parse_scene(camera_scene_text(model=model, position=position, look_at=look_at, resolution=(360, 240)))
    camera = camera_for(scene, model).native()
    rng = np.random.default_rng(3)
    raster = (rng.random((N_SAMPLES, 2)) * [360, 240]).astype(np.float32)
    raster[:4] = [[0, 0], [360, 240], [180, 120], [359.99997, 0.5]]
    lens = rng.random((N_SAMPLES, 2)).astype(np.float32)
    origin, direction, weight = _rays(_native.generate_rays, camera, raster, lens)
    batch_origin, batch_direction, batch_weight = _rays(diagnostics.generate_rays_batched, camera, raster, lens)
    assert np.isfinite(direction).all() and (weight > 0).all()
    assert batch_weight.tobytes() == weight.tobytes()
    # Single precision: each coordinate within a few float roundings of the
    # double reference, scaled by what it is made of (position, lens point, 1).
    scale = np.abs(origin).max() + 1.0
    assert np.abs(batch_origin - origin).max() <= ROUNDINGS * FLOAT_EPS * scale
    assert np.abs(batch_direction - direction).max() <= ROUNDINGS * FLOAT_EPS
    assert np.abs(np.linalg.norm(batch_direction, axis=1) - 1.0).max() <= ROUNDINGS * FLOAT_EPS
    if model == "pinhole":  # every ray from the centre, exactly
        assert batch_origin.tobytes() == origin.tobytes()
