"""The one place where metric arguments are checked and converted.

Every public metric passes its arguments through these helpers, so a bad image,
point list or option gives the same kind of message everywhere: a
:class:`ValueError` that names the argument and says what was expected.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "REC709_LUMINANCE_WEIGHTS",
    "as_center",
    "as_image",
    "as_image_pair",
    "as_number",
    "as_points",
    "as_positive",
    "luminance",
]

REC709_LUMINANCE_WEIGHTS = np.array([0.2126, 0.7152, 0.0722])
"""Relative luminance Y of linear Rec.709 / sRGB primaries (ITU-R BT.709-6)."""


def as_image(image, name: str = "image", *, rgb_only: bool = False) -> np.ndarray:
    """Return ``image`` as float64, checking it is (H, W) or (H, W, 3) and finite."""
    array = np.asarray(image)
    if array.dtype == object or not (
        np.issubdtype(array.dtype, np.floating) or np.issubdtype(array.dtype, np.integer)
    ):
        raise ValueError(f"{name} must be a real numeric array, got dtype {array.dtype}")
    is_rgb = array.ndim == 3 and array.shape[2] == 3
    if not is_rgb and (rgb_only or array.ndim != 2):
        expected = "(H, W, 3) RGB" if rgb_only else "(H, W) luminance or (H, W, 3) RGB"
        raise ValueError(f"{name} must be {expected}, got shape {array.shape}")
    if array.shape[0] == 0 or array.shape[1] == 0:
        raise ValueError(f"{name} is empty (shape {array.shape})")
    array = array.astype(np.float64, copy=False)
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return array


def as_image_pair(image_true, image_test, *, rgb_only: bool = False):
    """Check both images (see :func:`as_image`) and that their shapes match."""
    true = as_image(image_true, "image_true", rgb_only=rgb_only)
    test = as_image(image_test, "image_test", rgb_only=rgb_only)
    if true.shape != test.shape:
        raise ValueError(
            f"image_true and image_test must have the same shape, "
            f"got {true.shape} and {test.shape}"
        )
    return true, test


def luminance(image) -> np.ndarray:
    """Relative luminance of a linear image: Rec.709 weights for RGB, as-is for (H, W).

    Parameters
    ----------
    image : array_like, shape (H, W) or (H, W, 3)
        Linear RGB, or luminance already.

    Returns
    -------
    ndarray of float64, shape (H, W)
        ``0.2126 R + 0.7152 G + 0.0722 B``.

    Examples
    --------
    >>> import numpy as np
    >>> float(luminance(np.ones((1, 1, 3)))[0, 0])
    1.0
    """
    array = as_image(image)
    if array.ndim == 2:
        return array
    return array @ REC709_LUMINANCE_WEIGHTS


def as_points(points, name: str) -> np.ndarray:
    """Return ``points`` as a finite float64 (N, 2) array of (x, y) pixel positions."""
    array = np.asarray(points, dtype=np.float64)
    if array.ndim != 2 or array.shape[1] != 2:
        raise ValueError(
            f"{name} must be an (N, 2) array of (x, y) positions, got shape {array.shape}"
        )
    if not np.all(np.isfinite(array)):
        raise ValueError(f"{name} contains NaN or infinite values")
    return array


def as_center(center_px, name: str = "center_px") -> np.ndarray:
    """Return a finite (x, y) pixel position as a float64 array of shape (2,)."""
    array = np.asarray(center_px, dtype=np.float64)
    if array.shape != (2,) or not np.all(np.isfinite(array)):
        raise ValueError(f"{name} must be two finite numbers (x, y) in pixels, got {center_px!r}")
    return array


def as_number(value, name: str) -> float:
    """Return ``value`` as a finite float."""
    try:
        number = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number, got {value!r}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite, got {value!r}")
    return number


def as_positive(value, name: str, *, allow_zero: bool = False) -> float:
    """Return ``value`` as a finite float that is > 0 (or >= 0 with ``allow_zero``)."""
    number = as_number(value, name)
    if number < 0 or (number == 0 and not allow_zero):
        bound = ">= 0" if allow_zero else "> 0"
        raise ValueError(f"{name} must be a finite number {bound}, got {value!r}")
    return number
