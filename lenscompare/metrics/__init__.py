"""What a camera model does to the image: blur disks, distortion, vignetting,
similarity, motion-blur streaks and colour (per-channel dots and disks).

Conventions shared by every function here:

- Images are numpy arrays of linear values, ``(H, W, 3)`` RGB or ``(H, W)``
  luminance, row 0 at the TOP. Where one channel is needed, RGB is reduced to
  Rec.709 / sRGB relative luminance ``0.2126 R + 0.7152 G + 0.0722 B``
  (:func:`luminance`).
- Positions are raster coordinates in pixels: x to the right, y down, and the
  centre of the pixel in column ``i``, row ``j`` is at ``(i + 0.5, j + 0.5)``,
  so the image spans ``[0, W] x [0, H]`` and its centre is ``(W / 2, H / 2)``.
  Points are ``(x, y)`` pairs, point lists ``(N, 2)`` arrays. Names ending in
  ``_px`` are in pixels.
- Two-image metrics name their arguments by role, ``image_true`` (the
  reference) and ``image_test``; options are keyword-only.
- A bad argument raises :class:`ValueError` with a message naming it.
"""

from ._validate import luminance
from .blur_disk import BlurDisk, find_point_sources, measure_blur_disk
from .color import ChannelBlurDisks, LateralColor, channel_blur_disks, lateral_color
from .distortion import (
    RadialDistortion,
    RadialDistortionFit,
    distortion_percent,
    dot_centroids,
    fit_radial_distortion,
    match_points,
)
from .streak import Streak, measure_streak, streak_profile
from .similarity import ColourDifference, ciede2000, psnr, relative_rmse, rmse, ssim
from .vignetting import relative_illumination, relative_illumination_at

__all__ = [
    "luminance",
    "Streak",
    "measure_streak",
    "streak_profile",
    "BlurDisk",
    "measure_blur_disk",
    "find_point_sources",
    "LateralColor",
    "lateral_color",
    "ChannelBlurDisks",
    "channel_blur_disks",
    "RadialDistortion",
    "RadialDistortionFit",
    "dot_centroids",
    "match_points",
    "distortion_percent",
    "fit_radial_distortion",
    "relative_illumination",
    "relative_illumination_at",
    "ColourDifference",
    "psnr",
    "ssim",
    "rmse",
    "relative_rmse",
    "ciede2000",
]
