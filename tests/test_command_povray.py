"""``lenscompare povray SCENE -o OUT.exr``: output contract, JSON, exit statuses."""

import json
import shutil

import numpy as np
import pytest

from lenscompare.cli import main
from lenscompare.image import read_exr

needs_povray = pytest.mark.skipif(shutil.which("povray") is None, reason="POV-Ray (povray) is not installed")

SCENE = """
[camera]
model = "thin"
position = [0.0, 0.5, -2.0]
look_at = [0.0, 0.3, 1.0]
focal_length_mm = 50.0
f_number = 2.0
focus_distance = 3.0
resolution = [48, 32]

[render]
spp = 8

[background]
color = [0.0, 0.0, 0.25]

[materials.glow]
type = "emissive"
color = [2.0, 1.0, 0.5]

[[objects]]
type = "sphere"
center = [0.0, 0.3, 1.0]
radius = 0.2
material = "glow"
"""


@pytest.fixture
def scene_file(tmp_path):
    path = tmp_path / "tiny.toml"
    path.write_text(SCENE)
    return path


@needs_povray
@pytest.mark.parametrize("model, spp, rays", [("thin", "6", 6), ("pinhole", "5", 5), ("pinhole", "6", 10)])
def test_writes_exr_and_json(scene_file, tmp_path, capsys, model, spp, rays):
    out = tmp_path / "out.exr"
    status = main(["povray", str(scene_file), "-o", str(out), "--model", model, "--spp", spp, "--threads", "1",
                   "--json"])
    assert status == 0
    report = json.loads(capsys.readouterr().out)
    assert {"model", "spp", "seconds", "samples_per_second", "output"} <= set(report)
    assert report["model"] == model
    assert report["spp"] == rays  # rays per pixel actually traced
    assert report["output"] == str(out)
    assert report["seconds"] > 0 and report["samples_per_second"] > 0
    assert report["renderer"].startswith("POV-Ray 3.7")
    image = read_exr(out)
    assert image.pixels.shape == (32, 48, 3) and image.pixels.dtype == np.float32
    assert image.metadata["command"] == report["command"]  # provenance travels with the file
    assert image.pixels.max() == pytest.approx(2.0, rel=1e-3)  # emissive radiance above 1 kept
    assert image.pixels[0, 0] == pytest.approx([0.0, 0.0, 0.25])  # background, linear


@needs_povray
def test_spp_defaults_to_the_scene(scene_file, tmp_path, capsys):
    assert main(["povray", str(scene_file), "-o", str(tmp_path / "a.exr"), "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["spp"] == 8


@pytest.mark.parametrize("model", ["thick", "lens"])
def test_thick_and_lens_exit_2(scene_file, tmp_path, capsys, model):
    status = main(["povray", str(scene_file), "-o", str(tmp_path / "a.exr"), "--model", model])
    assert status == 2
    err = capsys.readouterr().err
    assert "POV-Ray has no thick-lens / lens-system camera" in err
    assert "Traceback" not in err
    assert not (tmp_path / "a.exr").exists()


def test_missing_povray_exits_1_and_keeps_the_old_output(scene_file, tmp_path, capsys):
    out = tmp_path / "out.exr"
    out.write_bytes(b"a good old render")
    status = main(["povray", str(scene_file), "-o", str(out), "--povray", "lenscompare-no-such-povray"])
    assert status == 1
    err = capsys.readouterr().err
    assert "POV-Ray is not installed" in err and "Traceback" not in err
    assert out.read_bytes() == b"a good old render"
    assert {p.name for p in tmp_path.iterdir()} == {"tiny.toml", "out.exr"}  # no temporary left behind


@pytest.mark.parametrize("args, words", [
    (["-o", "out.png"], "expected a .exr file name"),
    (["-o", "no/such/folder/out.exr"], "does not exist"),
    (["-o", "out.exr", "--spp", "0"], "--spp: expected an integer from 1 to 1,048,576"),
    (["-o", "out.exr", "--timeout", "-1"], "--timeout: expected a finite number > 0"),
])
def test_bad_options_exit_2(scene_file, tmp_path, monkeypatch, capsys, args, words):
    monkeypatch.chdir(tmp_path)
    assert main(["povray", str(scene_file), *args]) == 2
    assert words in capsys.readouterr().err


def test_bad_scene_exits_2(tmp_path, capsys):
    bad = tmp_path / "bad.toml"
    bad.write_text(SCENE.replace("f_number = 2.0", "f_number = -2.0"))
    assert main(["povray", str(bad), "-o", str(tmp_path / "a.exr")]) == 2
    err = capsys.readouterr().err
    assert "bad.toml" in err and "camera.f_number" in err
