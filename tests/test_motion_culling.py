"""The render asks Embree about moving spheres only for rays that may meet one.

The culling test (native motion.cpp) puts each sphere where it is at the ray's
own time and measures the distance from its centre to the ray's segment. It
must keep every ray that meets a sphere, grazing ones included (else moving
spheres would lose pixels or shadows), and it should drop rays that pass well
clear, behind their origin or beyond their end (else it buys nothing). Truth
here is the segment-sphere distance in double precision.
"""

from __future__ import annotations

import numpy as np
import pytest

from lenscompare._native import diagnostics

# Each test draws from its own generator, so what it draws does not hang on
# which tests ran before it in the same pytest-xdist worker.
def rng_of(seed: int) -> np.random.Generator:
    return np.random.default_rng(seed)


def random_rays(rng, n: int, spheres: np.ndarray, *, distance_over_radius: np.ndarray):
    """Rays whose line passes sphere k's centre, at the ray's time, at the given multiple of its radius,
    nearest at t = 1..20 m along a unit direction from an origin anywhere in a 20 m box."""
    k = rng.integers(0, len(spheres), n)
    time = rng.random(n).astype(np.float32)
    start, end, radius = spheres[k, 0:3], spheres[k, 3:6], spheres[k, 6]
    centre = start + time[:, None] * (end - start)
    direction = rng.normal(size=(n, 3))
    direction /= np.linalg.norm(direction, axis=1, keepdims=True)
    side = np.cross(direction, rng.normal(size=(n, 3)))
    side /= np.linalg.norm(side, axis=1, keepdims=True)
    nearest_t = rng.uniform(1.0, 20.0, n)
    origin = centre + side * (distance_over_radius * radius)[:, None] - direction * nearest_t[:, None]
    return (origin.astype(np.float32), direction.astype(np.float32), nearest_t, time, k)


def may_hit(spheres, origin, direction, t_max, time) -> np.ndarray:
    out = np.zeros(len(origin), dtype=bool)
    diagnostics.moving_spheres_may_hit(spheres, origin, direction, np.asarray(t_max, np.float32), time, out)
    return out


def spheres_of(rng, n: int) -> np.ndarray:
    """n spheres (radius 1 mm to 0.5 m) moving up to 2 m over the shutter, up to 100 m from the origin."""
    start = rng.uniform(-100.0, 100.0, (n, 3))
    end = start + rng.uniform(-2.0, 2.0, (n, 3))
    radius = np.exp(rng.uniform(np.log(1e-3), np.log(0.5), n))
    return np.column_stack([start, end, radius]).astype(np.float32)


@pytest.mark.parametrize("seed", [7, 8, 9])
def test_every_ray_that_meets_a_sphere_is_kept_grazing_ones_too(seed):
    rng = rng_of(seed)
    spheres = spheres_of(rng, 5)
    n = 20000
    # from deep inside to just past the rim (float32 rounding of the ray decides those)
    ratio = np.concatenate([rng.uniform(0.0, 1.0, n // 2), 1.0 - np.logspace(-7, -3, n // 4),
                            1.0 + np.logspace(-7, -5, n // 4)])
    origin, direction, nearest_t, time, _ = random_rays(rng, n, spheres, distance_over_radius=ratio)
    kept = may_hit(spheres, origin, direction, nearest_t * 2.0, time)
    assert kept.all(), f"{np.count_nonzero(~kept)} rays that meet a sphere were dropped"


@pytest.mark.parametrize("seed", [7, 8, 9])
def test_rays_clear_of_every_sphere_are_dropped(seed):
    rng = rng_of(seed)
    spheres = spheres_of(rng, 1)
    n = 4000
    # Clear by 5 % to 3 radii, plus 1e-4 of the coordinates: the culling test keeps
    # a margin of 2e-5 of them for float32 rounding, which for a 1 mm sphere 100 m
    # out is wider than the sphere (such rays are kept, rightly: it is conservative).
    coordinates_m = 2.0 * np.abs(spheres[0, :6]).max() + 25.0
    clear = rng.uniform(1.05, 3.0, n) + 1e-4 * coordinates_m / spheres[0, 6]
    origin, direction, nearest_t, time, _ = random_rays(rng, n, spheres, distance_over_radius=clear)
    assert not may_hit(spheres, origin, direction, nearest_t * 2.0, time).any()


def test_segments_that_end_before_or_start_past_the_sphere_are_dropped():
    rng = rng_of(7)
    spheres = spheres_of(rng, 1)
    spheres[0, 6] = 0.2
    n = 4000
    origin, direction, nearest_t, time, _ = random_rays(rng, n, spheres, distance_over_radius=np.zeros(n))
    # through the centre, but the segment stops 0.3 m short of the near surface
    assert not may_hit(spheres, origin, direction, nearest_t - 0.5, time).any()
    # ... or starts 0.3 m past the far surface (the line behind the origin meets the sphere)
    beyond = (origin + direction * (nearest_t + 0.5)[:, None]).astype(np.float32)
    assert not may_hit(spheres, beyond, direction, np.full(n, 50.0), time).any()


def test_the_sphere_is_where_it_is_at_the_ray_time():
    """A ray through the sphere's centre at the shutter's open misses it at close, where it has moved 1 m."""
    spheres = np.array([[0.0, 0.0, 5.0, 1.0, 0.0, 5.0, 0.1]], dtype=np.float32)
    origin = np.zeros((2, 3), np.float32)
    direction = np.array([[0.0, 0.0, 1.0]] * 2, np.float32)
    kept = may_hit(spheres, origin, direction, [100.0, 100.0], np.array([0.0, 0.999], np.float32))
    assert kept.tolist() == [True, False]


def test_shadow_rays_leaving_a_sphere_surface_are_dropped():
    """A shadow ray starts 1e-4 x the coordinates off the surface it lights (scene_trace.cpp); from a
    moving sphere's own surface, outward, it cannot meet that sphere, and the test must know it."""
    spheres = np.array([[0.3, 0.35, 3.0, 0.4, 0.35, 3.0, 0.35]], dtype=np.float32)
    n = 4000
    rng = rng_of(7)
    time = rng.random(n).astype(np.float32)
    centre = spheres[0, 0:3] + time[:, None] * (spheres[0, 3:6] - spheres[0, 0:3])
    normal = rng.normal(size=(n, 3))
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    point = centre + 0.35 * normal
    lift = 1e-4 * np.maximum(np.abs(point).max(axis=1), 1.0)
    origin = (point + normal * lift[:, None]).astype(np.float32)
    toward = normal + 0.9 * np.cross(normal, rng.normal(size=(n, 3)))  # any outward direction
    toward /= np.linalg.norm(toward, axis=1, keepdims=True)
    outward = np.einsum("ij,ij->i", toward, normal) > 0.05
    kept = may_hit(spheres, origin[outward], toward[outward].astype(np.float32), np.full(outward.sum(), 10.0),
                   time[outward])
    assert not kept.any()
