"""The render's own test for still quads (native quad_lanes.cpp: boxes' faces
and rectangles, all parallelograms), which replaces Embree's for scenes where a
ray meets at most 16 of them (three faces of a box).

Truth is the ray-plane intersection in extended precision (numpy's
longdouble) from the very float32 rays and corners the kernel sees. Rays aimed
at an edge two quads share must hit one of them (no gap: Embree needs its
robust mode for that), every kernel must give the same bits, and a render with
the own test must match one where Embree intersects the quads.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import REFERENCE_SCENES, REPO
from lenscompare._native import diagnostics
from lenscompare.native_scene import box_quads, rectangle_quad
from lenscompare.render import render
from lenscompare.scene import load_scene

RNG = np.random.default_rng(23)
_RNG_START = RNG.bit_generator.state


@pytest.fixture(autouse=True)
def _draws_of_its_own():
    """Every test starts the module's RNG afresh: what it draws does not hang on which tests
    ran before it in the same pytest-xdist worker."""
    RNG.bit_generator.state = _RNG_START


KERNELS = diagnostics.sphere_kernels()


def unit(v: np.ndarray) -> np.ndarray:
    return v / np.linalg.norm(v, axis=1, keepdims=True)


def closest(corners, origin, direction, kernel="default", t_far=None, first_quad=0):
    n = len(origin)
    t = np.full(n, np.inf, np.float32) if t_far is None else np.asarray(t_far, np.float32).copy()
    index = np.zeros(n, np.int32)
    diagnostics.own_quads_closest(np.ascontiguousarray(corners, np.float32), origin, direction, t, index, kernel,
                                  first_quad)
    return t, index


def occluded(corners, origin, direction, t_far, kernel="default"):
    out = np.zeros(len(origin), bool)
    diagnostics.own_quads_occluded(np.ascontiguousarray(corners, np.float32), origin, direction,
                                   np.asarray(t_far, np.float32), out, kernel)
    return out


def slanted_pair(size_m: float, offset_m: float, rng: np.random.Generator = RNG) -> np.ndarray:
    """Two parallelograms sharing an edge, not in one plane, at any scale."""
    c = rng.uniform(-1, 1, 3) * offset_m
    e1, e2, e3 = (rng.normal(size=(3, 3)) * size_m)
    return np.array([rectangle_quad(c - e1, e1, e2), rectangle_quad(c, e3, e2)], np.float32)


def split_pair(size_m: float, offset_m: float) -> np.ndarray:
    """One parallelogram cut in two along a line parallel to its edge e2: the halves share that line's
    float corners, and any ray across the whole must cross one of them."""
    c = RNG.uniform(-1, 1, 3) * offset_m
    e1, e2 = (RNG.normal(size=(2, 3)) * size_m)
    s = RNG.uniform(0.3, 0.7)
    cut = (c + s * e1).astype(np.float32).astype(np.float64)
    return np.array([[c, cut, cut + e2, c + e2], [cut, c + e1, c + e1 + e2, cut + e2]], np.float32)


def crossing(corners: np.ndarray, origin: np.ndarray, direction: np.ndarray):
    """Where float rays really cross the planes of parallelograms (corners: one 4 x 3 per ray, or one
    for all), in extended precision: the distance t and the coordinates (u, v) along the edges from
    corner 0 to corners 1 and 3, as float64."""
    ld = np.longdouble
    corners = np.broadcast_to(np.asarray(corners, np.float32).astype(ld), (len(origin), 4, 3))
    v0, e1, e2 = corners[:, 0], corners[:, 1] - corners[:, 0], corners[:, 3] - corners[:, 0]
    n = np.cross(e1, e2)
    t = np.sum((v0 - origin.astype(ld)) * n, axis=1) / np.sum(direction.astype(ld) * n, axis=1)
    p = origin.astype(ld) + t[:, None] * direction.astype(ld) - v0
    g11, g12, g22 = np.sum(e1 * e1, axis=1), np.sum(e1 * e2, axis=1), np.sum(e2 * e2, axis=1)
    b1, b2 = np.sum(p * e1, axis=1), np.sum(p * e2, axis=1)
    det = g11 * g22 - g12 * g12
    return t.astype(float), ((g22 * b1 - g12 * b2) / det).astype(float), ((g11 * b2 - g12 * b1) / det).astype(float)


def rays_at(points: np.ndarray, distance_m: float):
    """Rays from random directions toward the given points, each distance_m away."""
    direction = unit(RNG.normal(size=points.shape)).astype(np.float32)
    origin = (points.astype(np.float64) - direction * distance_m).astype(np.float32)
    return origin, direction


@pytest.mark.parametrize("seed", [0, 1, 2, 3])
@pytest.mark.parametrize("size_m,offset_m", [(1e-3, 1.0), (1.0, 0.0), (1.0, 100.0), (1e3, 10.0), (1e-2, 10.0)])
def test_rays_across_a_shared_edge_hit_one_of_its_quads(size_m, offset_m, seed):
    """Down to grazing: the halves' planes differ by their corners' rounding, so a ray crossing the
    edge at a slope s meets them up to (a few float steps) / s apart along it; a fixed margin let
    1 to 3 % of rays within 1 degree of the plane through (and 6 in 10^5 at 3 to 11 degrees)."""
    RNG.bit_generator.state = np.random.default_rng(seed).bit_generator.state
    quads = split_pair(size_m, offset_m)
    a, b = quads[0, 1].astype(np.float64), quads[0, 2].astype(np.float64)  # the shared edge's ends
    s = RNG.uniform(0.001, 0.999, 20000)[:, None]
    points = (a + s * (b - a)).astype(np.float32)
    origin, direction = rays_at(points, 3.0 * size_m)
    # Down to the slope the margins widen to (quad_lanes.h: sin 1/256), and only rays that really
    # cross the shared edge between its ends: the float origin moves a grazing ray's crossing (by
    # float steps over the slope), on coarse quads off the pair's end (along v)
    normal = unit(np.cross(quads[0, 1] - quads[0, 0], quads[0, 3] - quads[0, 0]).astype(np.float64)[None])[0]
    slope = np.abs(direction @ normal)
    _, _, v = crossing(quads[0], origin, direction)
    kept = (slope > 1.0 / 256.0) & (v > 1e-3) & (v < 1.0 - 1e-3)
    assert kept.sum() > 18000
    origin, direction, slope = origin[kept], direction[kept], slope[kept]
    t, index = closest(quads, origin, direction)
    assert np.all(index >= 0), f"{np.sum(index < 0)} of {len(index)} rays slipped through the shared edge"
    # Where: at the aimed-at point, give or take the origin's rounding (float steps of the offset)
    # and the quads' (of their largest coordinate) over the slope
    float_steps_m = 20 * 2.0**-24 * (max(offset_m, 1.0) + 3.0 * size_m)
    assert np.all(np.isclose(t, 3.0 * size_m, rtol=1e-4, atol=0.0) | (np.abs(t - 3.0 * size_m) <= float_steps_m / slope))


def test_rays_into_a_box_across_its_edges_and_corners_hit_it():
    lo, hi = np.array([-1.3, 0.2, 4.0]), np.array([0.7, 1.9, 4.6])
    quads = box_quads(lo, hi).astype(np.float32)
    corners = quads.reshape(-1, 3).astype(np.float64)
    pick = RNG.integers(0, len(corners), (40000, 2))
    s = RNG.uniform(0.0, 1.0, 40000)[:, None]
    points = corners[pick[:, 0]] + s * (corners[pick[:, 1]] - corners[pick[:, 0]])
    on_edge = np.sum(np.isclose(points, lo) | np.isclose(points, hi), axis=1) >= 2
    # A hair inside, so that every ray from outside toward the point crosses the surface at an edge
    inside = points[on_edge] + 1e-6 * ((lo + hi) / 2 - points[on_edge])
    origin, direction = rays_at(inside, 5.0)
    outside = np.any((origin < lo) | (origin > hi), axis=1)
    t, index = closest(quads, origin[outside], direction[outside])
    assert len(t) > 1000
    assert np.all(index >= 0), f"{np.sum(index < 0)} of {len(index)} rays slipped into the box"
    assert np.all(t <= 5.0 * (1 + 1e-5))


# Seeds of their own: the module's RNG state depends on which tests ran before in the same
# pytest worker.
@pytest.mark.parametrize("seed", [23, 1, 2])
def test_hits_match_extended_precision_and_rays_past_the_edges_miss(seed):
    rng = np.random.default_rng(seed)
    quads = np.concatenate([slanted_pair(10 ** rng.uniform(-2, 2), 50.0, rng) for _ in range(4)])
    k = rng.integers(0, len(quads), 8000)
    uv = rng.uniform(0.01, 0.99, (8000, 2))
    past = rng.random(8000) < 0.5
    uv[past, 0] = rng.uniform(1.01, 2.0, past.sum())  # past the edge e1 reaches
    ld = np.longdouble
    corners = quads[k].astype(ld)  # the edges from the float corners exactly, as the kernel takes them
    v0, e1, e2 = corners[:, 0], corners[:, 1] - corners[:, 0], corners[:, 3] - corners[:, 0]
    target = v0 + uv[:, :1] * e1 + uv[:, 1:] * e2
    scale = np.linalg.norm(quads[k, 1] - quads[k, 0], axis=1).astype(np.float64)
    direction = unit(rng.normal(size=(8000, 3))).astype(np.float32)
    origin = (target.astype(np.float64) - direction * (2.0 * scale)[:, None]).astype(np.float32)
    # Where each float ray really crosses the plane: a grazing ray's rounded origin moves its
    # crossing far from the target (by an origin step over the cosine).
    t_true, u_real, v_real = crossing(quads[k], origin, direction)
    inside = (u_real > 1e-3) & (u_real < 1 - 1e-3) & (v_real > 1e-3) & (v_real < 1 - 1e-3)
    outside = (u_real > 1 + 1e-3) | (u_real < -1e-3) | (v_real > 1 + 1e-3) | (v_real < -1e-3)
    assert inside.sum() > 3000 and outside.sum() > 3000
    for i in range(0, 8000, 1000):  # one quad at a time, so no other quad is in the way
        sl = slice(i, i + 1000)
        for q in np.unique(k[sl]):
            rows = np.flatnonzero(k[sl] == q) + i
            t, index = closest(quads[q:q + 1], origin[rows], direction[rows])
            hit, miss = inside[rows], outside[rows]
            assert np.all(index[hit] == 0) and np.all(index[miss] == -1)
            assert np.allclose(t[hit], t_true[rows][hit], rtol=3e-7)


def test_rays_in_the_plane_or_never_reaching_it_miss_without_nan():
    quad = np.array([rectangle_quad([0.0, 0.0, 5.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0])], np.float32)
    origin = np.array([[-1.0, 0.5, 5.0], [0.5, 0.5, 4.0], [0.5, 0.5, 4.0], [0.5, 0.5, 6.0]], np.float32)
    direction = np.array([[1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]], np.float32)
    t, index = closest(quad, origin, direction)
    assert np.all(index == -1) and np.all(np.isinf(t))
    assert not occluded(quad, origin, direction, np.full(4, 10.0)).any()


def test_a_segment_is_blocked_exactly_when_it_crosses():
    quad = np.array([rectangle_quad([-1.0, -1.0, 5.0], [2.0, 0.0, 0.0], [0.0, 2.0, 0.3])], np.float32)
    origin = np.zeros((3, 3), np.float32)
    direction = np.array([[0.0, 0.0, 1.0]] * 3, np.float32)
    # The plane is at z = 5.15 on the axis: ending before it, across it, starting past it
    origin[2, 2] = 6.0
    blocked = occluded(quad, origin, direction, np.array([5.0, 5.3, 3.0]))
    assert blocked.tolist() == [False, True, False]


def test_every_kernel_gives_the_same_bits():
    quads = np.concatenate([slanted_pair(1.0, 20.0) for _ in range(6)])
    target = quads[RNG.integers(0, len(quads), 4000), 0] + RNG.normal(size=(4000, 3)).astype(np.float32)
    origin, direction = rays_at(target.astype(np.float32), 7.0)
    results = {kernel: closest(quads, origin, direction, kernel) for kernel in KERNELS}
    blocked = {kernel: occluded(quads, origin, direction, np.full(4000, 7.0), kernel) for kernel in KERNELS}
    first = KERNELS[0]
    for kernel in KERNELS[1:]:
        assert np.array_equal(results[kernel][0], results[first][0])
        assert np.array_equal(results[kernel][1], results[first][1])
        assert np.array_equal(blocked[kernel], blocked[first])


def test_the_quad_tested_first_changes_no_hit():
    """A render tests first the quad its last packet met: ties (rays at a box's edges, where two faces
    meet at one float distance) still go to the lower index, and every hit is the same. Each packet is
    16 copies of one ray at an edge, so that the plane cull of the face tested second sees only a ray
    ending on its plane: it must not drop that face when its hit rounds to the same float."""
    lo, hi = np.array([-4.0, -0.1, -1.0]), np.array([4.0, 0.0, 12.0])  # lit_showcase's floor slab
    quads = box_quads(lo, hi).astype(np.float32)
    rays = []
    for a in range(3):  # the twelve edges: along axis a, at one of the four corners across
        for corner in range(4):
            across = [b for b in range(3) if b != a]
            end_lo = np.where([False] * 3, hi, lo).astype(float)
            end_lo[across[0]] = (lo, hi)[corner & 1][across[0]]
            end_lo[across[1]] = (lo, hi)[corner >> 1][across[1]]
            outward = np.sign(end_lo - (lo + hi) / 2)
            outward[a] = 0.0
            s = RNG.uniform(0.01, 0.99, (256, 1, 1))
            points = np.repeat(end_lo + s * np.eye(3)[a] * (hi[a] - lo[a]), 16, axis=1)
            toward = -unit(outward[None] + RNG.uniform(-0.3, 0.3, (256, 3)) * (outward != 0))
            direction = np.repeat(toward[:, None], 16, axis=1).astype(np.float32)
            origin = (points - direction * 6.0).astype(np.float32)
            rays.append((origin.reshape(-1, 3), direction.reshape(-1, 3)))
    origin = np.concatenate([o for o, _ in rays])
    direction = np.concatenate([d for _, d in rays])
    baseline = closest(quads, origin, direction)
    assert np.all(baseline[1] >= 0)
    for first in range(1, len(quads)):
        t, index = closest(quads, origin, direction, first_quad=first)
        assert np.array_equal(t, baseline[0]) and np.array_equal(index, baseline[1]), f"first quad {first}"
    ties = 0
    for k in range(len(quads)):  # the rays whose hit another quad matches exactly
        alone, _ = closest(quads[k:k + 1], origin, direction)
        ties += np.sum((alone == baseline[0]) & (baseline[1] != k))
    assert ties > 1000, "the rays should meet ties at the edges"


def test_a_quad_that_is_not_a_parallelogram_is_refused():
    quad = rectangle_quad([0.0, 0.0, 5.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]).astype(np.float32)
    quad[2] += 0.1
    with pytest.raises(ValueError, match="not a parallelogram"):
        closest(quad[None], np.zeros((1, 3), np.float32), np.array([[0.0, 0.0, 1.0]], np.float32))


@pytest.mark.parametrize("path", [REFERENCE_SCENES / "showcase.toml", REFERENCE_SCENES / "lit_showcase.toml",
                                  REPO / "bench" / "scenes" / "peers_lit.toml"],
                         ids=["showcase", "lit_showcase", "peers_lit"])
def test_renders_match_embree_quads(monkeypatch, path):
    scene = load_scene(path).with_camera(resolution=(120, 80))
    images = {}
    for own in ("16", "0"):  # peers_lit: 25 quads, 13 met
        monkeypatch.setenv("LENSCOMPARE_MAX_OWN_QUADS", own)
        images[own] = render(scene, model="thin", spp=16, threads=2, progress=False).pixels
    ours, embree = images["16"], images["0"]
    assert np.isfinite(ours).all()
    assert abs(ours.mean() - embree.mean()) < 1e-5 * embree.mean()
    # A sample at a hair from an edge or a checker line may land on the other side: a few pixels
    differ = np.abs(ours - embree).max(axis=2) > 1e-3
    assert differ.mean() < 1e-3


@pytest.mark.parametrize("objects", ["rectangle", "sphere", "both"])
def test_the_depth_buffer_sees_own_quads_and_spheres_alone_or_together(objects):
    """The depth buffer's one-ray query asks the own spheres and quads only when the scene has them (a call
    with none would read a primitive that is not there)."""
    from lenscompare.cameras import camera_for
    from lenscompare.postfilter.depth import depth_buffer_m
    from lenscompare.scene import parse_scene

    parts = {
        "rectangle": '[[objects]]\ntype = "rectangle"\ncorner = [-5.0, -5.0, 4.0]\nedge1 = [10.0, 0.0, 0.0]\n'
                     'edge2 = [0.0, 10.0, 0.0]\nmaterial = "m"\n',
        "sphere": '[[objects]]\ntype = "sphere"\ncenter = [0.0, 0.0, 3.0]\nradius = 0.5\nmaterial = "m"\n',
    }
    body = parts["rectangle"] + parts["sphere"] if objects == "both" else parts[objects]
    scene = parse_scene('name = "depth"\n[camera]\nmodel = "pinhole"\nposition = [0.0, 0.0, 0.0]\n'
                        'look_at = [0.0, 0.0, 1.0]\nfocal_length_mm = 50.0\nf_number = 2.8\nfocus_distance = 3.0\n'
                        'film_mm = [36.0, 24.0]\nresolution = [36, 24]\n[materials.m]\ntype = "emissive"\n'
                        'color = [1.0, 1.0, 1.0]\n' + body)
    depth = depth_buffer_m(scene, camera_for(scene, "pinhole"), threads=1)
    expected = 4.0 if objects == "rectangle" else 2.5  # the centre pixel: the wall, or the sphere's front
    assert depth[12, 18] == pytest.approx(expected, rel=1e-3)


def test_no_quads_and_no_spheres_are_no_hits():
    origin = np.zeros((3, 3), np.float32)
    direction = np.tile(np.array([0.0, 0.0, 1.0], np.float32), (3, 1))
    t, index = closest(np.zeros((0, 4, 3), np.float32), origin, direction)
    assert np.all(index == -1) and np.all(np.isinf(t))
    assert not occluded(np.zeros((0, 4, 3), np.float32), origin, direction, np.ones(3)).any()
    t_far, index, normal = np.full(3, np.inf, np.float32), np.zeros(3, np.int32), np.zeros((3, 3), np.float32)
    diagnostics.own_spheres_closest(np.zeros((0, 4), np.float32), origin, direction, t_far, index, normal,
                                    KERNELS[-1])
    assert np.all(index == -1) and np.all(np.isinf(t_far))
