"""Figure: a lens system in cross-section with real ray bundles (paper Fig. 4).

Any prescription: glass filled, the aperture stop as black blades, the exit
pupil from the paraxial data (position and diameter) with the cone it admits
from the axial film point (dotted, as in Kolb et al.'s figure), and the film
at the paraxial focus for the focus distance.  Two bundles from the plane of
focus are traced surface by surface with ``trace_from_scene``: one from the
axis and one off it.  Each bundle spans exactly the rays that get through
(found by a fine scan), plus one ray beyond each edge that does not; blocked
rays are drawn thin and stop where they are blocked (on the stop's blade or at
the edge of the element that vignettes them).

Lens frame: z in mm from the first vertex, positive toward the film.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..lenses import (
    ParaxialData,
    Prescription,
    film_distance_mm,
    front_most_z_mm,
    paraxial_data,
    sag_mm,
    trace_from_scene,
)
from ..units import MM_PER_M
from . import _style
from ._lens_drawing import RayPath, draw_lens, draw_ray_paths, stop_bar_mm, traced_paths

__all__ = ["Bundle", "LensSystemGeometry", "lens_system_geometry", "lens_system_figure",
           "OFF_AXIS_FILM_FRACTION", "FILM_HALF_DIAGONAL_MM"]

# The off-axis object is aimed (paraxially) at this fraction of the half
# diagonal of the default 36 x 24 mm film (DESIGN.md); lenses that do not
# cover that much get a smaller angle (see lens_system_geometry).
FILM_HALF_DIAGONAL_MM = math.hypot(18.0, 12.0)
OFF_AXIS_FILM_FRACTION = 0.7

_SCAN_RAYS = 1201
_RAYS_THROUGH = 9


@dataclass(frozen=True)
class Bundle:
    """Rays from one object point on the plane of focus.

    Attributes
    ----------
    field_angle_deg : float
        Angle of the object point above the axis, seen from the entrance pupil.
    start_heights_mm : numpy.ndarray
        Height of each ray where it crosses the first vertex plane (z = 0).
    paths : tuple of RayPath
        The traced rays, in order of ``start_heights_mm``.
    """

    field_angle_deg: float
    start_heights_mm: np.ndarray
    paths: tuple[RayPath, ...]

    @property
    def film_heights_mm(self) -> np.ndarray:
        """Heights on the film of the rays that get through."""
        return np.array([p.points_mm[-1, 1] for p in self.paths if p.passed])


@dataclass(frozen=True)
class LensSystemGeometry:
    """Everything the lens-system figure draws, in the lens frame (mm)."""

    prescription: Prescription
    paraxial: ParaxialData
    focus_distance_m: float
    film_z_mm: float
    start_z_mm: float
    axial: Bundle
    off_axis: Bundle

    @property
    def exit_pupil(self) -> tuple[float, float] | None:
        """``(z, semi-diameter)`` of the paraxial exit pupil; None when it is at infinity."""
        z, diameter = self.paraxial.exit_pupil_position_mm, self.paraxial.exit_pupil_diameter_mm
        if not (math.isfinite(z) and math.isfinite(diameter)):
            return None
        return z, diameter / 2.0

    @property
    def film_half_height_mm(self) -> float:
        """Half the drawn film: past the off-axis image and the rear element."""
        heights = self.off_axis.film_heights_mm
        image = abs(float(np.median(heights))) if heights.size else 0.0
        rear = self.prescription.surfaces[-1].semi_aperture_mm
        return max(1.25 * image, rear)


def lens_system_geometry(prescription: Prescription, *, focus_distance_m: float = 2.0,
                         field_angle_deg: float | None = None) -> LensSystemGeometry:
    """Trace the figure's two bundles through a prescription.

    Parameters
    ----------
    prescription : Prescription
        Drawn wide open (its own stop).
    focus_distance_m : float, optional
        Plane of focus, m from the entrance pupil (``math.inf`` allowed); the
        film is placed by :func:`lenscompare.lenses.film_distance_mm` and both
        object points lie on this plane.
    field_angle_deg : float, optional
        Angle of the off-axis point.  Default: the angle whose paraxial image
        is at ``OFF_AXIS_FILM_FRACTION`` of the 36 x 24 mm film's half
        diagonal, reduced (times 0.7 at a time) until rays get through.

    Raises
    ------
    InputError
        When the lens cannot focus there, or not even an axial ray gets through.
    """
    data = paraxial_data(prescription)
    film_z = prescription.total_track_mm + film_distance_mm(prescription, focus_distance_m)
    front = front_most_z_mm(prescription)
    start_z = front - 0.3 * (film_z - front)

    axial = _bundle(prescription, data, focus_distance_m, 0.0, start_z, film_z)
    if axial is None:
        raise InputError(prescription.source, "not even an axial ray gets through the lens")
    if field_angle_deg is not None:
        off_axis = _bundle(prescription, data, focus_distance_m, math.radians(field_angle_deg),
                           start_z, film_z)
        if off_axis is None:
            raise InputError(prescription.source, f"no ray at {field_angle_deg:g} deg gets "
                             "through the lens", key="field_angle_deg")
    else:
        target = OFF_AXIS_FILM_FRACTION * FILM_HALF_DIAGONAL_MM
        theta = math.atan(target / data.effective_focal_length_mm)
        off_axis = None
        for _ in range(12):
            off_axis = _bundle(prescription, data, focus_distance_m, theta, start_z, film_z)
            if off_axis is not None:
                break
            theta *= 0.7
        if off_axis is None:
            off_axis = axial
    return LensSystemGeometry(prescription, data, float(focus_distance_m), film_z, start_z,
                              axial, off_axis)


def _bundle(prescription, data, focus_distance_m, theta, start_z, film_z) -> Bundle | None:
    """The rays from the object point at angle theta that get through, plus one each side."""
    distance_mm = focus_distance_m * MM_PER_M
    if math.isinf(distance_mm):
        object_point = None
    else:
        object_point = np.array([0.0, distance_mm * math.tan(theta),
                                 data.entrance_pupil_position_mm - distance_mm])

    # Rays start on the plane start_z, or at the object point when that is nearer.
    start = start_z if object_point is None else max(start_z, float(object_point[2]))

    def rays_through(y0):
        # Rays labelled by the height y0 at which they cross the first vertex plane.
        y0 = np.asarray(y0, dtype=float)
        at_vertex = np.stack([np.zeros_like(y0), y0, np.zeros_like(y0)], axis=1)
        if object_point is None:
            directions = np.broadcast_to([0.0, -math.sin(theta), math.cos(theta)], at_vertex.shape)
        else:
            directions = at_vertex - object_point
        directions = directions / np.linalg.norm(directions, axis=1)[:, None]
        origins = at_vertex + directions * (start / directions[:, 2])[:, None]
        return origins, directions

    first = prescription.surfaces[0]
    # A ray drifts sideways by at most |sag| tan(theta) between z = 0 and the first surface.
    reach = first.semi_aperture_mm + abs(sag_mm(first.curvature_per_mm, first.semi_aperture_mm)
                                         ) * abs(math.tan(theta))
    scan = np.linspace(-1.5 * reach, 1.5 * reach, _SCAN_RAYS)
    passed = trace_from_scene(prescription, *rays_through(scan)).passed
    if np.count_nonzero(passed) < 3:
        return None
    low, high = scan[passed].min(), scan[passed].max()
    # The rays that get through, edge to edge, and one just beyond each edge.
    beyond = 0.4 * (high - low) / (_RAYS_THROUGH - 1)
    heights = np.concatenate([[low - beyond], np.linspace(low, high, _RAYS_THROUGH),
                              [high + beyond]])
    paths = traced_paths(prescription, *rays_through(heights), end_z_mm=film_z)
    return Bundle(math.degrees(theta), heights, tuple(paths))


def lens_system_figure(geometry: LensSystemGeometry):
    """The cross-section figure (a :class:`matplotlib.figure.Figure`)."""
    p, data = geometry.prescription, geometry.paraxial
    film_z, film_half = geometry.film_z_mm, geometry.film_half_height_mm
    largest = max(s.semi_aperture_mm for s in p.surfaces)
    # Steep rays may leave the frame on their way in; the lens and film may not.
    points = np.vstack([path.points_mm[1:] for bundle in (geometry.axial, geometry.off_axis)
                        for path in bundle.paths])
    # A wild ray (grazing after a near-total reflection) may leave it too.
    frame = max(film_half, largest)
    y_extent = min(max(float(np.abs(points[:, 1]).max()), frame) * 1.12, 2.0 * frame)
    x_min = geometry.start_z_mm
    x_max = film_z + 0.04 * (film_z - x_min)
    width = 10.5
    height = _style.height_for_aspect(width, x_max - x_min, 2 * y_extent, extra_in=1.5)

    with _style.figure_style():
        fig = _style.new_figure(width, height)
        ax = fig.add_subplot()
        _style.draw_axis_line(ax, x_min, x_max)
        draw_lens(ax, p)

        focus = "infinity" if math.isinf(geometry.focus_distance_m) else \
            f"{geometry.focus_distance_m:g} m"
        draw_ray_paths(ax, list(geometry.axial.paths), _style.BUNDLES[1], gid="axial",
                       label=f"axial point at {focus}", blocked_label="blocked ray (ends where "
                       "it is stopped)")
        if geometry.off_axis is not geometry.axial:
            draw_ray_paths(ax, list(geometry.off_axis.paths), _style.BUNDLES[0], gid="off-axis",
                           label=f"off-axis point, {geometry.off_axis.field_angle_deg:.1f}\u00b0")

        pupil = geometry.exit_pupil
        if pupil is not None:
            z_xp, r_xp = pupil
            for sign in (1.0, -1.0):
                ax.plot([film_z, z_xp], [0.0, sign * r_xp], color=_style.CARDINAL, lw=1.0,
                        ls=(0, (1, 2)), zorder=2.5, gid="exit-pupil-cone")
            ax.plot([z_xp, z_xp], [-r_xp, r_xp], color=_style.CARDINAL, lw=1.6,
                    ls=(0, (4, 2)), zorder=2.6, gid="exit-pupil",
                    label=f"exit pupil (paraxial), \u2300 {data.exit_pupil_diameter_mm:.1f} mm, "
                    "and the cone it admits")

        ax.plot([film_z, film_z], [-film_half, film_half], color=_style.FILM, lw=2.2,
                solid_capstyle="butt", zorder=3, gid="film")
        ax.annotate(f"film\n{_style.mm(film_z - p.total_track_mm, 1)} behind\nthe last vertex",
                    (film_z, film_half), xytext=(0, 4), textcoords="offset points",
                    ha="center", va="bottom", fontsize=8, color=_style.FILM)
        stop_index = p.stop_index
        if stop_index is not None:
            z_stop, _, outer = stop_bar_mm(p)
            ax.annotate("aperture stop", (z_stop, outer), xytext=(0, 3),
                        textcoords="offset points", ha="center", va="bottom", fontsize=8,
                        zorder=5, bbox=_style.LABEL_BOX)

        ax.set_xlim(x_min, x_max)
        ax.set_ylim(-y_extent, y_extent)
        ax.set_aspect("equal")
        ax.set_xlabel("z (mm from the first vertex, toward the film)")
        ax.set_ylabel("height (mm)")
        for side in ("top", "right"):
            ax.spines[side].set_visible(False)
        handles, labels = ax.get_legend_handles_labels()
        order = sorted(range(len(labels)), key=lambda i: labels[i].startswith("blocked"))
        ax.legend([handles[i] for i in order], [labels[i] for i in order], loc="lower left",
                  bbox_to_anchor=(0.0, 1.0), ncols=2, borderaxespad=0.3)
        fig.suptitle(f"Lens system {p.name}: f = {data.effective_focal_length_mm:.2f} mm, "
                     f"f/{data.f_number:.2f}, focused at {focus}", x=0.01, ha="left")
    return fig
