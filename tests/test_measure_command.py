"""``lenscompare measure IMAGE.exr --scene SCENE.toml``: another renderer's image judged.

The outside renderer is Mitsuba 3 (``scalar_rgb``). Its image of the shipped
``blur_disks`` scene passes; images made deliberately wrong (aperture doubled,
focus moved from 1 m to 1.2 m) fail, naming the quantity; these use the
cheaper ``test_povray_agreement.blur_disk_scene`` (360 x 240, six disks of
9-19 px) written to a file with ``measure = ["blur_disks"]``.
"""

import json
from dataclasses import replace

import pytest

from helpers import REFERENCE_SCENES, run_cli
from lenscompare.image import write_exr
from lenscompare.mitsuba import render_mitsuba
from lenscompare.verdict import judge_image
from test_povray_agreement import blur_disk_scene

pytest.importorskip("mitsuba")


def scene_file(scene, path):
    """The scene as a TOML file (camera, one emissive material, its spheres)."""
    c = scene.camera
    lines = ['measure = ["blur_disks"]', "[camera]", f'model = "{c.model}"', f"position = {list(c.position)}",
             f"look_at = {list(c.look_at)}", f"focal_length_mm = {c.focal_length_mm!r}", f"f_number = {c.f_number!r}",
             f"focus_distance = {c.focus_distance_m!r}", f"resolution = {list(c.resolution)}",
             "[materials.glow]", 'type = "emissive"', "color = [1.0, 1.0, 1.0]"]
    for s in scene.objects:
        lines += ["[[objects]]", 'type = "sphere"', f"center = {list(s.center)}", f"radius = {s.radius!r}",
                  'material = "glow"']
    path.write_text("\n".join(lines) + "\n")
    return path


@pytest.fixture(scope="module")
def blur_scene():
    scene, _ = blur_disk_scene()
    return replace(scene, measure=("blur_disks",))


def test_a_mitsuba_image_of_blur_disks_passes(tmp_path):
    """The user's flow on the shipped scene: ``lenscompare mitsuba blur_disks.toml --spp 256`` (720 x 480),
    then ``lenscompare measure`` and a check config with ``image = ...``. Measured: five disks within
    0.51 % of eq. 5, centroids within 0.18 px of the projection, SSIM 0.9995 against native."""
    scene = REFERENCE_SCENES / "blur_disks.toml"
    image = tmp_path / "mitsuba.exr"
    assert run_cli("mitsuba", scene, "-o", image, "--spp", "256").returncode == 0
    result = run_cli("measure", image, "--scene", scene, "--json")
    assert result.returncode == 0, result.stdout + result.stderr
    verdict = json.loads(result.stdout)
    assert verdict["passed"] and set(verdict["measurements"]) == {"blur_disks", "similarity"}
    config = tmp_path / "checks.toml"
    config.write_text('[[check]]\ntype = "blur_equation5"\nscene = "blur_disks"\nimage = "mitsuba.exr"\n')
    result = run_cli("check", config)
    assert result.returncode == 0 and "1 passed, 0 failed" in result.stdout, result.stdout + result.stderr


@pytest.mark.parametrize("wrong, names", [
    ({"f_number": 0.7}, ["blur-disk diameter"]),                          # aperture doubled
    ({"focus_distance_m": 1.2}, ["blur-disk diameter", "projection"]),    # focus moved: blur and scale change
])
def test_a_deliberately_wrong_image_fails_naming_the_quantity(tmp_path, blur_scene, wrong, names):
    bad = render_mitsuba(replace(blur_scene, camera=replace(blur_scene.camera, **wrong)), spp=128)
    verdicts = judge_image(blur_scene, bad)
    assert [v.measurement for v in verdicts] == ["blur_disks"] and not verdicts[0].passed
    for name in names:
        assert name in verdicts[0].message, verdicts[0].message
    write_exr(tmp_path / "bad.exr", bad)
    result = run_cli("measure", tmp_path / "bad.exr", "--scene", scene_file(blur_scene, tmp_path / "blur.toml"))
    assert result.returncode == 1 and "FAIL  blur_disks: blur-disk diameter" in result.stdout, result.stdout
    (tmp_path / "checks.toml").write_text('[[check]]\ntype = "measure"\nscene = "blur.toml"\nimage = "bad.exr"\n')
    result = run_cli("check", tmp_path / "checks.toml")
    assert result.returncode == 1 and "blur-disk diameter" in result.stdout, result.stdout


def test_bad_input_is_exit_2(tmp_path, blur_scene):
    path = scene_file(blur_scene, tmp_path / "blur.toml")
    small = replace(blur_scene, camera=replace(blur_scene.camera, resolution=(36, 24)))
    write_exr(tmp_path / "small.exr", render_mitsuba(small, spp=1))
    result = run_cli("measure", tmp_path / "small.exr", "--scene", path)
    assert result.returncode == 2 and "small.exr" in result.stderr and "360x240" in result.stderr
    result = run_cli("measure", tmp_path / "missing.exr", "--scene", path)
    assert result.returncode == 2 and "missing.exr" in result.stderr and "Traceback" not in result.stderr
