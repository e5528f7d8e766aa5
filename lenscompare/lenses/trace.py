"""Exact (real) ray trace through a lens system, vectorised over N rays.

Lens frame, used by every function of this package and by the native port:

- z is the optical axis: z = 0 at the FIRST vertex (scene side), positive
  toward the film (the ``lens info`` convention); x and y are transverse; mm.
- Surface i has its vertex at ``prescription.vertex_z_mm[i]``; the last vertex
  is at ``total_track_mm``; the film plane is at
  ``total_track_mm + film_distance_mm``.
- Light from the scene travels toward +z.  Tracing "from the film" (as Kolb et
  al. and pbrt do when rendering) goes toward -z.  Directions are unit vectors.
- The lens is rotationally symmetric, so the frame's handedness does not
  matter; a camera frame that looks along +z toward the scene is reached by
  ``z_camera = z_entrance_pupil - z`` (x and y unchanged).

At every surface, in order (:func:`_cross_surface`):

1. intersect the sphere through the vertex (a plane when the curvature is 0)
   and keep the nearest root ahead of the ray on the vertex-side hemisphere
   (the physical cap); no such root (discriminant < 0) -> blocked;
2. aperture test ``x^2 + y^2 <= semi_aperture^2`` (also at the stop);
3. the ray must reach the surface from the side it is travelling from
   (direction . normal has the travel sign), else blocked;
4. Snell's law in vector form; total internal reflection -> blocked;
5. the refracted ray must keep travelling the same way along z (a ray that
   turns back toward where it came from is blocked, cf. pbrt-v3 issue #92).

Blocked rays are carried along with harmless values and reported with
``passed = False`` and zero origin and direction: no NaN ever leaves here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .prescription import Prescription

__all__ = ["TracedRays", "trace_from_film", "trace_from_scene", "TOWARD_FILM", "TOWARD_SCENE"]

TOWARD_FILM = 1.0
TOWARD_SCENE = -1.0

# Roots this little behind the ray origin still count as ahead: a ray that
# leaves one surface where the next one touches it (cemented, zero
# thickness) starts on both.
_BEHIND_TOLERANCE_MM = 1e-9


@dataclass(frozen=True)
class TracedRays:
    """Rays after a trace.

    Attributes
    ----------
    origins_mm : numpy.ndarray, shape (..., 3)
        Point on the last surface crossed (the first surface when tracing
        toward the scene, the last one when tracing toward the film); 0 for
        blocked rays.
    directions : numpy.ndarray, shape (..., 3)
        Unit direction leaving the lens; 0 for blocked rays.
    passed : numpy.ndarray of bool, shape (...)
        True for rays that got through every surface.
    """

    origins_mm: np.ndarray
    directions: np.ndarray
    passed: np.ndarray


def trace_from_film(prescription: Prescription, origins_mm, directions, *,
                    clip: bool = True) -> TracedRays:
    """Trace rays from the film side through all surfaces toward the scene.

    Parameters
    ----------
    prescription : Prescription
    origins_mm : array_like, shape (..., 3)
        Ray origins in the lens frame, mm, behind the last surface (usually on
        the film plane).
    directions : array_like, shape (..., 3)
        Ray directions (normalised here); they must point toward -z.
    clip : bool, optional
        Apply the aperture tests (default).  False traces the full spheres,
        for chief-ray analysis beyond vignetting.

    Returns
    -------
    TracedRays
        Origins on the first surface and directions into the scene.
    """
    order = range(len(prescription.surfaces) - 1, -1, -1)
    return _trace(prescription, origins_mm, directions, order, TOWARD_SCENE, clip)


def trace_from_scene(prescription: Prescription, origins_mm, directions, *,
                     clip: bool = True, last: int | None = None) -> TracedRays:
    """Trace rays from the scene side through the surfaces toward the film.

    Parameters
    ----------
    prescription : Prescription
    origins_mm : array_like, shape (..., 3)
        Ray origins in the lens frame, mm, in front of the first surface.
    directions : array_like, shape (..., 3)
        Ray directions (normalised here); they must point toward +z.
    clip : bool, optional
        Apply the aperture tests (default).
    last : int, optional
        Stop after this surface index (e.g. the aperture stop); default: all.

    Returns
    -------
    TracedRays
        Origins on the last surface crossed and directions toward the film.
    """
    last = len(prescription.surfaces) - 1 if last is None else last
    return _trace(prescription, origins_mm, directions, range(0, last + 1), TOWARD_FILM, clip)


def _trace(prescription: Prescription, origins_mm, directions, order, travel: float,
           clip: bool) -> TracedRays:
    """Cross the surfaces in ``order``; ``travel`` is +1 toward the film, -1 toward the scene."""
    origins = np.asarray(origins_mm, dtype=np.float64)
    directions = np.asarray(directions, dtype=np.float64)
    shape = np.broadcast_shapes(origins.shape, directions.shape)
    o = np.broadcast_to(origins, shape).reshape(-1, 3).copy()
    d = np.broadcast_to(directions, shape).reshape(-1, 3).copy()

    # IEEE arithmetic as in C++: a ray blocked at a surface may reach inf or
    # NaN there (every test below is False for NaN) and is dropped before the
    # next; nothing of it is returned, so no warning is raised either.
    with np.errstate(all="ignore"):
        # Normalise; unusable input (zero, inf, NaN, heading the wrong way) is blocked.
        length = np.sqrt(np.einsum("ij,ij->i", d, d))
        alive = np.isfinite(o).all(axis=1) & np.isfinite(length) & (length > 0)
        d = np.where(alive[:, None], d / np.where(alive, length, 1.0)[:, None], 0.0)
        alive &= travel * d[:, 2] > 0
        # Only the rays still alive go on to the next surface (each ray's
        # arithmetic is its own, so dropping the others changes no bit).
        rows = np.flatnonzero(alive)
        o, d, still = o[rows], d[rows], np.ones(rows.size, dtype=bool)

        vertex_z = prescription.vertex_z_mm
        for index in order:
            surface = prescription.surfaces[index]
            n_front, n_back = prescription.n_before(index), surface.n_after
            n_from, n_to = (n_front, n_back) if travel > 0 else (n_back, n_front)
            o, d, still = _cross_surface(o, d, still, surface.curvature_per_mm,
                                         surface.semi_aperture_mm if clip else np.inf,
                                         vertex_z[index], n_from, n_to, travel)
            if not still.all():
                rows, o, d, still = rows[still], o[still], d[still], still[still]

    origins_out, directions_out = np.zeros((alive.size, 3)), np.zeros((alive.size, 3))
    origins_out[rows], directions_out[rows] = o, d
    passed = np.zeros(alive.size, dtype=bool)
    passed[rows] = True
    lead = shape[:-1]
    return TracedRays(origins_out.reshape(shape), directions_out.reshape(shape), passed.reshape(lead))


def _cross_surface(o, d, alive, curvature, semi_aperture, vertex_z, n_from, n_to, travel):
    """Move rays to one surface and refract them; returns (origins, directions, alive)."""
    c = curvature
    p = o - np.array([0.0, 0.0, vertex_z])  # origin relative to the vertex

    # Sphere through the vertex with centre (0, 0, 1/c): c|P|^2 - 2 P_z = 0.
    # Along P = p + t d (|d| = 1): c t^2 + 2 b t + k = 0 with
    b = c * np.einsum("ij,ij->i", p, d) - d[:, 2]
    k = c * np.einsum("ij,ij->i", p, p) - 2.0 * p[:, 2]
    discriminant = b * b - c * k
    alive = alive & (discriminant >= 0)
    root = np.sqrt(np.maximum(discriminant, 0.0))
    # Numerically stable pair of roots (no cancellation, finite as c -> 0):
    # q = -(b + sign(b) root), t = k / q and t = q / c.
    q = -(b + np.where(b >= 0, root, -root))
    alive &= q != 0
    q = np.where(q != 0, q, 1.0)
    t_near = k / q
    t_far = q / c if c != 0 else np.full_like(q, np.inf)

    t = _first_cap_root(p, d, c, t_near, t_far)
    alive &= np.isfinite(t)
    t = np.where(alive, t, 0.0)
    hit = p + t[:, None] * d

    alive &= hit[:, 0] ** 2 + hit[:, 1] ** 2 <= semi_aperture * semi_aperture
    alive &= np.isfinite(hit).all(axis=1)  # only when clip=False lets a far hit through

    # Unit normal of the sphere, +z at the vertex whatever the sign of c.
    normal = np.array([0.0, 0.0, 1.0]) - c * hit
    normal /= np.sqrt(np.einsum("ij,ij->i", normal, normal))[:, None]
    normal *= travel  # orient it along the travel
    cos_in = np.einsum("ij,ij->i", d, normal)
    alive &= cos_in > 0  # reaching the surface from the side we travel from

    if n_from != n_to:
        ratio = n_from / n_to
        cos_out_squared = 1.0 - ratio * ratio * (1.0 - cos_in * cos_in)
        alive &= cos_out_squared >= 0  # else total internal reflection
        cos_out = np.sqrt(np.maximum(cos_out_squared, 0.0))
        d = ratio * d + (cos_out - ratio * cos_in)[:, None] * normal

    alive &= travel * d[:, 2] > 0  # not turned back
    hit[:, 2] += vertex_z
    return hit, d, alive  # the caller drops the rays no longer alive


def _first_cap_root(p, d, c, t_near, t_far):
    """Nearest root ahead of the ray on the vertex-side hemisphere; inf if none.

    The cap (|height| <= semi-aperture <= |radius|) is the hemisphere holding
    the vertex: ``1 - c z > 0`` with z measured from the vertex.  Checking both
    roots also handles a steep ray that meets the cap twice.
    """
    best = np.full_like(t_near, np.inf)
    for t in (t_far, t_near):
        z = p[:, 2] + t * d[:, 2]
        ok = np.isfinite(t) & (t >= -_BEHIND_TOLERANCE_MM) & (1.0 - c * z > 0)
        best = np.where(ok & (t < best), t, best)
    return best
