"""The length and evenness of a motion-blur streak.

A small disk of diameter d that moves L px in a straight line during the
shutter, at constant speed on the film, leaves a streak whose profile along
its centre line is the disk's profile convolved with a box of length L: for
L >= d a trapezoid whose plateau is reached d/2 inside each end. Its value at
each end point (where the disk's centre was when the shutter opened or closed)
is exactly half the plateau, because the disk's profile is symmetric; so the
distance between the two half-plateau crossings is L, whatever d (and the
pixel's box filter, symmetric too, keeps it). That is what :func:`measure_streak`
returns as ``length_px``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.ndimage import map_coordinates

from ._validate import luminance

__all__ = ["Streak", "measure_streak", "streak_profile"]


@dataclass(frozen=True)
class Streak:
    """A measured streak.

    Attributes
    ----------
    length_px : float
        Distance between the half-plateau crossings along the line, px.
    start_px, end_px : (float, float)
        The two crossings, raster coordinates (x right, y down).
    plateau : float
        Median luminance of the profile where it rises at least half way from
        its surroundings (the outer halves of the margins) to its maximum.
    background : float
        The surroundings' median luminance; the length is measured between
        the crossings half way from it to the plateau.
    unevenness : float
        Standard deviation over mean of the profile on the middle half of the
        streak (0 for a perfectly flat streak).
    tilt : float
        Mean of the last quarter of that middle half minus the first, over
        the mean: a streak that brightens toward one end.
    """

    length_px: float
    start_px: tuple[float, float]
    end_px: tuple[float, float]
    plateau: float
    background: float
    unevenness: float
    tilt: float


def streak_profile(image, *, start_px, end_px, margin_px: float = 8.0,
                   step_px: float = 0.25) -> tuple[np.ndarray, np.ndarray]:
    """Luminance sampled (bilinearly) along the line through ``start_px`` and
    ``end_px``, extended by ``margin_px`` beyond both.

    Returns
    -------
    s_px, values : ndarray
        Distance along the line from ``start_px`` (negative before it), px,
        and the luminance there.
    """
    lum = luminance(np.asarray(image, dtype=np.float64)) if np.ndim(image) == 3 else np.asarray(image, float)
    a, b = np.asarray(start_px, dtype=float), np.asarray(end_px, dtype=float)
    length = float(np.linalg.norm(b - a))
    if not length > 0:
        raise ValueError("start_px and end_px must differ (the streak's direction)")
    direction = (b - a) / length
    s = np.arange(-margin_px, length + margin_px + step_px / 2, step_px)
    points = a[None, :] + s[:, None] * direction[None, :]
    # Raster (x, y) with pixel centres at +0.5 -> array (row, column) indices.
    values = map_coordinates(lum, [points[:, 1] - 0.5, points[:, 0] - 0.5], order=1, mode="nearest")
    return s, values


def measure_streak(image, *, start_px, end_px, margin_px: float = 8.0, step_px: float = 0.25) -> Streak:
    """Measure the streak lying roughly from ``start_px`` to ``end_px``.

    Parameters
    ----------
    image : array_like
        (H, W, 3) linear RGB or (H, W) luminance, row 0 at the top.
    start_px, end_px : (float, float)
        Where to look: two points on the streak's centre line (for example
        the predicted positions of the moving point when the shutter opens
        and closes), raster coordinates. The crossings are searched along
        this line, ``margin_px`` beyond both ends.
    margin_px, step_px : float, optional
        How far beyond the ends to look, and the sampling step, px.

    Returns
    -------
    Streak
    """
    s, values = streak_profile(image, start_px=start_px, end_px=end_px, margin_px=margin_px, step_px=step_px)
    # What lies behind the streak: the outer halves of both margins. The
    # streak is what rises above it (a moving lamp in front of a lit wall).
    length = float(s[-1] - s[0]) - 2 * margin_px
    outside = (s <= s[0] + margin_px / 2) | (s >= s[0] + 1.5 * margin_px + length)
    base = float(np.median(values[outside])) if outside.any() else 0.0
    peak = float(values.max())
    if not peak > base:
        raise ValueError("no streak along the line: nothing there rises above its surroundings")
    plateau = float(np.median(values[values >= base + 0.5 * (peak - base)]))
    level = base + 0.5 * (plateau - base)
    above = np.nonzero(values >= level)[0]
    first, last = int(above[0]), int(above[-1])

    def crossing(i_below: int, i_above: int) -> float:
        # Linear interpolation between the samples on either side of the level.
        v0, v1 = values[i_below], values[i_above]
        return float(s[i_below] + (s[i_above] - s[i_below]) * (level - v0) / (v1 - v0))

    s_start = crossing(first - 1, first) if first > 0 else float(s[0])
    s_end = crossing(last + 1, last) if last + 1 < len(s) else float(s[-1])
    a, b = np.asarray(start_px, dtype=float), np.asarray(end_px, dtype=float)
    direction = (b - a) / np.linalg.norm(b - a)
    middle = values[(s >= s_start + 0.25 * (s_end - s_start)) & (s <= s_end - 0.25 * (s_end - s_start))] - base
    mean = float(middle.mean()) if middle.size else float("nan")
    quarter = max(1, middle.size // 4)
    return Streak(
        length_px=s_end - s_start,
        start_px=tuple(float(c) for c in a + s_start * direction),
        end_px=tuple(float(c) for c in a + s_end * direction),
        plateau=plateau,
        background=base,
        unevenness=float(middle.std() / mean) if middle.size else float("nan"),
        tilt=float((middle[-quarter:].mean() - middle[:quarter].mean()) / mean) if middle.size else float("nan"),
    )
