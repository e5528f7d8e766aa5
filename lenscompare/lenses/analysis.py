"""Real-ray measurements of a lens: distortion, relative illumination, image circle.

Built on :mod:`.trace` (same lens frame: z = 0 at the first vertex, positive
toward the film, mm).  Field angles are in degrees from the axis; objects are
at infinity unless a focus distance (m from the entrance pupil) is given.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from ..errors import InputError
from ..units import MM_PER_M
from .focus import film_distance_mm, front_most_z_mm
from .paraxial import (
    aperture_stop_index,
    paraxial_data,
    ray_transfer_matrix,
    stopped_down,
)
from .prescription import Prescription, sag_mm
from .trace import trace_from_film, trace_from_scene

__all__ = [
    "paraxial_image_scale_mm",
    "field_at_film_height_deg",
    "traced_spot_diameter_mm",
    "point_source_spot_mm",
    "spot_diameter_mm",
    "chief_ray_distortion_percent",
    "chief_ray_film_height_mm",
    "relative_illumination",
    "image_circle_radius_mm",
    "real_f_number",
]



def chief_ray_film_height_mm(prescription: Prescription, field_angle_deg: float, *,
                             focus_distance_m: float = math.inf) -> float:
    """Film height (mm) of the real chief ray at a field angle.

    The chief ray comes from a point at ``field_angle_deg`` above the axis
    (seen from the entrance pupil; at infinity, or on the plane of focus) and
    passes through the centre of the aperture stop; it is found by root finding
    on its height at the first vertex plane.  Apertures are ignored for
    this ray (a vignetted chief ray still defines the image height).  The film
    is at the paraxial focus for ``focus_distance_m``.  The image is inverted,
    so the height is negative for a positive angle.

    Raises
    ------
    InputError
        When the field angle is not in [0, 90) degrees or the chief ray does
        not get through the lens (misses a surface or is totally reflected).
    """
    theta = _field_angle_rad(prescription, field_angle_deg)
    return _chief_ray_film_height_mm(prescription, theta, focus_distance_m)


def chief_ray_distortion_percent(prescription: Prescription, field_angle_deg: float, *,
                                 focus_distance_m: float = math.inf) -> float:
    """Distortion (%) of the real chief ray against the paraxial image height.

    ``100 * (y_real / y_paraxial - 1)``: y_real from
    :func:`chief_ray_film_height_mm`; y_paraxial the height of the paraxial
    chief ray (slope tan(theta) through the entrance-pupil centre) on the same
    film plane, which is ``f * tan(theta)`` for an object at infinity.
    Negative is barrel distortion.

    Parameters
    ----------
    prescription : Prescription
    field_angle_deg : float
        Field angle, degrees, in [0, 90).
    focus_distance_m : float, optional
        Object plane distance from the entrance pupil, m (default infinity).

    Returns
    -------
    float
        Distortion in percent; 0 on the axis.
    """
    if field_angle_deg == 0:
        return 0.0
    y_real = chief_ray_film_height_mm(prescription, field_angle_deg,
                                      focus_distance_m=focus_distance_m)
    y_ideal = _paraxial_chief_ray_film_height_mm(prescription, math.radians(field_angle_deg),
                                                 focus_distance_m)
    return 100.0 * (y_real / y_ideal - 1.0)


def field_at_film_height_deg(prescription: Prescription, film_height_mm: float, *,
                             focus_distance_m: float = math.inf, start_deg: float) -> float | None:
    """Field angle (degrees) whose real chief ray lands ``film_height_mm`` from
    the axis (film at the paraxial focus), or None when no chief ray reaches
    that height. ``start_deg`` (the paraxial guess) seeds the bracket, which
    then grows in 2-degree steps; a distorting lens images the film corner
    from another field than the paraxial one (the fisheye at 18 x 12 mm:
    61.5 deg, not 47)."""

    def excess(angle_deg):
        try:
            return abs(chief_ray_film_height_mm(prescription, angle_deg, focus_distance_m=focus_distance_m)) \
                - film_height_mm
        except InputError:
            return None

    a = min(max(start_deg, 1e-3), 89.0)
    fa = excess(a)
    if fa is None:
        return None
    step = 2.0 if fa < 0 else -2.0
    while True:
        b = min(max(a + step, 1e-3), 89.5)
        fb = excess(b)
        if fb is None or b == a:
            return None
        if (fa < 0) != (fb < 0):
            def excesses(angles_deg, _rows):  # None (no chief ray) is NaN: the root finder bisects there
                return np.array([math.nan if (e := excess(float(x))) is None else e for x in angles_deg])

            return float(_bracketed_roots(excesses, [a], [b], [fa], [fb], [True], tolerance_mm=1e-9)[0])
        a, fa = b, fb


def paraxial_image_scale_mm(prescription: Prescription, film_z_mm: float) -> float:
    """Film height per unit tangent of the field angle, mm: where the paraxial
    chief ray (through the entrance-pupil centre) meets a film at ``film_z_mm``
    (from the first vertex).

    The ideal image of a point seen at angle theta from the entrance pupil lies
    ``scale * tan(theta)`` from the axis (inverted); the scale is the EFL when
    the film is at the rear focal point, and grows as the lens focuses closer.
    Distortion is measured against it.
    """
    pupil_z = paraxial_data(prescription).entrance_pupil_position_mm
    y_out, w_out = ray_transfer_matrix(prescription) @ np.array([pupil_z, -1.0])
    return abs(float(y_out + (film_z_mm - prescription.total_track_mm) * w_out))


def traced_spot_diameter_mm(prescription: Prescription, *, height_mm: float, distance_mm: float,
                            film_z_mm: float, window_radius_mm: float = math.inf,
                            samples_across: int = 160) -> float:
    """Second-moment diameter (mm) of the spot a point source makes on the film,
    by real rays: the lens system's own blur disk, with no thin-lens assumption.

    Rays leave the point (``height_mm`` off the axis, ``distance_mm`` in front
    of the entrance pupil) toward a square grid over the first surface, each
    weighted by the solid angle of its cell, and are traced with every aperture
    (so vignetting and aberrations shape the spot). The diameter is that of the
    uniform disk with the same second moment, ``4 sqrt((var_x + var_y) / 2)``,
    the definition :func:`lenscompare.metrics.measure_blur_disk` uses on images.
    ``window_radius_mm`` keeps only rays that land within that distance of the
    spot's centroid, as that measurement keeps only the pixels in its window (a
    faint halo of aberrated rays weighs heavily in a second moment).

    The grid is laid over the part of the first surface the beam uses
    (:func:`point_source_spot_mm`): over the whole surface, a beam behind a
    pinpoint stop fell between its rays (NaN at f/1000 on the Double Gauss).

    Returns
    -------
    float
        Diameter in mm; NaN when no ray gets through.
    """
    on_film, w = point_source_spot_mm(prescription, height_mm=height_mm, distance_mm=distance_mm,
                                      film_z_mm=film_z_mm, samples_across=samples_across)
    return spot_diameter_mm(on_film, w, window_radius_mm=window_radius_mm)


def point_source_spot_mm(prescription: Prescription, *, height_mm: float, distance_mm: float, film_z_mm: float,
                         samples_across: int = 160) -> tuple[np.ndarray, np.ndarray]:
    """Where the rays from a point source land on the film, and their flux.

    The rays of :func:`traced_spot_diameter_mm`: a square grid of
    ``samples_across``^2 on the first vertex plane, solid-angle weights, laid
    over the part of the first surface the beam passes (found first by
    :func:`_window_round_the_beam`), so a stopped-down lens keeps as many rays
    as a wide-open one.

    Returns
    -------
    on_film : numpy.ndarray, shape (n, 2)
        Landing points (x, y), mm, of the n rays that pass (n may be 0).
    weight : numpy.ndarray, shape (n,)
        Their solid angles (unnormalised).
    """
    data = paraxial_data(prescription)
    first = prescription.surfaces[0]
    source = np.array([0.0, float(height_mm), data.entrance_pupil_position_mm - float(distance_mm)])
    # A grid on the first vertex plane covering the first surface (and the
    # sideways drift between that plane and the surface for an oblique beam).
    drift = abs(sag_mm(first.curvature_per_mm, first.semi_aperture_mm)) * abs(height_mm) / max(distance_mm, 1e-9)
    window = _window_round_the_beam(prescription, source, (first.semi_aperture_mm + drift) * 1.02, data)
    if window is None:
        return np.zeros((0, 2)), np.zeros(0)
    targets = _grid_on_first_vertex_plane(*window, samples_across)
    rays, weight = _trace_from_point(prescription, source, targets)
    if not rays.passed.any():
        return np.zeros((0, 2)), np.zeros(0)
    o, d, w = rays.origins_mm[rays.passed], rays.directions[rays.passed], weight[rays.passed]
    on_film = o[:, :2] + d[:, :2] * ((film_z_mm - o[:, 2]) / d[:, 2])[:, None]
    return on_film, w


def _window_round_the_beam(prescription: Prescription, source: np.ndarray, surface_half_mm: float, data):
    """Centre and half-width (mm) of a square on the first vertex plane that holds every ray from
    ``source`` that gets through, one coarse cell to spare; None when none does.

    A 48 x 48 grid over the first surface first; behind a pinpoint stop (a beam 0.2 mm wide at
    f/256 against 1.2 mm cells) it finds nothing, and a window round the line to the paraxial
    entrance pupil's centre, an entrance pupil across, grows until it holds the beam."""
    coarse = 48
    cell = 2.0 * surface_half_mm / coarse
    targets = _grid_on_first_vertex_plane((0.0, 0.0), surface_half_mm, coarse)
    passed = _trace_from_point(prescription, source, targets)[0].passed
    if not passed.any():
        pupil_z = data.entrance_pupil_position_mm
        along = -source[2] / (pupil_z - source[2])  # the source-to-pupil line's crossing of z = 0
        centre = (0.0, float(source[1]) * (1.0 - along))

        def passes(half_mm: float) -> np.ndarray:
            points = _grid_on_first_vertex_plane(centre, half_mm, coarse)
            return _trace_from_point(prescription, source, points)[0].passed

        half, passed = _grown_window(passes, 0.75 * data.entrance_pupil_diameter_mm * max(along, 1e-3),
                                     limit_mm=surface_half_mm, across=coarse)
        targets, passed, cell = _grid_on_first_vertex_plane(centre, half, coarse), passed.ravel(), 2.0 * half / coarse
        if not passed.any():
            return None
    hit = targets[passed, :2]
    lo, hi = hit.min(axis=0) - cell, hit.max(axis=0) + cell  # whole cells the beam touches, and one more
    return tuple(0.5 * (lo + hi)), 0.5 * float((hi - lo).max())


def _grown_window(passes, half_mm: float, *, limit_mm: float, across: int):
    """Grow a square window 1.6x at a time (pupil aberration: a beam is wider, or further off, than
    the paraxial pupil) until some ray passes and none touches its border, or it outgrows limit_mm.
    ``passes(half_mm)`` traces the window's ``across``^2 grid (:func:`_grid_on_first_vertex_plane`)
    and says which rays pass. Returns the half-width (mm) and that (across, across) answer."""
    while True:
        passed = passes(half_mm).reshape(across, across)
        border = passed[0].any() or passed[-1].any() or passed[:, 0].any() or passed[:, -1].any()
        if (passed.any() and not border) or half_mm > limit_mm:
            return half_mm, passed
        half_mm *= 1.6


def first_vertex_plane_height_mm(origin, direction) -> float:
    """Height (y, mm) at which a ray given in the lens frame crosses the first vertex plane z = 0."""
    return float(origin[1] - direction[1] * origin[2] / direction[2])


def spot_diameter_mm(on_film: np.ndarray, weight: np.ndarray, *, window_radius_mm: float = math.inf) -> float:
    """Second-moment diameter (mm) of landing points with weights (see
    :func:`traced_spot_diameter_mm`); NaN when there are none."""
    if len(weight) == 0:
        return math.nan
    w = weight
    centroid = (w[:, None] * on_film).sum(axis=0) / w.sum()
    if math.isfinite(window_radius_mm):
        inside = np.hypot(*(on_film - centroid).T) <= window_radius_mm
        if inside.any():  # an empty window (a ring-shaped spot, a tiny window) keeps every ray
            on_film, w = on_film[inside], w[inside]
        centroid = (w[:, None] * on_film).sum(axis=0) / w.sum()
    variance = (w[:, None] * (on_film - centroid) ** 2).sum(axis=0) / w.sum()
    return 4.0 * math.sqrt(0.5 * float(variance.sum()))


def _grid_on_first_vertex_plane(centre, half: float, samples_across: int):
    """Cell centres of a square grid on the plane z = 0, (n, 3) mm."""
    centres = (np.arange(samples_across) + 0.5) / samples_across * 2.0 * half - half
    x, y = np.meshgrid(centres + centre[0], centres + centre[1])
    return np.stack([x.ravel(), y.ravel(), np.zeros(x.size)], axis=1)


def _trace_from_point(prescription: Prescription, source: np.ndarray, targets: np.ndarray):
    """Rays from ``source`` toward ``targets``, traced; and each one's solid-angle weight."""
    towards = targets - source
    length = np.linalg.norm(towards, axis=1)
    weight = towards[:, 2] / length ** 3  # solid angle of a cell: dA cos(alpha) / r^2
    start_z = front_most_z_mm(prescription) - 1.0
    directions = towards / length[:, None]
    origins = source + directions * ((start_z - source[2]) / directions[:, 2])[:, None]
    return trace_from_scene(prescription, origins, directions), weight


def relative_illumination(prescription: Prescription, field_angle_deg: float, *,
                          f_number: float | None = None, samples_across: int = 400) -> float:
    """Relative illumination: film irradiance at a field angle over that on the axis.

    A distant object of uniform radiance L lights the film point where the
    chief ray at angle theta lands.  The flux from a patch of sky of solid
    angle dOmega is ``L * A(theta) * cos(theta) * dOmega``, where A(theta) is
    the area of the parallel beam at theta that gets through every aperture,
    measured in a plane perpendicular to the axis (``A cos theta`` is its
    cross-section).  That flux spreads over the film area
    ``dA = y * (dy/dtheta) / sin(theta) * dOmega`` (y the real chief-ray film
    height).  Hence

        RI(theta) = [A(theta) cos(theta) sin(theta) / (y dy/dtheta)] / [A(0) / f^2],

    which is ``cos^4(theta)`` times the vignetting ``A(theta) / A(0)`` for a
    lens without distortion, and also counts the image compression of a
    barrel-distorting lens.  A(theta) is the count of passing rays of a square
    grid of ``samples_across``^2 parallel rays over everything that could reach
    the first surface, times the cell area.  Transmission losses are ignored.

    Parameters
    ----------
    prescription : Prescription
    field_angle_deg : float
        Field angle, degrees, in [0, 90).
    f_number : float, optional
        Stop the lens down to this paraxial f-number first (default: wide open).
    samples_across : int, optional
        Grid size per side (default 400; the error is about 1/samples_across).

    Returns
    -------
    float
        Relative illumination, exactly 1 on the axis, 0 when nothing gets
        through.
    """
    if f_number is not None:
        prescription = stopped_down(prescription, f_number)
    theta = _field_angle_rad(prescription, field_angle_deg)
    if theta == 0.0:
        return 1.0
    on_axis = passing_beam_area_mm2(prescription, 0.0, samples_across=samples_across)
    origins, directions, found = _chief_rays(prescription, [theta], math.inf)
    # Round the real chief ray's crossing of the first vertex plane (the paraxial pupil's centre
    # when no chief ray is found: the window then grows till it holds the beam)
    centre_mm = first_vertex_plane_height_mm(origins[0], directions[0]) if found[0] else 0.0
    area = passing_beam_area_mm2(prescription, theta, centre_mm=centre_mm, samples_across=samples_across)
    if on_axis == 0 or area == 0:
        return 0.0
    return illumination_from_beam_areas(prescription, theta, area_mm2=area, on_axis_mm2=on_axis)


def illumination_from_beam_areas(prescription: Prescription, theta: float, *, area_mm2: float,
                                 on_axis_mm2: float) -> float:
    """RI(theta) of :func:`relative_illumination` from the passing beam areas
    A(theta) and A(0) (mm^2, however they were counted), the film area per
    solid angle taken from the real chief-ray mapping (central difference,
    object at infinity); 0 where that area is not positive.

    Raises
    ------
    InputError
        When the chief ray near theta does not get through the lens.
    """
    heights = [abs(_chief_ray_film_height_mm(prescription, t, math.inf)) for t in central_difference_angles(theta)]
    return illumination_from_heights(prescription, theta, heights, area_mm2=area_mm2, on_axis_mm2=on_axis_mm2)


def central_difference_angles(theta: float) -> tuple[float, float, float]:
    """The field angles (radians) whose chief-ray film heights
    :func:`illumination_from_heights` takes: theta and a step either side."""
    return theta - _RI_STEP_RAD, theta, theta + _RI_STEP_RAD


_RI_STEP_RAD = 1e-5


def illumination_from_heights(prescription: Prescription, theta: float, heights_mm, *, area_mm2: float,
                              on_axis_mm2: float) -> float:
    """:func:`illumination_from_beam_areas` with the chief rays' |film heights|
    (mm, object at infinity) at :func:`central_difference_angles` given."""
    low, middle, high = (float(h) for h in heights_mm)
    film_area_per_solid_angle = middle * (high - low) / (2.0 * _RI_STEP_RAD) / math.sin(theta)
    if not (film_area_per_solid_angle > 0.0 and on_axis_mm2 > 0.0):
        return 0.0
    focal_length = paraxial_data(prescription).effective_focal_length_mm
    return (area_mm2 * math.cos(theta) / film_area_per_solid_angle) / (on_axis_mm2 / focal_length ** 2)


# Memoised like paraxial_data: the planner's distortion and vignetting effects ask the
# same question of the same lens, and on a strongly curved lens it takes seconds.
@functools.lru_cache(maxsize=256)
def image_circle_radius_mm(prescription: Prescription, *, focus_distance_m: float = math.inf,
                           samples_across: int = 32, tolerance_mm: float = 1e-3) -> float:
    """Largest film radius (mm) from which any ray gets through the lens.

    From film points on the x axis, rays are aimed at points of the rear
    surface inside its clear aperture: a square grid of ``samples_across``^2
    and, finer, ``64 * samples_across`` along the meridional line, where the
    last rays get through.  The radius is found by a scan and then bisection
    down to ``tolerance_mm``.  The film is at the paraxial focus for
    ``focus_distance_m``.

    Returns
    -------
    float
        Image-circle radius, mm; 0 when not even the film centre sees light.
    """
    film_z = prescription.total_track_mm + film_distance_mm(prescription, focus_distance_m)

    def lit(radius_mm):
        return _any_ray_passes_from_film(prescription, film_z, radius_mm, samples_across)

    if not lit(0.0):
        return 0.0
    # Scan outward to the first dark radius, then bisect the last step. After
    # 64 even steps the step doubles: a flat rear surface can let grazing rays
    # through from any film radius, and 1e6 mm in even steps took minutes.
    step = max(prescription.surfaces[-1].semi_aperture_mm, film_z - prescription.total_track_mm)
    step = max(step, 1.0) / 8.0
    r_lit, r_dark = 0.0, step
    steps = 0
    while lit(r_dark):
        steps += 1
        step = step * 2.0 if steps >= 64 else step
        r_lit, r_dark = r_dark, r_dark + step
        if r_dark > 1e6:
            return math.inf
    while r_dark - r_lit > tolerance_mm:
        middle = 0.5 * (r_lit + r_dark)
        r_lit, r_dark = (middle, r_dark) if lit(middle) else (r_lit, middle)
    return r_lit


def real_f_number(prescription: Prescription, *, tolerance_mm: float = 1e-9) -> float:
    """Real-ray f-number: EFL over the diameter of the widest axial beam that passes.

    The beam from a distant point on the axis is limited by every aperture,
    not only the stop; its radius (the real entrance-pupil radius on the axis)
    is found by bisection on the height of rays parallel to the axis.  This is
    the definition behind the real-ray f-numbers in the shared lens README.

    Returns
    -------
    float
        ``effective_focal_length_mm / (2 * radius)``.
    """
    start_z = front_most_z_mm(prescription) - 1.0

    def passes(y):
        return bool(trace_from_scene(prescription, [0.0, y, start_z], [0.0, 0.0, 1.0]).passed)

    # The first surface's aperture bounds the beam, however the lens bends it.
    inside, outside = 0.0, prescription.surfaces[0].semi_aperture_mm * (1.0 + 1e-6)
    if not passes(inside):
        raise InputError(prescription.name, "not even the axial ray gets through the lens")
    while outside - inside > tolerance_mm:
        middle = 0.5 * (inside + outside)
        inside, outside = (middle, outside) if passes(middle) else (inside, middle)
    return paraxial_data(prescription).effective_focal_length_mm / (2.0 * inside)


def _field_angle_rad(prescription: Prescription, field_angle_deg: float) -> float:
    """Field angle in radians, after checking that it is in [0, 90) degrees."""
    if not 0.0 <= field_angle_deg < 90.0:
        raise InputError(prescription.name, f"field angle must be in [0, 90) degrees, got "
                         f"{field_angle_deg!r}", key="field_angle")
    return math.radians(field_angle_deg)


def _chief_ray_film_height_mm(prescription: Prescription, theta: float,
                              focus_distance_m: float) -> float:
    """Film height of the real chief ray at a signed field angle (radians)."""
    origin, direction = _chief_ray(prescription, theta, focus_distance_m)
    film_z = prescription.total_track_mm + film_distance_mm(prescription, focus_distance_m)
    return _chief_ray_height_on_mm(prescription, origin, direction, film_z,
                                   blocked=f"the chief ray at {math.degrees(theta):g} deg does not get through the lens")


def _chief_ray_height_on_mm(prescription: Prescription, origin, direction, film_z_mm: float, *,
                            blocked: str) -> float:
    """y where a chief ray traced through the lens (apertures ignored) meets the
    plane z = film_z_mm; ``blocked``: the error's message when it does not get through."""
    height = _chief_ray_heights_on_mm(prescription, [origin], [direction], [True], film_z_mm)[0]
    if math.isnan(height):
        raise InputError(prescription.name, blocked, key="field_angle")
    return float(height)


def _chief_ray_heights_on_mm(prescription: Prescription, origins, directions, found, film_z_mm: float) -> np.ndarray:
    """:func:`_chief_ray_height_on_mm` for the rays of :func:`_chief_rays`
    side by side: NaN where there is no chief ray or it does not get through."""
    rays = trace_from_scene(prescription, origins, directions, clip=False)
    o, d = rays.origins_mm, rays.directions
    with np.errstate(all="ignore"):
        heights = o[:, 1] + d[:, 1] * (film_z_mm - o[:, 2]) / d[:, 2]
    return np.where(np.asarray(found) & rays.passed, heights, np.nan)


def _chief_ray(prescription: Prescription, theta: float, focus_distance_m: float):
    """Object-space origin and direction of the real chief ray at field angle
    theta (radians): :func:`_chief_rays` for one angle.

    Raises
    ------
    InputError
        When no ray from the object point crosses the stop centre.
    """
    origins, directions, found = _chief_rays(prescription, [theta], focus_distance_m)
    if not found[0]:
        raise InputError(prescription.name, f"no chief ray through the stop centre at "
                         f"{math.degrees(theta):g} deg", key="field_angle")
    return origins[0], directions[0]


def _chief_rays(prescription: Prescription, thetas, focus_distance_m: float):
    """Object-space origins and directions of the real chief rays at field
    angles ``thetas`` (radians, shape (k,)), all found side by side.

    The rays from an object point are labelled by the height y0 at which they
    cross the first vertex plane (z = 0).  A scan over every y0 that could
    reach the first surface brackets the zero of the height at the stop; the
    bracket nearest the paraxial chief ray is then refined (Illinois method).
    Each angle's arithmetic is its own, in the same order whatever the other
    angles: the same ray as when it is found alone.

    Returns
    -------
    origins, directions : numpy.ndarray, shape (k, 3)
        Zero rows where no chief ray was found.
    found : numpy.ndarray of bool, shape (k,)
        False where no ray from the object point crosses the stop centre.
    """
    thetas = [float(t) for t in thetas]
    data = paraxial_data(prescription)
    start_z = front_most_z_mm(prescription) - 1.0
    stop = aperture_stop_index(prescription)
    first = prescription.surfaces[0]
    # Slope dy/dz of the ray through height y0 at z = 0.  Written so that a
    # far object (1e12 m) costs no precision and infinity gives -tan(theta).
    distance_mm = focus_distance_m * MM_PER_M
    lever_mm = distance_mm - data.entrance_pupil_position_mm  # object to first vertex
    along = 1.0 if math.isinf(distance_mm) else distance_mm / lever_mm
    tangents = np.array([math.tan(t) for t in thetas])

    def rays_through(y0, which):
        """Rays through heights y0 (flat) of the object points of angles ``which`` (indices, same shape)."""
        slope = y0 / lever_mm - tangents[which] * along
        directions = np.stack([np.zeros_like(slope), slope, np.ones_like(slope)], axis=1)
        directions /= np.linalg.norm(directions, axis=1)[:, None]
        origins = np.stack([np.zeros_like(y0), y0, np.zeros_like(y0)], axis=1)
        return origins + directions * (start_z / directions[:, 2])[:, None], directions

    def stop_height(y0, which):
        rays = trace_from_scene(prescription, *rays_through(y0, which), clip=False, last=stop)
        return np.where(rays.passed, rays.origins_mm[:, 1], np.nan)

    # Between the plane z = 0 and the first surface a ray drifts sideways by
    # at most |sag| tan(theta).
    scans = []
    for tangent in tangents:
        reach = first.semi_aperture_mm + abs(sag_mm(first.curvature_per_mm, first.semi_aperture_mm)) * abs(tangent)
        scans.append(np.linspace(-1.5 * reach, 1.5 * reach, 601))
    k = len(thetas)
    scans = np.array(scans).reshape(k, 601)
    heights = stop_height(scans.ravel(), np.repeat(np.arange(k), 601)).reshape(k, 601)
    a, b, fa, fb = (np.zeros(k) for _ in range(4))
    found = np.zeros(k, dtype=bool)
    for j in range(k):
        with np.errstate(invalid="ignore"):
            brackets = np.flatnonzero(heights[j, :-1] * heights[j, 1:] <= 0)  # NaN pairs drop out
        if brackets.size:
            paraxial_y0 = tangents[j] * data.entrance_pupil_position_mm
            i = brackets[np.argmin(np.abs(scans[j, brackets] - paraxial_y0))]
            a[j], b[j], fa[j], fb[j], found[j] = scans[j, i], scans[j, i + 1], heights[j, i], heights[j, i + 1], True
    y = _bracketed_roots(stop_height, a, b, fa, fb, found)
    origins, directions = rays_through(y, np.arange(k))
    origins[~found], directions[~found] = 0.0, 0.0
    return origins, directions, found


def _paraxial_chief_ray_film_height_mm(prescription: Prescription, theta: float,
                                       focus_distance_m: float) -> float:
    """Height on the film of the paraxial ray with slope -tan(theta) through the pupil centre."""
    pupil_z = paraxial_data(prescription).entrance_pupil_position_mm
    slope = -math.tan(theta)
    y_out, w_out = ray_transfer_matrix(prescription) @ np.array([-slope * pupil_z, slope])
    return float(y_out + film_distance_mm(prescription, focus_distance_m) * w_out)


def _bracketed_roots(function, a, b, fa, fb, active, *, tolerance_mm: float = 1e-12) -> np.ndarray:
    """Roots of continuous functions, one in each [a, b] with f(a) f(b) <= 0
    (Illinois method), side by side: ``function(x, which)`` evaluates the
    functions ``which`` (indices) at x.  Rows not ``active`` are left at b.

    Regula falsi that halves the weight of a stale end, so it keeps the
    bracket and converges fast on the nearly linear functions met here.  Each
    row takes the steps it would alone; a row whose function is not finite
    inside its bracket is bisected once, and stops if that fails too.
    """
    a, b, fa, fb = (np.array(v, dtype=np.float64) for v in (a, b, fa, fb))
    root = b.copy()
    at_a = np.asarray(active) & (fa == 0.0)
    root[at_a] = a[at_a]
    running = np.asarray(active) & ~at_a
    for _ in range(200):
        ended = running & ((fb == 0.0) | (np.abs(b - a) <= tolerance_mm))
        root[ended] = b[ended]
        running &= ~ended
        rows = np.flatnonzero(running)
        if rows.size == 0:
            break
        ar, br, far, fbr = a[rows], b[rows], fa[rows], fb[rows]
        c = br - fbr * (br - ar) / (fbr - far)
        fc = function(c, rows)
        blocked = ~np.isfinite(fc)  # a blocked ray inside the bracket: bisect instead
        if blocked.any():
            c[blocked] = 0.5 * (ar[blocked] + br[blocked])
            fc[blocked] = function(c[blocked], rows[blocked])
            failed = ~np.isfinite(fc)
            root[rows[failed]] = br[failed]
            running[rows[failed]] = False
            keep = ~failed
            rows, ar, br, far, fbr, c, fc = (v[keep] for v in (rows, ar, br, far, fbr, c, fc))
        swap = fc * fbr < 0
        a[rows] = np.where(swap, br, ar)
        fa[rows] = np.where(swap, fbr, far * 0.5)  # the same end stays: weigh it less
        b[rows], fb[rows] = c, fc
    root[running] = b[running]
    return root


def passing_beam_area_mm2(prescription: Prescription, theta: float, *, centre_mm: float = 0.0,
                          samples_across: int = 128) -> float:
    """Area (mm^2, perpendicular to the axis) of the parallel beam at theta (radians) that passes
    every aperture, counted on a square grid of ``samples_across``^2 rays round ``centre_mm`` (the
    height where the real chief ray crosses the first vertex plane; a wide-angle lens's pupil moves
    far from the paraxial one). The window starts at 0.75 entrance-pupil diameters over cos theta
    and grows (:func:`_grown_window`) until it holds the beam, so a pinpoint stop is counted on as
    fine a grid as a wide-open one (a grid over the whole first surface had a few cells across the
    beam at f/64 and none at f/1000)."""
    data = paraxial_data(prescription)
    direction = np.array([0.0, -math.sin(theta), math.cos(theta)])
    start_z = front_most_z_mm(prescription) - 1.0

    def passes(half_mm: float) -> np.ndarray:
        points = _grid_on_first_vertex_plane((0.0, centre_mm), half_mm, samples_across)
        return trace_from_scene(prescription, points - direction * (-start_z / direction[2]), direction).passed

    half_mm, passed = _grown_window(passes, 0.75 * data.entrance_pupil_diameter_mm / math.cos(theta),
                                    limit_mm=4.0 * max(s.semi_aperture_mm for s in prescription.surfaces),
                                    across=samples_across)
    return float(np.count_nonzero(passed)) * (2.0 * half_mm / samples_across) ** 2


def _any_ray_passes_from_film(prescription: Prescription, film_z: float, radius_mm: float,
                              samples_across: int) -> bool:
    """Whether any ray from film point (radius, 0) gets through the lens."""
    rear = prescription.surfaces[-1]
    # Aim at points of the rear surface itself, inside its clear aperture:
    # every ray that can get through meets it at one of them.  The last rays
    # to get through at the rim of the image circle lie in the meridional
    # plane (y = 0) by symmetry, often at the rim, so that line is sampled
    # finely up to just inside the rim (exactly on it, rounding may fail the
    # aperture test).
    h = rear.semi_aperture_mm * (1.0 - 1e-9)
    centres = (np.arange(samples_across) + 0.5) / samples_across * 2.0 * h - h
    x, y = np.meshgrid(centres, centres)
    line = np.linspace(-h, h, 64 * samples_across + 1)
    x = np.concatenate([x.ravel(), line])
    y = np.concatenate([y.ravel(), np.zeros_like(line)])
    inside = x * x + y * y <= h * h
    x, y = x[inside], y[inside]
    z = prescription.total_track_mm + sag_mm(rear.curvature_per_mm, np.hypot(x, y))
    targets = np.stack([x, y, z], axis=1)
    origin = np.array([radius_mm, 0.0, film_z])
    rays = trace_from_film(prescription, origin, targets - origin)
    return bool(rays.passed.any())
