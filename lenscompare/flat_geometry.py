"""Flat scene geometry as triangles, for renderers that read triangle meshes.

Boxes, rectangles (and meshes) become triangles; a checker material is cut
along its cube boundaries so that each piece has one colour. The cut is exact
for any plane: the native checker is the parity of floor(p / size + 0.001)
summed over x, y, z (``native/src/scene.cpp``), which is constant inside each
cell of the lattice of planes p_a = (k - 0.001) size, so a convex polygon
split along those planes gives convex pieces of one parity each, whatever its
tilt. Renderers whose checker texture is two-dimensional (Mitsuba's
``checkerboard`` works on UV coordinates) can then draw the solid checker as
two plain colours.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .native_scene import box_quads, rectangle_quad
from .scene import Box, Checker, Mesh, Rectangle, Scene

__all__ = ["CHECKER_TOLERANCE", "TrianglePiece", "flat_pieces", "checker_parity", "split_by_checker"]

CHECKER_TOLERANCE = 0.001
"""The native checker's tolerance: cube index floor(p / size + 0.001) (native/src/scene.cpp)."""


@dataclass(frozen=True)
class TrianglePiece:
    """Triangles of one object that share a material and (with a checker) a parity.

    ``vertices`` is (3 t, 3) float64, m: triangle i is rows 3 i .. 3 i + 2.
    ``odd`` is True where the checker's odd colour applies, None without a checker.
    """

    object_index: int
    material: str
    odd: bool | None
    vertices: np.ndarray


def checker_parity(point_m, size_m: float) -> bool:
    """True where the native checker shows its odd colour (``checker_is_odd``)."""
    cells = np.floor(np.asarray(point_m, dtype=float) / size_m + CHECKER_TOLERANCE)
    return bool(int(cells.sum()) & 1)


def _split(polygon: np.ndarray, axis: int, at: float) -> tuple[np.ndarray | None, np.ndarray | None]:
    """A convex polygon cut by the plane p[axis] = at: (below, above), None for an empty side."""
    below, above = [], []
    n = len(polygon)
    for i in range(n):
        p, q = polygon[i], polygon[(i + 1) % n]
        dp, dq = p[axis] - at, q[axis] - at
        (below if dp <= 0 else above).append(p)
        if (dp < 0 < dq) or (dq < 0 < dp):
            crossing = p + (q - p) * (dp / (dp - dq))
            crossing[axis] = at
            below.append(crossing)
            above.append(crossing.copy())
    return (np.array(below) if len(below) >= 3 else None, np.array(above) if len(above) >= 3 else None)


def _area(polygon: np.ndarray) -> float:
    total = np.zeros(3)
    for i in range(1, len(polygon) - 1):
        total += np.cross(polygon[i] - polygon[0], polygon[i + 1] - polygon[0])
    return 0.5 * float(np.linalg.norm(total))


def split_by_checker(polygon, checker: Checker) -> list[tuple[np.ndarray, bool]]:
    """A convex polygon cut into pieces of one checker parity each: [(polygon, odd), ...]."""
    size, tol = checker.size_m, CHECKER_TOLERANCE
    pieces = [np.asarray(polygon, dtype=float)]
    for axis in range(3):
        cut = []
        for piece in pieces:
            lo, hi = piece[:, axis].min(), piece[:, axis].max()
            # Planes strictly inside the piece: (k - tol) size in (lo, hi).
            first, last = math.floor(lo / size + tol) + 1, math.ceil(hi / size + tol) - 1
            rest = piece
            for k in range(first, last + 1):
                below, rest = _split(rest, axis, (k - tol) * size)
                if below is not None:
                    cut.append(below)
                if rest is None:
                    break
            if rest is not None:
                cut.append(rest)
        pieces = cut
    scale = size * size * 1e-12
    return [(p, checker_parity(p.mean(axis=0), size)) for p in pieces if _area(p) > scale]


def _fan(polygon: np.ndarray) -> np.ndarray:
    """Triangles (3 t, 3) of a convex polygon, in its own winding."""
    return np.concatenate([[polygon[0], polygon[i], polygon[i + 1]] for i in range(1, len(polygon) - 1)])


def flat_pieces(scene: Scene) -> list[TrianglePiece]:
    """Every box, rectangle and mesh of ``scene`` as triangles, grouped per
    object, material and checker parity. Spheres are left out (renderers draw
    them exactly)."""
    pieces = []
    for index, obj in enumerate(scene.objects):
        checker = getattr(scene.materials[obj.material], "checker", None)
        if isinstance(obj, Mesh) and checker is None:  # as it is, without a loop over 100k triangles
            pieces.append(TrianglePiece(index, obj.material, None, obj.polygons.reshape(-1, 3)))
            continue
        if isinstance(obj, Box):
            polygons = list(box_quads(obj.min, obj.max))
        elif isinstance(obj, Rectangle):
            polygons = [rectangle_quad(obj.corner, obj.edge1, obj.edge2)]
        elif isinstance(obj, Mesh):
            polygons = list(obj.polygons)
        else:
            continue
        if checker is None:
            pieces.append(TrianglePiece(index, obj.material, None, np.concatenate([_fan(p) for p in polygons])))
            continue
        by_parity: dict[bool, list[np.ndarray]] = {False: [], True: []}
        for polygon in polygons:
            for piece, odd in split_by_checker(polygon, checker):
                by_parity[odd].append(_fan(piece))
        for odd, triangles in by_parity.items():
            if triangles:
                pieces.append(TrianglePiece(index, obj.material, odd, np.concatenate(triangles)))
    return pieces
