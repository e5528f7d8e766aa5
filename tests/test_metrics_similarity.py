"""Similarity metrics: identities, analytic values, properties, and published test data."""

import numpy as np
import pytest

from lenscompare.metrics import ColourDifference, ciede2000, psnr, relative_rmse, rmse, ssim


def smooth_scene(shape=(48, 64), channels=3):
    """A smooth test image in [0.1, 0.9]: gradients and a bright blob."""
    y, x = np.mgrid[0 : shape[0], 0 : shape[1]] / max(shape)
    grey = 0.1 + 0.4 * x + 0.2 * y + 0.2 * np.exp(-((x - 0.5) ** 2 + (y - 0.3) ** 2) / 0.02)
    if channels == 1:
        return grey
    return np.stack([grey, 0.9 * grey, 0.7 * grey + 0.1], axis=-1)


def checkerboard_error(shape, amplitude):
    """+amplitude / -amplitude in a checkerboard: MSE = amplitude², exactly."""
    rows, cols = np.indices(shape[:2])
    sign = np.where((rows + cols) % 2 == 0, 1.0, -1.0)
    return amplitude * (sign[..., None] if len(shape) == 3 else sign)


def test_identical_images():
    image = smooth_scene()
    assert psnr(image, image, data_range=1.0) == np.inf
    assert ssim(image, image, data_range=1.0) == 1.0
    assert rmse(image, image) == 0.0
    assert relative_rmse(image, image) == 0.0
    difference = ciede2000(image, image)
    assert isinstance(difference, ColourDifference)
    assert (difference.mean, difference.percentile_95) == (0.0, 0.0)


@pytest.mark.parametrize("channels", [1, 3])
def test_psnr_of_known_error_is_analytic(channels):
    image = smooth_scene(channels=channels)
    test = image + checkerboard_error(image.shape, 0.01)  # MSE = 1e-4
    assert psnr(image, test, data_range=1.0) == pytest.approx(40.0, abs=1e-9)
    assert psnr(image, test, data_range=2.0) == pytest.approx(40.0 + 20 * np.log10(2.0), abs=1e-9)
    assert rmse(image, test) == pytest.approx(0.01, rel=1e-12)
    assert relative_rmse(image, test) == pytest.approx(0.01 / image.mean(), rel=1e-12)


def test_psnr_of_gaussian_noise_matches_its_sigma():
    rng = np.random.default_rng(42)
    image = smooth_scene()
    sigma = 0.05
    noisy = image + rng.normal(0.0, sigma, image.shape)  # 9216 samples: MSE within ~3 %
    assert psnr(image, noisy, data_range=1.0) == pytest.approx(-20 * np.log10(sigma), abs=0.15)


def test_ssim_drops_as_noise_grows():
    rng = np.random.default_rng(7)
    image = smooth_scene()
    noise = rng.normal(0.0, 1.0, image.shape)
    sigmas = (0.0, 0.01, 0.03, 0.1, 0.3)
    scores = [ssim(image, image + sigma * noise, data_range=1.0) for sigma in sigmas]
    assert scores[0] == 1.0
    assert all(a > b for a, b in zip(scores, scores[1:]))
    assert scores[-1] < 0.5


def test_ssim_of_rgb_is_the_mean_over_channels():
    rng = np.random.default_rng(3)
    image = smooth_scene()
    test = image + rng.normal(0.0, 0.05, image.shape)
    per_channel = [ssim(image[..., c], test[..., c], data_range=1.0) for c in range(3)]
    assert ssim(image, test, data_range=1.0) == pytest.approx(np.mean(per_channel), rel=1e-12)


@pytest.mark.parametrize("metric", [psnr, ssim])
def test_data_range_is_required(metric):
    image = smooth_scene()
    with pytest.raises(TypeError):
        metric(image, image)
    with pytest.raises(TypeError):
        metric(image, image, 1.0)  # keyword-only
    for bad in (0.0, -1.0, np.nan, "one"):
        with pytest.raises(ValueError, match="data_range"):
            metric(image, image, data_range=bad)


@pytest.mark.parametrize("metric", [rmse, relative_rmse, ciede2000])
def test_shape_mismatch_raises_value_error(metric):
    with pytest.raises(ValueError, match="same shape"):
        metric(np.ones((12, 12, 3)), np.ones((12, 13, 3)))


def test_relative_rmse_needs_a_positive_mean():
    with pytest.raises(ValueError, match="positive mean"):
        relative_rmse(np.zeros((4, 4)), np.ones((4, 4)))


def test_ciede2000_of_two_greys_by_hand():
    # Expected value computed by hand (plain Python, not colour-science) from
    # the CIE definitions: L* = 116 Y^(1/3) - 16 gives L1 = 49.496108 for
    # Y = 0.18 and L2 = 51.837212 for Y = 0.20; for two neutrals every chroma
    # and hue term of CIEDE2000 vanishes (Sharma et al. 2005, eqs. 1-4), so
    # dE00 = |L2 - L1| / S_L with S_L = 1 + 0.015 (L - 50)^2 / sqrt(20 + (L - 50)^2)
    # at the mean L = 50.666660: S_L = 1.0014744, dE00 = 2.3376573.
    grey_a, grey_b = np.full((4, 4, 3), 0.18), np.full((4, 4, 3), 0.20)
    result = ciede2000(grey_a, grey_b, white_luminance=1.0)
    assert result.mean == pytest.approx(2.3376573, abs=1e-6)
    assert result.percentile_95 == pytest.approx(2.3376573, abs=1e-6)
    assert result.white_luminance == 1.0


# Sharma, Wu & Dalal (2005), "The CIEDE2000 color-difference formula:
# implementation notes, supplementary test data, and mathematical
# observations", Color Res. Appl. 30(1), Table 1, pairs 25-34: L*a*b* pairs
# and the dE00 the authors computed.
SHARMA_2005_PAIRS = [
    ((60.2574, -34.0099, 36.2677), (60.4626, -34.1751, 39.4387), 1.2644),
    ((63.0109, -31.0961, -5.8663), (62.8187, -29.7946, -4.0864), 1.2630),
    ((61.2901, 3.7196, -5.3901), (61.4292, 2.2480, -4.9620), 1.8731),
    ((35.0831, -44.1164, 3.7933), (35.0232, -40.0716, 1.5901), 1.8645),
    ((22.7233, 20.0904, -46.6940), (23.0331, 14.9730, -42.5619), 2.0373),
    ((36.4612, 47.8580, 18.3852), (36.2715, 50.5065, 21.2231), 1.4146),
    ((90.8027, -2.0831, 1.4410), (91.1528, -1.6435, 0.0447), 1.4441),
    ((90.9257, -0.5406, -0.9208), (88.6381, -0.8985, -0.7239), 1.5381),
    ((6.7747, -0.2908, -2.4247), (5.8714, -0.0985, -2.2286), 0.6377),
    ((2.0776, 0.0795, -1.1350), (0.9033, -0.0636, -0.5514), 0.9082),
]

# Linear sRGB (IEC 61966-2-1) to XYZ; its white, RGB = 1, is the Lab white.
RGB_TO_XYZ = np.array(
    [[0.4124, 0.3576, 0.1805], [0.2126, 0.7152, 0.0722], [0.0193, 0.1192, 0.9505]]
)
REC709 = RGB_TO_XYZ[1]


def lab_to_linear_srgb(lab):
    """CIE L*a*b* -> XYZ (CIE 15 inverse) -> linear sRGB, written out independently of colour."""
    L, a, b = lab
    fy = (L + 16) / 116
    f = np.array([fy + a / 500, fy, fy - b / 200])
    delta = 6 / 29
    xyz_over_white = np.where(f > delta, f**3, 3 * delta**2 * (f - 4 / 29))
    return np.linalg.solve(RGB_TO_XYZ, xyz_over_white * RGB_TO_XYZ.sum(axis=1))


@pytest.mark.parametrize("lab_true, lab_test, expected", SHARMA_2005_PAIRS)
def test_ciede2000_vs_sharma_2005(lab_true, lab_test, expected):
    image_true = lab_to_linear_srgb(lab_true).reshape(1, 1, 3)
    image_test = lab_to_linear_srgb(lab_test).reshape(1, 1, 3)
    result = ciede2000(image_true, image_test, white_luminance=1.0)
    assert result.mean == pytest.approx(expected, abs=1e-4)  # the table's 4 decimals


def test_ciede2000_default_white_makes_exposure_irrelevant():
    image = smooth_scene()
    test = image * [1.0, 1.02, 0.97]
    base = ciede2000(image, test)
    assert base.white_luminance == pytest.approx(np.percentile(image @ REC709, 99))
    brighter = ciede2000(8.0 * image, 8.0 * test)
    assert brighter.mean == pytest.approx(base.mean, rel=1e-9)
    assert brighter.percentile_95 == pytest.approx(base.percentile_95, rel=1e-9)
    assert 0 < base.mean <= base.percentile_95


def test_ciede2000_grows_with_the_difference():
    image = smooth_scene()
    means = [ciede2000(image, image * [1.0, 1.0 + d, 1.0]).mean for d in (0.01, 0.03, 0.1)]
    assert means[0] < means[1] < means[2]


@pytest.mark.parametrize(
    "image, kwargs, match",
    [
        (np.ones((4, 4)), {}, "RGB"),
        (np.zeros((4, 4, 3)), {}, "white_luminance"),
        (np.ones((4, 4, 3)), {"white_luminance": 0.0}, "white_luminance"),
    ],
)
def test_ciede2000_bad_arguments(image, kwargs, match):
    with pytest.raises(ValueError, match=match):
        ciede2000(image, image, **kwargs)


@pytest.mark.parametrize("size", [1, 3, 7, 9])
def test_ssim_of_an_image_smaller_than_the_window_is_one_window_over_the_whole_image(size):
    """Below 11 px SSIM is Wang et al.'s formula over the whole image. An odd
    square image through scikit-image's uniform window of its own size keeps
    one output pixel, whose window is the whole image: the same number by an
    independent implementation."""
    from skimage.metrics import structural_similarity

    rng = np.random.default_rng(size)
    true = rng.random((size, size, 3))
    test = np.clip(true + rng.normal(0, 0.1, true.shape), 0, 1)
    ours = ssim(true, test, data_range=1.0)
    if size >= 7:  # scikit-image takes windows of 7 px and more
        theirs = structural_similarity(true, test, data_range=1.0, channel_axis=-1, win_size=size,
                                       use_sample_covariance=False)
        assert ours == pytest.approx(theirs, rel=1e-12)
    assert ssim(true, true, data_range=1.0) == pytest.approx(1.0)
    assert ours < 1.0 or size == 1
    # 1 x 1: no structure, only luminance: (2 x y + C1) / (x^2 + y^2 + C1), averaged over channels
    if size == 1:
        c1 = 0.01 ** 2
        expected = np.mean((2 * true * test + c1) / (true ** 2 + test ** 2 + c1))
        assert ours == pytest.approx(expected, rel=1e-12)
