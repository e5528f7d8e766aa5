"""Drawing a lens prescription in cross-section, and real rays through it.

Both thick-lens and lens-system figures use these.  Coordinates are the lens
frame of :mod:`lenscompare.lenses.trace`: z along the axis in mm from the first
vertex, positive toward the film; y the height in mm.  Every ray drawn lies in
the meridional plane x = 0, so a point is ``(z, y)``.

The geometry functions (:func:`surface_profile_mm`, :func:`element_outlines_mm`,
:func:`stop_bar_mm`, :func:`traced_paths`) are pure and tested; the ``draw_*``
functions only hand their numbers to matplotlib.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..lenses import Prescription, sag_mm, trace_from_scene
from . import _style

__all__ = [
    "RayPath", "surface_profile_mm", "rim_z_mm", "element_outlines_mm", "stop_bar_mm",
    "traced_paths", "draw_lens", "draw_ray_paths",
]

_PROFILE_SAMPLES = 81


@dataclass(frozen=True)
class RayPath:
    """A real ray in the meridional plane.

    Attributes
    ----------
    points_mm : numpy.ndarray, shape (K, 2)
        ``(z, y)`` of the start, every surface crossed, and the end: the end
        plane for a ray that got through, the point where it was blocked
        otherwise.
    passed : bool
        True when the ray got through every surface.
    blocked_at : int or None
        Index of the surface that stopped the ray (None when it passed).
    """

    points_mm: np.ndarray
    passed: bool
    blocked_at: int | None


def surface_profile_mm(prescription: Prescription, index: int, *,
                       samples: int = _PROFILE_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """``(z, y)`` of surface ``index`` across its clear aperture, y from -h to +h."""
    surface = prescription.surfaces[index]
    y = np.linspace(-surface.semi_aperture_mm, surface.semi_aperture_mm, samples)
    z = prescription.vertex_z_mm[index] + sag_mm(surface.curvature_per_mm, y)
    return z, y


def rim_z_mm(prescription: Prescription, index: int) -> float:
    """Axial position of the rim (edge of the clear aperture) of surface ``index``."""
    surface = prescription.surfaces[index]
    return prescription.vertex_z_mm[index] + float(
        sag_mm(surface.curvature_per_mm, surface.semi_aperture_mm))


def element_outlines_mm(prescription: Prescription) -> list[tuple[int, np.ndarray]]:
    """Closed outlines of the glass, one per medium between two surfaces.

    Returns ``(i, polygon)`` for every surface i followed by glass
    (``n_after > 1``); the polygon, shape (M, 2) of ``(z, y)``, runs down the
    front surface i, along the edge, and up the back surface i + 1.  When
    the two surfaces have different semi-apertures the smaller one gets a
    flat annulus out to the larger, as on a real element.
    """
    outlines = []
    surfaces = prescription.surfaces
    for i in range(len(surfaces) - 1):
        if surfaces[i].n_after <= 1.0:
            continue
        z_front, y_front = surface_profile_mm(prescription, i)
        z_back, y_back = surface_profile_mm(prescription, i + 1)
        h_front, h_back = surfaces[i].semi_aperture_mm, surfaces[i + 1].semi_aperture_mm
        h_edge = max(h_front, h_back)
        rim_front, rim_back = rim_z_mm(prescription, i), rim_z_mm(prescription, i + 1)
        # Up the front surface, across the top edge, down the back, along the bottom.
        points = [np.column_stack([z_front, y_front])]
        if h_front < h_edge:
            points.append([[rim_front, h_edge]])
        if h_back < h_edge:
            points.append([[rim_back, h_edge]])
        points.append(np.column_stack([z_back[::-1], y_back[::-1]]))
        if h_back < h_edge:
            points.append([[rim_back, -h_edge]])
        if h_front < h_edge:
            points.append([[rim_front, -h_edge]])
        outlines.append((i, np.vstack(points)))
    return outlines


def stop_bar_mm(prescription: Prescription) -> tuple[float, float, float] | None:
    """``(z, inner, outer)`` of the aperture stop's blades, or None without a stop.

    ``inner`` is the stop's semi-aperture; the blade reaches out past the
    neighbouring elements so that it reads as a diaphragm.
    """
    index = prescription.stop_index
    if index is None:
        return None
    surfaces = prescription.surfaces
    inner = surfaces[index].semi_aperture_mm
    neighbours = [surfaces[j].semi_aperture_mm for j in (index - 1, index + 1)
                  if 0 <= j < len(surfaces)]
    largest = max(s.semi_aperture_mm for s in surfaces)
    outer = max(1.12 * max(neighbours, default=inner), inner * 1.25, inner + 0.08 * largest)
    return prescription.vertex_z_mm[index], inner, outer


def traced_paths(prescription: Prescription, origins_mm, directions, *,
                 end_z_mm: float) -> list[RayPath]:
    """Real rays from the scene side, surface by surface (``trace_from_scene``).

    Parameters
    ----------
    prescription : Prescription
    origins_mm, directions : array_like, shape (N, 3)
        Rays in the lens frame, in front of the first surface, heading +z.
        Only their y and z are drawn (give x = 0).
    end_z_mm : float
        Rays that get through are drawn up to this plane (e.g. the film).

    Returns
    -------
    list of RayPath
        A blocked ray ends where it meets the blocking surface's sphere (on
        the stop's blade, or just outside an element's clear aperture, where
        its mount is); when even the unclipped sphere refuses it (total
        internal reflection), on the plane of that surface's rim.
    """
    origins = np.atleast_2d(np.asarray(origins_mm, dtype=float))
    directions = np.atleast_2d(np.asarray(directions, dtype=float))
    count = len(prescription.surfaces)
    hits, leaving, alive = [], [], []
    for k in range(count):
        rays = trace_from_scene(prescription, origins, directions, last=k)
        hits.append(rays.origins_mm)
        leaving.append(rays.directions)
        alive.append(rays.passed)
    unit = directions / np.linalg.norm(directions, axis=1)[:, None]

    paths = []
    for r in range(len(origins)):
        points = [origins[r, 1:]]
        point, direction = origins[r], unit[r]
        blocked_at = None
        for k in range(count):
            if not alive[k][r]:
                blocked_at = k
                break
            point, direction = hits[k][r], leaving[k][r]
            points.append(point[1:])
        if blocked_at is None:
            end = point + direction * (end_z_mm - point[2]) / direction[2]
        else:
            end = _blocked_end(prescription, origins[r], directions[r], blocked_at, point,
                               direction)
        points.append(end[1:])
        # Stored as (z, y).
        paths.append(RayPath(np.array(points)[:, ::-1].copy(), blocked_at is None, blocked_at))
    return paths


def _blocked_end(prescription, origin, direction, k, point, leaving):
    """Where a ray blocked at surface k is drawn to end (see :func:`traced_paths`)."""
    unclipped = trace_from_scene(prescription, origin, direction, clip=False, last=k)
    if bool(unclipped.passed):
        return unclipped.origins_mm
    rim = rim_z_mm(prescription, k)
    t = (rim - point[2]) / leaving[2] if leaving[2] else 0.0
    return point + leaving * max(t, 0.0)


def draw_lens(ax, prescription: Prescription) -> None:
    """Glass filled, every surface outlined, the aperture stop as black blades."""
    for i, polygon in element_outlines_mm(prescription):
        ax.fill(polygon[:, 0], polygon[:, 1], facecolor=_style.GLASS_FILL,
                edgecolor=_style.GLASS_EDGE, lw=0.9, zorder=1, gid=f"glass-{i}")
    for index, surface in enumerate(prescription.surfaces):
        if surface.is_stop:
            continue
        z, y = surface_profile_mm(prescription, index)
        glass = surface.n_after > 1.0 or prescription.n_before(index) > 1.0
        # A surface in air on both sides (a baffle) is drawn thin and grey.
        ax.plot(z, y, color=_style.GLASS_EDGE if glass else _style.MUTED,
                lw=0.9 if glass else 0.7, zorder=1.1, gid=f"surface-{index}")
    bar = stop_bar_mm(prescription)
    if bar is not None:
        z, inner, outer = bar
        for sign in (1.0, -1.0):
            ax.plot([z, z], [sign * inner, sign * outer], color=_style.STOP, lw=2.6,
                    solid_capstyle="butt", zorder=3, gid="aperture-stop")


def draw_ray_paths(ax, paths: list[RayPath], color: str, *, gid: str, lw: float = 0.9,
                   label: str | None = None, blocked_label: str | None = None) -> None:
    """Rays that pass in full colour; blocked rays thin, lighter, ending in a small bar."""
    for path in paths:
        z, y = path.points_mm[:, 0], path.points_mm[:, 1]
        if path.passed:
            ax.plot(z, y, color=color, lw=lw, zorder=2, gid=f"{gid}-passed", label=label)
            label = None
        else:
            ax.plot(z, y, color=color, lw=0.6 * lw, alpha=0.45, zorder=2, gid=f"{gid}-blocked",
                    label=blocked_label)
            ax.plot(z[-1], y[-1], marker="|", ms=5, mew=1.2, color=color, alpha=0.7, zorder=2.1,
                    markeredgecolor=color)
            blocked_label = None
