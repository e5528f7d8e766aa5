"""Chromatic aberration measured on RGB images, channel by channel.

- *Lateral colour* on a rendered dot grid: each dot's centroid in R, G and B
  (:func:`lenscompare.metrics.dot_centroids` on each channel), and the R - B
  displacement against the dot's distance from the image centre.
- *Longitudinal colour* on rendered blur disks: each disk's second-moment
  diameter in R, G and B (:func:`lenscompare.metrics.measure_blur_disk` on
  each channel, the windows found on the luminance by
  :func:`lenscompare.metrics.find_point_sources`).

A camera that does not disperse (any RGB render of a white chart) shows the
same image in the three channels, so both read 0.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._validate import as_image, as_positive
from .blur_disk import find_point_sources, measure_blur_disk
from .distortion import dot_centroids, match_points

__all__ = ["LateralColor", "ChannelBlurDisks", "lateral_color", "channel_blur_disks"]


@dataclass(frozen=True)
class LateralColor:
    """Per-dot channel centroids and their red-minus-blue displacement; arrays over N dots.

    Attributes
    ----------
    centroids_px : ndarray, shape (N, 3, 2)
        Centroid (x, y) of each dot in R, G and B, pixels.
    field_radius_px : ndarray, shape (N,)
        Distance of the green centroid from the centre, pixels.
    radial_shift_px : ndarray, shape (N,)
        Red centroid's distance from the centre minus blue's, pixels
        (positive: red imaged farther out, as behind an undercorrected lens).
    shift_px : ndarray, shape (N,)
        Length of the R - B centroid displacement, pixels.
    """

    centroids_px: np.ndarray
    field_radius_px: np.ndarray
    radial_shift_px: np.ndarray
    shift_px: np.ndarray


@dataclass(frozen=True)
class ChannelBlurDisks:
    """Per-source blur-disk diameters in each channel; arrays over N sources.

    Attributes
    ----------
    centroid_px : ndarray, shape (N, 2)
        Luminance centroid (x, y) of each source, pixels.
    diameter_px : ndarray, shape (N, 3)
        Second-moment diameter in R, G and B, pixels.
    """

    centroid_px: np.ndarray
    diameter_px: np.ndarray

    @property
    def red_minus_blue_px(self) -> np.ndarray:
        """R diameter minus B diameter per source, pixels."""
        return self.diameter_px[:, 0] - self.diameter_px[:, 2]


def lateral_color(image, *, center_px=None, max_distance_px=2.0) -> LateralColor:
    """Lateral colour of a rendered dot chart: per-channel dot centroids.

    Parameters
    ----------
    image : ndarray, shape (H, W, 3)
        Linear RGB: bright dots on a dark background.
    center_px : (float, float), optional
        The optical axis on the image (x, y), pixels. Default ``(W / 2, H / 2)``.
    max_distance_px : float, optional
        A red or blue centroid is paired with the nearest green one within
        this distance, pixels (default 2); dots without both partners are left out.

    Returns
    -------
    LateralColor
        The dots found in all three channels, in the green channel's order.

    Raises
    ------
    ValueError
        If ``image`` is not an RGB image or an option is not a positive number.

    Notes
    -----
    Each channel's centroids are those of :func:`dot_centroids` on that
    channel alone (its own Otsu threshold and background), so the channels'
    different brightness does not move them. Compare ``radial_shift_px``
    against ``field_radius_px``: lateral colour grows from 0 on the axis.

    Examples
    --------
    >>> import numpy as np
    >>> image = np.zeros((21, 40, 3))
    >>> image[9:12, 30:33] = 1.0       # a white dot 11.5 px right of the centre
    >>> image[9:12, 30, 0] = 0.0       # its red part one pixel farther out
    >>> image[9:12, 33, 0] = 1.0
    >>> result = lateral_color(image)
    >>> result.radial_shift_px.tolist(), result.field_radius_px.tolist()
    ([1.0], [11.5])
    """
    pixels = as_image(image, rgb_only=True)
    limit = as_positive(max_distance_px, "max_distance_px")
    height, width = pixels.shape[:2]
    center = np.array([width / 2.0, height / 2.0] if center_px is None else center_px, dtype=float)
    green = dot_centroids(pixels[..., 1])
    paired = [green]
    keep = np.ones(len(green), dtype=bool)
    for channel in (0, 2):
        found = dot_centroids(pixels[..., channel])
        measured, ideal = match_points(found, green, max_distance_px=limit) if len(found) and len(green) else ([], [])
        points = np.full_like(green, np.nan)
        points[np.asarray(ideal, dtype=int)] = found[np.asarray(measured, dtype=int)]
        keep &= np.isfinite(points[:, 0])
        paired.append(points)
    red, green, blue = paired[1][keep], green[keep], paired[2][keep]
    centroids = np.stack([red, green, blue], axis=1)
    radial = np.hypot(*(red - center).T) - np.hypot(*(blue - center).T)
    return LateralColor(centroids, np.hypot(*(green - center).T), radial, np.hypot(*(red - blue).T))


def channel_blur_disks(image, *, window_radius_px=None, min_separation_px=4.0, background=0.0) -> ChannelBlurDisks:
    """Longitudinal colour of rendered blur disks: per-channel diameters.

    Parameters
    ----------
    image : ndarray, shape (H, W, 3)
        Linear RGB: separate blur disks of small sources on a dark background.
    window_radius_px : float, optional
        Each channel is measured within this radius of the source's luminance
        centroid, pixels. Default: the source's luminance second-moment
        diameter plus ``min_separation_px`` (its window reaches past the edge
        of the largest channel's disk for a colour spread under half its size).
    min_separation_px : float, optional
        As for :func:`find_point_sources`, which finds the sources. Default 4.
    background : float, optional
        Value subtracted from every channel before measuring. Default 0.

    Returns
    -------
    ChannelBlurDisks
        One row per source, sorted as :func:`find_point_sources` sorts them.

    Raises
    ------
    ValueError
        If ``image`` is not an RGB image or an option is invalid.

    Notes
    -----
    The diameters are :func:`measure_blur_disk`'s second-moment diameters
    (pixel footprint removed), so a channel blurred by a further disk of
    diameter ``d`` reads ``sqrt(c**2 + d**2)``: variances add.
    """
    pixels = as_image(image, rgb_only=True)
    sources = find_point_sources(pixels, min_separation_px=min_separation_px, background=background)
    centroids, diameters = [], []
    for source in sources:
        radius = (source.second_moment_diameter_px + min_separation_px if window_radius_px is None
                  else as_positive(window_radius_px, "window_radius_px"))
        row = [measure_blur_disk(pixels[..., channel], center_px=source.centroid_px, window_radius_px=radius,
                                 background=background).second_moment_diameter_px for channel in range(3)]
        centroids.append(source.centroid_px)
        diameters.append(row)
    return ChannelBlurDisks(np.array(centroids).reshape(-1, 2), np.array(diameters).reshape(-1, 3))
