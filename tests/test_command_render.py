"""``lenscompare render``: the command-line contract of DESIGN.md."""

import json
import subprocess
import sys

import numpy as np
import pytest

from lenscompare.commands import COMMAND_HELP
from lenscompare.image import read_exr

from helpers import run_cli
from test_scene import BAD_SCENES


def test_render_writes_exr_and_json(write_scene, minimal_scene_text, tmp_path):
    scene = write_scene(minimal_scene_text)
    out = tmp_path / "out.exr"
    result = run_cli("render", scene, "-o", out, "--json", "--spp", "2", "--threads", "1")
    assert result.returncode == 0, result.stderr
    report = json.loads(result.stdout)
    for key in ("model", "spp", "seconds", "samples_per_second", "output"):
        assert key in report
    assert report["model"] == "thin" and report["spp"] == 2 and report["output"] == str(out)
    image = read_exr(out)
    assert image.pixels.shape == (24, 36, 3) and image.pixels.dtype == np.float32
    assert image.metadata["model"] == "thin"
    assert result.stderr == ""  # no progress bar when not on a terminal
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no temporary left


def test_model_flag_overrides_scene(write_scene, minimal_scene_text, tmp_path):
    result = run_cli("render", write_scene(minimal_scene_text), "-o", tmp_path / "p.exr", "--model", "pinhole",
                     "--json", "--spp", "1")
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["model"] == "pinhole"


def _assert_clean_input_error(result, *needles):
    assert result.returncode == 2, (result.returncode, result.stderr)
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]


@pytest.mark.parametrize("case", sorted(BAD_SCENES), ids=str)
def test_bad_scene_exit_2_no_output(case, write_scene, minimal_scene_text, tmp_path):
    this, that, key = BAD_SCENES[case]
    scene = write_scene(minimal_scene_text.replace(this, that, 1), name="broken.toml")
    out = tmp_path / "out.exr"
    _assert_clean_input_error(run_cli("render", scene, "-o", out), "broken.toml", key)
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["broken.toml"]


def test_failed_run_keeps_existing_output(write_scene, minimal_scene_text, tmp_path):
    out = tmp_path / "keep.exr"
    out.write_bytes(b"a good earlier render")
    scene = write_scene(minimal_scene_text.replace("radius = 0.1", "radius = -0.1"), name="broken.toml")
    _assert_clean_input_error(run_cli("render", scene, "-o", out), "broken.toml", "objects[0].radius")
    assert out.read_bytes() == b"a good earlier render"


@pytest.mark.parametrize("args, needle", [
    (["--spp", "0"], "--spp"),
    (["--spp", "many"], "--spp"),
    (["--seed", "-3"], "--seed"),
    (["--threads", "0"], "--threads"),
    (["--model", "fisheye"], "--model"),
    (["--sampler", "best"], "--sampler"),
])
def test_bad_options_exit_2(args, needle, write_scene, minimal_scene_text, tmp_path):
    out = tmp_path / "out.exr"
    _assert_clean_input_error(run_cli("render", write_scene(minimal_scene_text), "-o", out, *args), needle)
    assert not out.exists()


def test_missing_scene_and_bad_output_folder(write_scene, minimal_scene_text, tmp_path):
    _assert_clean_input_error(run_cli("render", tmp_path / "nope.toml", "-o", tmp_path / "o.exr"), "nope.toml")
    _assert_clean_input_error(run_cli("render", write_scene(minimal_scene_text), "-o", tmp_path / "no" / "o.exr"),
                              "-o", "does not exist")
    _assert_clean_input_error(run_cli("render", write_scene(minimal_scene_text), "-o", tmp_path / "o.png"), "-o")


def test_model_specific_missing_key(write_scene, minimal_scene_text, tmp_path):
    scene = write_scene(minimal_scene_text.replace("f_number = 2.8\n", ""), name="nofstop.toml")
    _assert_clean_input_error(run_cli("render", scene, "-o", tmp_path / "o.exr"), "nofstop.toml", "camera.f_number")
    # The pinhole does not need an f-number.
    assert run_cli("render", scene, "-o", tmp_path / "o.exr", "--model", "pinhole", "--spp", "1").returncode == 0


def test_adaptive_flag_and_scene_key(write_scene, minimal_scene_text, tmp_path):
    """``--adaptive`` (or ``[render] adaptive = true``) renders adaptively and
    says so in the JSON; a non-boolean value is refused with exit 2."""
    result = run_cli("render", write_scene(minimal_scene_text), "-o", tmp_path / "a.exr", "--json", "--spp", "16",
                     "--adaptive")
    assert result.returncode == 0, result.stderr
    info = json.loads(result.stdout)["adaptive"]
    assert info["base_spp"] == 4 and info["mean_spp"] <= 16
    in_file = minimal_scene_text.replace("[render]", "[render]\nadaptive = true") if "[render]" in \
        minimal_scene_text else minimal_scene_text + "\n[render]\nadaptive = true\n"
    result = run_cli("render", write_scene(in_file), "-o", tmp_path / "b.exr", "--json", "--spp", "16")
    assert result.returncode == 0, result.stderr
    assert "adaptive" in json.loads(result.stdout)
    bad = in_file.replace("adaptive = true", 'adaptive = "yes"')
    result = run_cli("render", write_scene(bad), "-o", tmp_path / "c.exr")
    assert result.returncode == 2
    assert "render.adaptive" in result.stderr and "true or false" in result.stderr
    assert not (tmp_path / "c.exr").exists()


def test_every_scene_command_takes_a_shipped_scene_by_its_short_name(tmp_path):
    # In a folder without such a file, "flat_field" is the shipped scene.
    out = tmp_path / "flat.exr"
    rendered = run_cli("render", "flat_field", "-o", out, "--spp", "1", "--threads", "1", "--json", cwd=tmp_path)
    assert rendered.returncode == 0, rendered.stderr
    assert read_exr(out).metadata["scene"] == "flat_field"
    planned = run_cli("plan", "flat_field", "--no-costs", "--json", cwd=tmp_path)
    assert planned.returncode == 0, planned.stderr
    assert json.loads(planned.stdout)["model"] in ("pinhole", "thin", "thick", "lens", "composite", "postfilter")
    exported = run_cli("export", "flat_field", "--to", "povray", "-o", tmp_path / "flat.pov", cwd=tmp_path)
    assert exported.returncode == 0, exported.stderr
    measured = run_cli("measure", out, "--scene", "flat_field", "--json", cwd=tmp_path)
    assert measured.returncode in (0, 1), measured.stderr  # judged (pass or fail), not refused


@pytest.mark.parametrize("command", ["render", "povray", "mitsuba", "plan", "cost"])
def test_a_bare_name_that_is_no_file_nor_shipped_scene_lists_the_shipped_ones(command, tmp_path):
    args = [command, "no_such_scene", "-o", tmp_path / ("out" if command == "cost" else "out.exr")]
    result = run_cli(*(args[:2] if command == "plan" else args), cwd=tmp_path)
    _assert_clean_input_error(result, "no_such_scene", "no such scene file", "showcase")


def test_help_and_a_light_command_do_not_import_the_others():
    # Only the command being run has its module imported (lenscompare.cli).
    code = ("import sys; from lenscompare import cli; status = cli.main(['lens', 'info', 'dgauss.50mm']); "
            "heavy = [m for m in ('matplotlib', 'pandas', 'dask', 'mitsuba', 'lenscompare.commands.report') "
            "if m in sys.modules]; print(status, heavy)")
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip().splitlines()[-1] == "0 []"
    listed = run_cli("--help")
    assert listed.returncode == 0 and all(name in listed.stdout for name in COMMAND_HELP)
    assert COMMAND_HELP["render"] in listed.stdout  # a stub's line of help, as its module's parser has it
