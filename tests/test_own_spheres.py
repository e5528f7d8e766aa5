"""The render's own test for still spheres (native sphere_lanes.cpp), which
replaces Embree's for scenes of at most 32 of them.

Truth is the ray-sphere quadratic solved in extended precision (numpy's
longdouble) from the very float32 rays and spheres the kernel sees. Every
kernel (one per instruction set) must give the same bits, and a render with
the own test must match one where Embree intersects the spheres to within
the rounding of hit distances.
"""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
import pytest

from helpers import REFERENCE_SCENES
from lenscompare._native import diagnostics

RNG = np.random.default_rng(11)
_RNG_START = RNG.bit_generator.state


@pytest.fixture(autouse=True)
def _draws_of_its_own():
    """Every test starts the module's RNG afresh: what it draws does not hang on which tests
    ran before it in the same pytest-xdist worker."""
    RNG.bit_generator.state = _RNG_START


KERNELS = diagnostics.sphere_kernels()


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def spheres_of(n: int) -> np.ndarray:
    """n spheres, radius 1 mm to 1 km (tiny and huge), centres up to 100 m from the origin."""
    centre = RNG.uniform(-100.0, 100.0, (n, 3))
    radius = np.exp(RNG.uniform(np.log(1e-3), np.log(1e3), n))
    return np.column_stack([centre, radius]).astype(np.float32)


def rays_past(spheres: np.ndarray, ratio: np.ndarray):
    """Unit rays whose line passes a random sphere's centre at ratio x its radius, nearest 1-20 m (plus the
    radius) along the ray; ratio near 1 grazes."""
    n = len(ratio)
    k = RNG.integers(0, len(spheres), n)
    centre, radius = spheres[k, :3].astype(np.float64), spheres[k, 3].astype(np.float64)
    direction = unit(RNG.normal(size=(n, 3)))
    side = unit(np.cross(direction, RNG.normal(size=(n, 3))))
    along = RNG.uniform(1.0, 20.0, n) + radius
    origin = centre + side * (ratio * radius)[:, None] - direction * along[:, None]
    return origin.astype(np.float32), direction.astype(np.float32)


def rays_from_inside(spheres: np.ndarray, n: int):
    k = RNG.integers(0, len(spheres), n)
    centre, radius = spheres[k, :3].astype(np.float64), spheres[k, 3].astype(np.float64)
    offset = unit(RNG.normal(size=(n, 3))) * (radius * RNG.uniform(0.0, 0.99, n))[:, None]
    return (centre + offset).astype(np.float32), unit(RNG.normal(size=(n, 3))).astype(np.float32)


def truth(spheres: np.ndarray, origin: np.ndarray, direction: np.ndarray):
    """Nearest t >= 0 per ray and sphere (inf: none), and each root's discriminant scale, in longdouble."""
    ld = np.longdouble
    f = origin.astype(ld)[:, None, :] - spheres[None, :, :3].astype(ld)
    d = direction.astype(ld)[:, None, :]
    r = spheres[None, :, 3].astype(ld)
    a = (d * d).sum(-1)
    b = (f * d).sum(-1)
    perp = f - (b / a)[..., None] * d
    disc = r * r - (perp * perp).sum(-1)
    root = np.sqrt(np.maximum(disc, 0) * a)
    t_lo, t_hi = (-b - root) / a, (-b + root) / a
    t = np.where(t_lo >= 0, t_lo, t_hi)
    t = np.where((disc >= 0) & (t >= 0), t, np.inf)
    # how close the ray is to grazing, relative to the rounding of a double evaluation
    scale = (f * f).sum(-1) + r * r
    return t, disc, scale


def closest(spheres, origin, direction, kernel, t_far=None):
    n = len(origin)
    t = np.full(n, np.inf, np.float32) if t_far is None else np.asarray(t_far, np.float32).copy()
    index = np.zeros(n, np.int32)
    normal = np.zeros((n, 3), np.float32)
    diagnostics.own_spheres_closest(spheres, origin, direction, t, index, normal, kernel)
    return t, index, normal


def test_hits_match_the_quadratic_in_extended_precision_grazing_and_from_inside():
    spheres = spheres_of(6)
    n = 6000
    ratio = np.concatenate([RNG.uniform(0.0, 1.0, n // 3), 1.0 - np.logspace(-7, -2, n // 6),
                            1.0 + np.logspace(-7, -2, n // 6), RNG.uniform(1.0, 3.0, n // 3)])
    o1, d1 = rays_past(spheres, ratio)
    o2, d2 = rays_from_inside(spheres, 2000)
    origin, direction = np.concatenate([o1, o2]), np.concatenate([d1, d2])
    t_true, disc, scale = truth(spheres, origin, direction)
    nearest = np.argmin(t_true, axis=1)
    t_best = t_true[np.arange(len(origin)), nearest]
    # Rays within double rounding of tangency may go either way: the only ones allowed to disagree.
    tangent = (np.abs(disc) <= 1e-13 * scale).any(axis=1)
    t, index, normal = closest(spheres, origin, direction, KERNELS[-1])
    assert np.isfinite(t[index >= 0]).all() and not np.isnan(normal).any()
    hit_true = np.isfinite(t_best)
    assert ((index >= 0) == hit_true)[~tangent].all(), f"{np.count_nonzero(((index >= 0) != hit_true) & ~tangent)}"
    both = (index >= 0) & hit_true & ~tangent
    assert both.sum() > 4000 and (~hit_true).sum() > 300 and tangent.sum() < 50  # hits, misses; few undecidable
    assert (index[both] == nearest[both]).all()
    # t is the float nearest the true distance
    assert np.all(np.abs(t[both] - t_best[both].astype(np.float64)) <= 1.5 * np.spacing(t[both]))
    # the outward unit normal at the true hit point
    hit_point = origin[both].astype(np.longdouble) + direction[both].astype(np.longdouble) * t_best[both][:, None]
    normal_true = (hit_point - spheres[index[both], :3]) / spheres[index[both], 3][:, None]
    assert np.abs(normal[both] - normal_true.astype(np.float64)).max() < 1e-5
    # from inside the sphere hit: the far root, the normal pointing along the ray (outward)
    to_origin = origin.astype(np.float64) - spheres[index, :3]
    inside = both & (np.linalg.norm(to_origin, axis=1) < 0.999 * spheres[index, 3])
    assert inside.sum() > 1000
    assert (np.einsum("ij,ij->i", normal[inside], direction[inside]) > 0).all()


def test_a_nearer_hit_already_found_is_kept():
    spheres = np.array([[0.0, 0.0, 5.0, 1.0]], np.float32)
    origin = np.zeros((2, 3), np.float32)
    direction = np.array([[0, 0, 1], [0, 0, 1]], np.float32)
    t, index, _ = closest(spheres, origin, direction, KERNELS[-1], t_far=[3.0, 4.5])
    assert t.tolist() == [3.0, 4.0] and index.tolist() == [-1, 0]


@pytest.mark.skipif(len(KERNELS) < 2, reason="this CPU runs one sphere kernel only")
def test_every_kernel_gives_the_same_bits():
    spheres = spheres_of(16)
    ratio = np.concatenate([RNG.uniform(0.0, 3.0, 3000), 1.0 - np.logspace(-7, -2, 1000), 1.0 + np.logspace(-7, -2, 1000)])
    origin, direction = rays_past(spheres, ratio)
    results = {k: closest(spheres, origin, direction, k) for k in KERNELS}
    t_far = RNG.uniform(0.0, 200.0, len(origin)).astype(np.float32)
    start = RNG.integers(-1, 16, len(origin)).astype(np.int32)
    self_blocks = RNG.random(len(origin)) < 0.5
    blocked = {}
    for k in KERNELS:
        blocked[k] = np.zeros(len(origin), bool)
        diagnostics.own_spheres_occluded(spheres, origin, direction, t_far, start, self_blocks, blocked[k], k)
    base = KERNELS[0]
    for k in KERNELS[1:]:
        for a, b in zip(results[k], results[base]):
            assert np.array_equal(a.view(np.uint32) if a.dtype == np.float32 else a,
                                  b.view(np.uint32) if b.dtype == np.float32 else b), k
        assert np.array_equal(blocked[k], blocked[base]), k


def surface_rays(sphere: np.ndarray, n: int, *, outward: bool):
    """Shadow rays from points on the sphere, lifted as the render lifts them (1e-4 x the coordinates,
    scene_trace.cpp) along the normal facing the viewer: outward, or inward for a view from inside."""
    normal = unit(RNG.normal(size=(n, 3)))
    point = sphere[:3].astype(np.float64) + sphere[3] * normal
    facing = normal if outward else -normal
    lift = 1e-4 * np.maximum(np.abs(point).max(axis=1), 1.0)
    origin = (point + facing * lift[:, None]).astype(np.float32)
    toward = unit(facing + RNG.uniform(0.0, 20.0, n)[:, None] * unit(np.cross(facing, RNG.normal(size=(n, 3)))))
    return origin, toward.astype(np.float32), point, facing


def occluded(spheres, origin, direction, t_far, start, self_blocks, kernel):
    out = np.zeros(len(origin), bool)
    diagnostics.own_spheres_occluded(spheres, origin, direction, np.asarray(t_far, np.float32),
                                     np.asarray(start, np.int32), np.asarray(self_blocks, bool), out, kernel)
    return out


@pytest.mark.parametrize("radius", [1e-3, 0.35, 1e3])
def test_a_shadow_ray_leaving_its_own_sphere_is_not_blocked_by_it(radius):
    sphere = np.array([[0.3, 0.35 + radius, 3.0, radius]], np.float32)
    n = 4000
    origin, direction, _, _ = surface_rays(sphere[0], n, outward=True)
    out = occluded(sphere, origin, direction, np.full(n, 50.0), np.zeros(n), np.zeros(n, bool), KERNELS[-1])
    assert not out.any()


def test_a_shadow_ray_from_inside_is_blocked_exactly_when_its_light_is_outside():
    sphere = np.array([[0.0, 1.0, 4.0, 2.0]], np.float32)
    n = 2000
    origin, direction, _, _ = surface_rays(sphere[0], n, outward=False)
    # the render knows which: self_blocks is "leaves the inner side toward a light outside"
    light_outside = RNG.random(n) < 0.5
    out = occluded(sphere, origin, direction, np.full(n, 3.0), np.zeros(n), light_outside, KERNELS[-1])
    assert np.array_equal(out, light_outside)


def test_other_spheres_block_a_segment_only_when_it_crosses_their_surface():
    spheres = np.array([[0.0, 0.0, 5.0, 1.0], [0.0, 0.0, 20.0, 0.001]], np.float32)
    origin = np.zeros((5, 3), np.float32)
    direction = np.tile(np.array([0, 0, 1], np.float32), (5, 1))
    t_far = [3.9, 4.1, 19.0, 19.9995, 30.0]  # short of the big sphere (z = 4 to 6), into it, through it, ...
    out = occluded(spheres, origin, direction, t_far, [-1] * 5, [False] * 5, KERNELS[-1])
    assert out.tolist() == [False, True, True, True, True]
    # past the big one: the tiny one's near surface (z = 19.999) only
    beyond = np.array([[0, 0, 7.0]] * 2, np.float32)
    out = occluded(spheres, beyond, direction[:2], [12.998, 12.9995], [-1, -1], [False, False], KERNELS[-1])
    assert out.tolist() == [False, True]
    inner = np.array([[0, 0, 4.5]] * 2, np.float32)
    out = occluded(spheres, inner, direction[:2], [1.0, 1.6], [-1, -1], [False, False], KERNELS[-1])
    assert out.tolist() == [False, True]  # inside, the segment ends inside; or crosses out at z = 6


RENDER = """
import sys, numpy as np
from lenscompare.render import render
from lenscompare.scene import load_scene
scene = load_scene(sys.argv[1]).with_camera(resolution=(120, 80))
for model in ("pinhole", "thin"):
    np.save(f"{sys.argv[2]}_{model}.npy", render(scene, model=model, spp=8, seed=3, threads=2).pixels)
"""


@pytest.mark.parametrize("scene", ["showcase", "lit_showcase"])
def test_renders_match_embree_spheres_to_hit_rounding(tmp_path, scene):
    """LENSCOMPARE_MAX_OWN_SPHERES=0 hands the spheres back to Embree (float arithmetic, an approximate
    reciprocal): the images may differ by the rounding of hit points only, not by a lost hit or shadow."""
    images = {}
    for own in ("0", "16"):
        env = dict(os.environ, LENSCOMPARE_MAX_OWN_SPHERES=own)
        path = REFERENCE_SCENES / f"{scene}.toml"
        subprocess.run([sys.executable, "-c", RENDER, str(path), str(tmp_path / own)], env=env, check=True)
        images[own] = {m: np.load(tmp_path / f"{own}_{m}.npy").astype(np.float64) for m in ("pinhole", "thin")}
    for model in ("pinhole", "thin"):
        embree, own = images["0"][model], images["16"][model]
        assert own.max() > 0 and np.isfinite(own).all()
        difference = np.abs(own - embree)
        assert difference.max() < 1e-4 and difference.sum() < 1e-6 * embree.sum(), (model, difference.max())
