"""A dispersive thin lens's rays in the spectral render: the batch in float
(generate_shared_ray_rows, session 28) against the one-sample reference in
double (generate_rays_sharing)."""

from pathlib import Path

import numpy as np
import pytest

from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.render import render
from lenscompare.render_spectral import inverse_focus_per_m
from lenscompare.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
DISPERSIVE_LENS = ROOT / "tests" / "data" / "lenses" / "dgauss_abbe.dat"


def _scene(resolution=(36, 24), **camera):
    showcase = load_scene(ROOT / "reference_scenes" / "showcase.toml")
    return showcase.with_camera(resolution=resolution, lens=str(DISPERSIVE_LENS), focal_length_mm=None, **camera)


def _native_camera(scene, disk_mapping):
    camera = camera_for(scene, "thin")
    native = camera.native(disk_mapping=disk_mapping)
    native.set_dispersion(inverse_focus_per_m(scene.camera.lens, film_distance_mm=camera.film_distance_mm,
                                              focal_length_mm=camera.focal_length_mm))
    return native


def _rays(camera, raster, lens, nm, batched):
    n = 4 * len(raster)
    out = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, dtype=bool)
    diagnostics.generate_thin_rays_sharing(camera, raster, lens, nm, batched, *out)
    return out


@pytest.mark.parametrize("disk_mapping", ["concentric", "polar"])
@pytest.mark.parametrize("blades", [0, 6])
def test_batched_sharing_rays_are_the_one_sample_rays(disk_mapping, blades):
    # Fine pixels, so that many secondaries leave their pixel and trace their own ray.
    camera = _native_camera(_scene(resolution=(720, 480), aperture_blades=blades), disk_mapping)
    rng = np.random.default_rng(28)
    count = 32 * 40 + 7  # whole batches and a partial one
    raster = (rng.random((count, 2)) * [720, 480]).astype(np.float32)
    lens = rng.random((count, 2)).astype(np.float32)
    hero = rng.uniform(380.0, 780.0, count)
    nm = np.stack([380.0 + (hero - 380.0 + 100.0 * k) % 400.0 for k in range(4)], axis=1).astype(np.float32)
    scalar = _rays(camera, raster, lens, nm, batched=False)
    batched = _rays(camera, raster, lens, nm, batched=True)
    # The same decisions: which wavelengths ride on the hero's ray and which trace their own.
    np.testing.assert_array_equal(batched[2], scalar[2])
    own = scalar[2].reshape(-1, 4)
    assert own[:, 0].all() and 0.05 < own[:, 1:].mean() < 0.95  # both kinds are tested
    # The same rays to float rounding (a few ulp of the metre-scale origins and unit directions).
    assert np.abs(batched[0] - scalar[0]).max() < 1e-6
    assert np.abs(batched[1] - scalar[1]).max() < 1e-6
    # A secondary's own ray is not the hero's: the batch really traced it.
    by_sample = scalar[1].reshape(-1, 4, 3)
    assert np.abs(by_sample[own[:, 1], 1] - by_sample[own[:, 1], 0]).max() > 1e-4


def test_a_dispersive_thin_lens_render_keeps_its_guarantees():
    scene = _scene().with_render(spectral=True)
    one = render(scene, model="thin", spp=16, threads=1, progress=False)
    two = render(scene, model="thin", spp=16, threads=2, progress=False)
    assert one.metadata["spectral"]["camera_disperses"]
    np.testing.assert_array_equal(one.pixels, two.pixels)
    assert np.isfinite(one.pixels).all() and one.pixels.mean() > 0
    # The thick lens is the thin lens at its front principal plane, in spectral renders too.
    thick = render(scene, model="thick", spp=16, threads=2, progress=False)
    np.testing.assert_array_equal(thick.pixels, one.pixels)
