"""Radial distortion from a rendered dot grid: centroids, matching, percent, k1/k2 fit."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree
from skimage import filters, measure, segmentation

from ._validate import as_center, as_number, as_points, as_positive, luminance

__all__ = [
    "RadialDistortion",
    "RadialDistortionFit",
    "dot_centroids",
    "match_points",
    "distortion_percent",
    "fit_radial_distortion",
]

_GROW_PX = 2.0  # dot regions grow this far past the threshold, to take in their soft edges


@dataclass(frozen=True)
class RadialDistortion:
    """Per-point radial distortion; arrays of shape (N,).

    Attributes
    ----------
    ideal_radius_px, measured_radius_px : ndarray
        Distances from the centre, pixels.
    percent : ndarray
        ``(measured - ideal) / ideal * 100``; NaN where the ideal radius is 0.
    """

    ideal_radius_px: np.ndarray
    measured_radius_px: np.ndarray
    percent: np.ndarray


@dataclass(frozen=True)
class RadialDistortionFit:
    """Fit of ``r_d = r_u (1 + k1 ρ² + k2 ρ⁴)``, ``ρ = r_u / normalize_radius_px``.

    Attributes
    ----------
    k1, k2 : float
        Dimensionless coefficients (k1 < 0: barrel, k1 > 0: pincushion).
    normalize_radius_px : float
        The radius at which ρ = 1, pixels.
    rms_residual_px : float
        Root-mean-square radial residual of the fit, pixels.
    """

    k1: float
    k2: float
    normalize_radius_px: float
    rms_residual_px: float


def dot_centroids(image, *, threshold=None) -> np.ndarray:
    """Flux-weighted centroids of the bright dots of a rendered dot chart.

    Parameters
    ----------
    image : ndarray, shape (H, W) or (H, W, 3)
        Linear luminance or RGB (reduced to Rec.709 luminance): bright dots
        on a darker background. For dark dots, pass ``image.max() - image``.
    threshold : float, optional
        Luminance above which a pixel belongs to a dot. Default: Otsu's
        threshold (:func:`skimage.filters.threshold_otsu`).

    Returns
    -------
    ndarray, shape (N, 2)
        Centroids (x, y) in raster coordinates, pixels, one per connected
        region above the threshold, in scikit-image's label order (by each
        region's first pixel in raster order).

    Notes
    -----
    Each region above the threshold is grown by 2 px
    (:func:`skimage.segmentation.expand_labels`, which never merges two
    regions), because leaving out the dim edge pixels below the threshold
    would pull the centroid toward the brighter side by up to 0.1 px. The
    centroid is ``centroid_weighted`` of :func:`skimage.measure.regionprops`
    over the grown region, weighted by luminance minus the background (the
    median outside all grown regions), with (row, col) turned into raster
    (x, y) = (col + 0.5, row + 0.5). Dots must be at least 4 px apart edge
    to edge and blurred by less than 2 px past the threshold. A dot cut by
    the image border has a biased centroid; leave it unmatched.

    Examples
    --------
    >>> import numpy as np
    >>> image = np.zeros((10, 10))
    >>> image[2:4, 5:8] = 1.0
    >>> dot_centroids(image).tolist()
    [[6.5, 3.0]]
    """
    values = luminance(image)
    if threshold is None:
        if values.min() == values.max():
            return np.empty((0, 2))
        level = filters.threshold_otsu(values)
    else:
        level = as_number(threshold, "threshold")
    labels = segmentation.expand_labels(measure.label(values > level, connectivity=2), _GROW_PX)
    outside = values[labels == 0]
    background = float(np.median(outside)) if outside.size else 0.0
    regions = measure.regionprops(labels, intensity_image=values - background)
    rows_cols = np.array([region.centroid_weighted for region in regions]).reshape(-1, 2)
    return rows_cols[:, ::-1] + 0.5


def match_points(measured_px, ideal_px, *, max_distance_px) -> tuple[np.ndarray, np.ndarray]:
    """Pair measured and ideal points that are each other's nearest neighbour.

    Parameters
    ----------
    measured_px, ideal_px : array_like, shape (N, 2) and (M, 2)
        Point positions (x, y), pixels.
    max_distance_px : float
        Pairs farther apart than this are not matched, pixels.

    Returns
    -------
    measured_index, ideal_index : ndarray of int, shape (K,)
        ``measured_px[measured_index[k]]`` pairs with ``ideal_px[ideal_index[k]]``;
        one-to-one, ordered by ideal index.

    Notes
    -----
    A pair is kept only when each point is the other's nearest neighbour
    (:class:`scipy.spatial.cKDTree`), so a missing or extra dot never takes a
    neighbour's partner. Choose ``max_distance_px`` below half the grid
    pitch and above the largest expected displacement.

    Examples
    --------
    >>> measured = [[10.2, 10.1], [20.3, 9.8], [55.0, 55.0]]
    >>> ideal = [[20.0, 10.0], [10.0, 10.0], [30.0, 10.0]]
    >>> measured_index, ideal_index = match_points(measured, ideal, max_distance_px=3.0)
    >>> measured_index.tolist(), ideal_index.tolist()
    ([1, 0], [0, 1])
    """
    measured = as_points(measured_px, "measured_px")
    ideal = as_points(ideal_px, "ideal_px")
    limit = as_positive(max_distance_px, "max_distance_px")
    if len(measured) == 0 or len(ideal) == 0:
        return np.empty(0, dtype=int), np.empty(0, dtype=int)
    distance, nearest_measured = cKDTree(measured).query(ideal)
    _, nearest_ideal = cKDTree(ideal).query(measured)
    ideal_index = np.arange(len(ideal))
    keep = (distance <= limit) & (nearest_ideal[nearest_measured] == ideal_index)
    return nearest_measured[keep], ideal_index[keep]


def distortion_percent(measured_px, ideal_px, *, center_px) -> RadialDistortion:
    """Radial distortion of each matched point, in percent of its ideal radius.

    Parameters
    ----------
    measured_px, ideal_px : array_like, shape (N, 2)
        Matched positions (x, y), pixels: where each point was imaged and
        where a distortion-free camera (the pinhole) puts it.
    center_px : (float, float)
        Centre of distortion (x, y), pixels — the optical axis on the film,
        ``(W / 2, H / 2)`` for a centred lens.

    Returns
    -------
    RadialDistortion
        Ideal and measured radii and ``100 (r_measured - r_ideal) / r_ideal``.

    Notes
    -----
    Negative values are barrel distortion, positive pincushion. The point at
    the centre itself has no defined distortion and reads NaN.

    Examples
    --------
    >>> d = distortion_percent([[110.0, 50.0]], [[108.0, 50.0]], center_px=(58.0, 50.0))
    >>> d.percent.tolist()
    [4.0]
    """
    measured, ideal = _matched(measured_px, ideal_px)
    center = as_center(center_px)
    r_measured = np.hypot(*(measured - center).T)
    r_ideal = np.hypot(*(ideal - center).T)
    with np.errstate(divide="ignore", invalid="ignore"):
        percent = np.where(r_ideal > 0, 100.0 * (r_measured - r_ideal) / r_ideal, np.nan)
    return RadialDistortion(r_ideal, r_measured, percent)


def fit_radial_distortion(
    measured_px, ideal_px, *, center_px, normalize_radius_px
) -> RadialDistortionFit:
    """Fit the radial distortion polynomial ``r_d = r_u (1 + k1 ρ² + k2 ρ⁴)``.

    Parameters
    ----------
    measured_px, ideal_px : array_like, shape (N, 2)
        Matched positions (x, y), pixels: distorted (measured) and
        undistorted (ideal, e.g. from the pinhole render).
    center_px : (float, float)
        Centre of distortion (x, y), pixels.
    normalize_radius_px : float
        Radius at which ρ = 1, pixels; the half-diagonal of the image makes
        k1 and k2 comparable between resolutions.

    Returns
    -------
    RadialDistortionFit
        ``k1``, ``k2`` and the RMS radial residual.

    Notes
    -----
    The model is linear in (k1, k2): ``r_d - r_u = k1 r_u ρ² + k2 r_u ρ⁴``,
    solved by linear least squares. ``r_d`` is the measured point's
    component along the ideal point's radial direction, so a tangential
    error does not leak into the fit. This is Brown's radial model with
    the undistorted radius as argument (OpenCV's ``k1, k2`` up to the scale
    of ρ). At least two points off the centre at different radii are needed.

    References
    ----------
    .. [1] Brown, D. C. (1966). Decentering distortion of lenses.
       Photogrammetric Engineering 32(3), 444-462.

    Examples
    --------
    >>> import numpy as np
    >>> ideal = np.array([[60.0, 50.0], [100.0, 50.0], [50.0, 150.0]])
    >>> rho = np.array([0.1, 0.5, 1.0])     # radii 10, 50, 100 px over 100 px
    >>> measured = 50 + (ideal - 50) * (1 - 0.1 * rho**2)[:, None]
    >>> fit = fit_radial_distortion(measured, ideal, center_px=(50, 50), normalize_radius_px=100)
    >>> round(fit.k1, 12), round(fit.k2, 12)
    (-0.1, 0.0)
    """
    measured, ideal = _matched(measured_px, ideal_px)
    center = as_center(center_px)
    scale = as_positive(normalize_radius_px, "normalize_radius_px")
    r_u_all = np.hypot(*(ideal - center).T)
    off_center = r_u_all > 0  # the centre point carries no information
    if len(np.unique(r_u_all[off_center])) < 2:
        raise ValueError(
            "fit_radial_distortion needs points at two or more distinct radii off the centre"
        )
    r_u = r_u_all[off_center]
    offset_ideal, offset_measured = ideal[off_center] - center, measured[off_center] - center
    r_d = np.sum(offset_measured * offset_ideal, axis=1) / r_u  # radial component
    rho2 = (r_u / scale) ** 2
    design = np.column_stack([r_u * rho2, r_u * rho2**2])
    (k1, k2), *_ = np.linalg.lstsq(design, r_d - r_u, rcond=None)
    residual = r_d - r_u - design @ (k1, k2)
    return RadialDistortionFit(float(k1), float(k2), scale, float(np.sqrt(np.mean(residual**2))))


def _matched(measured_px, ideal_px):
    measured = as_points(measured_px, "measured_px")
    ideal = as_points(ideal_px, "ideal_px")
    if measured.shape != ideal.shape:
        raise ValueError(
            f"measured_px and ideal_px must be matched pairs of the same shape, "
            f"got {measured.shape} and {ideal.shape} (see match_points)"
        )
    return measured, ideal
