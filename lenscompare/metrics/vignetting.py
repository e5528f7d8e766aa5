"""Relative illumination (vignetting) from the render of a uniformly bright scene."""

from __future__ import annotations

import numpy as np

from ._validate import as_center, as_positive, luminance

__all__ = ["relative_illumination", "relative_illumination_at"]


def relative_illumination(
    image, *, center_px=None, n_bins=32, max_radius_px=None
) -> tuple[np.ndarray, np.ndarray]:
    """Radial profile of a flat-field render, normalised to its centre.

    Parameters
    ----------
    image : ndarray, shape (H, W) or (H, W, 3)
        Linear render of a uniform scene (RGB is reduced to Rec.709 luminance).
    center_px : (float, float), optional
        Optical axis on the film (x, y), pixels. Default: the image centre
        ``(W / 2, H / 2)``.
    n_bins : int, optional
        Number of equal-width radial bins from 0 to ``max_radius_px``. Default 32.
    max_radius_px : float, optional
        Outer edge of the last bin, pixels. Default: the distance from the
        centre to the farthest image corner.

    Returns
    -------
    radius_px : ndarray, shape (n_bins,)
        Mean distance from the centre of the pixel centres in each bin
        (near the bin's middle; see Notes), pixels.
    illumination : ndarray, shape (n_bins,)
        Mean luminance of the pixels whose centres fall in each bin, divided
        by that of the central bin (so the first value is 1). Both arrays
        are NaN for a bin that holds no pixel centre.

    Raises
    ------
    ValueError
        If an argument is invalid or the central bin is empty or not bright.

    Notes
    -----
    Each value is plotted at the mean radius of the pixels it averages,
    not at the middle of its bin: beyond the image's shorter half-side the
    bins are cut by the image edges and hold more pixels near their inner
    edge, and the middle of the bin would misplace their value by up to 2 %
    of the falloff (the first bin's mean radius is 2/3 of its width). Then
    a smooth profile is read to second order in the bin width.

    Lens-system renders are normalised so that the image centre reads 1
    (DESIGN.md), so their profile is the relative illumination directly;
    dividing by the central bin makes renders of any brightness comparable.
    The central bin is a small disk, so a profile that falls as ``1 - a r²``
    reads high by about ``a w² / 2`` for a bin width ``w``: 0.08 % for a
    cos⁴ law with f = 200 px and 5.7 px bins. Monte Carlo noise averages
    down with the number of pixels per bin, fewest in the central bin.

    References
    ----------
    .. [1] Kolb, C., Mitchell, D. and Hanrahan, P. (1995). A realistic camera
       model for computer graphics. SIGGRAPH '95, 317-324.
       :DOI:`10.1145/218380.218463`

    Examples
    --------
    >>> import numpy as np
    >>> radius_px, illumination = relative_illumination(np.full((64, 64), 0.5), n_bins=4)
    >>> radius_px.round(2).tolist()
    [7.44, 17.51, 28.34, 37.48]
    >>> illumination.tolist()
    [1.0, 1.0, 1.0, 1.0]
    """
    values = luminance(image)
    radius, edges = _pixel_radii(values.shape, center_px, n_bins, max_radius_px)
    index = np.digitize(radius.ravel(), edges) - 1
    inside = (index >= 0) & (index < len(edges) - 1)
    mean_radius = _bin_means(index[inside], radius.ravel()[inside], len(edges) - 1)
    mean_value = _bin_means(index[inside], values.ravel()[inside], len(edges) - 1)
    if not mean_value[0] > 0:
        raise ValueError(
            "the central bin holds no pixel centre or is not bright: use fewer n_bins, "
            "check center_px, and that the image is a flat field"
        )
    return mean_radius, mean_value / mean_value[0]


def relative_illumination_at(
    image, radius_px, *, center_px=None, n_bins=32, max_radius_px=None
) -> float | np.ndarray:
    """Relative illumination at given radii, interpolated in the radial profile.

    Parameters
    ----------
    image : ndarray, shape (H, W) or (H, W, 3)
        Linear render of a uniform scene.
    radius_px : float or array_like
        Radii from the centre, pixels, within ``[0, max_radius_px]``.
    center_px, n_bins, max_radius_px
        As in :func:`relative_illumination`.

    Returns
    -------
    float or ndarray
        Linear interpolation between bin centres of
        :func:`relative_illumination`, between the bins' mean radii; shaped
        like ``radius_px``. Below the first mean radius and above the last,
        the nearest bin's value.

    Examples
    --------
    >>> import numpy as np
    >>> relative_illumination_at(np.ones((64, 64)), 20.0)
    1.0
    """
    values = luminance(image)
    _, edges = _pixel_radii(values.shape, center_px, n_bins, max_radius_px)
    centers, illumination = relative_illumination(
        values, center_px=center_px, n_bins=n_bins, max_radius_px=max_radius_px
    )
    radius = np.asarray(radius_px, dtype=np.float64)
    limit = edges[-1]
    in_range = np.isfinite(radius) & (radius >= 0) & (radius <= limit * (1 + 1e-12))
    if not np.all(in_range):
        raise ValueError(
            f"radius_px must lie in [0, {limit:g}] px (the measured range), got {radius_px!r}"
        )
    known = np.isfinite(illumination)
    result = np.interp(radius, centers[known], illumination[known])
    return float(result) if result.ndim == 0 else result


def _bin_means(index, values, n_bins) -> np.ndarray:
    counts = np.bincount(index, minlength=n_bins)
    sums = np.bincount(index, weights=values, minlength=n_bins)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(counts > 0, sums / counts, np.nan)


def _pixel_radii(shape, center_px, n_bins, max_radius_px):
    """Distance of every pixel centre from the centre, and the bin edges."""
    height, width = shape
    center = np.array([width / 2, height / 2]) if center_px is None else as_center(center_px)
    if isinstance(n_bins, bool) or not isinstance(n_bins, (int, np.integer)) or n_bins < 1:
        raise ValueError(f"n_bins must be a positive integer, got {n_bins!r}")
    if max_radius_px is None:
        corners_x, corners_y = np.array([0, width]) - center[0], np.array([0, height]) - center[1]
        max_radius = float(np.hypot(np.abs(corners_x).max(), np.abs(corners_y).max()))
    else:
        max_radius = as_positive(max_radius_px, "max_radius_px")
    rows, cols = np.indices(shape)
    radius = np.hypot(cols + 0.5 - center[0], rows + 0.5 - center[1])
    return radius, np.linspace(0.0, max_radius, n_bins + 1)
