"""The boxes' faces the render's own quad tests skip (native solid_faces.cpp).

From a point outside a box and behind one face's plane, that face is never
the first hit (camera rays skip it); a face the light is behind blocks no
segment ending at that light that the box's other faces do not (shadow rays
skip it). Truth is brute force: the own quad test on every face, against the
same test on the faces kept; and renders, which the skips must not change.
"""

from __future__ import annotations

import numpy as np
import pytest

from helpers import REFERENCE_SCENES, REPO
from lenscompare import native_scene
from lenscompare._native import diagnostics
from lenscompare.native_scene import box_quads, rectangle_quad
from lenscompare.render import render
from lenscompare.scene import load_scene

RNG = np.random.default_rng(31)
_RNG_START = RNG.bit_generator.state


@pytest.fixture(autouse=True)
def _draws_of_its_own():
    """Every test starts the module's RNG afresh: what it draws does not hang on which tests
    ran before it in the same pytest-xdist worker."""
    RNG.bit_generator.state = _RNG_START


LANES = 16


def box(lo, hi):
    return np.asarray(box_quads(lo, hi), np.float32)


def outward_normals(lo, hi):
    """The six faces' outward normals in box_quads' order (-x, +x, -y, +y, -z, +z)."""
    return np.array([[-1, 0, 0], [1, 0, 0], [0, -1, 0], [0, 1, 0], [0, 0, -1], [0, 0, 1]], float)


def offsets(lo, hi):
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return np.array([-lo[0], hi[0], -lo[1], hi[1], -lo[2], hi[2]])


def kept(mask: int, n: int) -> np.ndarray:
    return np.array([(mask >> k) & 1 for k in range(n)], bool)


def closest(corners, origin, direction):
    t = np.full(len(origin), np.inf, np.float32)
    index = np.zeros(len(origin), np.int32)
    diagnostics.own_quads_closest(np.ascontiguousarray(corners, np.float32), origin, direction, t, index,
                                  "default")
    return t, index


def occluded(corners, origin, direction, t_far):
    out = np.zeros(len(origin), bool)
    if len(corners):
        diagnostics.own_quads_occluded(np.ascontiguousarray(corners, np.float32), origin, direction,
                                       np.asarray(t_far, np.float32), out, "default")
    return out


def random_box():
    lo = RNG.uniform(-3, 3, 3)
    return lo, lo + RNG.uniform(0.2, 2.0, 3)


def point_outside(lo, hi, *, gap_m=0.05):
    """A point outside the box and at least gap_m from every face's plane."""
    while True:
        p = RNG.uniform(lo - 3.0, hi + 3.0)
        outside = (p < lo - gap_m) | (p > hi + gap_m)
        near_plane = (np.abs(p - lo) < gap_m) | (np.abs(p - hi) < gap_m)
        if outside.any() and not near_plane.any():
            return p


def test_a_point_outside_keeps_exactly_the_faces_it_is_in_front_of():
    for _ in range(200):
        lo, hi = random_box()
        p = point_outside(lo, hi)
        quads = np.concatenate([box(lo, hi), rectangle_quad([9, 9, 9], [1, 0, 0], [0, 1, 0])[None]]).astype(np.float32)
        solid = np.array([0] * 6 + [-1], np.int32)
        mask = diagnostics.solid_faces_first_hits(quads, solid, p[None].astype(np.float32))
        in_front = outward_normals(lo, hi) @ p > offsets(lo, hi)
        assert (kept(mask, 7) == np.append(in_front, True)).all(), (lo, hi, p)
        # A light at p: the faces it is in front of, the same
        assert diagnostics.solid_faces_blocking(quads, solid, tuple(p)) == mask


def test_origins_inside_touching_or_straddling_keep_what_they_may_hit():
    lo, hi = np.zeros(3), np.ones(3)
    quads, solid = box(lo, hi), np.zeros(6, np.int32)
    inside = RNG.uniform(0.1, 0.9, (LANES, 3)).astype(np.float32)
    assert kept(diagnostics.solid_faces_first_hits(quads, solid, inside), 6).all()
    # One origin inside among outside ones: every face
    mixed = np.array([[0.5, 0.5, 0.5]] + [[0.5, 3.0, 0.5]] * 15, np.float32)
    assert kept(diagnostics.solid_faces_first_hits(quads, solid, mixed), 6).all()
    # On a face's plane (the top's, y = 1, beside the box): that face stays
    on_plane = np.array([[3.0, 1.0, 0.5]], np.float32)
    assert kept(diagnostics.solid_faces_first_hits(quads, solid, on_plane), 6)[3]
    # Origins on both sides of the top's plane: the top stays, the bottom goes
    straddle = np.array([[0.5, 2.0, -1.0], [3.0, 0.5, -1.0]], np.float32)
    mask = kept(diagnostics.solid_faces_first_hits(quads, solid, straddle), 6)
    assert mask[3] and not mask[2]
    # A NaN origin: no box to decide by, every face
    assert kept(diagnostics.solid_faces_first_hits(quads, solid, np.full((1, 3), np.nan, np.float32)), 6).all()


def box_seen_from_outside():
    """A random box (as quads, one solid) and a point outside it, 0.2 m clear of its planes."""
    lo, hi = random_box()
    return lo, hi, box(lo, hi), np.zeros(6, np.int32), point_outside(lo, hi, gap_m=0.2)


def aimed_at_box(lo, hi, origin, n):
    """Unit directions from origin toward points on and about the box, many of them at its edges."""
    targets = RNG.uniform(lo - 0.1, hi + 0.1, (n, 3))
    # Half of them snapped onto an edge (two coordinates at a bound): ties and grazes
    half = n // 2
    axes = RNG.integers(0, 3, half)
    for i, a in enumerate(axes):
        for b in range(3):
            if b != a:
                targets[i, b] = (lo if RNG.random() < 0.5 else hi)[b]
    d = targets.astype(np.float32).astype(float) - origin
    return (d / np.linalg.norm(d, axis=1, keepdims=True)).astype(np.float32)


# 1048 and 2048: seeds under which a first widening of the own quads' margins for grazing
# rays (past a box's edges too) let a hidden face report a hit a hair nearer
@pytest.mark.parametrize("seed", [31, 1048, 2048])
def test_no_skipped_face_is_nearer_than_the_first_hit_of_the_faces_kept(seed):
    RNG.bit_generator.state = np.random.default_rng(seed).bit_generator.state
    tested = hits = 0
    for _ in range(150):
        lo, hi, quads, solid, centre = box_seen_from_outside()
        # One packet: origins within 1 cm of one point (a lens aperture's spread)
        origin = (centre + RNG.uniform(-0.01, 0.01, (LANES, 3))).astype(np.float32)
        mask = kept(diagnostics.solid_faces_first_hits(quads, solid, origin), 6)
        direction = aimed_at_box(lo, hi, centre, LANES)
        t_all, index_all = closest(quads, origin, direction)
        t_kept, _ = closest(quads[mask], origin, direction)
        assert np.array_equal(t_all, t_kept)
        met = index_all >= 0
        tested += LANES
        hits += met.sum()
        # Off the edges the face met is one kept (on an edge, a tie may go to the other face)
        assert mask[index_all[met]].mean() > 0.9
    assert hits > 0.3 * tested


def test_no_skipped_face_blocks_a_segment_toward_the_light_that_the_kept_faces_do_not():
    blocked = total = 0
    for _ in range(150):
        lo, hi, quads, solid, light = box_seen_from_outside()
        mask = kept(diagnostics.solid_faces_blocking(quads, solid, tuple(light.astype(np.float32))), 6)
        # Segments from points all round the box (some on its faces) to the light
        start = RNG.uniform(lo - 2.0, hi + 2.0, (64, 3))
        on_face = RNG.random(64) < 0.3
        axis = RNG.integers(0, 3, 64)
        for i in np.flatnonzero(on_face):
            start[i, axis[i]] = (lo if RNG.random() < 0.5 else hi)[axis[i]]
            start[i] = np.clip(start[i], lo, hi)
        inside = ((start > lo) & (start < hi)).all(axis=1)
        start = start[~inside].astype(np.float32)
        to_light = light.astype(np.float32).astype(float) - start
        length = np.linalg.norm(to_light, axis=1)
        direction = (to_light / length[:, None]).astype(np.float32)
        t_far = (length * 0.999).astype(np.float32)
        every = occluded(quads, start, direction, t_far)
        assert np.array_equal(every, occluded(quads[mask], start, direction, t_far))
        blocked += every.sum()
        total += len(start)
    assert 0.1 * total < blocked < 0.9 * total


@pytest.fixture
def without_solids(monkeypatch):
    """Scenes built without saying which quads are a box's faces: nothing skipped."""
    real = native_scene._native

    class Native:
        def __getattr__(self, name):
            return getattr(real, name)

        @staticmethod
        def Scene(*args, quad_solid=None, **kwargs):
            return real.Scene(*args, **kwargs)

    return lambda: monkeypatch.setattr(native_scene, "_native", Native())


@pytest.mark.parametrize("path", [REFERENCE_SCENES / "lit_showcase.toml", REPO / "bench" / "scenes" / "peers_lit.toml"],
                         ids=["lit_showcase", "peers_lit"])
@pytest.mark.parametrize("model", ["pinhole", "thin"])
def test_skipping_hidden_faces_changes_no_image(monkeypatch, without_solids, path, model):
    scene = load_scene(path).with_camera(resolution=(96, 64))
    monkeypatch.setenv("LENSCOMPARE_MAX_OWN_QUADS", "64")  # the own test for every quad, either way
    skipped = render(scene, model=model, spp=8, threads=2, progress=False).pixels
    without_solids()
    every = render(scene, model=model, spp=8, threads=2, progress=False).pixels
    assert np.isfinite(skipped).all()
    assert np.array_equal(skipped, every)
