"""Best focus: the film position where a lens system's on-axis spot is smallest.

A contrast autofocus does not stop at the paraxial image of the focus plane: with
spherical aberration the marginal rays cross the axis elsewhere, and the
smallest blur lies between the paraxial and the marginal focus.  This module
finds that film position from real rays (``camera.focus_mode = "best"``), and,
the other way round, the object plane a given film position shows sharpest.

Lens frame of :mod:`.trace`: mm, z = 0 at the first vertex, positive toward
the film.  Focus distances are m from the entrance pupil.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import InputError
from ..units import MM_PER_M
from .focus import closest_focus_distance_m, film_distance_mm, front_most_z_mm
from .paraxial import paraxial_data, stopped_down
from .prescription import Prescription, sag_mm
from .trace import trace_from_scene

__all__ = ["AxialFan", "axial_fan", "best_focus_film_z_mm", "rms_spot_radius_mm", "sharpest_plane_m"]

RINGS = 2048
"""Rings of the pupil the axial fan samples (midpoint rule: error ~ 1/RINGS^2)."""

_SCAN = 4096      # heights scanned to find the rim of the axial beam
_REFINE = 64      # points per refinement round of the rim
_ROUNDS = 3       # rounds: the rim is known to scan step / 64^3


class AxialFan:
    """Rays from the axial point of a focus plane, one per ring of the beam.

    On the axis every ray is meridional, so a ring of rays at height h (where
    they cross the first vertex plane) lands on a circle of signed radius
    ``rho(z) = intercept + slope * z`` on a film at z: linear in z.  The spot is
    round and centred on the axis, so its mean squared radius is
    ``sum(w rho^2) / sum(w)`` with ``w`` the flux of each ring.

    Attributes
    ----------
    intercept_mm, slope : numpy.ndarray
        ``rho(z) = intercept_mm + slope * z`` (z in mm, lens frame).
    weight : numpy.ndarray
        Flux of each ring (solid angle seen from the point), normalised to sum 1.
    """

    def __init__(self, intercept_mm: np.ndarray, slope: np.ndarray, weight: np.ndarray):
        self.intercept_mm, self.slope, self.weight = intercept_mm, slope, weight

    def mean_square_radius_mm2(self, film_z_mm) -> np.ndarray:
        """Flux-weighted mean of rho^2 on films at ``film_z_mm`` (scalar or array)."""
        z = np.asarray(film_z_mm, dtype=float)[..., None]
        return ((self.intercept_mm + self.slope * z) ** 2 * self.weight).sum(axis=-1)

    def smallest_spot_z_mm(self) -> float:
        """Film z of the smallest RMS spot, in closed form.

        The mean square radius is a quadratic in z,
        ``sum w (a + b z)^2 = A + 2 B z + C z^2``, so its minimum is at
        ``z = -B / C`` with ``B = sum w a b`` and ``C = sum w b^2`` -- no search.
        """
        c = float((self.weight * self.slope ** 2).sum())
        if not c > 0.0:  # every ray parallel to the axis: an afocal beam has no focus
            raise ValueError("the axial beam leaves the lens parallel: no focus")
        return -float((self.weight * self.intercept_mm * self.slope).sum()) / c


@functools.lru_cache(maxsize=256)
def axial_fan(prescription: Prescription, *, focus_distance_m: float, rings: int = RINGS) -> AxialFan:
    """The rays from the axial point at ``focus_distance_m`` that get through the lens.

    Rays are labelled by the height h at which they cross the first vertex
    plane; the beam that passes is 0 <= h <= h_rim (every aperture limits it:
    the stop, and any other rim that cuts the axial beam).  h_rim is found by a
    scan and refined to about 1e-9 of the first surface's radius, since the
    marginal rays weigh most in an RMS spot.  The rings are the midpoints of
    ``rings`` equal steps of [0, h_rim].

    Raises
    ------
    InputError
        The lens cannot focus there (:func:`.film_distance_mm`'s message), or
        not even the axial ray gets through.
    """
    film_distance_mm(prescription, focus_distance_m)  # refuses a focus the lens cannot reach
    data = paraxial_data(prescription)
    lever_mm = focus_distance_m * MM_PER_M - data.entrance_pupil_position_mm  # object to first vertex
    start_z = front_most_z_mm(prescription) - 1.0
    first = prescription.surfaces[0]

    def trace(heights):
        # Written with the slope h / lever so that infinity (and 1e12 m) cost no precision.
        slope = heights / lever_mm
        directions = np.stack([np.zeros_like(heights), slope, np.ones_like(heights)], axis=1)
        directions /= np.linalg.norm(directions, axis=1)[:, None]
        origins = np.stack([np.zeros_like(heights), heights + slope * start_z, np.full_like(heights, start_z)], axis=1)
        return trace_from_scene(prescription, origins, directions)

    reach = 2.0 * (first.semi_aperture_mm + abs(sag_mm(first.curvature_per_mm, first.semi_aperture_mm))) + 1.0
    heights = np.linspace(0.0, reach, _SCAN + 1)
    passed = trace(heights).passed
    if not passed[0]:
        raise InputError(prescription.name, "not even the axial ray gets through the lens")
    # The beam is the disk up to the first blocked height; refine that edge.
    edge = int(np.argmin(passed)) if not passed.all() else _SCAN
    lo, hi = heights[max(edge - 1, 0)], heights[edge]
    for _ in range(_ROUNDS):
        if hi == lo:
            break
        candidates = np.linspace(lo, hi, _REFINE + 1)
        ok = trace(candidates).passed
        last = int(np.argmin(ok)) - 1 if not ok.all() else _REFINE
        lo, hi = candidates[max(last, 0)], candidates[min(last + 1, _REFINE)]
    rim = lo

    heights = (np.arange(rings) + 0.5) / rings * rim
    rays = trace(heights)
    o, d = rays.origins_mm, rays.directions
    slope = np.where(rays.passed, d[:, 1] / np.where(rays.passed, d[:, 2], 1.0), 0.0)
    intercept = np.where(rays.passed, o[:, 1] - slope * o[:, 2], 0.0)
    # Flux of a ring: the solid angle of the annulus 2 pi h dh at distance
    # lever, lever * 2 pi h dh / (lever^2 + h^2)^(3/2); constants dropped.
    weight = np.where(rays.passed, heights / (1.0 + (heights / lever_mm) ** 2) ** 1.5, 0.0)
    weight = weight / weight.sum()
    return AxialFan(intercept, slope, weight)


def _lens(prescription: Prescription, f_number: float | None) -> Prescription:
    return prescription if f_number is None else stopped_down(prescription, f_number)


@functools.lru_cache(maxsize=256)
def best_focus_film_z_mm(prescription: Prescription, *, focus_distance_m: float,
                         f_number: float | None = None) -> float:
    """Film position (mm from the first vertex) of the smallest on-axis RMS spot.

    Parameters
    ----------
    prescription : Prescription
    focus_distance_m : float
        The plane to focus on, m from the entrance pupil (``math.inf`` allowed).
    f_number : float, optional
        Stop the lens down to this paraxial f-number first (default: as given,
        which for a camera's prescription is already its working aperture).

    Returns
    -------
    float
        Film z, mm; compare ``total_track_mm + film_distance_mm(...)`` for
        the paraxial focus.  Memoised (prescriptions are frozen values).

    Notes
    -----
    The spot of a fixed traced bundle is a quadratic function of film z (each
    ray's landing point is linear in z), so the minimum has a closed form
    (:meth:`AxialFan.smallest_spot_z_mm`); nothing is searched.
    """
    fan = axial_fan(_lens(prescription, f_number), focus_distance_m=focus_distance_m)
    try:
        return fan.smallest_spot_z_mm()
    except ValueError as error:
        raise InputError(prescription.name, str(error)) from None


def rms_spot_radius_mm(prescription: Prescription, *, focus_distance_m: float, film_z_mm: float,
                       f_number: float | None = None) -> float:
    """RMS radius (mm) of the on-axis spot of the point at ``focus_distance_m`` on a film at ``film_z_mm``."""
    fan = axial_fan(_lens(prescription, f_number), focus_distance_m=focus_distance_m)
    return math.sqrt(float(fan.mean_square_radius_mm2(film_z_mm)))


def sharpest_plane_m(prescription: Prescription, *, film_z_mm: float, f_number: float | None = None) -> float:
    """The object distance (m from the entrance pupil) whose best focus is at ``film_z_mm``.

    With the film at the paraxial image of a plane (``focus_mode =
    "paraxial"``), this is the plane the image actually shows sharpest.  Solved
    in reciprocal distance 1/D (Brent's method), where infinity is 0.

    Returns
    -------
    float
        Distance, m; ``math.inf`` when even infinity's best focus lies behind
        ``film_z_mm`` (the sharpest plane would be "beyond infinity").
    """
    lens = _lens(prescription, f_number)

    def excess(per_m):  # best-focus film z for the plane at 1/per_m, minus the film
        distance_m = math.inf if per_m == 0.0 else 1.0 / per_m
        return best_focus_film_z_mm(lens, focus_distance_m=distance_m) - film_z_mm

    if excess(0.0) >= 0.0:  # best_z falls as the plane recedes: no finite plane reaches this film
        return math.inf
    closest_m = closest_focus_distance_m(lens)
    near_per_m = 1.0 / max(closest_m * 1.05, 1e-3)
    while excess(near_per_m) < 0.0:  # a film far behind: the plane is closer still
        if near_per_m * closest_m > 0.999:
            raise InputError(prescription.name, f"no plane in front of the lens is sharpest on a film at "
                             f"{film_z_mm:g} mm")
        near_per_m = 0.5 * (near_per_m + 1.0 / closest_m) if closest_m > 0 else 2.0 * near_per_m
    from scipy.optimize import brentq  # SciPy takes 0.4 s to import: only this search needs it, not lens info

    return 1.0 / brentq(excess, 0.0, near_per_m, xtol=1e-12, rtol=1e-12)
