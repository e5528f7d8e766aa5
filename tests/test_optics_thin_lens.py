"""Equations 1-10 of the paper against values computed by hand."""

import math

import numpy as np
import pytest

from lenscompare import optics


def test_image_distance_eq2_by_hand():
    # l' = f l / (l - f) = 50 * 1000 / 950
    assert optics.image_distance_mm(1000.0, 50.0) == pytest.approx(52.631578947368421, rel=1e-14)


def test_gaussian_lens_equation_eq1_holds():
    l = np.array([120.0, 500.0, 3000.0, 1e7])
    l_prime = optics.image_distance_mm(l, 50.0)
    np.testing.assert_allclose(1 / l + 1 / l_prime, 1 / 50.0, rtol=1e-13)


def test_image_distance_limits():
    assert optics.image_distance_mm(math.inf, 35.0) == 35.0
    assert optics.image_distance_mm(50.0, 50.0) == math.inf  # object at the focal length
    assert optics.image_distance_mm(25.0, 50.0) == pytest.approx(-50.0)  # virtual image


def test_f_number_and_aperture_eq3():
    assert optics.f_number(50.0, 25.0) == 2.0
    assert optics.aperture_diameter_mm(85.0, 1.7) == pytest.approx(50.0)


def test_focus_film_distance_eq4():
    # 50 * 2000 / 1950
    assert optics.focus_film_distance_mm(2000.0, 50.0) == pytest.approx(51.282051282051282, rel=1e-14)


def test_circle_of_confusion_eq5_by_hand():
    # a = 25, d' = 51.28205128, l' (1 m) = 52.63157895: c = 25 * 1.34952767 / 52.63157895
    c = optics.circle_of_confusion_mm(1000.0, focus_distance_mm=2000.0, focal_length_mm=50.0,
                                      aperture_diameter_mm=25.0)
    assert c == pytest.approx(0.64102564, rel=1e-7)
    # Behind focus: l = 4 m, l' = 50.63291139, c = 25 * 0.64913989 / 50.63291139
    c = optics.circle_of_confusion_mm(4000.0, focus_distance_mm=2000.0, focal_length_mm=50.0,
                                      aperture_diameter_mm=25.0)
    assert c == pytest.approx(0.32051282, rel=1e-7)


def test_circle_of_confusion_zero_in_focus_and_finite_in_hard_cases():
    kw = dict(focus_distance_mm=2000.0, focal_length_mm=50.0, aperture_diameter_mm=25.0)
    assert optics.circle_of_confusion_mm(2000.0, **kw) == pytest.approx(0.0, abs=1e-12)
    # Object at the focal length: image at infinity, the blur is the whole aperture.
    assert optics.circle_of_confusion_mm(50.0, **kw) == pytest.approx(25.0)
    # Object at infinity: c = a (d' - f) / f
    assert optics.circle_of_confusion_mm(math.inf, **kw) == pytest.approx(25.0 * (51.28205128205128 - 50) / 50)


def test_blur_angle_eq6_eq7():
    assert optics.blur_angle_rad(1.0, 50.0) == pytest.approx(2 * math.atan(0.01))
    assert optics.blur_angle_rad(1.0, 50.0, small_angle=True) == pytest.approx(0.02)


def test_blur_angle_equals_aperture_times_defocus_eq8_to_eq10():
    # theta = c / d' (eq. 7) equals a_diam * D (eq. 10) exactly, with D in 1/m and a in m.
    f, d, a = 50.0, 2000.0, 25.0
    d_prime = optics.focus_film_distance_mm(d, f)
    for l in (700.0, 1500.0, 3000.0, 1e6):
        c = optics.circle_of_confusion_mm(l, focus_distance_mm=d, focal_length_mm=f, aperture_diameter_mm=a)
        D = optics.defocus_diopters(optics.image_distance_mm(l, f), d_prime)
        assert abs(optics.blur_angle_rad(c, d_prime, small_angle=True)) == pytest.approx(abs(a / 1000.0 * D), rel=1e-12)


def test_defocus_diopters_by_hand_and_power():
    assert optics.defocus_diopters(52.0, 50.0) == pytest.approx(1000 * (1 / 50 - 1 / 52))
    assert optics.lens_power_diopters(50.0) == 20.0
