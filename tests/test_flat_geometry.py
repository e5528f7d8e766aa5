"""Checker cells: a convex polygon cut along the native checker's cube boundaries."""

import numpy as np
import pytest

from lenscompare.flat_geometry import checker_parity, split_by_checker
from lenscompare.scene import Checker


def _area(polygon):
    total = sum(np.cross(polygon[i] - polygon[0], polygon[i + 1] - polygon[0]) for i in range(1, len(polygon) - 1))
    return 0.5 * np.linalg.norm(total)


@pytest.mark.parametrize("seed", range(5))
def test_tilted_polygon_pieces_cover_it_and_have_one_parity_each(seed):
    """Pieces of a random tilted quad: areas add up, and random points inside each piece
    all have the piece's parity under the native rule floor(p / s + 0.001)."""
    rng = np.random.default_rng(seed)
    corner, e1, e2 = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3)
    quad = np.array([corner, corner + e1, corner + e1 + e2, corner + e2])
    checker = Checker(color=(0.0, 0.0, 0.0), size_m=0.3)
    pieces = split_by_checker(quad, checker)
    assert len(pieces) > 4
    assert sum(_area(p) for p, _ in pieces) == pytest.approx(_area(quad), rel=1e-9)
    for polygon, odd in pieces:
        weights = rng.dirichlet(np.ones(len(polygon)), size=20)
        assert all(checker_parity(w @ polygon, checker.size_m) == odd for w in weights)


def test_floor_at_y_zero_is_not_cut_along_y():
    """The tolerance puts the boundary at y = -0.001 s, not at the floor's y = 0."""
    floor = np.array([[0.05, 0.0, 0.05], [0.35, 0.0, 0.05], [0.35, 0.0, 0.35], [0.05, 0.0, 0.35]])
    pieces = split_by_checker(floor, Checker(color=(0.0, 0.0, 0.0), size_m=0.1))
    assert len(pieces) == 16  # x and z cut at 0.0999, 0.1999, 0.2999
    assert not checker_parity([0.01, 0.0, 0.01], 0.1)
