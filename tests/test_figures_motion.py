"""The motion teaching figure: a moving point's streak with and without
defocus (native renders), and one pixel's samples in lens x time."""

import numpy as np
import pytest

from lenscompare import _native
from lenscompare._native import diagnostics
from lenscompare.figures import motion_figure, motion_geometry
from lenscompare.figures.motion import CELLS, SAMPLES, STREAK_PX, occupied_cells, pixel_samples
from lenscompare.optics import circle_of_confusion_mm


def test_streaks_are_v_t_projected_with_and_without_defocus():
    g = motion_geometry()
    # v T projected (about 84 px): within 2 % or 0.5 px, in focus and focused at 0.8 m
    assert g.expected_length_px > 80
    assert abs(g.sharp_length_px - g.expected_length_px) <= max(0.02 * g.expected_length_px, 0.5)
    assert abs(g.defocused_length_px - g.defocused_expected_px) <= max(0.02 * g.defocused_expected_px, 0.5)
    # Focused nearer, the film sits farther back: the image, and the streak, are larger (d' / d'_4m).
    assert g.defocused_expected_px > 1.04 * g.expected_length_px
    # Defocus widens the streak across its length by the blur disk (eq. 5, about 9 px here):
    # rows lit above 5 % of the peak, within 2 px
    coc_px = circle_of_confusion_mm(4000.0, focus_distance_mm=800.0, focal_length_mm=50.0,
                                    aperture_diameter_mm=25.0) / (36.0 / STREAK_PX[0])
    rows = lambda image: int((image.max(axis=1) > 0.05 * image.max()).sum())  # noqa: E731
    assert abs(rows(g.defocused) - rows(g.sharp) - coc_px) <= 2.0


def test_sobol_fills_every_film_lens_time_cell_and_padding_does_not():
    g = motion_geometry(images=False)
    assert g.occupied["sobol"] == CELLS ** 3  # one sample per 4 x 4 x 4 cell: 64 spp, 64 cells
    assert g.occupied["padded"] < CELLS ** 3 - 8
    # Over many pixels, not only the drawn one
    for pixel in range(50):
        assert occupied_cells(*pixel_samples(_native.SAMPLER_SOBOL, pixel_index=pixel)) == CELLS ** 3
    padded = [occupied_cells(*pixel_samples(diagnostics.SAMPLER_SOBOL_PADDED, pixel_index=p)) for p in range(50)]
    assert np.mean(padded) < 0.8 * CELLS ** 3
    # Each dimension alone is stratified in both: one time per 1/64 of the shutter
    for name in ("sobol", "padded"):
        time = g.samples[name][2]
        assert sorted((time * SAMPLES).astype(int)) == list(range(SAMPLES))


def test_figure_draws_both_streaks_and_every_sample():
    g = motion_geometry()
    fig = motion_figure(g)
    drawn = {a.get_gid(): a for a in fig.findobj(lambda a: a.get_gid() is not None)}
    assert "streak-sharp" in drawn and "streak-defocused" in drawn
    for name in ("sobol", "padded"):
        film, lens, time = g.samples[name]
        xs = np.concatenate([drawn[f"samples-{name}-{q}"].get_xdata() for q in range(CELLS)])
        ys = np.concatenate([drawn[f"samples-{name}-{q}"].get_ydata() for q in range(CELLS)])
        assert sorted(xs) == pytest.approx(sorted(lens[:, 0])) and sorted(ys) == pytest.approx(sorted(time))
    titles = " ".join(a.get_title(loc="left") for a in fig.axes)
    assert f"64 of {CELLS ** 3}" in titles and f"{g.occupied['padded']} of {CELLS ** 3}" in titles
