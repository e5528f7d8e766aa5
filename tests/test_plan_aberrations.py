"""The ``aberrations`` effect: 0-safe cases, hard lenses, and its size (with
defocus, distortion and vignetting) against lens-system renders
(:mod:`lenscompare.plan.prediction`)."""

import math
from pathlib import Path

import pytest

from lenscompare.plan import plan_scene
from lenscompare.plan.effects import aberrations, ideal_camera
from lenscompare.metrics import find_point_sources, measure_blur_disk
from lenscompare.plan.prediction import compare_predictions, source_image_diameter_px
from lenscompare.render import render
from lenscompare.reference_scenes import scenes_dir
from lenscompare.scene import load_scene, parse_scene

from helpers import camera_scene_text, sphere_text

DATA = Path(__file__).resolve().parent / "data" / "lenses"


def lens_scene(lens, *, f_number=None, focus_m=2.0, focus_mode="paraxial", film_mm=(36.0, 24.0),
               resolution=(360, 240)):
    text = camera_scene_text(model="lens", focus_distance=focus_m, film_mm=film_mm, resolution=resolution,
                             objects=sphere_text((0.0, 0.0, focus_m), 0.01))
    text = text.replace("focal_length_mm = 50.0\n", f'lens = "{lens}"\nfocus_mode = "{focus_mode}"\n')
    text = text.replace("f_number = 2.8\n", "" if f_number is None else f"f_number = {f_number!r}\n")
    return parse_scene(text)


def size(scene):
    return aberrations(scene, ideal_camera(scene))


def test_no_prescription_means_no_aberrations():
    scene = parse_scene(camera_scene_text(objects=sphere_text((0.0, 0.0, 2.0), 0.01)))
    effect = size(scene)
    assert (effect.magnitude, effect.unit, effect.needed_by) == (0.0, "px", "lens")
    assert effect.detail == "ideal lens (no prescription)"


def test_corner_outside_the_image_circle_is_said_and_the_axis_spot_counts():
    effect = size(lens_scene("fisheye.10mm"))
    assert "no light reaches the film corner 21.6 mm off the axis: outside the image circle" in effect.detail
    assert math.isfinite(effect.magnitude) and 0.0 < effect.magnitude < 5.0


def test_stopping_down_shrinks_the_spot_and_best_focus_shrinks_the_axis_spot():
    wide_open, stopped = size(lens_scene("dgauss.50mm")), size(lens_scene("dgauss.50mm", f_number=8.0))
    assert stopped.magnitude < 0.25 * wide_open.magnitude
    # wide.22mm wide open: undercorrected, the axial spot shrinks 2.6x at best focus.
    paraxial = size(lens_scene("wide.22mm", film_mm=(3.6, 2.4)))
    best = size(lens_scene("wide.22mm", film_mm=(3.6, 2.4), focus_mode="best"))
    axis = [float(e.detail.split(" px on axis")[0].split()[-1]) for e in (paraxial, best)]
    assert axis[1] < 0.5 * axis[0] and "best focus" in best.detail


def test_a_pinpoint_stop_still_has_its_spot_sized():
    """The spot's window was found on a 48 x 48 grid over the first surface (1.2 mm cells), which a
    beam 0.2 mm wide at f/256 slips through: the planner said no ray reaches the film centre.
    Behind a stop this small the corner's spot (coma, astigmatism) shrinks as the aperture."""
    spots = {n: size(lens_scene("dgauss.50mm", f_number=n)) for n in (64.0, 256.0, 1000.0)}
    for n, effect in spots.items():
        assert "spot" in effect.detail and "no ray" not in effect.detail, (n, effect.detail)
        assert math.isfinite(effect.magnitude) and effect.magnitude > 0.0
    assert spots[256.0].magnitude == pytest.approx(spots[64.0].magnitude / 4, rel=0.15)
    assert spots[1000.0].magnitude < spots[256.0].magnitude


@pytest.mark.parametrize("lens", ["planoconvex_flat_front", "planoconvex_flat_back", "planoconvex_nearly_flat_front",
                                  "thin_singlet", "biconvex_stop_front", "cemented_zero_layer"])
@pytest.mark.parametrize("f_number", [None, 64.0])
def test_hard_lenses_give_a_finite_size(lens, f_number):
    path = DATA / f"{lens}.dat"
    scene = lens_scene(str(path), f_number=f_number, focus_m=5.0, resolution=(36, 24))
    effect = size(scene)
    assert math.isfinite(effect.magnitude) and effect.magnitude >= 0.0, effect.detail
    assert "nan" not in effect.detail.lower()


def test_plan_json_carries_aberrations():
    data = plan_scene(lens_scene("dgauss.50mm"), measure_costs=False).to_json()
    entry = data["effects"]["aberrations"]
    assert entry["unit"] == "px" and entry["simulated_from"] == "lens" and entry["needed"]


def test_predicted_sizes_match_a_lens_system_render():
    # far_landscape (240 x 160): distortion and vignetting well above
    # tolerance, defocus and aberrations under it -- each predicted size within
    # 15 % of the measured one, or both under tolerance (issue 14's done-when).
    scene = load_scene(scenes_dir() / "far_landscape.toml")
    plan = plan_scene(scene, measure_costs=False)
    rows = {r.effect: r for r in compare_predictions(scene, plan, spp=256, threads=2)}
    for row in rows.values():
        print(row.to_json())
    assert list(rows) == ["defocus", "aberrations", "distortion", "vignetting"]
    assert all(r.within for r in rows.values())
    for name, floor in (("distortion", 1.5), ("vignetting", 15.0)):
        assert rows[name].measured > floor
        assert rows[name].predicted == pytest.approx(rows[name].measured, rel=0.15)
    assert rows["aberrations"].measured < plan.tolerance_px and rows["defocus"].measured < plan.tolerance_px


def test_an_oblique_source_images_as_the_ellipse_taken_out_of_its_spot():
    # A sphere 36.9 deg off the axis through a pinhole (no blur at all): its
    # sharp image is 1/cos = 1.25 times longer radially than on the axis. The
    # measured second moment is the ellipse's, not the 8 px disk's (13 % less,
    # which the study read as a 4 px aberration spot).
    focal_mm, z_m, tan_theta, on_axis_px, pitch_mm = 22.0, 2.0, 0.75, 8.0, 0.1
    radius_m = 0.5 * on_axis_px * pitch_mm * z_m / focal_mm
    centre = (tan_theta * z_m, 0.0, z_m)
    scene = parse_scene(camera_scene_text(model="pinhole", focal_length_mm=focal_mm, resolution=(360, 240),
                                          objects=sphere_text(centre, radius_m)))
    pixels = render(scene, spp=64, threads=2, progress=False).pixels
    (source,) = find_point_sources(pixels)
    measured = measure_blur_disk(pixels, center_px=source.centroid_px, window_radius_px=15.0).second_moment_diameter_px
    expected = source_image_diameter_px(lambda deg: focal_mm * math.tan(math.radians(deg)), centre, radius_m,
                                        pixel_pitch_mm=pitch_mm)
    assert expected == pytest.approx(on_axis_px * math.sqrt((1.25 ** 2 + 1.0) / 2.0), rel=1e-3)
    assert measured == pytest.approx(expected, rel=0.01)
    assert measured > 1.1 * on_axis_px


def test_corner_spot_of_the_wide_angle_stopped_down_matches_the_trace():
    # wide.22mm at f/8, 44 deg corner field: the traced spot (0.31 px; an
    # independent Monte Carlo trace of the .dat rows gives 0.29) against the
    # probe render, whose source image there is stretched by the field and by
    # the lens's steep distortion gradient (11 %). Before that was taken out
    # the probe read 2.1 px.
    scene = load_scene(scenes_dir() / "effects" / "wide_stopped_down.toml")
    plan = plan_scene(scene, measure_costs=False)
    (row,) = compare_predictions(scene, plan, spp=512, threads=2, effects=("aberrations",))
    print(row.to_json())
    assert 0.25 < row.predicted < 0.4
    assert row.predicted == pytest.approx(row.measured, rel=0.15)
