"""lenscompare.verdict on distortion and vignetting scenes: right images pass, wrong ones fail
naming the quantity. (Blur disks and the command line: test_measure_command.py.)"""

from dataclasses import replace

import pytest

from helpers import REFERENCE_SCENES
from lenscompare.errors import InputError
from lenscompare.render import render
from lenscompare.scene import load_scene
from lenscompare.verdict import Tolerances, judge_image


def test_dot_grid_distortion():
    """Ideal cameras do not distort (native thin lens: measured 0.03 %); a 51 mm lens rendered for the
    50 mm scene reads as +2 % 'distortion'; the Double Gauss matches its chief-ray trace (0.06 %)."""
    scene = load_scene(REFERENCE_SCENES / "dot_grid.toml")
    [ok] = judge_image(scene, render(scene, spp=16, threads=2))
    assert ok.passed and ok.measurement == "distortion", ok.message
    wrong = render(replace(scene, camera=replace(scene.camera, focal_length_mm=51.0)), spp=16, threads=2)
    [bad] = judge_image(scene, wrong)
    assert not bad.passed and "radial distortion" in bad.message
    lens_scene = scene.with_camera(lens="dgauss.50mm")
    image = render(lens_scene, model="lens", spp=16, threads=2)
    assert not judge_image(lens_scene, image)[0].passed  # judged as the thin lens the scene names: it distorts
    [real] = judge_image(lens_scene, image, model="lens")
    assert real.passed and "chief-ray trace" in real.message, real.message


def test_flat_field_vignetting():
    scene = load_scene(REFERENCE_SCENES / "flat_field.toml")
    assert judge_image(scene, render(scene, spp=16, threads=2))[0].passed
    lens_scene = scene.with_camera(lens="dgauss.50mm")
    image = render(lens_scene, model="lens", spp=16, threads=2)
    [bad] = judge_image(lens_scene, image)
    assert not bad.passed and "relative illumination at 10°" in bad.message
    [good] = judge_image(lens_scene, image, model="lens", tolerances=Tolerances(vignetting_tolerance=0.02))
    assert good.passed, good.message


def test_wrong_size_names_the_image():
    scene = load_scene(REFERENCE_SCENES / "flat_field.toml")
    small = render(scene.with_camera(resolution=(90, 60)), spp=1, threads=2)
    with pytest.raises(InputError, match=r"theirs\.exr: image is 90x60.*180x120"):
        judge_image(scene, small, source="theirs.exr")
