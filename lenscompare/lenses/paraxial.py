"""First-order (paraxial) properties of a lens system, by ray-transfer matrices.

Rays are columns ``(y, w)``: height y in mm and reduced angle ``w = n * u``
(u the slope dy/dz in a medium of index n).  With reduced angles every matrix
has determinant 1.  A refraction at a surface of curvature c from index n to
n' is ``[[1, 0], [-(n' - n) * c, 1]]``; a transfer over t mm in index n is
``[[1, t / n], [0, 1]]``.

Axial positions are mm from the FIRST vertex, positive toward the film (the
``lens info`` convention of DESIGN.md).  The object is at infinity, light is
n_d, and the lenses sit in air on both sides.  For the system matrix
``[[A, B], [C, D]]`` from the first to the last vertex:

- effective focal length ``f = -1 / C``; back focal length ``-A / C``;
- front focal point at ``D / C``; principal planes ``H = F + f``,
  ``H' = F' - f``;
- entrance pupil: the stop seen through the surfaces in front of it; with
  ``[[A, B], ...]`` the matrix from the first vertex to the stop, it lies at
  ``B / A`` with semi-diameter ``stop / |A|``;
- exit pupil: the stop seen through the surfaces behind it; with
  ``[[A, B], [C, D]]`` from the stop to the last vertex, it lies ``-B / D``
  behind the last vertex with semi-diameter ``stop / |D|``.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .glass import C_NM, F_NM
from .prescription import Prescription

__all__ = [
    "ParaxialData",
    "paraxial_data",
    "ray_transfer_matrix",
    "aperture_stop_index",
    "stop_semi_aperture_for_f_number",
    "stopped_down",
    "chromatic_focal_shift_mm",
]


@dataclass(frozen=True)
class ParaxialData:
    """First-order data of a lens, object at infinity, n_d light.

    Positions are mm from the first vertex, positive toward the film.

    Attributes
    ----------
    effective_focal_length_mm : float
        EFL: distance from the rear principal plane to the rear focal point.
    back_focal_length_mm : float
        From the last vertex to the rear focal point F'.
    front_focal_length_mm : float
        From the front focal point F to the first vertex (positive when F lies
        in front of the lens).
    front_focal_point_mm, rear_focal_point_mm : float
        Positions of F and F'.
    front_principal_plane_mm, rear_principal_plane_mm : float
        Positions of H and H'.
    entrance_pupil_position_mm, entrance_pupil_diameter_mm : float
        The aperture stop imaged through the surfaces in front of it.
    exit_pupil_position_mm, exit_pupil_diameter_mm : float
        The aperture stop imaged through the surfaces behind it.
    f_number : float
        Paraxial f-number, EFL / entrance-pupil diameter.
    total_track_mm : float
        First vertex to last vertex.
    stop_index : int
        Index of the aperture-stop surface (0-based).
    """

    effective_focal_length_mm: float
    back_focal_length_mm: float
    front_focal_length_mm: float
    front_focal_point_mm: float
    rear_focal_point_mm: float
    front_principal_plane_mm: float
    rear_principal_plane_mm: float
    entrance_pupil_position_mm: float
    entrance_pupil_diameter_mm: float
    exit_pupil_position_mm: float
    exit_pupil_diameter_mm: float
    f_number: float
    total_track_mm: float
    stop_index: int


def ray_transfer_matrix(prescription: Prescription, *, first: int = 0,
                        last: int | None = None) -> np.ndarray:
    """Paraxial matrix from just in front of one surface to just behind another.

    Parameters
    ----------
    prescription : Prescription
    first : int, optional
        Index of the first surface included (its vertex plane is the input
        plane).  Default 0.
    last : int, optional
        Index of the last surface included (its vertex plane, after its
        refraction, is the output plane).  Default: the last surface.
        ``last < first`` gives the identity.

    Returns
    -------
    numpy.ndarray
        2x2 float64 matrix acting on ``(y_mm, n * u)``.
    """
    surfaces = prescription.surfaces
    last = len(surfaces) - 1 if last is None else last
    matrix = np.eye(2)
    for index in range(first, last + 1):
        surface = surfaces[index]
        if index > first:
            # Transfer from the previous vertex through the medium between.
            before = surfaces[index - 1]
            matrix = np.array([[1.0, before.thickness_mm / before.n_after], [0.0, 1.0]]) @ matrix
        power = (surface.n_after - prescription.n_before(index)) * surface.curvature_per_mm
        matrix = np.array([[1.0, 0.0], [-power, 1.0]]) @ matrix
    return matrix


def aperture_stop_index(prescription: Prescription) -> int:
    """Index of the aperture stop.

    The surface marked with radius 0 when there is one; otherwise the surface
    that limits an axial beam from infinity (smallest semi-aperture over
    paraxial marginal-ray height).
    """
    if prescription.stop_index is not None:
        return prescription.stop_index
    ratios = []
    for index, surface in enumerate(prescription.surfaces):
        # Height at this vertex of the axial ray entering at y = 1, u = 0.
        height = float(_to_stop_matrix(prescription, index)[0, 0])
        ratios.append(surface.semi_aperture_mm / abs(height) if height else math.inf)
    return int(np.argmin(ratios))


@functools.lru_cache(maxsize=256)
def paraxial_data(prescription: Prescription) -> ParaxialData:
    """First-order data of a lens for an object at infinity in n_d light.

    Parameters
    ----------
    prescription : Prescription

    Returns
    -------
    ParaxialData
        Positions in mm from the first vertex, positive toward the film.

    Raises
    ------
    InputError
        When the lens has no optical power (afocal), so no focal length.

    Notes
    -----
    A pupil at infinity (a telecentric side) reads ``inf``. Memoised: a
    prescription (a frozen value) has its data computed once per process.
    """
    (a, b), (c, d) = ray_transfer_matrix(prescription).tolist()
    if c == 0.0:
        raise InputError(prescription.source, "the lens has no optical power (afocal): "
                         "no focal length")
    track = prescription.total_track_mm
    efl = -1.0 / c
    front_focal_point = d / c
    rear_focal_point = track - a / c

    stop = aperture_stop_index(prescription)
    stop_semi = prescription.surfaces[stop].semi_aperture_mm
    entrance_position, entrance_diameter = _entrance_pupil(prescription, stop, stop_semi)
    exit_position, exit_diameter = _exit_pupil(prescription, stop, stop_semi)
    return ParaxialData(
        effective_focal_length_mm=efl,
        back_focal_length_mm=-a / c,
        front_focal_length_mm=-front_focal_point,
        front_focal_point_mm=front_focal_point,
        rear_focal_point_mm=rear_focal_point,
        front_principal_plane_mm=front_focal_point + efl,
        rear_principal_plane_mm=rear_focal_point - efl,
        entrance_pupil_position_mm=entrance_position,
        entrance_pupil_diameter_mm=entrance_diameter,
        exit_pupil_position_mm=exit_position,
        exit_pupil_diameter_mm=exit_diameter,
        f_number=efl / entrance_diameter,
        total_track_mm=track,
        stop_index=stop,
    )


def chromatic_focal_shift_mm(prescription: Prescription) -> float:
    """Paraxial back focal length at F (486.13 nm) minus at C (656.27 nm), mm.

    Object at infinity (DESIGN.md, "Glass and dispersion").  Negative when
    blue focuses nearer the lens (an undercorrected singlet); 0 for a lens
    whose media do not disperse.

    Raises
    ------
    InputError
        When the lens is afocal at F or C.
    """
    if not prescription.disperses:
        return 0.0
    blue = paraxial_data(prescription.at_wavelength(F_NM)).back_focal_length_mm
    red = paraxial_data(prescription.at_wavelength(C_NM)).back_focal_length_mm
    return blue - red


F_NUMBER_RELATIVE_TOLERANCE = 1e-4
"""Relative difference below which a requested f-number counts as the lens's own."""


def _distinct_digits(a: float, b: float) -> tuple[str, str]:
    """``a`` and ``b`` printed with the fewest significant digits (at least 3)
    that tell them apart, so a refusal shows why."""
    for digits in range(3, 17):
        shown = f"{a:.{digits}g}", f"{b:.{digits}g}"
        if shown[0] != shown[1]:
            return shown
    return shown


def stop_semi_aperture_for_f_number(prescription: Prescription, f_number: float, *,
                                    source: str | None = None,
                                    key: str | None = "f_number") -> float:
    """Stop semi-aperture (mm) that gives a requested paraxial f-number.

    The entrance pupil scales linearly with the stop, so the result is exact
    in paraxial optics.  :func:`stopped_down` applies it.

    Parameters
    ----------
    prescription : Prescription
    f_number : float
        Requested paraxial f-number, EFL / entrance-pupil diameter.
    source, key : str, optional
        Where the request came from, for the error message (default: the lens
        name and ``"f_number"``).

    Returns
    -------
    float
        Semi-aperture of the aperture stop, mm.

    Raises
    ------
    InputError
        When ``f_number`` is not a positive finite number, or is faster (smaller)
        than the lens's own f-number: a stop can only be closed, so this is
        refused.
    """
    source = prescription.name if source is None else source
    try:
        requested = float(f_number)
    except (TypeError, ValueError):
        requested = math.nan
    if not (math.isfinite(requested) and requested > 0):
        raise InputError(source, f"f-number must be a positive number, got {f_number!r}", key=key)
    f_number = requested
    data = paraxial_data(prescription)
    if not (math.isfinite(data.f_number) and data.f_number > 0):
        raise InputError(source, f"{prescription.name} has no usable aperture (focal length "
                         f"{data.effective_focal_length_mm:.4g} mm, entrance pupil "
                         f"{data.entrance_pupil_diameter_mm:.4g} mm): it cannot be stopped down", key=key)
    # A request within F_NUMBER_RELATIVE_TOLERANCE of the lens's own f-number is
    # wide open: a file's f/5 must not be refused for a lens at f/5.00002.
    if f_number < data.f_number * (1.0 - F_NUMBER_RELATIVE_TOLERANCE):
        asked, own = _distinct_digits(f_number, data.f_number)
        raise InputError(source, f"f/{asked} is faster than {prescription.name} allows "
                         f"(f/{own} wide open); it can only be stopped down",
                         key=key)
    stop_semi = prescription.surfaces[data.stop_index].semi_aperture_mm
    return stop_semi * min(1.0, data.f_number / f_number)


def stopped_down(prescription: Prescription, f_number: float, *, source: str | None = None,
                 key: str | None = "f_number") -> Prescription:
    """The lens with its aperture stop closed to a paraxial f-number.

    Parameters and errors as :func:`stop_semi_aperture_for_f_number`; asking
    for the lens's own f-number returns an equal prescription.
    """
    semi_aperture = stop_semi_aperture_for_f_number(prescription, f_number, source=source, key=key)
    return prescription.with_semi_aperture(aperture_stop_index(prescription), semi_aperture)


def _entrance_pupil(prescription: Prescription, stop: int, stop_semi: float) -> tuple[float, float]:
    """Position and diameter (mm) of the stop's image through the surfaces before it."""
    (a, b), _ = _to_stop_matrix(prescription, stop).tolist()
    if a == 0.0:
        return math.inf, math.inf
    return b / a, 2.0 * stop_semi / abs(a)


def _exit_pupil(prescription: Prescription, stop: int, stop_semi: float) -> tuple[float, float]:
    """Position and diameter (mm) of the stop's image through the surfaces behind it."""
    (_, b), (_, d) = ray_transfer_matrix(prescription, first=stop).tolist()
    if d == 0.0:
        return math.inf, math.inf
    return prescription.total_track_mm - b / d, 2.0 * stop_semi / abs(d)


def _to_stop_matrix(prescription: Prescription, stop: int) -> np.ndarray:
    """Matrix from the first vertex to surface ``stop``'s vertex plane, before it refracts."""
    matrix = ray_transfer_matrix(prescription, last=stop - 1)
    if stop > 0:
        before = prescription.surfaces[stop - 1]
        matrix = np.array([[1.0, before.thickness_mm / before.n_after], [0.0, 1.0]]) @ matrix
    return matrix
