"""How alike two renders are: PSNR, SSIM, RMSE, relative RMSE and CIEDE2000."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from skimage import metrics

from ._validate import as_image_pair, as_positive, luminance

__all__ = ["ColourDifference", "psnr", "ssim", "rmse", "relative_rmse", "ciede2000"]


@dataclass(frozen=True)
class ColourDifference:
    """Summary of the per-pixel CIEDE2000 colour difference ΔE00.

    Attributes
    ----------
    mean : float
        Mean ΔE00 over all pixels.
    percentile_95 : float
        95th percentile of ΔE00 (5 % of the pixels differ more).
    white_luminance : float
        Luminance of the input that was mapped to the Lab white (Y = 1, L* = 100).
    """

    mean: float
    percentile_95: float
    white_luminance: float


def psnr(image_true, image_test, *, data_range) -> float:
    """Peak signal-to-noise ratio, in decibels.

    Parameters
    ----------
    image_true, image_test : ndarray, shape (H, W) or (H, W, 3)
        Reference and compared images, same shape, linear values.
    data_range : float
        Peak value of the signal, e.g. 1.0 for renders whose white reads 1.
        Required: a float image has no natural range.

    Returns
    -------
    float
        ``10 log10(data_range² / MSE)``; ``inf`` for identical images.

    Notes
    -----
    Wraps :func:`skimage.metrics.peak_signal_noise_ratio` but never guesses
    ``data_range``: scikit-image assumes 1 for floats, which silently makes
    values from HDR renders incomparable. PSNR values compare only between
    pairs with the same ``data_range``.

    Examples
    --------
    >>> import numpy as np
    >>> image = np.full((4, 4), 0.5)
    >>> round(psnr(image, image + 0.01, data_range=1.0), 6)   # 10 log10(1 / 1e-4)
    40.0
    """
    true, test = as_image_pair(image_true, image_test)
    peak = as_positive(data_range, "data_range")
    with np.errstate(divide="ignore"):
        return float(metrics.peak_signal_noise_ratio(true, test, data_range=peak))


def ssim(image_true, image_test, *, data_range) -> float:
    """Mean structural similarity index (SSIM) of Wang et al. (2004).

    Parameters
    ----------
    image_true, image_test : ndarray, shape (H, W) or (H, W, 3)
        Reference and compared images, same shape, any size (1 x 1 too).
        RGB channels are compared separately and averaged.
    data_range : float
        Peak value of the signal (sets the constants C1, C2). Required.

    Returns
    -------
    float
        Mean SSIM, 1 for identical images, lower for less alike ones.

    Notes
    -----
    :func:`skimage.metrics.structural_similarity` with the paper's settings:
    an 11 x 11 Gaussian window of σ = 1.5 px and population covariances
    (``gaussian_weights=True, sigma=1.5, use_sample_covariance=False``).
    An image narrower than the window (under 11 px either way: the smallest
    scenes the schema allows) is one window: the paper's formula with the
    means, variances and covariance of the whole image, C1 = (0.01 L)²,
    C2 = (0.03 L)².

    References
    ----------
    .. [1] Wang, Z., Bovik, A. C., Sheikh, H. R. and Simoncelli, E. P.
       (2004). Image quality assessment: from error visibility to structural
       similarity. IEEE Trans. Image Process. 13(4), 600-612.
       :DOI:`10.1109/TIP.2003.819861`

    Examples
    --------
    >>> import numpy as np
    >>> image = np.random.default_rng(0).random((16, 16, 3))
    >>> ssim(image, image, data_range=1.0)
    1.0
    """
    true, test = as_image_pair(image_true, image_test)
    peak = as_positive(data_range, "data_range")
    if min(true.shape[:2]) < SSIM_WINDOW_PX:
        return _ssim_one_window(true, test, peak)
    return float(
        metrics.structural_similarity(
            true,
            test,
            data_range=peak,
            channel_axis=-1 if true.ndim == 3 else None,
            gaussian_weights=True,
            sigma=1.5,
            use_sample_covariance=False,
        )
    )


SSIM_WINDOW_PX = 11
"""Side of the Gaussian SSIM window: 2 * int(3.5 * 1.5 + 0.5) + 1 (scikit-image, σ = 1.5, truncated at 3.5 σ)."""


def _ssim_one_window(true: np.ndarray, test: np.ndarray, peak: float) -> float:
    """SSIM of Wang et al. (2004), eq. 13, with the whole image as the window
    (uniform weights, population statistics), averaged over channels."""
    c1, c2 = (0.01 * peak) ** 2, (0.03 * peak) ** 2
    x = true.reshape(-1, true.shape[2] if true.ndim == 3 else 1)
    y = test.reshape(x.shape)
    mx, my = x.mean(axis=0), y.mean(axis=0)
    vx, vy = ((x - mx) ** 2).mean(axis=0), ((y - my) ** 2).mean(axis=0)
    cxy = ((x - mx) * (y - my)).mean(axis=0)
    values = ((2 * mx * my + c1) * (2 * cxy + c2)) / ((mx ** 2 + my ** 2 + c1) * (vx + vy + c2))
    return float(values.mean())


def rmse(image_true, image_test) -> float:
    """Root-mean-square error, in the images' units.

    Parameters
    ----------
    image_true, image_test : ndarray, shape (H, W) or (H, W, 3)
        Reference and compared images, same shape.

    Returns
    -------
    float
        ``sqrt(mean((image_test - image_true)²))`` over all pixels and channels.

    Examples
    --------
    >>> import numpy as np
    >>> rmse(np.zeros((2, 2)), np.full((2, 2), 3.0))
    3.0
    """
    true, test = as_image_pair(image_true, image_test)
    return float(np.sqrt(metrics.mean_squared_error(true, test)))


def relative_rmse(image_true, image_test) -> float:
    """RMSE divided by the mean of ``image_true``.

    Parameters
    ----------
    image_true, image_test : ndarray, shape (H, W) or (H, W, 3)
        Reference and compared images, same shape; ``image_true`` must have a
        positive mean.

    Returns
    -------
    float
        ``rmse(image_true, image_test) / mean(image_true)`` (0.01 = 1 %).

    Notes
    -----
    The mean (scikit-image's ``normalized_root_mse(normalization="mean")``)
    rather than the RMS of ``image_true`` so that the value reads as the
    error relative to the average brightness of the scene — for a Monte Carlo
    render against a converged reference, its relative noise level, which
    falls as 1/sqrt(samples per pixel) — whatever the exposure.

    Examples
    --------
    >>> import numpy as np
    >>> relative_rmse(np.full((2, 2), 2.0), np.full((2, 2), 2.5))
    0.25
    """
    true, test = as_image_pair(image_true, image_test)
    if not true.mean() > 0:
        raise ValueError("relative_rmse needs image_true with a positive mean")
    return float(metrics.normalized_root_mse(true, test, normalization="mean"))


def ciede2000(image_true, image_test, *, white_luminance=None) -> ColourDifference:
    """Perceptual colour difference ΔE00 (CIEDE2000) between two linear RGB renders.

    Parameters
    ----------
    image_true, image_test : ndarray, shape (H, W, 3)
        Linear RGB with Rec.709 / sRGB primaries and D65 white (no transfer
        function), same shape.
    white_luminance : float, optional
        Luminance (Rec.709 weights) that is shown as white: both images are
        divided by it so that it maps to Y = 1 (L* = 100). Default: the 99th
        percentile of the luminance of ``image_true``.

    Returns
    -------
    ColourDifference
        Mean and 95th percentile of the per-pixel ΔE00, and the white used.

    Notes
    -----
    Each pixel goes linear RGB -> CIE XYZ (``colour.RGB_to_XYZ`` with the
    sRGB colourspace, no decoding, no chromatic adaptation) -> CIE L*a*b*
    (``colour.XYZ_to_Lab``, reference white = the colourspace's white, so
    equal R, G and B are neutral) -> ``colour.delta_E(method="CIE 2000")``.
    Both images share one scale factor, so a brightness difference shows up
    as a lightness difference. ΔE00 near 1 is about a just-noticeable
    difference for large uniform patches; values compare only between pairs
    with the same ``white_luminance``. Pixels brighter than the white are not
    clipped (L* > 100).

    References
    ----------
    .. [1] Sharma, G., Wu, W. and Dalal, E. N. (2005). The CIEDE2000
       color-difference formula: implementation notes, supplementary test
       data, and mathematical observations. Color Res. Appl. 30(1), 21-30.
       :DOI:`10.1002/col.20070`

    Examples
    --------
    >>> import numpy as np
    >>> grey = np.full((2, 2, 3), 0.18)
    >>> ciede2000(grey, grey).mean
    0.0
    """
    true, test = as_image_pair(image_true, image_test, rgb_only=True)
    if white_luminance is None:
        white = float(np.percentile(luminance(true), 99))
        if not white > 0:
            raise ValueError(
                "the 99th-percentile luminance of image_true is not positive: give white_luminance"
            )
    else:
        white = as_positive(white_luminance, "white_luminance")
    delta_e = _delta_e_2000(true / white, test / white)
    return ColourDifference(float(delta_e.mean()), float(np.percentile(delta_e, 95)), white)


def _colour():
    """colour-science, imported on use: it takes most of a second to import."""
    with np.printoptions():  # importing colour sets numpy's legacy printing globally: undo it
        import colour  # here, not at the top: colour-science takes about a second to import
    return colour


def _delta_e_2000(rgb_true, rgb_test) -> np.ndarray:
    """Per-pixel ΔE00 of two linear sRGB images, scaled so that white is Y = 1."""
    colour = _colour()
    srgb = colour.RGB_COLOURSPACES["sRGB"]
    white_xy = colour.XYZ_to_xy(srgb.matrix_RGB_to_XYZ @ np.ones(3))

    def lab(rgb):
        xyz = colour.RGB_to_XYZ(
            rgb, srgb, apply_cctf_decoding=False, chromatic_adaptation_transform=None
        )
        return colour.XYZ_to_Lab(xyz, white_xy)

    with colour.utilities.domain_range_scale("reference"):
        return np.asarray(colour.delta_E(lab(rgb_true), lab(rgb_test), method="CIE 2000"))
