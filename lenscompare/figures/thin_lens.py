"""Figure: the thin lens with real numbers (paper Figs. 1 and 2).

Every number comes from :mod:`lenscompare.optics.thin_lens`: the aperture
diameter a = f/N (eq. 3), the film distance d' (eq. 4), each object point's
image distance l' (eq. 2), blur-disk diameter c (eq. 5), blur angle theta
(eq. 6) and defocus D (eq. 9).  The cones are drawn from the aperture edges to
the image points; where they cross the film is where the blur disk is drawn,
and that equals eq. 5 (similar triangles; the tests check it).

Three panels:

(a) the whole set-up along the axis: object points, plane of focus, lens,
    F and F', cones, film.  The object side is metres long and the image side
    millimetres, so the axis is broken: to the right of the break everything
    is to scale in mm; to the left distances are compressed (ticks in m).
    Heights are to scale throughout.
(b) the film region, to scale and magnified: where each cone comes to a point
    (l') and the blur disk it leaves on the film (c).
(c) the blur angle: each blur disk seen from the lens centre (heights
    magnified, ticks in mm).

Lengths in mm, measured from the lens; object distances in front of it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from matplotlib.patches import Ellipse, Rectangle
from matplotlib.ticker import MaxNLocator

from ..errors import InputError
from ..optics import thin_lens as optics
from ..units import MM_PER_M
from . import _style

__all__ = ["ObjectPoint", "ThinLensGeometry", "thin_lens_geometry", "thin_lens_figure"]

_SUB = str.maketrans("0123456789", "\u2080\u2081\u2082\u2083\u2084\u2085\u2086\u2087\u2088\u2089")
_SOURCE = "teaching figures"


@dataclass(frozen=True)
class ObjectPoint:
    """One object point on the axis and what the thin lens does with it (mm, rad).

    Attributes
    ----------
    object_distance_mm : float
        l, in front of the lens.
    image_distance_mm : float
        l' behind the lens (eq. 2).
    blur_diameter_mm : float
        c on the film (eq. 5).
    blur_angle_rad : float
        theta = 2 atan(c / 2d') (eq. 6).
    defocus_diopters : float
        D = 1/d' - 1/l' in 1/m (eq. 9); theta ~ a D (eq. 10).
    """

    object_distance_mm: float
    image_distance_mm: float
    blur_diameter_mm: float
    blur_angle_rad: float
    defocus_diopters: float


@dataclass(frozen=True)
class ThinLensGeometry:
    """The numbers the thin-lens figure draws (mm from the lens)."""

    focal_length_mm: float
    f_number: float
    aperture_diameter_mm: float
    focus_distance_mm: float
    film_distance_mm: float
    points: tuple[ObjectPoint, ...]

    def cone_edge_height_mm(self, index: int, z_mm):
        """Height of the upper edge of cone ``index`` at axial position ``z_mm``.

        The edge runs from the object point (-l, 0) to the top of the aperture
        (0, a/2) and on to the image point (l', 0); past l' it is below the
        axis.  The lower edge is its mirror image.
        """
        point = self.points[index]
        z = np.asarray(z_mm, dtype=float)
        half = self.aperture_diameter_mm / 2.0
        return np.where(z < 0.0, half * (1.0 + z / point.object_distance_mm),
                        half * (1.0 - z / point.image_distance_mm))

    def drawn_blur_diameter_mm(self, index: int) -> float:
        """Width of cone ``index`` where it meets the film: the blur disk as drawn."""
        return 2.0 * abs(float(self.cone_edge_height_mm(index, self.film_distance_mm)))


def thin_lens_geometry(*, focal_length_mm: float = 50.0, f_number: float = 2.0,
                       focus_distance_m: float = 2.0,
                       object_distances_m=(1.0, 5.0)) -> ThinLensGeometry:
    """The thin-lens numbers for the figure, from equations 2-9.

    Parameters
    ----------
    focal_length_mm : float
        f, mm.
    f_number : float
        N; the aperture diameter is f / N.
    focus_distance_m : float
        Plane of focus d, m in front of the lens; must lie beyond f.
    object_distances_m : sequence of float
        One to three axial object points, m in front of the lens, each beyond
        f (typically one nearer than the plane of focus and one farther).
        Drawn nearest first.

    Raises
    ------
    InputError
        A value that is not a finite positive number, a distance not beyond
        the focal length (no real image), or no / too many object points.
    """
    f = _positive(focal_length_mm, "focal_length_mm")
    n = _positive(f_number, "f_number")
    d = _positive(focus_distance_m, "focus_distance_m") * MM_PER_M
    if d <= f:
        raise InputError(_SOURCE, f"the plane of focus ({d / MM_PER_M:g} m) must lie beyond the "
                         f"focal length ({f:g} mm)", key="focus_distance_m")
    try:
        distances = [float(x) for x in object_distances_m]
    except (TypeError, ValueError):
        raise InputError(_SOURCE, f"expected a list of distances in m, got "
                         f"{object_distances_m!r}", key="object_distances_m") from None
    if not 1 <= len(distances) <= 3:
        raise InputError(_SOURCE, f"expected 1 to 3 object distances, got {len(distances)}",
                         key="object_distances_m")
    for value in distances:
        _positive(value, "object_distances_m")
        if value * MM_PER_M <= f:
            raise InputError(_SOURCE, f"an object at {value:g} m is not beyond the focal length "
                             f"({f:g} mm): it has no real image", key="object_distances_m")

    a = optics.aperture_diameter_mm(f, n)
    film = optics.focus_film_distance_mm(d, f)
    points = []
    for l_mm in sorted(x * MM_PER_M for x in distances):
        image = optics.image_distance_mm(l_mm, f)
        blur = optics.circle_of_confusion_mm(l_mm, focus_distance_mm=d, focal_length_mm=f,
                                             aperture_diameter_mm=a)
        points.append(ObjectPoint(
            object_distance_mm=l_mm,
            image_distance_mm=image,
            blur_diameter_mm=blur,
            blur_angle_rad=optics.blur_angle_rad(blur, film),
            defocus_diopters=optics.defocus_diopters(image, film),
        ))
    return ThinLensGeometry(f, n, a, d, film, tuple(points))


def _positive(value, key: str) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        number = math.nan
    if not (math.isfinite(number) and number > 0):
        raise InputError(_SOURCE, f"expected a finite positive number, got {value!r}", key=key)
    return number


# --------------------------------------------------------------------------- drawing


@dataclass(frozen=True)
class _BrokenAxis:
    """Panel (a)'s axis: to scale for z >= -true_from_mm, compressed beyond a gap."""

    true_from_mm: float
    gap: float
    scale: float  # drawn units per mm on the compressed side

    def x(self, z_mm):
        z = np.asarray(z_mm, dtype=float)
        far = -self.true_from_mm - self.gap - self.scale * (-z - self.true_from_mm)
        return np.where(z >= -self.true_from_mm, z, far)

    def segments(self, z0, y0, z1, y1):
        """A straight segment in z, as drawn: split at the break (one or two pieces)."""
        cut = -self.true_from_mm
        if (z0 - cut) * (z1 - cut) >= 0:
            return [((float(self.x(z0)), float(self.x(z1))), (y0, y1))]
        y_cut = y0 + (y1 - y0) * (cut - z0) / (z1 - z0)
        near, far = (z0, y0), (z1, y1)
        if z0 > z1:
            near, far = far, near
        return [((float(self.x(near[0])), float(self.x(cut - 1e-9))), (near[1], y_cut)),
                ((float(self.x(cut)), float(self.x(far[0]))), (y_cut, far[1]))]


def _broken_axis(g: ThinLensGeometry, right_mm: float) -> _BrokenAxis:
    f = g.focal_length_mm
    farthest = max(g.focus_distance_mm, *(p.object_distance_mm for p in g.points))
    true_from = 1.6 * f
    if farthest <= 1.3 * true_from:  # everything fits to scale: no break
        return _BrokenAxis(1.15 * farthest, 0.0, 1.0)
    span = true_from + right_mm
    scale = 0.85 * span / (1.06 * farthest - true_from)
    return _BrokenAxis(true_from, 0.07 * span, scale)


def thin_lens_figure(geometry: ThinLensGeometry):
    """The three-panel thin-lens figure (a :class:`matplotlib.figure.Figure`)."""
    g = geometry
    with _style.figure_style():
        fig = _style.new_figure(11.0, 6.9)
        grid = fig.add_gridspec(2, 2, height_ratios=(0.8, 1.0), width_ratios=(1.2, 1.0))
        _draw_overview(fig.add_subplot(grid[0, :]), g)
        _draw_film_zoom(fig.add_subplot(grid[1, 0]), g)
        _draw_blur_angle(fig.add_subplot(grid[1, 1]), g)
        fig.suptitle(f"Thin lens (paper Figs. 1\u20132): f = {g.focal_length_mm:g} mm, "
                     f"f/{g.f_number:g}, focused at {g.focus_distance_mm / MM_PER_M:g} m",
                     x=0.01, ha="left")
    return fig


def _label(i: int) -> str:
    return str(i + 1).translate(_SUB)


def _zoom_window(g: ThinLensGeometry) -> tuple[float, float, float]:
    """``(z_min, z_max, half_height)`` of panel (b), mm."""
    zs = [g.film_distance_mm] + [p.image_distance_mm for p in g.points]
    low, high = min(zs), max(zs)
    pad = max(0.45 * (high - low), 0.02 * g.focal_length_mm)
    z_min, z_max = low - pad, high + pad
    half = max(abs(float(g.cone_edge_height_mm(i, z))) for i in range(len(g.points))
               for z in (z_min, z_max))
    return z_min, z_max, 1.08 * half


def _draw_overview(ax, g: ThinLensGeometry) -> None:
    f, half = g.focal_length_mm, g.aperture_diameter_mm / 2.0
    right = max(g.film_distance_mm, *(p.image_distance_mm for p in g.points)) + 0.3 * f
    axis = _broken_axis(g, right)
    farthest = max(g.focus_distance_mm, *(p.object_distance_mm for p in g.points))
    left = float(axis.x(-1.06 * farthest))
    _style.draw_axis_line(ax, left, right)

    # Cones: object point -> aperture -> image point, to the film; past the
    # film (an image behind it) the light never gets there: dotted.
    for i, point in enumerate(g.points):
        colour = _style.BUNDLES[i]
        l = point.object_distance_mm
        for (xs, ys) in axis.segments(-l, 0.0, 0.0, half) + axis.segments(-l, 0.0, 0.0, -half):
            ax.plot(xs, ys, color=colour, lw=1.0, zorder=2)
        for (xs, ys) in axis.segments(-l, 0.0, 0.0, half):
            ax.fill_between(xs, ys, [-y for y in ys], color=colour, alpha=0.10, lw=0, zorder=1)
        _draw_image_cone(ax, g, i, colour, z_end=g.film_distance_mm)
        x_object = float(axis.x(-l))
        ax.plot(x_object, 0.0, "o", color=colour, ms=5, zorder=4, gid=f"object-point-{i + 1}")
        # Below the axis; above it when the previous point's label would be too near.
        previous = float(axis.x(-g.points[i - 1].object_distance_mm)) if i else math.inf
        above = i % 2 == 1 and abs(x_object - previous) < 0.15 * (right - left)
        ax.annotate(f"P{_label(i)}, l{_label(i)} = {l / MM_PER_M:g} m", (x_object, 0.0),
                    xytext=(0, 8 if above else -8), textcoords="offset points", ha="center",
                    va="bottom" if above else "top", color=colour, fontsize=8.5,
                    bbox=_style.LABEL_BOX, zorder=5)

    # Plane of focus.
    x_focus = float(axis.x(-g.focus_distance_mm))
    ax.plot([x_focus, x_focus], [-1.15 * half, 1.15 * half], color=_style.FOCUS_PLANE, lw=1.2,
            ls=(0, (5, 3)), zorder=1.5, gid="plane-of-focus")
    ax.annotate(f"plane of focus\nd = {g.focus_distance_mm / MM_PER_M:g} m",
                (x_focus, 1.15 * half), xytext=(0, 3), textcoords="offset points", ha="center",
                va="bottom", color=_style.FOCUS_PLANE, fontsize=8.5)

    # The thin lens, F and F'.
    ax.add_patch(Ellipse((0.0, 0.0), 0.08 * f, 2.0 * half, facecolor=_style.GLASS_FILL,
                         edgecolor=_style.GLASS_EDGE, lw=1.0, zorder=3, gid="lens"))
    digits = 3 if g.aperture_diameter_mm < 10 else 1
    ax.annotate(f"thin lens\na = f/N = {_style.mm(g.aperture_diameter_mm, digits)}", (0.0, half),
                xytext=(0, 4), textcoords="offset points", ha="center", va="bottom",
                fontsize=8.5, color=_style.GLASS_EDGE)
    # F' sits next to the film and the image points: its label goes below, to the left.
    for z, name, gid, dx, ha in ((-f, "F", "F", 0, "center"), (f, "F\u2032", "F'", -3, "right")):
        ax.plot(z, 0.0, "o", color="black", ms=3.5, zorder=4, gid=gid)
        ax.annotate(name, (z, 0.0), xytext=(dx, -5), textcoords="offset points", ha=ha,
                    va="top", fontsize=9)
    ax.annotate("", (-f, -1.22 * half), (0.0, -1.22 * half),
                arrowprops=dict(arrowstyle="<->", color=_style.MUTED, lw=0.7, shrinkA=0, shrinkB=0))
    ax.annotate(f"f = {f:g} mm", (-f / 2.0, -1.22 * half), xytext=(0, -3),
                textcoords="offset points", ha="center", va="top", fontsize=8, color=_style.MUTED)

    # Film.
    film = g.film_distance_mm
    ax.plot([film, film], [-1.15 * half, 1.15 * half], color=_style.FILM, lw=2.2,
            solid_capstyle="butt", zorder=3, gid="film")
    ax.annotate(f"film\nd\u2032 = {_style.mm(film)}", (film, 1.15 * half), xytext=(0, 3),
                textcoords="offset points", ha="center", va="bottom", fontsize=8.5)

    # Where panel (b) looks.
    z_min, z_max, zoom_half = _zoom_window(g)
    ax.add_patch(Rectangle((z_min, -zoom_half), z_max - z_min, 2 * zoom_half, fill=False,
                           ec=_style.MUTED, lw=0.7, ls=(0, (2, 2)), zorder=5))
    ax.annotate("(b)", (z_max, zoom_half), xytext=(2, 2), textcoords="offset points",
                fontsize=8, color=_style.MUTED)

    _draw_break_and_ticks(ax, axis, g, left, right, half)
    ax.set_xlim(left, right)
    # Room for the labels, which are sized in points, when the drawing is very long.
    y_limit = max(1.95 * half, 0.09 * (right - left))
    ax.set_ylim(-y_limit, y_limit)
    ax.set_aspect("equal")
    ax.set_title("(a) image formation (eqs. 1\u20134): each object point's cone of rays "
                 "through the aperture")


def _draw_image_cone(ax, g: ThinLensGeometry, i: int, colour: str, *, z_end: float) -> None:
    """Cone i behind the lens, solid up to the film, dotted past it to its image point."""
    image = g.points[i].image_distance_mm
    z_solid = np.array([0.0, min(image, z_end), z_end]) if image < z_end else np.array([0.0, z_end])
    y_solid = g.cone_edge_height_mm(i, z_solid)
    for sign in (1.0, -1.0):
        ax.plot(z_solid, sign * y_solid, color=colour, lw=1.0, zorder=2, gid=f"cone-{i + 1}")
    ax.fill_between(z_solid, y_solid, -y_solid, color=colour, alpha=0.10, lw=0, zorder=1)
    if image > z_end:  # focuses behind the film: the rest is a construction
        z_dots = np.array([z_end, image])
        for sign in (1.0, -1.0):
            ax.plot(z_dots, sign * g.cone_edge_height_mm(i, z_dots), color=colour, lw=0.9,
                    ls=(0, (1, 1.5)), zorder=2)


def _draw_break_and_ticks(ax, axis: _BrokenAxis, g, left, right, half) -> None:
    """Break marks on the axis and ticks: metres left of the break, mm right of it."""
    for side in ("top", "right", "left"):
        ax.spines[side].set_visible(False)
    ax.set_yticks([])
    ticks, labels = [], []
    if axis.gap > 0:
        x0, x1 = -axis.true_from_mm - axis.gap, -axis.true_from_mm
        ax.add_patch(Rectangle((x0, -0.02 * half), x1 - x0, 0.04 * half, fc="white", ec="none",
                               zorder=0.6))
        for x in (x0, x1):
            ax.plot([x - 0.25 * axis.gap, x + 0.25 * axis.gap], [-0.12 * half, 0.12 * half],
                    color=_style.MUTED, lw=1.0, zorder=0.7)
        farthest_m = max(g.focus_distance_mm, *(p.object_distance_mm for p in g.points)) / MM_PER_M
        for value in MaxNLocator(nbins=6, steps=[1, 2, 2.5, 5, 10]).tick_values(
                axis.true_from_mm / MM_PER_M, farthest_m):
            if axis.true_from_mm / MM_PER_M * 1.15 < value <= farthest_m * 1.06:
                ticks.append(float(axis.x(-value * MM_PER_M)))
                labels.append(f"{value:g} m")
        ax.text((left + x0) / 2.0, -1.9 * half, "object side: distances compressed",
                ha="center", va="bottom", fontsize=7.5, color=_style.MUTED, style="italic")
        ax.text((x1 + right) / 2.0, -1.9 * half, "to scale", ha="center", va="bottom",
                fontsize=7.5, color=_style.MUTED, style="italic")
    for value in MaxNLocator(nbins=5, steps=[1, 2, 2.5, 5, 10]).tick_values(
            -axis.true_from_mm, right):
        if -axis.true_from_mm <= value <= right:
            ticks.append(float(value))
            labels.append(f"{value:g} mm".replace("-", "\u2212") if value else "0")
    ax.set_xticks(ticks, labels)
    ax.spines["bottom"].set_bounds(left, right)


def _draw_film_zoom(ax, g: ThinLensGeometry) -> None:
    z_min, z_max, half = _zoom_window(g)
    film = g.film_distance_mm
    _style.draw_axis_line(ax, z_min, z_max)
    width = z_max - z_min
    rows = []
    for i, point in enumerate(g.points):
        colour = _style.BUNDLES[i]
        _draw_image_cone(ax, g, i, colour, z_end=film)
        image = point.image_distance_mm
        behind = image > film  # light never gets there: an open marker
        ax.plot(image, 0.0, "o", ms=5, zorder=4, color=colour, mfc="white" if behind else colour,
                gid=f"image-point-{i + 1}")
        note = "\n(behind the film)" if behind else ""
        ax.annotate(f"l\u2032{_label(i)}{note}", (image, 0.0), xytext=(0, -6),
                    textcoords="offset points", ha="center", va="top", fontsize=8.5,
                    color=colour)

        # The blur disk as drawn: the cone's width at the film (eq. 5), with
        # its dimension arrow beside the film (alternately right and left).
        c = g.drawn_blur_diameter_mm(i)
        side = 1 if i % 2 == 0 else -1
        x = film + side * (0.05 + 0.045 * (i // 2)) * width
        ax.annotate("", (x, c / 2), (x, -c / 2), arrowprops=dict(
            arrowstyle="<|-|>", color=colour, lw=1.0, shrinkA=0, shrinkB=0, mutation_scale=7))
        ax.plot([film, x], [c / 2, c / 2], color=colour, lw=0.5, zorder=2)
        ax.plot([film, x], [-c / 2, -c / 2], color=colour, lw=0.5, zorder=2)
        ax.plot([film, film], [-c / 2, c / 2], color=colour, lw=4.0, alpha=0.55,
                solid_capstyle="butt", zorder=3.5, gid=f"blur-disk-{i + 1}")
        ax.annotate(f"c{_label(i)}", (x, c / 2), xytext=(0, 2), textcoords="offset points",
                    ha="center", va="bottom", fontsize=8.5, color=colour, fontweight="bold")
        rows.append((colour, f"P{_label(i)}: l\u2032{_label(i)} = {_style.mm(image)}, "
                     f"c{_label(i)} = {_style.mm(c, 3)}"))

    ax.plot([film, film], [-half, half], color=_style.FILM, lw=1.8, zorder=3, gid="film-zoom")
    ax.annotate(f"film\nd\u2032 = {_style.mm(film)} (eq. 4)", (film, -half), xytext=(4, 3),
                textcoords="offset points", ha="left", va="bottom", fontsize=8)
    _value_table(ax, rows, (0.99, 0.98), "right", "top")
    ax.set_xlim(z_min, z_max)
    ax.set_ylim(-half, half)
    # To scale unless that would make a sliver (a strongly defocused point).
    to_scale = (z_max - z_min) <= 4.0 * (2.0 * half)
    ax.set_aspect("equal" if to_scale else "auto")
    ax.set_xlabel("distance behind the lens (mm)")
    ax.set_ylabel("height (mm)" if to_scale else "height (mm), magnified")
    ax.set_title("(b) at the film" + (", to scale" if to_scale else "")
                 + ": images at l\u2032 (eq. 2), blur disks c (eq. 5)")


def _value_table(ax, rows, xy, ha: str, va: str) -> None:
    """Coloured lines of text, one per object point, in a corner of the panel."""
    step = 11  # points between lines
    for j, (colour, text) in enumerate(rows):
        offset = -j * step if va == "top" else (len(rows) - 1 - j) * step
        ax.annotate(text, xy, xycoords="axes fraction", xytext=(0, offset),
                    textcoords="offset points", ha=ha, va=va, fontsize=8, color=colour,
                    bbox=_style.LABEL_BOX, zorder=6)


def _draw_blur_angle(ax, g: ThinLensGeometry) -> None:
    film = g.film_distance_mm
    largest = max(p.blur_diameter_mm for p in g.points) or g.aperture_diameter_mm * 1e-3
    half = 0.75 * largest
    ax.axhline(0.0, color=_style.AXIS, lw=0.8, ls=(0, (8, 3, 1.5, 3)), zorder=0.5)
    rows = []
    for i, point in sorted(enumerate(g.points), key=lambda item: -item[1].blur_diameter_mm):
        colour = _style.BUNDLES[i]
        c = point.blur_diameter_mm
        ax.fill([0.0, film, film], [0.0, c / 2, -c / 2], color=colour, alpha=0.12, lw=0)
        ax.plot([film, 0.0, film], [c / 2, 0.0, -c / 2], color=colour, lw=1.1,
                gid=f"blur-angle-{i + 1}")
        theta = point.blur_angle_rad
        defocus = f"{point.defocus_diopters:.3f}".replace("-", "\u2212")
        ax.annotate(f"\u03b8{_label(i)}", (film, c / 2), xytext=(5, 0), textcoords="offset points",
                    ha="left", va="center", fontsize=8.5, color=colour, fontweight="bold")
        rows.append((colour, f"\u03b8{_label(i)} = {1e3 * theta:.2f} mrad = "
                     f"{math.degrees(theta):.2f}\u00b0 \u2248 a\u00b7|D{_label(i)}|, "
                     f"D{_label(i)} = {defocus} dpt"))
    ax.plot([film, film], [-half, half], color=_style.FILM, lw=1.8, zorder=3)
    ax.plot([0.0, 0.0], [-half, half], color=_style.GLASS_EDGE, lw=2.5, alpha=0.5, zorder=3)
    ax.annotate("lens centre", (0.0, -half), xytext=(4, 3), textcoords="offset points",
                ha="left", va="bottom", fontsize=8, color=_style.GLASS_EDGE)
    ax.annotate("film", (film, -half), xytext=(-4, 3), textcoords="offset points",
                ha="right", va="bottom", fontsize=8)
    rows.sort(key=lambda row: row[1])
    rows.append((_style.MUTED, "eq. 10: \u03b8 \u2248 a\u00b7|D|, D = 1/d\u2032 \u2212 1/l\u2032 "
                 "(eq. 9)"))
    _value_table(ax, rows, (0.03, 0.98), "left", "top")
    ax.set_xlim(-0.04 * film, 1.12 * film)
    ax.set_ylim(-half, half)
    ax.set_xticks([t for t in MaxNLocator(nbins=4).tick_values(0.0, film) if 0 <= t <= film])
    for side in ("top", "right"):
        ax.spines[side].set_visible(False)
    ax.spines["bottom"].set_bounds(0.0, film)
    ax.set_xlabel("distance behind the lens (mm)")
    ax.set_ylabel("height (mm), magnified")
    ax.set_title("(c) blur angle \u03b8 (eq. 6): tan(\u03b8/2) = (c/2)/d\u2032")
