"""The per-tile cull of camera rays (native/src/cameras/camera_pencil.h): a ball that some ray of
the tile meets is never culled, whatever the camera, aperture and focus; and balls well clear of
the tile's rays are culled, so that the cull does cull. Rays are the cameras' own (generate_rays,
in double), tens of thousands per tile; the render-level check (cull on and off, the same bits)
is in test_packet_cull.py."""

from __future__ import annotations

import numpy as np
import pytest

from lenscompare import _native
from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.scene import parse_scene

from helpers import camera_scene_text

TILE_PX = (200.0, 40.0, 216.0, 56.0)  # x0, y0, x1, y1 of a 360 x 240 film: off-centre, near the top
N_RAYS = 40000
N_BALLS = 3000

CAMERAS = {
    "pinhole": dict(model="pinhole"),
    "thin f/2 focused at 2 m": dict(model="thin", f_number=2.0, focus_distance=2.0),
    # A wide aperture focused near: the pencil narrows to its waist at 0.3 m, then widens again
    "thin f/1 focused at 0.3 m": dict(model="thin", f_number=1.0, focus_distance=0.3),
    "thin f/1.4 focused far": dict(model="thin", f_number=1.4, focus_distance=1e4),
    # Five blades: the aperture reaches past the circle of the same area
    "thin f/1, five blades": dict(model="thin", f_number=1.0, focus_distance=1.0,
                                  extra_camera='aperture_blades = 5\naperture_rotation_deg = 17.0\n'),
}


def _camera(options):
    options = dict(options)
    extra = options.pop("extra_camera", "")
    text = camera_scene_text(position=(0.3, 1.7, -2.0), look_at=(-1.0, 0.25, 4.0), resolution=(360, 240),
                             **options)
    if extra:
        text = text.replace("[render]", extra + "\n[render]")
    scene = parse_scene(text)
    return camera_for(scene, options["model"]).native()


def _tile_rays(camera, rng):
    x0, y0, x1, y1 = TILE_PX
    raster = np.column_stack([rng.uniform(x0, x1, N_RAYS), rng.uniform(y0, y1, N_RAYS)]).astype(np.float32)
    lens = rng.random((N_RAYS, 2)).astype(np.float32)
    lens[:64] = np.column_stack([np.linspace(0, 1, 64), np.ones(64) * 0.999]).astype(np.float32)  # the rim
    origin, direction, weight = np.zeros((N_RAYS, 3)), np.zeros((N_RAYS, 3)), np.zeros(N_RAYS, np.float32)
    _native.generate_rays(camera, raster, lens, origin, direction, weight)
    assert (weight > 0).all()
    return origin, direction


def _distances(origin, direction, centres):
    """Each centre's distance to the nearest ray (t >= 0), brute force."""
    out = np.full(len(centres), np.inf)
    for start in range(0, len(centres), 100):
        c = centres[start:start + 100, None, :]
        f = c - origin[None, :, :]
        t = np.maximum(np.einsum("bra,ra->br", f, direction), 0.0)
        gap = f - t[..., None] * direction[None, :, :]
        out[start:start + 100] = np.sqrt(np.einsum("bra,bra->br", gap, gap)).min(axis=1)
    return out


def _balls(origin, direction, rng):
    """Balls round points on the rays (0 to 12 m along), nudged sideways by up to twice their
    radius (radii from 1 mm to 1 m): about half touch the ray they were put by, the rest lie
    near it; and balls anywhere within 15 m: most far from the tile's rays, some behind the lens."""
    pick = rng.integers(0, len(origin), N_BALLS)
    along_m = rng.uniform(0.0, 12.0, N_BALLS)
    radius_m = 10.0 ** rng.uniform(-3, 0, N_BALLS)
    sideways = rng.normal(size=(N_BALLS, 3))
    sideways /= np.linalg.norm(sideways, axis=1, keepdims=True)
    centres = (origin[pick] + along_m[:, None] * direction[pick]
               + sideways * (radius_m * rng.uniform(0.0, 2.0, N_BALLS))[:, None])
    scattered = origin[0] + rng.uniform(-15.0, 15.0, (N_BALLS, 3))
    centres = np.vstack([centres, scattered]).astype(np.float32)
    radius_m = np.concatenate([radius_m, 10.0 ** rng.uniform(-3, 0, N_BALLS)]).astype(np.float32)
    return np.column_stack([centres, radius_m]).astype(np.float32)


def _assert_pencil_keeps_every_ball_met(camera, origin, direction, balls):
    """No ball a ray meets is culled; returns the balls' gaps to the rays and which were kept."""
    kept = np.zeros(len(balls), bool)
    diagnostics.pencil_may_meet(camera, *TILE_PX, balls, kept)
    gap_m = _distances(origin, direction, balls[:, :3].astype(np.float64))
    met = gap_m <= balls[:, 3]
    assert met.sum() > 1000  # the check has teeth
    assert kept[met].all(), f"{(~kept[met]).sum()} balls a ray meets were culled"
    return gap_m, kept


@pytest.mark.parametrize("name", list(CAMERAS))
def test_no_ball_a_ray_meets_is_culled_and_far_ones_are(name):
    camera = _camera(CAMERAS[name])
    rng = np.random.default_rng(11)
    origin, direction = _tile_rays(camera, rng)
    balls = _balls(origin, direction, rng)
    gap_m, kept = _assert_pencil_keeps_every_ball_met(camera, origin, direction, balls)
    # Balls clear of every sampled ray by a metre or more: the pencil's box is tight enough to cull them
    clear = gap_m > balls[:, 3] + 1.0
    assert clear.sum() > 1000
    assert (~kept[clear]).mean() > 0.95


@pytest.mark.parametrize("name", ["thin f/1 focused at 0.3 m", "thin f/1, five blades"])
def test_a_dispersive_thin_lens_pencil_holds_every_wavelength(name):
    """Each wavelength aims at its own plane of focus (the spectral render's rays,
    generate_shared_ray_rows): the tile's pencil spans them all. An exaggerated dispersion,
    the plane of focus from 0.25 m at 380 nm to 5 m at 780 nm."""
    camera = _camera(CAMERAS[name])
    camera.set_dispersion(np.linspace(1.0 / 0.25, 1.0 / 5.0, 401))
    SAMPLES = N_RAYS // 4  # four rays each
    rng = np.random.default_rng(12)
    x0, y0, x1, y1 = TILE_PX
    raster = np.column_stack([rng.uniform(x0, x1, SAMPLES), rng.uniform(y0, y1, SAMPLES)]).astype(np.float32)
    lens = rng.random((SAMPLES, 2)).astype(np.float32)
    hero = rng.uniform(380.0, 780.0, SAMPLES)
    nm = np.stack([380.0 + (hero - 380.0 + 100.0 * k) % 400.0 for k in range(4)], axis=1).astype(np.float32)
    origin, direction, own = np.zeros((4 * SAMPLES, 3)), np.zeros((4 * SAMPLES, 3)), np.zeros(4 * SAMPLES, bool)
    diagnostics.generate_thin_rays_sharing(camera, raster, lens, nm, True, origin, direction, own)
    assert own.reshape(-1, 4)[:, 1:].mean() > 0.5  # most secondaries trace their own ray
    origin, direction = origin[own], direction[own]
    _assert_pencil_keeps_every_ball_met(camera, origin, direction, _balls(origin, direction, rng))


def test_balls_wholly_behind_the_lens_are_culled_and_ones_round_it_are_not():
    camera = _camera(CAMERAS["thin f/2 focused at 2 m"])
    position = np.array([0.3, 1.7, -2.0])
    forward = np.array([-1.0, 0.25, 4.0]) - position
    forward /= np.linalg.norm(forward)
    balls = np.array([[*(position - 2.0 * forward), 1.0],   # behind, clear of the lens plane
                      [*(position - 0.5 * forward), 1.0],   # round the lens: rays start inside it
                      [*position, 1e-3]], np.float32)       # a tiny one at the lens centre
    kept = np.zeros(3, bool)
    diagnostics.pencil_may_meet(camera, *TILE_PX, balls, kept)
    assert kept.tolist() == [False, True, True]


def test_a_ball_with_a_coordinate_not_finite_is_kept():
    camera = _camera(CAMERAS["pinhole"])
    balls = np.array([[np.inf, 0.0, 0.0, 1.0], [0.0, np.nan, 0.0, 1.0], [0.0, 0.0, 5.0, np.inf]], np.float32)
    kept = np.zeros(3, bool)
    diagnostics.pencil_may_meet(camera, *TILE_PX, balls, kept)
    assert kept.all()
