"""Chromatic aberration of a lens system: lateral and longitudinal colour.

Both are measured with the film fixed where the camera puts it (in n_d light)
and the object fixed in space, so that only the wavelength changes:

- *lateral colour*: the film height of the real chief ray (through the stop
  centre) from one object point, at each wavelength
  (:func:`chief_ray_heights_at_mm`); F minus C is the contract's size;
- *longitudinal colour*: where the paraxial image of the axial object point
  lies at each wavelength (:func:`axial_image_z_mm`), and the blur disk one
  line's light makes at the other line's focus (:func:`longitudinal_color_blur_mm`).

The object point is given as seen from the n_d entrance pupil (the camera's
perspective centre).  At another wavelength the entrance pupil moves a little;
the object is then placed at the same point in space, so no part of the
difference comes from moving it.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import InputError
from ..units import MM_PER_M
from .analysis import _chief_ray, _chief_ray_height_on_mm, _chief_ray_heights_on_mm, _chief_rays
from .glass import C_NM, F_NM
from .paraxial import paraxial_data, ray_transfer_matrix
from .prescription import Prescription

__all__ = ["chief_ray_height_at_mm", "chief_ray_heights_at_mm", "lateral_color_mm", "axial_image_z_mm",
           "longitudinal_color_blur_mm"]


def _seen_from_own_pupil(prescription: Prescription, wavelength_nm: float, field_angle_deg: float,
                         focus_distance_m: float) -> tuple[Prescription, float, float]:
    """The lens at ``wavelength_nm`` and the (angle rad, distance m) of the
    object point from that wavelength's entrance pupil, the point being the
    one at ``field_angle_deg`` and ``focus_distance_m`` from the n_d pupil."""
    at = prescription.at_wavelength(wavelength_nm)
    theta = math.radians(field_angle_deg)
    if math.isinf(focus_distance_m):  # a direction: the same from every pupil
        return at, theta, focus_distance_m
    shift_mm = paraxial_data(at).entrance_pupil_position_mm - paraxial_data(prescription).entrance_pupil_position_mm
    distance_mm = focus_distance_m * MM_PER_M
    height_mm = distance_mm * math.tan(theta)
    distance_mm += shift_mm  # the object stays put; its distance from the moved pupil changes
    return at, math.atan(height_mm / distance_mm), distance_mm / MM_PER_M


def chief_ray_height_at_mm(prescription: Prescription, field_angle_deg: float, *, wavelength_nm: float,
                           film_z_mm: float, focus_distance_m: float = math.inf) -> float:
    """Film height (mm) of the real chief ray from one object point at one wavelength.

    Parameters
    ----------
    prescription : Prescription
        The lens (its n_d entrance pupil places the object point).
    field_angle_deg : float
        Field angle of the object point seen from the n_d entrance pupil, degrees.
    wavelength_nm : float
        Wavelength, nm.
    film_z_mm : float
        The film plane, mm from the first vertex (the same for every wavelength).
    focus_distance_m : float, optional
        Distance of the object plane from the n_d entrance pupil, m (default infinity).

    Returns
    -------
    float
        Signed height (negative above the axis: the image is inverted).
        Apertures are ignored, as for :func:`.analysis.chief_ray_film_height_mm`.

    Raises
    ------
    InputError
        When the chief ray does not get through the lens at that wavelength.
    """
    at, theta, distance_m = _seen_from_own_pupil(prescription, float(wavelength_nm), field_angle_deg,
                                                  focus_distance_m)
    if theta == 0.0:
        return 0.0
    origin, direction = _chief_ray(at, theta, distance_m)
    return _chief_ray_height_on_mm(at, origin, direction, film_z_mm,
                                   blocked=f"the chief ray at {field_angle_deg:g} deg does not get through "
                                           f"the lens at {wavelength_nm:g} nm")


def _chief_ray_heights_at_mm(prescription: Prescription, field_angles_deg, *, wavelength_nm: float,
                             film_z_mm: float, focus_distance_m: float = math.inf) -> np.ndarray:
    """:func:`chief_ray_height_at_mm` at each of ``field_angles_deg`` (all
    nonzero), the chief rays found side by side: NaN where it would raise."""
    seen = [_seen_from_own_pupil(prescription, float(wavelength_nm), float(a), focus_distance_m)
            for a in field_angles_deg]
    if not seen:
        return np.zeros(0)
    at, distance_m = seen[0][0], seen[0][2]  # the same for every angle: the pupil shift is along the axis
    rays = _chief_rays(at, [theta for _, theta, _ in seen], distance_m)
    return _chief_ray_heights_on_mm(at, *rays, film_z_mm)


def chief_ray_heights_at_mm(prescription: Prescription, field_angle_deg: float, *, wavelengths_nm,
                            film_z_mm: float, focus_distance_m: float = math.inf) -> np.ndarray:
    """:func:`chief_ray_height_at_mm` at each of ``wavelengths_nm``, as an array."""
    return np.array([chief_ray_height_at_mm(prescription, field_angle_deg, wavelength_nm=w, film_z_mm=film_z_mm,
                                            focus_distance_m=focus_distance_m) for w in wavelengths_nm])


def lateral_color_mm(prescription: Prescription, field_angle_deg: float, *, film_z_mm: float,
                     focus_distance_m: float = math.inf) -> float:
    """Chief-ray film height at F (486.13 nm) minus at C (656.27 nm), mm.

    The sign is that of the heights' magnitudes: positive when blue lands
    farther from the axis than red. 0 for a lens that does not disperse.
    See :func:`chief_ray_heights_at_mm` for the parameters.
    """
    if not prescription.disperses or field_angle_deg == 0.0:
        return 0.0
    blue, red = chief_ray_heights_at_mm(prescription, field_angle_deg, wavelengths_nm=(F_NM, C_NM),
                                        film_z_mm=film_z_mm, focus_distance_m=focus_distance_m)
    return float(abs(blue) - abs(red))


def _marginal_ray_out(prescription: Prescription, wavelength_nm: float, focus_distance_m: float):
    """(height mm, slope) behind the last vertex of the paraxial ray from the
    axial object point through the rim of the entrance pupil, at ``wavelength_nm``."""
    at, _, distance_m = _seen_from_own_pupil(prescription, wavelength_nm, 0.0, focus_distance_m)
    data = paraxial_data(at)
    rim_mm = 0.5 * data.entrance_pupil_diameter_mm
    if math.isinf(distance_m):
        ray = np.array([rim_mm, 0.0])
    else:
        slope = rim_mm / (distance_m * MM_PER_M)
        ray = np.array([slope * (distance_m * MM_PER_M - data.entrance_pupil_position_mm), slope])
    y_out, u_out = ray_transfer_matrix(at) @ ray
    if u_out == 0.0:
        raise InputError(prescription.name, f"afocal at {wavelength_nm:g} nm: no image of the focus plane")
    return float(y_out), float(u_out)


def axial_image_z_mm(prescription: Prescription, *, wavelength_nm: float,
                     focus_distance_m: float = math.inf) -> float:
    """Paraxial image of the axial object point at ``wavelength_nm``, mm from the first vertex.

    The object lies ``focus_distance_m`` in front of the n_d entrance pupil;
    at d this is where :func:`.focus.film_distance_mm` puts the film.
    """
    y_out, u_out = _marginal_ray_out(prescription, wavelength_nm, focus_distance_m)
    return prescription.total_track_mm - y_out / u_out


def longitudinal_color_blur_mm(prescription: Prescription, *, focus_distance_m: float = math.inf) -> float:
    """Diameter (mm) of the blur disk the F light makes where the C light focuses.

    Paraxial: the F marginal ray (through the rim of the entrance pupil of
    ``prescription`` as given, so stop it down first) crosses the C image
    plane at height h; the disk is 2|h|.  For a distant object it is
    |chromatic focal shift| / N.  The film at the d focus lies between the two
    foci, where the F and C disks together span the same.  0 for a lens that
    does not disperse.
    """
    if not prescription.disperses:
        return 0.0
    y_out, u_out = _marginal_ray_out(prescription, F_NM, focus_distance_m)
    red_z = axial_image_z_mm(prescription, wavelength_nm=C_NM, focus_distance_m=focus_distance_m)
    return 2.0 * abs(y_out + u_out * (red_z - prescription.total_track_mm))

