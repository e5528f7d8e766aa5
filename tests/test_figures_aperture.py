"""The aperture teaching figure: defocus against diffraction over the
f-number, the best aperture, and the bokeh and PSFs of 5, 6, 7, 9 blades."""

import math

import numpy as np
import pytest

from lenscompare.figures import aperture_figure, aperture_geometry
from lenscompare.figures.aperture import BLADES
from lenscompare.optics import circle_of_confusion_mm, focus_film_distance_mm
from lenscompare.optics.diffraction import airy_diameter_mm


def test_curves_come_from_the_optics_and_the_best_aperture_minimises_their_sum():
    g = aperture_geometry(focal_length_mm=50.0, focus_distance_m=2.0, object_distance_m=5.0, images=False,
                          f_numbers=np.geomspace(1.4, 64.0, 4001))
    d_prime = focus_film_distance_mm(2000.0, 50.0)
    for n, defocus, diffraction in list(zip(g.f_numbers, g.defocus_um, g.diffraction_um))[::500]:
        assert defocus == pytest.approx(1000 * circle_of_confusion_mm(
            5000.0, focus_distance_mm=2000.0, focal_length_mm=50.0, aperture_diameter_mm=50.0 / n))
        assert diffraction == pytest.approx(1000 * airy_diameter_mm(550.0, n * d_prime / 50.0))
    total = g.defocus_um + g.diffraction_um
    assert g.best_f_number == pytest.approx(g.f_numbers[np.argmin(total)], rel=2e-3)
    assert g.best_sum_um == pytest.approx(total.min(), rel=1e-5)
    # Here about f/24: the two blurs are equal there (c = A / N, Airy = B N).
    assert 20 < g.best_f_number < 28
    i = np.argmin(total)
    assert g.defocus_um[i] == pytest.approx(g.diffraction_um[i], rel=0.01)
    # In focus, nothing to trade: wide open is best.
    assert aperture_geometry(object_distance_m=2.0, images=False).best_f_number == pytest.approx(1.4)


def test_figure_draws_the_curves_the_best_point_and_every_blade_count():
    g = aperture_geometry()
    fig = aperture_figure(g)
    drawn = {a.get_gid(): a for a in fig.findobj(lambda a: a.get_gid() is not None)}
    np.testing.assert_allclose(drawn["diffraction-curve"].get_ydata(), g.diffraction_um)
    np.testing.assert_allclose(drawn["sum-curve"].get_ydata(), g.defocus_um + g.diffraction_um)
    assert drawn["best-aperture"].get_xdata()[0] == pytest.approx(g.best_f_number)
    titles = [a.get_title(loc="left") for a in fig.axes]
    for blades in BLADES:
        assert f"bokeh-{blades}" in drawn and f"psf-{blades}" in drawn
        assert f"{blades} blades" in titles
    assert "PSF: 10 spikes" in titles and "PSF: 6 spikes" in titles and "PSF: 18 spikes" in titles
    # The bokeh have one area, the circle's (flux over the plateau, within 3 %).
    areas = []
    for blades in BLADES:
        bokeh = g.bokeh[blades]
        n = bokeh.shape[0]
        plateau = np.median(bokeh[n // 2 - 6:n // 2 + 6, n // 2 - 6:n // 2 + 6])
        areas.append(bokeh.sum() / plateau)
    assert max(areas) / min(areas) < 1.03
