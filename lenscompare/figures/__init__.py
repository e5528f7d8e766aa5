"""Teaching figures drawn from the project's own optics code (paper Figs. 1-4).

One module per figure, each with a pure ``*_geometry`` function (the numbers,
tested against the optics functions) and a ``*_figure`` function (the
drawing, a :class:`matplotlib.figure.Figure` rendered with Agg, no display):

- :mod:`.thin_lens`: thin lens with real numbers, eqs. 1-10 (Figs. 1-2);
- :mod:`.thick_lens`: a prescription's H, H', F, F', model against real rays (Fig. 3);
- :mod:`.lens_system`: any prescription in cross-section with traced bundles (Fig. 4);
- :mod:`.aperture`: where the geometric models stop: defocus against
  diffraction over the f-number (the best aperture), and bokeh and diffraction
  stars of 5, 6, 7 and 9 blades;
- :mod:`.chromatic`: ray fans at F, d and C through a dispersive lens, and
  its focal shift against wavelength (issue 15).
- :mod:`.motion`: time as a sample dimension: a moving point's streak with and
  without defocus, and one pixel's samples in lens x time (sobol against padding).

:func:`write_teaching_figures` writes all five; ``lenscompare figures`` is its
command line.
"""

from __future__ import annotations

import contextlib
import os
from pathlib import Path

from ..atomic import atomic_output, prepare_output_dir
from ..errors import InputError
from ..lenses import load_prescription
from ._style import figure_bytes
from .aperture import aperture_figure, aperture_geometry
from .chromatic import chromatic_figure, chromatic_geometry, teaching_singlet
from .lens_system import lens_system_figure, lens_system_geometry
from .motion import motion_figure, motion_geometry
from .thick_lens import thick_lens_figure, thick_lens_geometry
from .thin_lens import thin_lens_figure, thin_lens_geometry

__all__ = [
    "FIGURE_NAMES",
    "write_teaching_figures",
    "thin_lens_geometry",
    "thin_lens_figure",
    "thick_lens_geometry",
    "thick_lens_figure",
    "lens_system_geometry",
    "lens_system_figure",
    "aperture_geometry",
    "aperture_figure",
    "chromatic_geometry",
    "chromatic_figure",
    "motion_geometry",
    "motion_figure",
]

FIGURE_NAMES = ("thin_lens", "thick_lens", "lens_system", "aperture", "chromatic", "motion")


def write_teaching_figures(out_dir: str | os.PathLike, *, lens: str | os.PathLike = "dgauss.50mm",
                           focal_length_mm: float = 50.0, f_number: float = 2.0,
                           focus_distance_m: float = 2.0, object_distances_m=(1.0, 5.0),
                           chromatic_lens: str | os.PathLike | None = None, svg: bool = True) -> dict[str, Path]:
    """Draw the teaching figures and write them into a folder.

    Parameters
    ----------
    out_dir : str or os.PathLike
        Folder for the files; created (with its parents) if missing.
    lens : str or os.PathLike, optional
        Prescription for the thick-lens and lens-system figures: a shipped
        name or the path of a lens file.  Drawn wide open.
    focal_length_mm, f_number : float, optional
        The thin lens of the thin-lens figure.
    focus_distance_m : float, optional
        Plane of focus, m: from the thin lens in the thin-lens figure, from
        the entrance pupil for the lens system (its film is placed there).
    object_distances_m : sequence of float, optional
        One to three axial object points for the thin-lens figure, m; the
        farthest is the point whose blur the aperture figure follows.
    chromatic_lens : str or os.PathLike, optional
        Prescription for the chromatic figure; it must disperse. Default:
        ``lens`` when it disperses, else the N-BK7 teaching singlet
        (:func:`lenscompare.figures.chromatic.teaching_singlet`).
    svg : bool, optional
        Also write an SVG next to each PNG (same stem).

    Returns
    -------
    dict of str to Path
        Figure name (``"thin_lens"``, ``"thick_lens"``, ``"lens_system"``,
        ``"aperture"``, ``"chromatic"``, ``"motion"``) to
        its PNG file; with ``svg`` the SVG is ``path.with_suffix(".svg")``.

    Raises
    ------
    InputError
        A bad lens (unknown name, unreadable or invalid file, cannot focus at
        ``focus_distance_m``) or a bad thin-lens parameter.

    Notes
    -----
    All the figures are computed and rendered in memory before anything is
    written, and each file is written atomically; so a bad input leaves no
    file (and does not create ``out_dir``), and a failed run never replaces a
    good figure with a partial one.
    """
    out = Path(out_dir)
    if out.exists() and not out.is_dir():
        raise InputError(os.fspath(out), "exists and is not a folder")

    # Everything that can fail on bad input, before any file is touched.
    prescription = load_prescription(lens)
    if chromatic_lens is not None:
        dispersive = load_prescription(chromatic_lens)
    else:
        dispersive = prescription if prescription.disperses else teaching_singlet()
    figures = {
        "thin_lens": thin_lens_figure(thin_lens_geometry(
            focal_length_mm=focal_length_mm, f_number=f_number,
            focus_distance_m=focus_distance_m, object_distances_m=object_distances_m)),
        "thick_lens": thick_lens_figure(thick_lens_geometry(prescription)),
        "lens_system": lens_system_figure(lens_system_geometry(
            prescription, focus_distance_m=focus_distance_m)),
        "aperture": aperture_figure(aperture_geometry(
            focal_length_mm=focal_length_mm, focus_distance_m=focus_distance_m,
            object_distance_m=max(object_distances_m))),
        "chromatic": chromatic_figure(chromatic_geometry(dispersive)),
        "motion": motion_figure(motion_geometry()),
    }
    formats = ("png", "svg") if svg else ("png",)
    rendered = {(name, fmt): figure_bytes(figure, fmt)
                for name, figure in figures.items() for fmt in formats}

    prepare_output_dir(out)  # a read-only place: exit 2 naming -o, not a traceback
    # Every file goes to a temporary first; all are renamed into place only
    # once all of them are written.
    with contextlib.ExitStack() as stack:
        for (name, fmt), data in rendered.items():
            temporary = stack.enter_context(atomic_output(out / f"{name}.{fmt}"))
            temporary.write_bytes(data)
    return {name: out / f"{name}.png" for name in figures}
