"""The thin-lens relations, equations 1-10 of Barsky et al. 2003 (Part I, sec. 2.2).

All lengths are millimetres, measured from the lens (object distances in front,
image distances behind); angles are radians; diopters are inverse metres.
Every function accepts scalars or NumPy arrays and is written so that the hard
cases stay finite: an object at infinity, and an object exactly at the focal
length (image at infinity), give finite blur.

References
----------
.. [1] B. A. Barsky, D. R. Horn, S. A. Klein, J. A. Pang, M. Yu, "Camera models
   and optical systems used in computer graphics: Part I, object-based
   techniques", ICCSA 2003, LNCS 2669, doi:10.1007/3-540-44842-X_26.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "lens_power_diopters",
    "image_distance_mm",
    "f_number",
    "aperture_diameter_mm",
    "focus_film_distance_mm",
    "circle_of_confusion_mm",
    "blur_angle_rad",
    "defocus_diopters",
]


def lens_power_diopters(focal_length_mm):
    """Power of a lens, 1/f, in diopters (eq. 1's right-hand side).

    Examples
    --------
    >>> lens_power_diopters(50.0)
    20.0
    """
    return _result(1000.0 / np.asarray(focal_length_mm, dtype=float))


def _result(value):
    # Scalars in, Python floats out; arrays in, arrays out.
    value = np.asarray(value, dtype=float)
    return float(value) if value.ndim == 0 else value


def _inverse_image_distance(object_distance_mm, focal_length_mm):
    # 1/l' = 1/f - 1/l (eq. 1); finite for l = f (0) and l = inf (1/f).
    return 1.0 / np.asarray(focal_length_mm, dtype=float) - 1.0 / np.asarray(object_distance_mm, dtype=float)


def image_distance_mm(object_distance_mm, focal_length_mm):
    """Distance behind the lens where an object comes to focus (eq. 2).

    Parameters
    ----------
    object_distance_mm : float or array_like
        Object distance l in front of the lens, mm (``inf`` allowed).
    focal_length_mm : float or array_like
        Focal length f, mm.

    Returns
    -------
    float or ndarray
        l' = f l / (l - f), mm. ``inf`` for an object at the focal length;
        negative (a virtual image) for an object inside it.

    Examples
    --------
    >>> image_distance_mm(2000.0, 50.0)
    51.282051282051285
    >>> image_distance_mm(float("inf"), 50.0)
    50.0
    """
    inverse = _inverse_image_distance(object_distance_mm, focal_length_mm)
    with np.errstate(divide="ignore"):
        return _result(np.where(inverse == 0.0, np.inf, 1.0 / np.where(inverse == 0.0, 1.0, inverse)))


def f_number(focal_length_mm, aperture_diameter_mm):
    """f-stop N = f / a_diam (eq. 3).

    Examples
    --------
    >>> f_number(50.0, 25.0)
    2.0
    """
    return _result((np.asarray(focal_length_mm, dtype=float) / np.asarray(aperture_diameter_mm, dtype=float)))


def aperture_diameter_mm(focal_length_mm, f_number):
    """Aperture diameter a_diam = f / N (eq. 3 solved for the diameter), mm.

    Examples
    --------
    >>> aperture_diameter_mm(50.0, 2.0)
    25.0
    """
    return _result((np.asarray(focal_length_mm, dtype=float) / np.asarray(f_number, dtype=float)))


def focus_film_distance_mm(focus_distance_mm, focal_length_mm):
    """Film distance d'_focus that makes the plane at d_focus sharp (eq. 4), mm.

    Examples
    --------
    >>> focus_film_distance_mm(2000.0, 50.0)
    51.282051282051285
    """
    return image_distance_mm(focus_distance_mm, focal_length_mm)


def circle_of_confusion_mm(object_distance_mm, *, focus_distance_mm, focal_length_mm, aperture_diameter_mm):
    """Diameter of the blur disk on the film for a point at a given depth (eq. 5).

    Parameters
    ----------
    object_distance_mm : float or array_like
        Depth l of the point in front of the lens, measured along the optical
        axis (not the Euclidean distance), mm. ``inf`` allowed.
    focus_distance_mm : float
        Depth of the plane of sharp focus, mm.
    focal_length_mm : float
        Focal length f, mm.
    aperture_diameter_mm : float
        Lens (aperture) diameter, mm.

    Returns
    -------
    float or ndarray
        |c_diam| = a_diam |l' - d'| / l', mm.

    Notes
    -----
    Computed as a_diam |1 - d' (1/f - 1/l)|, the same quantity with no division
    by l', so an object exactly at the focal length (l' = inf) gives
    c = a_diam instead of NaN. A point nearer than the focal plane has l' > d'
    (its sharp image lies behind the film), a farther one l' < d'; both give a
    disk of the same shape, so the diameter is returned without sign.

    Examples
    --------
    >>> round(circle_of_confusion_mm(1000.0, focus_distance_mm=2000.0,
    ...                              focal_length_mm=50.0, aperture_diameter_mm=25.0), 6)
    0.641026
    """
    d_prime = focus_film_distance_mm(focus_distance_mm, focal_length_mm)
    inverse = _inverse_image_distance(object_distance_mm, focal_length_mm)
    return _result((np.asarray(aperture_diameter_mm, dtype=float) * np.abs(1.0 - d_prime * inverse)))


def blur_angle_rad(circle_of_confusion_mm, film_distance_mm, *, small_angle=False):
    """Angular size of a blur disk seen from the lens (eq. 6, or eq. 7).

    Parameters
    ----------
    circle_of_confusion_mm : float or array_like
        Blur-disk diameter c on the film, mm.
    film_distance_mm : float
        Film distance d'_focus, mm.
    small_angle : bool, optional
        If True, return eq. 7's approximation c / d'.

    Returns
    -------
    float or ndarray
        theta = 2 atan(c / (2 d')) radians (eq. 6).

    Examples
    --------
    >>> blur_angle_rad(1.0, 50.0, small_angle=True)
    0.02
    """
    c = np.asarray(circle_of_confusion_mm, dtype=float)
    d = np.asarray(film_distance_mm, dtype=float)
    if small_angle:
        return _result((c / d))
    return _result((2.0 * np.arctan(c / (2.0 * d))))


def defocus_diopters(image_distance_mm, film_distance_mm):
    """Diopters of defocus, D = 1/d'_focus - 1/l' (eq. 9's bracket), in 1/m.

    Multiplied by the aperture diameter in metres it gives the blur angle of
    eq. 10, theta = a_diam D (small-angle).

    Parameters
    ----------
    image_distance_mm : float or array_like
        Where the point focuses, l', mm (``inf`` allowed).
    film_distance_mm : float
        Where the film is, d'_focus, mm.

    Examples
    --------
    >>> round(defocus_diopters(52.0, 50.0), 6)
    0.769231
    """
    l_prime = np.asarray(image_distance_mm, dtype=float)
    d_prime = np.asarray(film_distance_mm, dtype=float)
    return _result((1000.0 * (1.0 / d_prime - 1.0 / l_prime)))
