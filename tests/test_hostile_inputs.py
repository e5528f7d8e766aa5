"""Hostile and careless input (issue 13), one test per failure class, by
hypothesis where the class is a space of inputs.

Every bad value is exit 2 (or an InputError) naming the file and key or the
option, one line, no traceback; every value inside the limits gives a finite
answer. Examples per run: about 1,520 here (``LENSCOMPARE_HYPOTHESIS_SCALE``
multiplies them), beside the 2,450 of ``test_hard_inputs.py``.
"""

from __future__ import annotations

import math
import os
import re
import shutil
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from lenscompare import cli, commands
from lenscompare.atomic import safe_file_name, unique_file_names
from lenscompare.checks import DEFAULT_CONFIG, load_checks
from lenscompare.errors import InputError
from lenscompare.limits import (
    MAX_COLOR,
    MAX_F_NUMBER,
    MAX_FILE_BYTES,
    MAX_LENGTH_M,
    MAX_SEED,
    MAX_SPP,
    MAX_THREADS,
    MIN_CHECKER_M,
    MIN_F_NUMBER,
)
from lenscompare.povray.export import scene_to_pov
from lenscompare.render import render
from lenscompare.scene import DiffuseMaterial, EmissiveMaterial, Sphere, load_scene, parse_scene

from helpers import MINIMAL_SCENE

SCALE = int(os.environ.get("LENSCOMPARE_HYPOTHESIS_SCALE", "1"))
FAST = dict(deadline=None, derandomize=True,
            suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture,
                                   HealthCheck.filter_too_much])


def one_error_line(err: str) -> str:
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("lenscompare: error: ") and "Traceback" not in err, err
    return lines[0]


# ------------------------------------------------------- class 3: option limits
# (command, option, the values the command may receive: low, high, integer?)
NUMERIC_OPTIONS = [
    ("render", "--spp", 1, MAX_SPP, True), ("render", "--seed", 0, MAX_SEED, True),
    ("render", "--threads", 1, MAX_THREADS, True),
    ("povray", "--spp", 1, MAX_SPP, True), ("povray", "--threads", 1, MAX_THREADS, True),
    ("povray", "--timeout", 0.0, math.inf, False),
    ("preview", "--exposure", 0.0, math.inf, False),
    ("report", "--threads", 1, MAX_THREADS, True), ("cost", "--threads", 1, MAX_THREADS, True),
    ("check", "--threads", 1, MAX_THREADS, True),
    ("plan", "--tolerance-px", 0.0, math.inf, False), ("plan", "--tolerance-percent", 0.0, math.inf, False),
    ("render", "--tolerance-px", 0.0, math.inf, False), ("render", "--tolerance-percent", 0.0, math.inf, False),
    ("figures", "--focal-length-mm", 0.01, 1e6, False), ("figures", "--f-number", MIN_F_NUMBER, MAX_F_NUMBER, False),
    ("figures", "--focus-distance", 0.0, MAX_LENGTH_M, False),
    ("mitsuba", "--spp", 1, MAX_SPP, True), ("mitsuba", "--seed", 0, 2**32 - 1, True),
    ("export", "--spp", 1, MAX_SPP, True), ("export", "--seed", 0, MAX_SEED, True),
    ("measure", "--threads", 1, MAX_THREADS, True), ("measure", "--blur-tolerance-percent", 0.0, math.inf, False),
    ("measure", "--min-ssim", 0.0, 1.0, False),
    ("sweep", "--workers", 1, MAX_THREADS, True), ("sweep", "--threads", 1, MAX_THREADS, True),
]
POSITIONAL = {"render": ["s.toml", "-o", "o.exr"], "povray": ["s.toml", "-o", "o.exr"],
              "preview": ["i.exr", "-o", "o.png"], "report": ["-o", "out"], "cost": ["s.toml", "-o", "out"],
              "check": [], "plan": ["s.toml"], "figures": ["-o", "out"],
              "mitsuba": ["s.toml", "-o", "o.exr"], "export": ["s.toml", "--to", "povray", "-o", "o.pov"],
              "measure": ["i.exr", "--scene", "s.toml"], "sweep": ["w.toml", "-o", "out"]}

option_text = st.one_of(
    st.sampled_from(["0", "-1", "1", "nan", "inf", "-inf", "1e12", "1e400", "", " ", "1.5", "0.5", "0x10", "1_0",
                     "2**64", str(2**20), str(2**20 + 1), str(2**64 - 1), str(2**64), str(2**64 + 1), "9" * 400,
                     "9" * 5000, "4096", "4097", "abc", "+3", " 7 ", "1e-300", "5e-324", "1e9", "1000000001"]),
    st.integers(-2**70, 2**70).map(str),
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.text(max_size=12),
)


@settings(max_examples=500 * SCALE, **FAST)
@given(st.sampled_from(NUMERIC_OPTIONS), option_text)
def test_every_numeric_option_takes_a_value_inside_its_limit_or_exits_2_naming_it(monkeypatch, capsys, spec, text):
    command, option, low, high, integer = spec
    received = {}

    def record(args):
        received.update(vars(args))
        return 0

    module = commands.load(command)
    monkeypatch.setattr(module, "run", record)
    status = cli.main([command, *POSITIONAL[command], f"{option}={text}"])
    err = capsys.readouterr().err
    if status == 0:
        value = received[option.lstrip("-").replace("-", "_")]
        value = value[0] if isinstance(value, list) else value
        assert isinstance(value, int) if integer else isinstance(value, float)
        assert math.isfinite(value) and low <= value <= high
        assert not integer or value >= low
        assert integer or value > 0 or option.startswith("--tolerance")
    else:
        assert status == 2
        assert f"argument {option}" in one_error_line(err)


@pytest.mark.parametrize("adaptive", [False, True])
def test_the_largest_values_inside_the_limits_render(tmp_path, main, adaptive):
    """The limits themselves are accepted and give a finite image (6 pixels,
    2^20 spp: adaptive passes must not ask the tracer for more per pixel)."""
    scene = tmp_path / "one.toml"
    scene.write_text(MINIMAL_SCENE.replace("resolution = [36, 24]", "resolution = [3, 2]")
                     .replace("film_mm = [36.0, 24.0]", "film_mm = [3.0, 2.0]"))
    out = tmp_path / "one.exr"
    assert main(["render", str(scene), "-o", str(out), "--spp", str(MAX_SPP), "--seed", str(MAX_SEED),
                 "--threads", str(MAX_THREADS), *(["--adaptive"] if adaptive else [])]) == 0
    from lenscompare.image import read_exr

    image = read_exr(out)
    assert np.isfinite(image.pixels).all() and image.metadata["seed"] == MAX_SEED
    assert image.metadata["threads"] == os.cpu_count()  # more threads than cores are not started


def test_a_render_past_the_sample_or_memory_limit_is_refused_before_any_allocation(write_scene, tmp_path, main,
                                                                                   capsys, monkeypatch):
    big = write_scene(MINIMAL_SCENE.replace("resolution = [36, 24]", "resolution = [12000, 8000]"))
    out = tmp_path / "big.exr"
    assert main(["render", str(big), "-o", str(out), "--spp", str(2**15)]) == 2
    assert "render.spp" in one_error_line(capsys.readouterr().err) and not out.exists()
    # A machine with 100 MiB free: the 96 M-pixel image (about 5.7 GiB) is refused with the figures.
    from lenscompare import limits

    monkeypatch.setattr(limits, "available_memory_bytes", lambda: 100 * 2**20)
    assert main(["render", str(big), "-o", str(out), "--spp", "1"]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "camera.resolution" in line and "GiB of memory" in line and "100.0 MiB free" in line


# ----------------------------------------------- classes 2 and 5: scenes at the limits
def _scene_text(draw_values) -> str:
    v = draw_values
    return MINIMAL_SCENE.replace("focal_length_mm = 50.0", f"focal_length_mm = {v['focal']!r}\n"
                                                           f"principal_plane_gap_mm = {v['gap']!r}").replace(
        "f_number = 2.8", f"f_number = {v['f_number']!r}").replace(
        "focus_distance = 2.0", f"focus_distance = {v['focus']!r}").replace(
        "resolution = [36, 24]", "resolution = [6, 4]").replace(
        "film_mm = [36.0, 24.0]", f"film_mm = [{v['film'] * 1.5!r}, {v['film']!r}]").replace(
        'color = [1.0, 1.0, 1.0]\n\n[materials.grey]', f'color = {v["glow"]!r}\n\n[materials.grey]').replace(
        'color = [0.5, 0.5, 0.5]', f'color = {v["albedo"]!r}\nchecker = {{ color = [0.1, 0.1, 0.1], '
                                   f'size = {v["checker"]!r} }}').replace(
        "center = [0.0, 0.0, 2.0]", f"center = {v['center']!r}").replace(
        "radius = 0.1", f"radius = {v['radius']!r}").replace(
        "position = [1.0, 2.0, -1.0]", f"position = {v['light']!r}").replace(
        "[[lights]]\ntype = \"point\"\nposition", "[[lights]]\ntype = \"point\"\nposition") + (
        f"\n[background]\ncolor = {v['background']!r}\n")


colour = st.lists(st.one_of(st.just(0.0), st.just(MAX_COLOR), st.floats(0.0, MAX_COLOR)), min_size=3, max_size=3)
coordinate = st.one_of(st.just(MAX_LENGTH_M), st.just(-MAX_LENGTH_M), st.floats(-MAX_LENGTH_M, MAX_LENGTH_M))
extreme_scene = st.fixed_dictionaries({
    "focal": st.one_of(st.just(0.01), st.just(1e6), st.floats(0.01, 1e6)),
    "f_number": st.one_of(st.just(MIN_F_NUMBER), st.just(MAX_F_NUMBER), st.floats(MIN_F_NUMBER, MAX_F_NUMBER)),
    "gap": st.one_of(st.just(0.0), st.just(-1e6), st.just(1e6), st.floats(-1e6, 1e6)),
    "focus": st.one_of(st.just(1.7e308), st.just(1e200), st.floats(1e3, 1e308)),
    "film": st.one_of(st.just(0.01), st.just(6000.0), st.floats(0.01, 6000.0)),
    "glow": colour, "albedo": colour, "background": colour,
    "checker": st.one_of(st.just(MIN_CHECKER_M), st.just(MAX_LENGTH_M), st.floats(MIN_CHECKER_M, 10.0)),
    "center": st.lists(coordinate, min_size=3, max_size=3),
    "radius": st.one_of(st.just(MAX_LENGTH_M), st.just(1e-300), st.floats(1e-9, MAX_LENGTH_M)),
    "light": st.lists(coordinate, min_size=3, max_size=3),
})


@settings(max_examples=120 * SCALE, **FAST)
@given(extreme_scene, st.sampled_from(["pinhole", "thin", "thick"]))
def test_a_scene_inside_every_limit_renders_finite_or_is_refused_with_a_key(values, model):
    """Colours of 1e6, coordinates of 1e9 m, f/0.5, focus at 1.7e308 m...: a
    finite image, or an InputError naming the scene and a key. Never NaN,
    never an Embree abort."""
    text = _scene_text(values)
    try:
        scene = parse_scene(text, source="limits.toml")
        image = render(scene, model=model, spp=2, threads=1, progress=False)
    except InputError as error:
        assert str(error).startswith("limits.toml: ")
        return
    assert np.isfinite(image.pixels).all()
    assert image.pixels.min() >= 0


@pytest.mark.parametrize("renderer", ["native", "povray"])
def test_a_thin_lens_focused_at_1e200_m_renders_as_focused_at_infinity(write_scene, renderer):
    """It rendered black (native: p_focus overflowed; POV-Ray: its focal blur)."""
    from lenscompare.povray import render_povray

    if renderer == "povray" and shutil.which("povray") is None:
        pytest.skip("needs POV-Ray")
    images = []
    for focus in ("1e200", "1e9"):
        scene = load_scene(write_scene(MINIMAL_SCENE.replace("focus_distance = 2.0", f"focus_distance = {focus}")))
        images.append(render(scene, spp=4, seed=3, progress=False).pixels if renderer == "native"
                      else render_povray(scene, spp=4).pixels)
    assert images[1].max() > 0.5  # the glowing sphere is there...
    np.testing.assert_allclose(images[0], images[1], atol=1e-6)  # ...and at 1e200 m too


@pytest.mark.parametrize("key, value, words", [
    ("f_number = 2.8", "f_number = 1e-20", "camera.f_number: expected a number >= 0.5"),
    ("f_number = 2.8", "f_number = 1e9", "camera.f_number: expected a number <= 10000"),
    ("color = [1.0, 1.0, 1.0]\n\n[materials.grey]", "color = [1e39, 1.0, 1.0]\n\n[materials.grey]",
     "materials.glow.color: expected a number <= 1e+06"),
    ("color = [1.0, 1.0, 1.0]\n\n[materials.grey]", "color = [1.7e308, 1.0, 1.0]\n\n[materials.grey]",
     "materials.glow.color"),
    ("center = [0.0, 0.0, 2.0]", "center = [0.0, 0.0, 1e200]", "objects[0].center: expected a number between"),
    ("resolution = [36, 24]", "resolution = [30000, 20000]", "camera.resolution: 30000x20000"),
    ("resolution = [36, 24]", "resolution = [9223372036854775807, 1]", "camera.resolution: expected an integer <="),
    ("spp = 4", "spp = 100000000000000000000", "render.spp: expected an integer <="),
    ("spp = 4", f"spp = 4\nseed = {2**64}", "render.seed: expected an integer <="),
    ("spp = 4", "spp = 4\nseed = " + "1" * 400, "render.seed"),
    ("radius = 0.1", "radius = " + "1" * 400, "radius: expected a finite number, got an integer of about 400 digits"),
    ("focal_length_mm = 50.0", "focal_length_mm = 1e-300", "camera.focal_length_mm: expected a number >= 0.01"),
])
def test_values_past_a_limit_are_refused_naming_the_key(minimal_scene_text, key, value, words):
    with pytest.raises(InputError, match=re.escape(words)):
        parse_scene(minimal_scene_text.replace(key, value, 1), source="s.toml")


@pytest.mark.parametrize("lens, words", [
    ("-50 3 1.5 20\n50 5 1 20\n0 5 0 10\n", "negative focal length (-49.5 mm)"),      # diverging
    ("1e9 5 1.5 20\n-1e9 5 1 20\n0 5 0 10\n", "outside the limits"),                   # nearly no power
    ("1e300 5 1.5 20\n-1e300 5 1 20\n0 5 0 10\n", "outside the limits"),
])
@pytest.mark.parametrize("model", ["pinhole", "thin", "thick", "lens", "auto"])
def test_a_lens_that_forms_no_usable_image_is_refused_at_the_edge(tmp_path, main, capsys, minimal_scene_text, lens,
                                                                words, model):
    (tmp_path / "bad.dat").write_text(lens)
    scene = tmp_path / "s.toml"
    scene.write_text(minimal_scene_text.replace('model = "thin"', f'model = "thin"\nlens = "bad.dat"'))
    assert main(["render", str(scene), "-o", str(tmp_path / "o.exr"), "--model", model]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert "s.toml: camera.lens: lens bad" in line and words in line
    # the same lens given as --lens: the message names the option
    (tmp_path / "plain.toml").write_text(minimal_scene_text)
    assert main(["render", str(tmp_path / "plain.toml"), "-o", str(tmp_path / "o.exr"), "--lens",
                 str(tmp_path / "bad.dat"), "--model", model]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert line.startswith("lenscompare: error: --lens: lens bad") and words in line


def test_an_inverse_square_light_touching_a_surface_gives_a_finite_image(write_scene):
    """1 / d^2 as d -> 0 is capped at (0.1 mm)^-2, natively and in POV-Ray's
    export; POV-Ray's half floats get a scale from the nearest surface."""
    from lenscompare.povray import render_povray
    from lenscompare.povray.export import radiance_bound

    text = MINIMAL_SCENE.replace("position = [1.0, 2.0, -1.0]", "position = [0.0, 0.0, 2.999999]").replace(
        'type = "point"', 'type = "point"\nfalloff = "inverse_square"').replace("radius = 0.1", "radius = 0.001")
    scene = load_scene(write_scene(text))  # the light 1 micrometre in front of the box's face at z = 3
    assert radiance_bound(scene) == pytest.approx(max(1.0, 0.5 / 1e-4 ** 2))
    native = render(scene, spp=4, progress=False).pixels
    assert np.isfinite(native).all() and native.max() > 0.0  # lit (at grazing incidence), and finite
    if shutil.which("povray"):
        pov = render_povray(scene, spp=4)
        assert np.isfinite(pov.pixels).all() and pov.metadata["radiance_scale"] == 2.0 ** -11  # 5e7 / 2^11 < 32768


@pytest.mark.parametrize("axis, value, words", [
    ("f_number", "[1e-20]", "axes.f_number[0]: expected a number >= 0.5"),
    ("f_number", "[2.8, 1e9]", "axes.f_number[1]: expected a number <= 10000"),
    ("spp", "[1048577]", "axes.spp[0]: expected an integer <= 1,048,576"),
    ("seed", f"[{2**64}]", "axes.seed[0]: expected an integer <="),
])
def test_sweep_axes_are_bounded_like_the_scene_keys(tmp_path, axis, value, words):
    from lenscompare.sweep import load_sweep

    sweep = tmp_path / "w.toml"
    sweep.write_text(f'scenes = ["showcase"]\n[axes]\n{axis} = {value}\n')
    with pytest.raises(InputError, match=re.escape(words)):
        load_sweep(sweep)
    with pytest.raises(InputError, match="is not a regular file"):
        load_sweep("/dev/zero")


def test_mitsuba_seed_past_32_bits_is_refused_as_bad_input(write_scene):
    from lenscompare.mitsuba import scene_to_mitsuba

    scene = load_scene(write_scene(MINIMAL_SCENE.replace("spp = 4", f"spp = 4\nseed = {2**32}").replace(
        'type = "point"', 'type = "point"\nfalloff = "inverse_square"')))
    with pytest.raises(InputError, match=r"render.seed: Mitsuba's seed is at most 4,294,967,295"):
        scene_to_mitsuba(scene)


# ------------------------------------------------------------ class 6: parser edges
@pytest.mark.parametrize("make, words", [
    (lambda d: "/dev/zero", "is not a regular file"),
    (lambda d: "/dev/urandom", "is not a regular file"),
    (lambda d: str(d), "is a folder"),
    (lambda d: _write(d / "big.toml", b"#" * (MAX_FILE_BYTES + 1)), "larger than 16.0 MiB"),
    (lambda d: _write(d / "bin.toml", bytes(range(256))), "not a text file"),
    (lambda d: _write(d / "deep.toml", ("x = " + "[" * 5000 + "]" * 5000).encode()), "nested"),
    (lambda d: _write(d / "deep2.toml", ("x = " + "{a = " * 40 + "1" + "}" * 40).encode()), "nested more than 32 levels deep"),
    (lambda d: _write(d / "digits.toml", ("x = " + "9" * 5000).encode()), "not valid TOML"),
])
@pytest.mark.parametrize("reader", ["scene", "config"])
def test_unreadable_or_endless_input_files_are_refused_before_reading_them_whole(tmp_path, make, words, reader):
    path = make(tmp_path)
    with pytest.raises(InputError, match=words) as error:
        load_scene(path) if reader == "scene" else load_checks(path)
    assert str(error.value).startswith(str(path))


def _write(path: Path, data: bytes) -> str:
    path.write_bytes(data)
    return str(path)


@pytest.mark.parametrize("source", ["/dev/zero", "/dev/urandom"])
def test_a_device_as_a_lens_file_is_refused(source):
    from lenscompare.lenses import load_prescription

    with pytest.raises(InputError, match="is not a regular file"):
        load_prescription(source)


# ------------------------------------------------------------ class 7: check configs
config_lines = (DEFAULT_CONFIG.read_text().splitlines())
bad_values = st.one_of(st.sampled_from(["5", "42", '"fisheye"', "0.5", "0", "-1", "nan", "inf", "1e400", "[]", "{}",
                                        '"magic"', "true", '"/dev/zero"', '"../../../etc"', '"showcase.toml"',
                                        f"{2**64}", '"lens"', '"pinhole"', "2.0", '"nosuch.dat"']),
                       st.floats(allow_nan=False, allow_infinity=False).map(repr),
                       st.text(max_size=8).map(lambda t: '"' + t.replace("\\", "").replace('"', "") + '"'))


@st.composite
def mutated_config(draw):
    lines = list(config_lines)
    for _ in range(draw(st.integers(1, 3))):
        action = draw(st.sampled_from(["value", "value", "value", "value", "delete", "key", "type"]))
        keyed = [i for i, line in enumerate(lines) if "=" in line and not line.startswith("#")
                 and (action != "type" or line.startswith("type"))]
        i = draw(st.sampled_from(keyed))
        key = lines[i].split("=")[0].strip()
        if action == "value":
            lines[i] = f"{key} = {draw(bad_values)}"
        elif action == "delete":
            lines.pop(i)
        elif action == "type":
            kind = draw(st.sampled_from(["blur_equation5", "povray_ssim", "lens_paraxial", "image_matches", "x"]))
            lines[i] = f'type = "{kind}"'
        else:
            lines.insert(i, f"{draw(st.sampled_from(['tolerance', 'spp', 'image', 'lens', 'scene', 'zz']))} = 1")
    return "\n".join(lines) + "\n"


@settings(max_examples=250 * SCALE, **FAST)
@given(mutated_config())
def test_a_broken_check_config_is_an_input_error_naming_the_file_the_check_and_the_key(tmp_path_factory, text):
    folder = tmp_path_factory.mktemp("config")
    config = folder / "checks.toml"
    config.write_text(text)
    try:
        checks = load_checks(config)
    except InputError as error:
        message = str(error)
        assert message.startswith(str(config) + ": ")
        assert re.match(re.escape(str(config)) + r": (check\[\d+\]\.\w+: |\w+: unknown key|not valid TOML|"
                        r"no \[\[check\]\])", message), message
        return
    for check in checks:  # loaded: every option has its type
        for key in ("spp", "povray_spp"):
            if key in check.options:
                assert isinstance(check.options[key], int) and 1 <= check.options[key] <= MAX_SPP


def test_check_config_errors_from_the_issue_are_exit_2(tmp_path, main, capsys):
    cases = {
        'type = "lens_paraxial"\nlens = 5\nquantity = "f_number"\nexpected = 2': "check[0].lens: expected a string",
        'type = "blur_equation5"\nscene = 42': "check[0].scene: expected a string",
        'type = "lens_paraxial"\nlens = "dgauss.50mm"\nquantity = "magic"\nexpected = 2': "check[0].quantity",
        'type = "blur_equation5"\nscene = "showcase"\nspp = 0.5': "check[0].spp: expected an integer, got 0.5",
        'type = "blur_equation5"\nscene = "showcase"\nmodel = "fisheye"': "check[0].model: expected one of",
        'type = "povray_ssim"\nscene = "showcase"\nmodel = "lens"': "check[0].model: expected one of 'pinhole', 'thin'",
        'type = "blur_equation5"\nscene = "nosuch"': "check[0].scene:",
    }
    for body, words in cases.items():
        config = tmp_path / "c.toml"
        config.write_text(f"[[check]]\n{body}\n")
        assert main(["check", str(config)]) == 2, body
        assert words in one_error_line(capsys.readouterr().err)
    (tmp_path / "bin.toml").write_bytes(bytes(range(256)) * 4)
    assert main(["check", str(tmp_path / "bin.toml")]) == 2
    assert "not a text file" in one_error_line(capsys.readouterr().err)


# ------------------------------------------------------- class 1: names become file names
hostile_name = st.one_of(
    st.sampled_from(["../../../somewhere", "/etc/passwd", "..", ".", "", "a/b\\c", "\x00", "con", "-rf", ".hidden",
                     "a" * 300, "名前", "$\\frac{1}{0}$", "x\ny", " ", "./../x", "~/x", "%2e%2e%2f"]),
    st.text(max_size=60),
)


@settings(max_examples=400 * SCALE, **FAST)
@given(st.lists(hostile_name, min_size=1, max_size=4, unique=True))
def test_any_scene_name_becomes_a_file_name_inside_the_output_folder(tmp_path_factory, names):
    out = tmp_path_factory.mktemp("out")
    stems = unique_file_names(names)
    assert len({s.lower() for s in stems.values()}) == len(names)  # no two scenes share a file
    for name, stem in stems.items():
        assert stem == safe_file_name(name) or re.fullmatch(re.escape(safe_file_name(name)) + r"-\d+", stem)
        assert re.fullmatch(r"[A-Za-z0-9_][A-Za-z0-9._-]*", stem) and len(stem) <= 110
        for suffix in (".thin.exr", ".blur.png", ".cost.png"):
            path = out / "renders" / f"{stem}{suffix}"
            assert path.resolve().parent == (out / "renders").resolve()


def test_hostile_scene_names_write_only_inside_the_report_folder(tmp_path, main, capsys, minimal_scene_text,
                                                                 monkeypatch):
    """The issue's own case: ``name = "../../../somewhere"`` and an absolute
    name, through a whole report (36 x 24, 18 x 12 with --quick: the smallest
    scenes must not crash SSIM either). The teaching figures (no scene name
    in them; tested in test_figures.py) are left out for time."""
    from lenscompare import report

    monkeypatch.setattr(report, "_teaching_figures", lambda out, settings, notes: {})
    work = tmp_path / "a" / "b" / "c"
    work.mkdir(parents=True)
    scenes = []
    for i, name in enumerate(["../../../somewhere", str(tmp_path / "abs")]):
        text = minimal_scene_text.replace('name = "minimal"', f'name = "{name}"\nmeasure = ["similarity", '
                                          '"blur_disks", "distortion", "vignetting"]')
        scenes.append(work / f"s{i}.toml")
        scenes[-1].write_text(text)
    before = {p for p in tmp_path.rglob("*")}
    out = work / "out"
    assert main(["report", *map(str, scenes), "-o", str(out), "--quick", "--no-povray"]) == 0, \
        capsys.readouterr().err
    created = {p for p in tmp_path.rglob("*")} - before
    outside = [p for p in created if out not in p.parents and p != out]
    assert outside == []
    assert (out / "renders" / "_.._.._somewhere.thin.exr").is_file()
    assert (out / "index.html").is_file() and not (tmp_path / "abs.thin.exr").exists()


# -------------------------------------------------- class 11: escaping into POV-Ray SDL
sdl_text = st.text(st.characters(codec="utf-8"), max_size=40) | st.sampled_from([
    '"\n#fopen F "/tmp/x" write\n', "}\n#system(\"rm -rf /\")\n//", "*/ #include \"/etc/passwd\" /*",
    "\r#declare x=1;", "\u2028#write", "\x0b\x0c\x85", "\\", "\x00"])
sdl_number = st.floats(-MAX_LENGTH_M, MAX_LENGTH_M) | st.sampled_from([0.0, -0.0, 1e-300, 5e-324, MAX_LENGTH_M])


def _sdl_scene(name: str, source: str, material_names, numbers, glow):
    base = parse_scene(MINIMAL_SCENE)
    mats = {m: (EmissiveMaterial(m, tuple(glow)) if i == 0 else DiffuseMaterial(m, (0.5, 0.5, 0.5)))
            for i, m in enumerate(material_names)}
    objects = (Sphere(tuple(numbers[:3]), abs(numbers[3]) or 1.0, material_names[0]),)
    return replace(base, name=name, source=source, materials=mats, objects=objects,
                   background=tuple(abs(n) % MAX_COLOR for n in numbers[4:7]))


@settings(max_examples=250 * SCALE, **FAST)
@given(name=sdl_text, source=sdl_text, materials=st.lists(sdl_text, min_size=1, max_size=3, unique=True),
       numbers=st.lists(sdl_number, min_size=7, max_size=7),
       glow=st.lists(st.floats(0, MAX_COLOR), min_size=3, max_size=3))
def test_no_string_or_number_from_a_scene_escapes_into_povray_directives(name, source, materials, numbers, glow):
    """Every string field (name, source, material keys) and every number
    that reaches the SDL: outside ``//`` comments the text holds only our own
    tokens (no string literal, no directive but #version/#declare, balanced
    braces), and hostile strings add no line: the same scene with plain
    strings gives the same lines outside the comments."""
    text = scene_to_pov(_sdl_scene(name, source, materials, numbers, glow), model="thin")
    text.encode("utf-8")  # writable as the runner writes it
    code = [line.split("//", 1)[0] for line in text.split("\n")]
    joined = "\n".join(code)
    assert '"' not in joined and "/*" not in joined and "*/" not in joined and "\r" not in text
    assert set(re.findall(r"#\w+", joined)) <= {"#version", "#declare"}
    assert joined.count("{") == joined.count("}")
    plain = scene_to_pov(_sdl_scene("n", "s", [f"m{i}" for i in range(len(materials))], numbers, glow), model="thin")
    assert code == [line.split("//", 1)[0] for line in plain.split("\n")]


@pytest.mark.skipif(shutil.which("povray") is None, reason="needs POV-Ray")
def test_povray_renders_a_scene_with_hostile_strings_and_writes_nothing_else(tmp_path, main, capsys,
                                                                           minimal_scene_text):
    text = minimal_scene_text.replace('name = "minimal"', 'name = "\\"\\n#fopen F \\"' + str(tmp_path / "pwned")
                                      + '\\" write #write (F, \\"x\\") #fclose F //"').replace(
        "[materials.glow]", '[materials."glow\\n#system(\\"touch pwned2\\")"]').replace(
        'material = "glow"', 'material = "glow\\n#system(\\"touch pwned2\\")"')
    scene = tmp_path / "evil.toml"
    scene.write_text(text)
    out = tmp_path / "out.exr"
    assert main(["povray", str(scene), "-o", str(out), "--spp", "4"]) == 0, capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["evil.toml", "out.exr"]


@pytest.mark.parametrize("fifth, words", [
    ("N-BK7", "line 2: n_d 1.600000 disagrees with N-BK7 (Schott)'s catalogue n_d 1.516800"),
    ("N-BK77", "line 2: unknown glass 'N-BK77'"),
    ("7-up", "line 2: 5th column '7-up' is neither an Abbe number nor a glass name"),
    ("-inf", "line 2: abbe_v_d must be finite and >= 0"),
    ("x" * 41, "line 2: 5th column"),
])
def test_a_bad_glass_column_is_exit_2_naming_the_line(tmp_path, main, capsys, minimal_scene_text, fifth, words):
    """Issue 15: the 5th lens-file column, through lens info and a render's --lens."""
    lens = tmp_path / "g.dat"
    lens.write_text(f"# glass\n50 5 1.6 20 {fifth}\n-50 0 1 20\n0 5 0 10\n")
    assert main(["lens", "info", str(lens)]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert f"{lens}: {words}" in line, line
    (tmp_path / "s.toml").write_text(minimal_scene_text)
    assert main(["render", str(tmp_path / "s.toml"), "-o", str(tmp_path / "o.exr"), "--lens", str(lens),
                 "--model", "lens"]) == 2
    assert words in one_error_line(capsys.readouterr().err)
    assert not (tmp_path / "o.exr").exists()


# A stop behind every element that the elements magnify: its image, the entrance pupil, is 65.9
# mm across behind a 29.3 mm front element, so the lens's own f-number is f/0.388 (found by
# rendering random prescriptions, session 55).
MAGNIFIED_STOP = """inf 3.4942 1.5626 29.2692
-367.14416265419106 2.3611 1 29.2692
-378.7289480928532 4.2784 1.8091 29.2692
inf 2.3917 1 29.2692
257.9532606952384 10.1567 1.8992 29.2692
-22.42024360684536 6.9762 1 29.2692
-183.533554493709 5.0030 1.8716 29.2692
-1000000000.0 5.8533 1 29.2692
0 0 0 23.4153
"""


def test_a_lens_whose_own_stop_is_faster_than_f_0_5_is_exit_2_naming_the_lens(tmp_path, main, capsys,
                                                                                minimal_scene_text):
    """The f-number came from the lens, not from the scene: the error names the lens file, why,
    and the key that renders it; the pinhole, which takes no f-number, renders the scene, and
    with camera.f_number set the lens system does."""
    lens = tmp_path / "magnified_stop.dat"
    lens.write_text(MAGNIFIED_STOP)
    scene = tmp_path / "s.toml"
    scene.write_text(minimal_scene_text.replace("f_number = 2.8\n", ""))
    out = tmp_path / "o.exr"
    assert main(["render", str(scene), "-o", str(out), "--lens", str(lens), "--model", "lens"]) == 2
    line = one_error_line(capsys.readouterr().err)
    assert f"camera.lens: lens magnified_stop ({lens}): its stop images to an entrance pupil 65.92 mm across, " \
           "wider than its front element (29.27 mm): f/0.388" in line, line
    assert "set camera.f_number to stop it down" in line
    assert not out.exists()
    # The pinhole takes no f-number: the same scene renders through it.
    assert main(["render", str(scene), "-o", str(out), "--lens", str(lens), "--model", "pinhole", "--spp", "4"]) == 0
    out.unlink()
    scene.write_text(minimal_scene_text.replace("f_number = 2.8\n", "f_number = 4.0\n"))
    assert main(["render", str(scene), "-o", str(out), "--lens", str(lens), "--model", "lens", "--spp", "4"]) == 0
    assert out.exists()
