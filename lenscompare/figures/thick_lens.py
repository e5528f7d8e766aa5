"""Figure: the thick-lens model of a real lens (paper Fig. 3).

The principal planes H and H' and the focal points F and F' come from
:func:`lenscompare.lenses.paraxial_data` of the prescription.  Three parallel
rays from a distant point at field angle alpha are drawn twice:

- the thick-lens model (dotted, vermillion): each ray goes straight on to H,
  is moved parallel to the axis to H' (same height), and leaves as from a
  thin lens there: toward the point ``(F', -f tan alpha)`` in the rear focal
  plane, where a parallel bundle at alpha comes to focus;
- the real ray (blue), traced surface by surface with ``trace_from_scene``:
  solid in air, dashed inside the lens, as in the paper.

Where the two disagree after the lens is what the model leaves out
(aberrations).  Lens frame: z in mm from the first vertex, toward the film.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..lenses import ParaxialData, Prescription, front_most_z_mm, paraxial_data
from . import _style
from ._lens_drawing import RayPath, draw_lens, traced_paths
from .lens_system import FILM_HALF_DIAGONAL_MM

__all__ = ["ThickLensGeometry", "thick_lens_geometry", "thick_lens_figure", "PUPIL_FRACTIONS"]

# Where the three rays cross the entrance-pupil plane, as fractions of its radius.
PUPIL_FRACTIONS = (0.6, 0.0, -0.6)
# Default field angle: the paraxial image lands at this fraction of the
# 36 x 24 mm film's half diagonal.
FIELD_FILM_FRACTION = 0.35


@dataclass(frozen=True)
class ThickLensGeometry:
    """What the thick-lens figure draws, in the lens frame (mm).

    Attributes
    ----------
    prescription : Prescription
    paraxial : ParaxialData
        Source of H, H', F, F' and f.
    field_angle_deg : float
        Angle of the parallel bundle (its rays descend toward +z).
    start_z_mm, end_z_mm : float
        Where the rays are drawn from and to.
    heights_at_h_mm : numpy.ndarray
        Height of each model ray at H, which is also its height at H'.
    real : tuple of RayPath
        The traced rays.
    """

    prescription: Prescription
    paraxial: ParaxialData
    field_angle_deg: float
    start_z_mm: float
    end_z_mm: float
    heights_at_h_mm: np.ndarray
    real: tuple[RayPath, ...]

    @property
    def slope(self) -> float:
        """dy/dz of the incoming rays."""
        return -math.tan(math.radians(self.field_angle_deg))

    @property
    def focal_point_image_mm(self) -> tuple[float, float]:
        """``(z, y)`` where the model bundle meets: on the rear focal plane at -f tan(alpha)."""
        data = self.paraxial
        return data.rear_focal_point_mm, data.effective_focal_length_mm * self.slope

    def model_ray_mm(self, index: int) -> np.ndarray:
        """Model ray ``index`` as points ``(z, y)``: start, at H, at H', end."""
        data = self.paraxial
        y_h = float(self.heights_at_h_mm[index])
        z_h, z_h2 = data.front_principal_plane_mm, data.rear_principal_plane_mm
        y_start = y_h + (self.start_z_mm - z_h) * self.slope
        z_f, y_f = self.focal_point_image_mm
        y_end = y_h + (y_f - y_h) * (self.end_z_mm - z_h2) / (z_f - z_h2)
        return np.array([[self.start_z_mm, y_start], [z_h, y_h], [z_h2, y_h],
                         [self.end_z_mm, y_end]])


def thick_lens_geometry(prescription: Prescription, *,
                        field_angle_deg: float | None = None) -> ThickLensGeometry:
    """H, H', F, F' of a prescription and three rays through model and lens.

    Parameters
    ----------
    prescription : Prescription
    field_angle_deg : float, optional
        Angle of the parallel bundle; default: the angle whose paraxial image
        is at 0.35 of the 36 x 24 mm film's half diagonal.
    """
    data = paraxial_data(prescription)
    f = data.effective_focal_length_mm
    if field_angle_deg is None:
        image_height_mm = FIELD_FILM_FRACTION * FILM_HALF_DIAGONAL_MM
        field_angle_deg = math.degrees(math.atan(image_height_mm / abs(f)))
    slope = -math.tan(math.radians(field_angle_deg))

    cardinal = [data.front_focal_point_mm, data.rear_focal_point_mm,
                data.front_principal_plane_mm, data.rear_principal_plane_mm]
    front = min(front_most_z_mm(prescription), *cardinal)
    back = max(prescription.total_track_mm, *cardinal)
    start_z = front - 0.12 * (back - front)
    end_z = back + 0.12 * (back - front)

    # The rays cross the entrance-pupil plane at fractions of its radius
    # (the middle one is the paraxial chief ray); if the pupil is at infinity,
    # the first vertex plane stands in for it, with the first surface's aperture.
    pupil_z, pupil_d = data.entrance_pupil_position_mm, data.entrance_pupil_diameter_mm
    if not (math.isfinite(pupil_z) and math.isfinite(pupil_d)):
        pupil_z, pupil_d = 0.0, 2.0 * prescription.surfaces[0].semi_aperture_mm
    at_pupil = np.array(PUPIL_FRACTIONS) * pupil_d / 2.0
    heights_at_h = at_pupil + (data.front_principal_plane_mm - pupil_z) * slope

    y_start = at_pupil + (start_z - pupil_z) * slope
    origins = np.stack([np.zeros_like(y_start), y_start, np.full_like(y_start, start_z)], axis=1)
    direction = np.array([0.0, slope, 1.0]) / math.hypot(slope, 1.0)
    real = traced_paths(prescription, origins, np.broadcast_to(direction, origins.shape),
                        end_z_mm=end_z)
    return ThickLensGeometry(prescription, data, float(field_angle_deg), start_z, end_z,
                             heights_at_h, tuple(real))


def thick_lens_figure(geometry: ThickLensGeometry):
    """The thick-lens figure (a :class:`matplotlib.figure.Figure`)."""
    g, p, data = geometry, geometry.prescription, geometry.paraxial
    largest = max(s.semi_aperture_mm for s in p.surfaces)
    z_f, y_f = g.focal_point_image_mm
    inner = [path.points_mm[1:-1] for path in g.real] + [g.model_ray_mm(i)[1:3]
                                                        for i in range(len(g.real))]
    y_top = max(largest, float(np.abs(np.vstack(inner)[:, 1]).max())) * 1.25
    y_bottom = max(y_top, abs(y_f) * 1.15 + 0.1 * largest)
    x_min, x_max = g.start_z_mm, g.end_z_mm
    width = 10.5
    dimension_f = -1.25 * largest
    dimension_f2 = dimension_f - 0.2 * largest
    y_bottom = max(y_bottom, -dimension_f2 + 0.15 * largest)
    y_top += 0.3 * largest  # the H and H' labels
    height = _style.height_for_aspect(width, x_max - x_min, y_top + y_bottom, extra_in=1.6)

    with _style.figure_style():
        fig = _style.new_figure(width, height)
        ax = fig.add_subplot()
        _style.draw_axis_line(ax, x_min, x_max)
        draw_lens(ax, p)

        # Principal planes and focal points.
        plane_top = 1.15 * largest
        for z, name, gid, dx, ha in _principal_plane_labels(data):
            ax.plot([z, z], [dimension_f2, plane_top], color=_style.CARDINAL, lw=1.2,
                    ls=(0, (5, 2.5)), zorder=1.6, gid=gid)
            ax.annotate(name, (z, plane_top), xytext=(dx, 2), textcoords="offset points",
                        ha=ha, va="bottom", fontsize=10, color=_style.CARDINAL, fontweight="bold")
        for z, name, gid in ((data.front_focal_point_mm, "F", "F"),
                             (data.rear_focal_point_mm, "F\u2032", "F'")):
            ax.plot(z, 0.0, "o", color="black", ms=4, zorder=4, gid=gid)
            ax.annotate(name, (z, 0.0), xytext=(0, 5), textcoords="offset points",
                        ha="center", va="bottom", fontsize=10, fontweight="bold")
        ax.plot([z_f, z_f], [dimension_f2, plane_top], color=_style.MUTED, lw=0.6,
                ls=(0, (1, 2)), zorder=0.8)
        ax.plot(z_f, y_f, "o", ms=4.5, mfc="white", color=_style.MODEL_RAY, zorder=4, ls="none",
                gid="model-image-point", label=f"model focus on the rear focal plane: "
                f"y = \u2212f tan \u03b1 = {_style.mm(y_f)}")
        _dimension(ax, data.front_focal_point_mm, data.front_principal_plane_mm, dimension_f, "f")
        _dimension(ax, data.rear_principal_plane_mm, data.rear_focal_point_mm, dimension_f2,
                   "f\u2032")

        # The model: to H, across to H', on toward the focal-plane point.
        for i in range(len(g.real)):
            model = g.model_ray_mm(i)
            first_hit = g.real[i].points_mm[1] if len(g.real[i].points_mm) > 2 else model[0]
            label = "thick-lens model: on to H, across to H\u2032, out as from a thin lens" \
                if i == 0 else None
            ax.plot([first_hit[0], model[1, 0]], [first_hit[1], model[1, 1]],
                    color=_style.MODEL_RAY, lw=1.1, ls=(0, (1, 1.6)), zorder=2.4)
            ax.annotate("", model[2], model[1], arrowprops=dict(
                arrowstyle="-|>", color=_style.MODEL_RAY, lw=1.1, shrinkA=0, shrinkB=0,
                linestyle=(0, (1, 1.6)), mutation_scale=8), zorder=2.5)
            ax.plot(model[2:, 0], model[2:, 1], color=_style.MODEL_RAY, lw=1.1,
                    ls=(0, (1, 1.6)), zorder=2.4, gid=f"model-ray-{i + 1}", label=label)
            ax.plot(model[1:3, 0], model[1:3, 1], "o", ms=2.8, color=_style.MODEL_RAY, zorder=2.6,
                    gid=f"model-translation-{i + 1}")

        # The real rays: solid in air, dashed in the lens.
        for i, path in enumerate(g.real):
            _draw_real_ray(ax, path, label=f"real rays from a distant point at \u03b1 = "
                           f"{g.field_angle_deg:.1f}\u00b0, traced (dashed inside the lens)"
                           if i == 0 else None, gid=f"real-ray-{i + 1}")

        ax.set_xlim(x_min, x_max)
        ax.set_ylim(-y_bottom, y_top)
        ax.set_aspect("equal")
        positions = "   ".join(f"{name} {value:.2f}".replace("-", "\u2212") for name, value in (
            ("F", data.front_focal_point_mm), ("H", data.front_principal_plane_mm),
            ("H\u2032", data.rear_principal_plane_mm), ("F\u2032", data.rear_focal_point_mm)))
        ax.set_xlabel(f"z (mm from the first vertex, toward the film)\n{positions}")
        ax.set_ylabel("height (mm)")
        for side in ("top", "right"):
            ax.spines[side].set_visible(False)
        handles, labels = ax.get_legend_handles_labels()
        order = [labels.index(x) for x in sorted(labels, key=lambda x: not x.startswith("real"))]
        ax.legend([handles[i] for i in order], [labels[i] for i in order], loc="lower left",
                  bbox_to_anchor=(0.0, 1.0), ncols=2, borderaxespad=0.3)
        gap = data.rear_principal_plane_mm - data.front_principal_plane_mm
        fig.suptitle(f"Thick lens (paper Fig. 3): {p.name} as H, H\u2032, F, F\u2032 \u2014 "
                     f"f = {data.effective_focal_length_mm:.2f} mm, H\u2192H\u2032 = "
                     f"{_style.mm(gap)}",
                     x=0.01, ha="left")
    return fig


def _principal_plane_labels(data: ParaxialData):
    """H and H' with their labels pushed apart (they may be close, or crossed)."""
    z_h, z_h2 = data.front_principal_plane_mm, data.rear_principal_plane_mm
    h_left = z_h <= z_h2
    return ((z_h, "H", "H", -3 if h_left else 3, "right" if h_left else "left"),
            (z_h2, "H\u2032", "H'", 3 if h_left else -3, "left" if h_left else "right"))


def _dimension(ax, z0: float, z1: float, y: float, name: str) -> None:
    """A length along the axis: arrows from z0 to z1 at height y, with its name and value."""
    ax.annotate("", (z1, y), (z0, y), arrowprops=dict(arrowstyle="<->", color=_style.MUTED,
                                                     lw=0.7, shrinkA=0, shrinkB=0))
    ax.annotate(f"{name} = {_style.mm(abs(z1 - z0))}", ((z0 + z1) / 2.0, y), xytext=(0, 2),
                textcoords="offset points", ha="center", va="bottom", fontsize=8,
                color=_style.MUTED, bbox=_style.LABEL_BOX)


def _draw_real_ray(ax, path: RayPath, *, label: str | None, gid: str) -> None:
    points = path.points_mm
    colour, lw = _style.REAL_RAY, 1.1
    alpha = 1.0 if path.passed else 0.5
    if len(points) <= 2:  # blocked at the first surface
        ax.plot(points[:, 0], points[:, 1], color=colour, lw=lw, alpha=alpha, gid=gid, label=label)
        return
    inside_end = len(points) - 1 if path.passed else len(points)
    ax.plot(points[:2, 0], points[:2, 1], color=colour, lw=lw, alpha=alpha, zorder=2.2, gid=gid,
            label=label)
    ax.plot(points[1:inside_end, 0], points[1:inside_end, 1], color=colour, lw=lw, alpha=alpha,
            ls=(0, (4, 2)), zorder=2.2, gid=gid)
    if path.passed:
        ax.plot(points[-2:, 0], points[-2:, 1], color=colour, lw=lw, zorder=2.2, gid=gid)
    else:
        ax.plot(points[-1, 0], points[-1, 1], marker="|", ms=5, mew=1.2, color=colour, zorder=2.3)
