"""Figure: chromatic aberration of a dispersive lens (issue 15's teaching figure).

Three panels, all from the project's own optics code:

- the lens in cross-section with a fan of real rays from an axial point at
  infinity, traced at F (486.13 nm), d (587.56 nm) and C (656.27 nm) through
  the prescription at each wavelength (:meth:`Prescription.at_wavelength`);
- the same fans near the focus, enlarged, with each wavelength's paraxial
  focus marked: blue focuses nearer the lens behind an undercorrected lens;
- the focal shift, back focal length at each wavelength minus at d, over
  400-700 nm, with F, d and C marked; F minus C is ``lens info``'s
  ``chromatic_focal_shift_mm``.

The default lens is a biconvex N-BK7 singlet (:data:`TEACHING_SINGLET`): the
shipped lenses carry no dispersion data.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from ..lenses import Prescription, front_most_z_mm, paraxial_data, parse_prescription
from ..lenses.glass import C_NM, D_NM, F_NM
from ..lenses.paraxial import chromatic_focal_shift_mm
from . import _style
from ._lens_drawing import RayPath, draw_lens, draw_ray_paths
from .lens_system import _bundle

__all__ = ["ChromaticGeometry", "chromatic_geometry", "chromatic_figure", "teaching_singlet", "TEACHING_SINGLET",
           "LINES_NM"]

TEACHING_SINGLET = """\
# Teaching singlet: biconvex N-BK7 (n_d 1.5168, V_d 64.17, Schott data sheet),
# f = 100 mm, f/4 stop 2 mm in front; dispersion by the contract's Cauchy fit.
0        2   0       25
103.36   6   1.5168  27   64.17
-103.36  0   1       27
"""

LINES_NM = {"F": F_NM, "d": D_NM, "C": C_NM}
"""The Fraunhofer lines drawn, and their wavelengths, nm."""

# Colours of the three lines: blue, yellow-green, red (colour-blind safe).
_LINE_COLOURS = {"F": "#0072B2", "d": "#009E73", "C": "#D55E00"}
_CURVE_NM = np.arange(400.0, 700.0 + 1e-9, 5.0)


def teaching_singlet() -> Prescription:
    """The default lens of the figure: :data:`TEACHING_SINGLET`."""
    return parse_prescription(TEACHING_SINGLET.encode(), source="teaching singlet", name="N-BK7 singlet")


@dataclass(frozen=True)
class ChromaticGeometry:
    """Everything the chromatic figure draws, in the lens frame (mm).

    Attributes
    ----------
    prescription : Prescription
    fans : dict of str to tuple of RayPath
        Real rays from the axial point at infinity at each line (``"F"``, ``"d"``, ``"C"``).
    paraxial_focus_z_mm : dict of str to float
        Each line's paraxial focus (rear focal point), mm from the first vertex.
    curve_nm : numpy.ndarray
        Wavelengths of the focal-shift curve, nm.
    focal_shift_mm : numpy.ndarray
        Back focal length at each of ``curve_nm`` minus at d, mm.
    chromatic_focal_shift_mm : float
        Back focal length at F minus at C (``lens info``'s value), mm.
    start_z_mm, end_z_mm : float
        Where the drawn rays start and end.
    """

    prescription: Prescription
    fans: dict
    paraxial_focus_z_mm: dict
    curve_nm: np.ndarray
    focal_shift_mm: np.ndarray
    chromatic_focal_shift_mm: float
    start_z_mm: float
    end_z_mm: float

    def focal_shift_at_mm(self, wavelength_nm: float) -> float:
        """The plotted curve, linear between its points, mm."""
        return float(np.interp(wavelength_nm, self.curve_nm, self.focal_shift_mm))


def chromatic_geometry(prescription: Prescription | None = None, *, curve_nm=_CURVE_NM) -> ChromaticGeometry:
    """Trace the figure's fans and the focal-shift curve.

    Parameters
    ----------
    prescription : Prescription, optional
        A lens whose media disperse (Abbe numbers or glass names). Default:
        :func:`teaching_singlet`. Drawn wide open, object at infinity.
    curve_nm : array_like, optional
        Wavelengths of the focal-shift curve, nm (default 400-700 nm every 5 nm,
        F, d and C added).

    Raises
    ------
    InputError
        When the lens does not disperse, or no axial ray gets through it.
    """
    lens = teaching_singlet() if prescription is None else prescription
    if not lens.disperses:
        raise InputError(lens.source, f"{lens.name} does not disperse (no Abbe number or glass in its 5th "
                         "column): the chromatic figure needs a lens that does")
    curve = np.unique(np.concatenate([np.asarray(curve_nm, dtype=float), list(LINES_NM.values())]))
    d_bfl = paraxial_data(lens.at_wavelength(D_NM)).back_focal_length_mm
    shift = np.array([paraxial_data(lens.at_wavelength(w)).back_focal_length_mm - d_bfl for w in curve])
    foci = {name: lens.total_track_mm + paraxial_data(lens.at_wavelength(w)).back_focal_length_mm
            for name, w in LINES_NM.items()}
    front = front_most_z_mm(lens)
    end_z = max(foci.values()) + 0.15 * (max(foci.values()) - lens.total_track_mm)
    start_z = front - 0.25 * (end_z - front)
    fans = {}
    for name, wavelength in LINES_NM.items():
        at = lens.at_wavelength(wavelength)
        bundle = _bundle(at, paraxial_data(at), math.inf, 0.0, start_z, end_z)
        if bundle is None:
            raise InputError(lens.source, "not even an axial ray gets through the lens")
        fans[name] = tuple(p for p in bundle.paths if p.passed)
    return ChromaticGeometry(lens, fans, foci, curve, shift, chromatic_focal_shift_mm(lens), start_z, end_z)


def axis_crossing_z_mm(path: RayPath) -> float:
    """Where a passed ray's last segment crosses the axis, mm (NaN when parallel to it)."""
    (z0, y0), (z1, y1) = path.points_mm[-2], path.points_mm[-1]
    return z0 - y0 * (z1 - z0) / (y1 - y0) if y1 != y0 else math.nan


def chromatic_figure(geometry: ChromaticGeometry):
    """The three-panel figure (a :class:`matplotlib.figure.Figure`)."""
    p = geometry.prescription
    data = paraxial_data(p)
    with _style.figure_style():
        fig = _style.new_figure(10.5, 7.2)
        grid = fig.add_gridspec(2, 2, height_ratios=(1.0, 1.0))
        section, zoom, curve = fig.add_subplot(grid[0, :]), fig.add_subplot(grid[1, 0]), fig.add_subplot(grid[1, 1])

        # Cross-section: the lens and the three fans.
        _style.draw_axis_line(section, geometry.start_z_mm, geometry.end_z_mm)
        draw_lens(section, p)
        for name, paths in geometry.fans.items():
            draw_ray_paths(section, list(paths), _LINE_COLOURS[name], gid=f"fan-{name}", lw=0.7,
                           label=f"{name} {LINES_NM[name]:.2f} nm")
        largest = max(s.semi_aperture_mm for s in p.surfaces)
        section.set_xlim(geometry.start_z_mm, geometry.end_z_mm)
        section.set_ylim(-1.25 * largest, 1.25 * largest)
        section.set_xlabel("z (mm from the first vertex, toward the film)")
        section.set_ylabel("height (mm)")
        section.legend(loc="upper left", ncols=3)
        section.set_title("real rays from a point at infinity on the axis, at three wavelengths", loc="left")

        # Near the focus, enlarged: the paraxial foci marked.
        foci = geometry.paraxial_focus_z_mm
        spread = max(foci.values()) - min(foci.values())
        half = max(1.5 * spread, 0.02 * data.effective_focal_length_mm)
        middle = foci["d"]
        _style.draw_axis_line(zoom, middle - half, middle + half)
        slope = max(abs(path.points_mm[-1, 1] - path.points_mm[-2, 1]) /
                    abs(path.points_mm[-1, 0] - path.points_mm[-2, 0]) for path in geometry.fans["d"])
        for name, paths in geometry.fans.items():
            draw_ray_paths(zoom, list(paths), _LINE_COLOURS[name], gid=f"zoom-{name}", lw=0.8)
            zoom.axvline(foci[name], color=_LINE_COLOURS[name], lw=1.0, ls=(0, (4, 2)), gid=f"focus-{name}")
            zoom.annotate(f"{name}", (foci[name], 0.0), xytext=(2, 4), textcoords="offset points",
                          color=_LINE_COLOURS[name], fontsize=9)
        zoom.set_xlim(middle - half, middle + half)
        zoom.set_ylim(-1.1 * slope * half, 1.1 * slope * half)
        zoom.set_xlabel("z (mm)")
        zoom.set_ylabel("height (mm)")
        zoom.set_title("near the focus (enlarged); dashed: paraxial foci", loc="left")

        # Focal shift against wavelength.
        curve.plot(geometry.curve_nm, geometry.focal_shift_mm, color=_style.MUTED, lw=1.4, gid="focal-shift")
        for name, wavelength in LINES_NM.items():
            curve.plot([wavelength], [geometry.focal_shift_at_mm(wavelength)], "o", color=_LINE_COLOURS[name],
                       gid=f"line-{name}")
            curve.annotate(name, (wavelength, geometry.focal_shift_at_mm(wavelength)), xytext=(5, -3),
                           textcoords="offset points", color=_LINE_COLOURS[name])
        curve.axhline(0.0, color=_style.AXIS, lw=0.8)
        curve.set_xlabel("wavelength (nm)")
        curve.set_ylabel("back focal length minus at d (mm)")
        curve.set_title(f"focal shift: F \u2212 C = {_style.mm(geometry.chromatic_focal_shift_mm, 3)}", loc="left")
        for ax in (section, zoom, curve):
            for side in ("top", "right"):
                ax.spines[side].set_visible(False)
        fig.suptitle(f"Chromatic aberration of {p.name}: f = {data.effective_focal_length_mm:.2f} mm (d), "
                     f"f/{data.f_number:.2f}", x=0.01, ha="left")
    return fig

