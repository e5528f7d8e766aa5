"""The shape of a lens aperture: a circle, or a regular N-blade diaphragm of
the same area (DESIGN.md: ``camera.aperture_blades``, ``aperture_rotation_deg``).

Orientation, shared with the native samplers (``native/src/aperture.h``): the
lens seen from behind, x right and y up (camera space); vertex 0 points up
(+y) at rotation 0, and a positive rotation turns the polygon
counter-clockwise. A point behind the plane of focus images the aperture
upright in the picture; one in front of it, turned by 180 degrees.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = ["polygon_circumradius", "polygon_apothem", "aperture_vertices", "inside_aperture",
           "second_moment_diameter_ratio"]


def polygon_circumradius(blades: int, *, radius: float = 1.0) -> float:
    """Circumradius of the regular ``blades``-gon whose area is that of the
    circle of ``radius``: N R² sin(2π/N) / 2 = π r².

    Examples
    --------
    >>> round(polygon_circumradius(6), 6)
    1.099636
    """
    return radius * math.sqrt(2.0 * math.pi / (blades * math.sin(2.0 * math.pi / blades)))


def polygon_apothem(blades: int, *, radius: float = 1.0) -> float:
    """Distance from the centre to each edge of that polygon."""
    return polygon_circumradius(blades, radius=radius) * math.cos(math.pi / blades)


def aperture_vertices(blades: int, rotation_deg: float = 0.0, *, radius: float = 1.0) -> np.ndarray:
    """The N-gon's vertices, (N, 2), counter-clockwise from the one at
    90° + ``rotation_deg``; same area as the circle of ``radius``."""
    if blades < 3:
        raise ValueError(f"a polygon needs at least 3 blades, got {blades}")
    angles = math.radians(90.0 + rotation_deg) + 2.0 * math.pi * np.arange(blades) / blades
    r = polygon_circumradius(blades, radius=radius)
    return np.stack([r * np.cos(angles), r * np.sin(angles)], axis=-1)


def inside_aperture(x, y, *, blades: int, rotation_deg: float = 0.0, radius: float = 1.0) -> np.ndarray:
    """Whether points (x, y) lie in the aperture (boundary included): the
    circle of ``radius`` for ``blades`` 0, else the N-gon of its area."""
    x, y = np.asarray(x, dtype=float), np.asarray(y, dtype=float)
    if blades == 0:
        return x * x + y * y <= radius * radius
    apothem = polygon_apothem(blades, radius=radius)
    # Edge k's outward normal points between vertices k and k + 1.
    normal = math.radians(90.0 + rotation_deg) + math.pi / blades + 2.0 * math.pi * np.arange(blades) / blades
    inside = np.ones(np.broadcast(x, y).shape, dtype=bool)
    for a in normal:
        inside &= x * math.cos(a) + y * math.sin(a) <= apothem
    return inside


def second_moment_diameter_ratio(blades: int) -> float:
    """The N-gon's second-moment diameter over the circle's of the same area:
    a uniform N-gon of circumradius R has E[r²] = R² (2 + cos(2π/N)) / 6, the
    circle r² / 2. 1 for ``blades`` 0; 1.0996 for a triangle, 1.0038 for a
    hexagon.

    Examples
    --------
    >>> round(second_moment_diameter_ratio(5), 4)
    1.0085
    """
    if blades == 0:
        return 1.0
    r2 = polygon_circumradius(blades) ** 2
    return math.sqrt(r2 * (2.0 + math.cos(2.0 * math.pi / blades)) / 3.0)
