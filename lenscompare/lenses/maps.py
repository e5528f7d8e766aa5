"""Radial maps of a lens system, traced once, for the composite camera.

Two tables over film radius, evenly spaced from the axis to the film corner:

- the *distortion map*: the tangent of the field angle (seen from the entrance
  pupil) whose real chief ray lands at that film radius, with the film at the
  camera's focus (:func:`.analysis.chief_ray_film_height_mm`);
- the *illumination map*: the relative illumination at that film radius
  (the formula of :func:`.analysis.relative_illumination`: pupil area, cos
  factors and mechanical vignetting; 1 on the axis), with each beam's
  passing area counted on a grid over the entrance pupil rather than over the
  whole front element, so that a small pupil behind a large front element (a
  stopped-down fisheye) is still resolved by thousands of rays.

A third table, the *lateral-colour map* (:func:`lateral_color_map`), is the
distortion map once per wavelength (a small grid with F, d and C on it), the
object on the plane of focus and the film where it is for n_d light: a
spectral composite looks up its ray's wavelength in it (linear in
wavelength between grid entries).

A composite render (:mod:`lenscompare.cameras.composite`) reads them instead
of tracing every ray through the lens. Beyond ``max_radius_mm`` (the image
circle, or the last film radius a chief ray reaches) the lens passes no light
and the composite sends no ray. Maps are memoised per prescription hash,
f-number, film position, focus and film size.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import InputError
from .analysis import (
    _chief_ray_heights_on_mm,
    _chief_rays,
    central_difference_angles,
    first_vertex_plane_height_mm,
    illumination_from_heights,
    image_circle_radius_mm,
    passing_beam_area_mm2,
)
from .chromatic import _chief_ray_heights_at_mm
from .focus import film_distance_mm
from .glass import C_NM, D_NM, F_NM
from .paraxial import paraxial_data
from .prescription import Prescription

__all__ = ["RadialMaps", "radial_maps", "pupil_relative_illumination", "LateralColorMap", "lateral_color_map",
           "COLOR_MAP_WAVELENGTHS_NM", "COLOR_MAP_MARGIN", "MAX_FIELD_DEG"]

# A screen direction (tan theta, 1) cannot look sideways: past this the
# composite cannot stand in for the lens (a fisheye), and says so.
MAX_FIELD_DEG = 80.0

# Field angles traced for each map (the maps are smooth; the tables then
# resample them evenly in film radius).
_DISTORTION_ANGLES = 65
_ILLUMINATION_ANGLES = 33
_PUPIL_GRID = 128  # rays across the window round the entrance pupil

_CACHE: dict[tuple, "RadialMaps"] = {}
_COLOR_CACHE: dict[tuple, "LateralColorMap"] = {}

COLOR_MAP_WAVELENGTHS_NM = (380.0, 430.0, F_NM, 540.0, D_NM, C_NM, 720.0, 780.0)
"""The lateral-colour map's wavelengths: the film response's range (DESIGN.md,
380-780 nm), with F, d and C among them so that their values are traced, not
interpolated."""
COLOR_MAP_MARGIN = 0.05
"""Film radius the lateral-colour map covers past the corner, as a share of the half diagonal."""


@dataclass(frozen=True, eq=False)
class RadialMaps:
    """Distortion and illumination against film radius, as the composite reads them.

    Attributes
    ----------
    radius_step_mm : float
        Film radius between table entries; entry i is at ``i * radius_step_mm``.
    field_tangent : numpy.ndarray
        Distortion map: real chief-ray field tangent at each film radius.
    illumination : numpy.ndarray
        Illumination map: relative illumination at each film radius (1 on the
        axis, 0 where no light gets through).
    paraxial_scale_mm : float
        The ideal image scale (film height per unit tangent) the maps sit on.
    max_radius_mm : float
        Film radius beyond which the lens passes no light (``math.inf``: the
        whole film is lit).
    covers_film : bool
        Whether the composite can stand in for the lens over the whole film:
        False when a film radius the lens lights needs a field angle beyond
        :data:`MAX_FIELD_DEG` (``reason`` says why).
    reason : str
        Why ``covers_film`` is False ("" otherwise).
    """

    radius_step_mm: float
    field_tangent: np.ndarray
    illumination: np.ndarray
    paraxial_scale_mm: float
    max_radius_mm: float
    covers_film: bool
    reason: str = ""

    @property
    def film_radius_mm(self) -> np.ndarray:
        return np.arange(len(self.field_tangent)) * self.radius_step_mm

    @property
    def screen_scale(self) -> np.ndarray:
        """Real chief-ray tangent over the paraxial one, per entry (1 on the
        axis): the factor the composite scales its screen direction by."""
        radius = self.film_radius_mm
        scale = np.ones_like(radius)
        scale[1:] = self.field_tangent[1:] * self.paraxial_scale_mm / radius[1:]
        return scale

    def corner_shift_px(self, *, pixel_pitch_mm: float) -> float:
        """Film shift of the last entry (the film corner) from its paraxial place, px."""
        radius = self.film_radius_mm[-1]
        return abs(self.field_tangent[-1] * self.paraxial_scale_mm - radius) / pixel_pitch_mm


def radial_maps(prescription: Prescription, *, film_z_mm: float, paraxial_scale_mm: float, focus_distance_m: float,
                film_half_diagonal_mm: float, entries: int = 129) -> RadialMaps:
    """The distortion and illumination maps of a focused, stopped-down lens.

    Parameters
    ----------
    prescription : Prescription
        The lens as rendered (stopped down to the camera's f-number).
    film_z_mm : float
        Film position, mm from the first vertex (the camera's focus).
    paraxial_scale_mm : float
        Film height per unit tangent of the paraxial chief ray on that film.
    focus_distance_m : float
        Plane of focus from the entrance pupil, m: the chief rays come from it.
    film_half_diagonal_mm : float
        The tables run from the axis to this radius.
    entries : int
        Table entries (at least 2).

    Returns
    -------
    RadialMaps
        Memoised: the same arguments return the same value.

    Raises
    ------
    InputError
        When not even the film centre sees light through the lens.
    """
    f_number = paraxial_data(prescription).f_number
    key = (prescription.sha256, prescription.surfaces, round(f_number, 12), film_z_mm, focus_distance_m,
           film_half_diagonal_mm, paraxial_scale_mm, entries)
    if key not in _CACHE:
        _CACHE[key] = _trace_maps(prescription, film_z_mm=film_z_mm, paraxial_scale_mm=paraxial_scale_mm,
                                  focus_distance_m=focus_distance_m, half_diagonal_mm=film_half_diagonal_mm,
                                  entries=max(2, int(entries)))
    return _CACHE[key]


def pupil_relative_illumination(prescription: Prescription, field_angle_deg: float) -> float:
    """Relative illumination at a field angle (object at infinity), its beams
    counted on a grid round the real chief ray's pupil.

    The quantity of :func:`.analysis.relative_illumination`; a small pupil
    behind a large front element (a fisheye stopped down) gets the grid's
    whole resolution, where a grid over the front element gives it a few cells.

    Returns
    -------
    float
        1 on the axis; 0 where the chief ray does not get through.
    """
    return float(_relative_illuminations(prescription, [float(field_angle_deg)])[0])


def _chief_ray_heights_mm(prescription: Prescription, angles_deg: np.ndarray, focus_distance_m: float) -> np.ndarray:
    """|film height| of the real chief ray at each angle; the list ends at the
    first angle whose chief ray fails or whose height stops growing."""
    film_z_mm = prescription.total_track_mm + film_distance_mm(prescription, focus_distance_m)
    rays = _chief_rays(prescription, [math.radians(float(a)) for a in angles_deg[1:]], focus_distance_m)
    return _growing_heights(_chief_ray_heights_on_mm(prescription, *rays, film_z_mm))


def _growing_heights(heights_mm) -> np.ndarray:
    """0 and then the |heights| (mm) of the chief rays at increasing angles
    after the axis, up to the first that fails (NaN) or stops growing."""
    kept = [0.0]
    for h in np.abs(heights_mm):
        if not (math.isfinite(h) and h > kept[-1]):
            break
        kept.append(float(h))
    return np.array(kept)


def _relative_illuminations(prescription: Prescription, angles_deg) -> np.ndarray:
    """RI at each of ``angles_deg`` (:func:`.analysis.relative_illumination`'s
    quantity) with the beam counted round the real chief ray's pupil; 1 on
    the axis, 0 where a chief ray the formula needs fails.  Every angle's
    chief rays (its own and one a step either side, for the film area per
    solid angle) are found together."""
    angles = [float(a) for a in angles_deg]
    tilted = [i for i, a in enumerate(angles) if a != 0.0]
    thetas = [math.radians(angles[i]) for i in tilted]
    probes = [t for theta in thetas for t in central_difference_angles(theta)]
    origins, directions, found = _chief_rays(prescription, probes, math.inf)
    film_z_mm = prescription.total_track_mm + film_distance_mm(prescription, math.inf)
    heights = np.abs(_chief_ray_heights_on_mm(prescription, origins, directions, found, film_z_mm)).reshape(-1, 3)
    on_axis_mm2 = passing_beam_area_mm2(prescription, 0.0, samples_across=_PUPIL_GRID)
    ri = np.ones(len(angles))
    for n, (i, theta) in enumerate(zip(tilted, thetas)):
        if not np.isfinite(heights[n]).all():  # a chief ray it needs fails
            ri[i] = 0.0
            continue
        origin, chief = origins[3 * n + 1], directions[3 * n + 1]
        centre_mm = first_vertex_plane_height_mm(origin, chief)
        ri[i] = illumination_from_heights(prescription, theta, heights[n],
                                          area_mm2=passing_beam_area_mm2(prescription, theta, centre_mm=centre_mm,
                                                                         samples_across=_PUPIL_GRID),
                                          on_axis_mm2=on_axis_mm2)
    return ri


def _trace_maps(prescription: Prescription, *, film_z_mm: float, paraxial_scale_mm: float, focus_distance_m: float,
                half_diagonal_mm: float, entries: int) -> RadialMaps:
    circle_mm = image_circle_radius_mm(prescription, focus_distance_m=focus_distance_m)
    if not circle_mm > 0.0:
        raise InputError(prescription.name, "not even the film centre sees light through the lens (no maps)")
    # Field angles up to what the film corner needs (with room for barrel
    # distortion), never past MAX_FIELD_DEG.
    paraxial_corner_deg = math.degrees(math.atan(half_diagonal_mm / paraxial_scale_mm))
    top_deg = min(MAX_FIELD_DEG, 1.5 * paraxial_corner_deg + 2.0)
    lit_mm = min(circle_mm, half_diagonal_mm)
    while True:
        angles = np.linspace(0.0, top_deg, _DISTORTION_ANGLES)
        heights = _chief_ray_heights_mm(prescription, angles, focus_distance_m)
        angles = angles[: len(heights)]
        reached_mm = heights[-1]
        if reached_mm >= lit_mm or len(heights) < _DISTORTION_ANGLES or top_deg >= MAX_FIELD_DEG:
            break
        top_deg = MAX_FIELD_DEG  # strong barrel distortion: the corner lies further out
    covers = reached_mm >= lit_mm
    reason = "" if covers else (f"the chief rays reach only {reached_mm:.3g} mm of film (up to "
                                f"{angles[-1]:.3g} deg), the lens lights {lit_mm:.3g} mm")
    step = half_diagonal_mm / (entries - 1)
    radius = np.arange(entries) * step
    tangent = np.interp(radius, heights, np.tan(np.radians(angles)))  # the last value beyond the reach

    # Illumination: traced at fewer angles, over the reach of the chief rays.
    ri_angles = np.linspace(0.0, angles[-1], _ILLUMINATION_ANGLES)
    ri_heights = np.interp(ri_angles, angles, heights)
    ri = _relative_illuminations(prescription, ri_angles)
    illumination = np.interp(radius, ri_heights, ri)
    max_radius = min(circle_mm, reached_mm)
    illumination[radius > max_radius] = 0.0
    if not (np.isfinite(tangent).all() and np.isfinite(illumination).all()):  # never hand NaN to the tracer
        raise InputError(prescription.name, "the traced distortion or illumination map came out non-finite")
    max_radius_mm = math.inf if max_radius >= half_diagonal_mm else float(max_radius)
    return RadialMaps(step, tangent, np.clip(illumination, 0.0, None), paraxial_scale_mm, max_radius_mm, covers,
                      reason)


@dataclass(frozen=True, eq=False)
class LateralColorMap:
    """The distortion map per wavelength: lateral colour as the composite reads it.

    Attributes
    ----------
    wavelengths_nm : numpy.ndarray, shape (k,)
        Increasing wavelengths, nm.
    radius_step_mm : float
        Film radius between table entries; entry i is at ``i * radius_step_mm``.
    field_tangent : numpy.ndarray, shape (k, entries)
        Row j: the tangent of the field angle (seen from the n_d entrance
        pupil) whose real chief ray at ``wavelengths_nm[j]`` lands at each film
        radius, the film fixed at the camera's focus. The rows run a little
        past the film corner (:data:`COLOR_MAP_MARGIN`).
    paraxial_scale_mm : float
        The n_d paraxial image scale the tangents are compared with.
    """

    wavelengths_nm: np.ndarray
    radius_step_mm: float
    field_tangent: np.ndarray
    paraxial_scale_mm: float

    @property
    def film_radius_mm(self) -> np.ndarray:
        return np.arange(self.field_tangent.shape[1]) * self.radius_step_mm

    @property
    def screen_scale(self) -> np.ndarray:
        """Real chief-ray tangent over the n_d paraxial one, per wavelength and
        entry, shape (k, entries): what a spectral composite scales its screen
        direction by (1 on the axis)."""
        radius = self.film_radius_mm
        scale = np.ones_like(self.field_tangent)
        scale[:, 1:] = self.field_tangent[:, 1:] * self.paraxial_scale_mm / radius[1:]
        return scale

    def field_tangent_at(self, wavelength_nm: float) -> np.ndarray:
        """The table at ``wavelength_nm``, linear between grid wavelengths (clamped at the ends)."""
        return np.array([np.interp(wavelength_nm, self.wavelengths_nm, column) for column in self.field_tangent.T])

    def image_radius_mm(self, tangent: float, wavelength_nm: float) -> float:
        """Where a point at field ``tangent`` images at ``wavelength_nm``, mm
        from the axis: the table read backward."""
        return float(np.interp(tangent, self.field_tangent_at(wavelength_nm), self.film_radius_mm))

    def lateral_color_mm(self, tangent: float, *, short_nm: float = F_NM, long_nm: float = C_NM) -> float:
        """Image radius at ``short_nm`` minus at ``long_nm`` of the point at
        field ``tangent``, mm (F minus C by default)."""
        return self.image_radius_mm(tangent, short_nm) - self.image_radius_mm(tangent, long_nm)


def lateral_color_map(prescription: Prescription, *, film_z_mm: float, paraxial_scale_mm: float,
                      focus_distance_m: float, film_half_diagonal_mm: float, entries: int = 129,
                      wavelengths_nm=COLOR_MAP_WAVELENGTHS_NM) -> LateralColorMap:
    """The lateral-colour map of a focused lens (parameters as :func:`radial_maps`).

    Same radius step as the radial maps, and :data:`COLOR_MAP_MARGIN` more of
    the film radius: the point imaged at the corner in d light lands beyond
    it at some wavelengths.

    Each wavelength's row covers the radii its chief rays reach; beyond the
    last one the last tangent is repeated (the composite sends no ray past
    the radial maps' ``max_radius_mm`` anyway). For a lens that does not
    disperse every row is the same.

    Returns
    -------
    LateralColorMap
        Memoised: the same arguments return the same value.
    """
    wavelengths = tuple(sorted(float(w) for w in wavelengths_nm))
    key = (prescription.sha256, prescription.surfaces, film_z_mm, focus_distance_m, film_half_diagonal_mm,
           paraxial_scale_mm, entries, wavelengths)
    if key not in _COLOR_CACHE:
        entries = max(2, int(entries))
        step = film_half_diagonal_mm / (entries - 1)
        # 5 % past the corner: the corner's point lands beyond it in some colours.
        radius = np.arange(entries + math.ceil(COLOR_MAP_MARGIN * (entries - 1))) * step
        paraxial_corner_deg = math.degrees(math.atan(film_half_diagonal_mm / paraxial_scale_mm))
        angles = np.linspace(0.0, min(MAX_FIELD_DEG, 1.5 * paraxial_corner_deg + 2.0), _DISTORTION_ANGLES)
        rows = []
        for wavelength in wavelengths:
            if rows and not prescription.disperses:  # every wavelength sees the same glass: the same row
                rows.append(rows[0])
                continue
            heights = _growing_heights(_chief_ray_heights_at_mm(
                prescription, angles[1:], wavelength_nm=wavelength, film_z_mm=film_z_mm,
                focus_distance_m=focus_distance_m))
            rows.append(np.interp(radius, heights, np.tan(np.radians(angles[: len(heights)]))))
        _COLOR_CACHE[key] = LateralColorMap(np.array(wavelengths), step, np.array(rows), paraxial_scale_mm)
    return _COLOR_CACHE[key]
