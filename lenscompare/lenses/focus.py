"""Focusing a lens system by moving the film (unit focusing), paraxially.

The focus distance is in metres, measured from the entrance pupil along the
axis toward the scene (DESIGN.md: ``camera.position`` is the entrance-pupil
centre and ``focus_distance`` is measured from it).  The film distance is in
mm behind the last vertex.  Positions follow :mod:`.paraxial`: mm from the
first vertex, positive toward the film.
"""

from __future__ import annotations

import math

from ..errors import InputError
from ..units import MM_PER_M
from .paraxial import paraxial_data, ray_transfer_matrix
from .prescription import Prescription, sag_mm

__all__ = ["film_distance_mm", "closest_focus_distance_m", "front_most_z_mm"]



def front_most_z_mm(prescription: Prescription) -> float:
    """Axial position (mm) of the lens point nearest the scene (a vertex or a rim)."""
    return min(
        z + min(0.0, sag_mm(surface.curvature_per_mm, surface.semi_aperture_mm))
        for z, surface in zip(prescription.vertex_z_mm, prescription.surfaces)
    )


def closest_focus_distance_m(prescription: Prescription) -> float:
    """Closest-focus limit, m from the entrance pupil; focus must lie beyond it.

    The limit is the front focal point (an object there is imaged at
    infinity, one inside it has no real image behind the lens) or the front of
    the lens itself, whichever is nearer the scene; 0 when both lie behind the
    entrance pupil.  :func:`film_distance_mm` accepts only distances strictly
    greater.

    Raises
    ------
    InputError
        When the lens forms no real image of a distant object (negative focal
        length, or the rear focal point inside the lens).
    """
    data = _check_forms_images(prescription)
    limit_z = min(data.front_focal_point_mm, front_most_z_mm(prescription))
    return max(0.0, (data.entrance_pupil_position_mm - limit_z) / MM_PER_M)


def film_distance_mm(prescription: Prescription, focus_distance_m: float, *,
                     source: str | None = None, key: str | None = "focus_distance") -> float:
    """Film distance behind the last vertex that brings a plane into paraxial focus.

    Parameters
    ----------
    prescription : Prescription
    focus_distance_m : float
        Distance of the plane of sharp focus from the entrance pupil, m;
        ``math.inf`` for infinity.
    source, key : str, optional
        Where the request came from, for the error message (default: the lens
        name and ``"focus_distance"``).

    Returns
    -------
    float
        Distance from the last vertex to the film, mm.  At infinity this is the
        back focal length.

    Raises
    ------
    InputError
        When ``focus_distance_m`` is not a positive number, or not beyond
        :func:`closest_focus_distance_m` (the message gives that distance).
    """
    source = prescription.name if source is None else source
    try:
        distance_m = float(focus_distance_m)
    except (TypeError, ValueError):
        distance_m = math.nan
    if not distance_m > 0:
        raise InputError(source, f"focus distance must be a positive number of metres, "
                         f"got {focus_distance_m!r}", key=key)
    closest_m = closest_focus_distance_m(prescription)
    if distance_m <= closest_m:
        raise InputError(source, f"{prescription.name} cannot focus at {distance_m:g} m: the "
                         f"closest focus is beyond {closest_m:.4g} m from the entrance pupil",
                         key=key)

    data = paraxial_data(prescription)
    (a, b), (c, d) = ray_transfer_matrix(prescription).tolist()
    # Object distance in front of the first vertex, mm.  Divide through by it,
    # so that infinity (and 1e12 m) give -A/C, the back focal length, without
    # inf/inf.
    object_mm = distance_m * MM_PER_M - data.entrance_pupil_position_mm
    inverse = 1.0 / object_mm
    numerator = a + b * inverse
    denominator = c + d * inverse
    if not denominator < 0.0 or not -numerator / denominator > 0.0:
        # Only reachable through rounding right at the closest focus.
        raise InputError(source, f"{prescription.name} cannot focus at {distance_m:g} m: the "
                         f"closest focus is beyond {closest_m:.4g} m from the entrance pupil",
                         key=key)
    return -numerator / denominator


def _check_forms_images(prescription: Prescription):
    """Paraxial data, after checking that a distant object has a real image."""
    data = paraxial_data(prescription)
    if data.effective_focal_length_mm <= 0:
        raise InputError(prescription.source, f"focal length "
                         f"{data.effective_focal_length_mm:.4g} mm is negative: the lens forms "
                         f"no real image, so it cannot be focused on film")
    if data.back_focal_length_mm <= 0:
        raise InputError(prescription.source, f"the rear focal point lies "
                         f"{-data.back_focal_length_mm:.4g} mm inside the lens: no film "
                         f"position can be in focus")
    return data
