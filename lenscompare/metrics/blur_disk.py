"""Blur-disk size of the image of a point source: second moment and encircled energy."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy import ndimage
from skimage import measure

from ._validate import as_center, as_number, as_positive, luminance

__all__ = ["BlurDisk", "measure_blur_disk", "find_point_sources"]

PIXEL_VARIANCE_PX2 = 1.0 / 12.0
"""Per-axis variance of a square pixel of side 1 px (a box of width 1)."""

ENCIRCLED_FRACTION = 0.5
"""Fraction of the flux inside the circle that defines the encircled-energy diameter."""

_MAX_SUBSAMPLES = 1_000_000  # bound on the encircled-energy work per measurement


@dataclass(frozen=True)
class BlurDisk:
    """One blur-disk measurement; every position and length is in pixels.

    Attributes
    ----------
    centroid_px : tuple of float
        Flux-weighted centre (x, y) in raster coordinates.
    flux : float
        Sum of the background-subtracted luminance in the window (pixel value x px).
    second_moment_diameter_px : float
        Diameter of the uniform disk with the same corrected second moment.
    encircled_energy_diameter_px : float
        Diameter of the uniform disk with the same half-energy radius.
    variance_px2 : tuple of float
        Measured per-axis variances (var_x, var_y) about the centroid, px².
    corrected_variance_px2 : float
        Mean of the two variances minus the pixel and source terms, px².
    half_energy_radius_px : float
        Radius of the circle about the centroid that holds half the flux.
    """

    centroid_px: tuple[float, float]
    flux: float
    second_moment_diameter_px: float
    encircled_energy_diameter_px: float
    variance_px2: tuple[float, float]
    corrected_variance_px2: float
    half_energy_radius_px: float


def measure_blur_disk(
    image, *, center_px=None, window_radius_px=None, source_diameter_px=0.0, background=0.0
) -> BlurDisk:
    """Measure the size of one blur disk (the image of a small light source).

    Parameters
    ----------
    image : ndarray, shape (H, W) or (H, W, 3)
        Linear luminance or linear RGB (reduced to Rec.709 luminance).
    center_px : (float, float), optional
        Centre (x, y) of the measurement window, raster coordinates in pixels;
        needs ``window_radius_px``. Default: the window follows the blob (it
        starts on the centroid of the whole image and moves to the centroid of
        what it holds until it settles).
    window_radius_px : float, optional
        Only pixels whose centres lie within this radius of the window centre
        are used. Default: the whole image, which should then hold one source.
    source_diameter_px : float, optional
        Diameter, in pixels, of the in-focus image of the source (a uniformly
        bright disk) — removed from the second-moment diameter. Default 0.
    background : float, optional
        Luminance subtracted from every pixel before measuring. Default 0.

    Returns
    -------
    BlurDisk
        Centroid, flux, both diameters and the intermediate variances.

    Raises
    ------
    ValueError
        If an argument is invalid or the window holds no positive flux.

    Notes
    -----
    **Second-moment diameter.** The per-axis variances about the centroid,
    ``var = sum(w (x - x_c)²) / sum(w)``, are those of the true blur disk
    convolved with the pixel footprint and with the in-focus image of the
    source, and variances add under convolution. A uniform disk of diameter
    ``c`` has per-axis variance ``c²/16``; a box pixel adds ``1/12`` px² and a
    source disk of diameter ``s`` adds ``s²/16``, so

        c = 4 sqrt(mean(var_x, var_y) - 1/12 - s²/16),

    exactly for the continuous image (0 if the corrected variance is
    negative). Sampling it on the pixel grid adds an error that depends on
    the disk's sub-pixel position: for pixel-integrated uniform disks at
    random positions, within ±0.2 % at 10 px, ±0.8 % at 6 px, ±1.5 % at
    4 px and ±3.5 % at 3 px.

    **Encircled-energy diameter.** The radius ``r50`` of the circle about the
    centroid holding half the flux (each pixel is split into up to 8 x 8
    equal sub-squares to make the curve smooth) is converted to the uniform
    disk with the same ``r50``: the encircled energy of a uniform disk is
    ``(2r/c)²``, so ``c = 2 sqrt(2) r50``. The half-energy circle lies well
    inside the disk's edge, so the pixel footprint hardly changes it (within
    ±0.3 % from 6 px up, +2 % at 4 px, +6 % at 3 px), nor does a source
    smaller than about 0.3 c (0.3 % for s = c/3); it is *not* corrected for
    the source, because no exact correction exists (s = 0.4 c adds about 1 %).

    **Why they differ.** Both give ``c`` for a uniform disk. The second
    moment weights each pixel by its squared distance, so a faint halo, stray
    light, or noise and a wrong ``background`` far from the centre can
    dominate it; the encircled energy sees those only through the total flux.
    The encircled energy, in turn, assumes the uniform profile: it is smaller
    than the second moment for a blur with a bright core (a Gaussian of
    standard deviation σ gives 3.33 σ against 4 σ) and larger for one with a
    bright rim, so the pair tells a uniform disk from an aberrated one.

    References
    ----------
    .. [1] Kolb, C., Mitchell, D. and Hanrahan, P. (1995). A realistic camera
       model for computer graphics. SIGGRAPH '95, 317-324.
       :DOI:`10.1145/218380.218463`

    Examples
    --------
    >>> import numpy as np
    >>> image = np.zeros((9, 9))
    >>> image[3:6, 3:6] = 1.0   # three equal pixels per axis: var = 2/3 px²
    >>> disk = measure_blur_disk(image)
    >>> disk.centroid_px
    (4.5, 4.5)
    >>> round(disk.second_moment_diameter_px, 4)   # 4 sqrt(2/3 - 1/12)
    3.0551
    """
    values = luminance(image) - as_number(background, "background")
    source_px = as_positive(source_diameter_px, "source_diameter_px", allow_zero=True)
    rows, cols = np.indices(values.shape)
    x, y = cols + 0.5, rows + 0.5

    if window_radius_px is None:
        if center_px is not None:
            raise ValueError("center_px places the window: give window_radius_px too")
        window = np.ones(values.shape, dtype=bool)
    else:
        radius = as_positive(window_radius_px, "window_radius_px")
        if center_px is None:
            window = _recentred_window(values, x, y, radius)
        else:
            window = _disk(x, y, as_center(center_px), radius)

    w, x, y = values[window], x[window], y[window]
    flux = float(w.sum())
    if not flux > 0:
        raise ValueError("no positive flux in the measurement window (check background and window)")
    cx, cy = float((w * x).sum() / flux), float((w * y).sum() / flux)
    var_x = float((w * (x - cx) ** 2).sum() / flux)
    var_y = float((w * (y - cy) ** 2).sum() / flux)

    corrected = 0.5 * (var_x + var_y) - PIXEL_VARIANCE_PX2 - source_px**2 / 16.0
    r50 = _encircled_radius(w, x, y, (cx, cy), ENCIRCLED_FRACTION)
    return BlurDisk(
        centroid_px=(cx, cy),
        flux=flux,
        second_moment_diameter_px=4.0 * float(np.sqrt(max(corrected, 0.0))),
        encircled_energy_diameter_px=2.0 * r50 / float(np.sqrt(ENCIRCLED_FRACTION)),
        variance_px2=(var_x, var_y),
        corrected_variance_px2=corrected,
        half_energy_radius_px=r50,
    )


def find_point_sources(
    image, *, threshold=None, min_separation_px=4.0, background=0.0
) -> list[BlurDisk]:
    """Find the separate blur disks in an image and measure each one.

    Parameters
    ----------
    image : ndarray, shape (H, W) or (H, W, 3)
        Linear luminance or linear RGB (reduced to Rec.709 luminance).
    threshold : float, optional
        Luminance above which a pixel belongs to a source. Default:
        ``background`` plus the larger of five robust standard deviations of
        the image (1.4826 x median absolute deviation) and 0.1 % of the peak
        above ``background``.
    min_separation_px : float, optional
        Thresholded regions closer than this (edge to edge, px) are one source.
        Each region's window also grows by half of it, to take in the faint
        edge below the threshold. Default 4.
    background : float, optional
        Luminance of the empty background, subtracted before measuring. Default 0.

    Returns
    -------
    list of BlurDisk
        One per source (see :func:`measure_blur_disk`, with
        ``source_diameter_px=0``), sorted by centroid x, then y.

    Notes
    -----
    The thresholded mask is grown by ``min_separation_px / 2`` (a Euclidean
    distance transform) and labelled with :func:`skimage.measure.label`; each
    grown region is the window of one source, so windows never overlap. A
    source whose faint edge reaches farther than that beyond the threshold is
    cut, which biases its second moment low; raise ``min_separation_px`` or
    measure it alone with :func:`measure_blur_disk`.

    Examples
    --------
    >>> import numpy as np
    >>> image = np.zeros((20, 40))
    >>> image[4:7, 4:7] = 1.0
    >>> image[10:15, 25:30] = 1.0
    >>> [disk.centroid_px for disk in find_point_sources(image)]
    [(5.5, 5.5), (27.5, 12.5)]
    """
    background = as_number(background, "background")
    values = luminance(image) - background
    separation = as_positive(min_separation_px, "min_separation_px", allow_zero=True)
    if threshold is None:
        level = _default_threshold(values)
    else:
        level = as_number(threshold, "threshold") - background
    mask = values > level
    grown = ndimage.distance_transform_edt(~mask) <= separation / 2.0
    labels = measure.label(grown, connectivity=2)

    disks = []
    for region in measure.regionprops(labels):
        row0, col0, row1, col1 = region.bbox
        crop = np.where(region.image, values[row0:row1, col0:col1], 0.0)
        if not crop[region.image].sum() > 0:
            continue
        disk = measure_blur_disk(crop)
        cx, cy = disk.centroid_px
        disks.append(replace(disk, centroid_px=(cx + col0, cy + row0)))
    return sorted(disks, key=lambda disk: disk.centroid_px)


def _centroid(values, x, y) -> np.ndarray:
    flux = values.sum()
    if not flux > 0:
        raise ValueError("no positive flux in the image (check background)")
    return np.array([(values * x).sum() / flux, (values * y).sum() / flux])


def _encircled_radius(w, x, y, center, fraction) -> float:
    """Radius holding ``fraction`` of the flux, pixels split into n x n sub-squares."""
    n = int(np.clip(np.sqrt(_MAX_SUBSAMPLES / w.size), 1, 8))
    offsets = (np.arange(n) + 0.5) / n - 0.5
    dx = (x - center[0])[:, None, None] + offsets[None, :, None]
    dy = (y - center[1])[:, None, None] + offsets[None, None, :]
    distance = np.hypot(dx, dy).ravel()
    weight = np.repeat(w / n**2, n * n)
    order = np.argsort(distance)
    distance, cumulative = distance[order], np.cumsum(weight[order])
    target = fraction * cumulative[-1]
    i = int(np.argmax(cumulative >= target))  # first crossing (robust to noise)
    if i == 0:
        return float(distance[0])
    below = cumulative[i - 1]
    t = (target - below) / (cumulative[i] - below)
    return float(distance[i - 1] + t * (distance[i] - distance[i - 1]))


def _disk(x, y, center, radius) -> np.ndarray:
    return (x - center[0]) ** 2 + (y - center[1]) ** 2 <= radius**2


def _recentred_window(values, x, y, radius) -> np.ndarray:
    """Circular window moved onto the centroid of what it holds, until it settles."""
    center = _centroid(values, x, y)
    for _ in range(50):
        window = _disk(x, y, center, radius)
        previous, center = center, _centroid(np.where(window, values, 0.0), x, y)
        if np.max(np.abs(center - previous)) < 1e-9:
            break
    return _disk(x, y, center, radius)


def _default_threshold(values) -> float:
    median = np.median(values)
    sigma = 1.4826 * np.median(np.abs(values - median))
    return float(max(5.0 * sigma, 1e-3 * values.max()))
