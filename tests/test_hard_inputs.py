"""Property-based hard-input suite (hypothesis): random valid prescriptions,
cameras and scenes never produce NaN, Inf, negative weights or a crash; the
scene and lens parsers, fed malformed input, only ever answer with a clean
InputError.

Examples: about 2,400 per run by default; set LENSCOMPARE_HYPOTHESIS_SCALE=10
for ten times as many.
"""

import math
import os

import numpy as np
from hypothesis import HealthCheck, assume, example, given, settings
from hypothesis import strategies as st

from lenscompare import _native
from lenscompare.cameras import camera_for
from lenscompare.errors import InputError
from lenscompare.lenses import film_distance_mm, paraxial_data, parse_prescription, trace_from_scene
from lenscompare.scene import parse_scene

from helpers import MINIMAL_SCENE

SCALE = int(os.environ.get("LENSCOMPARE_HYPOTHESIS_SCALE", "1"))
FAST = dict(deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.filter_too_much], derandomize=True)


# ---------------------------------------------------------------- prescriptions
@st.composite
def prescription_text(draw):
    """Lens files that are usually valid: 1-5 elements and a stop, random radii
    (including inf, 1e9 and nearly flat), thicknesses (including 0) and indices."""
    rows = []
    n_elements = draw(st.integers(1, 4))
    stop_at = draw(st.integers(0, n_elements))
    semi = draw(st.floats(2.0, 15.0))
    for i in range(n_elements):
        if i == stop_at:
            rows.append(f"0 {draw(st.floats(0.0, 8.0)):.4f} 0 {2 * semi * draw(st.floats(0.2, 1.0)):.4f}")
        n = draw(st.floats(1.4, 1.95))
        r1 = draw(st.one_of(st.just(math.inf), st.just(1e9), st.floats(semi * 1.05, 400.0)))
        r2 = draw(st.one_of(st.just(math.inf), st.just(-1e9), st.floats(-400.0, -semi * 1.05)))
        r1 = r1 if draw(st.booleans()) or r1 == math.inf else -r1
        thickness = draw(st.floats(0.5, 12.0))
        gap = draw(st.floats(0.0, 10.0))
        rows.append(f"{r1} {thickness:.4f} {n:.4f} {2 * semi:.4f}")
        rows.append(f"{r2} {gap:.4f} 1 {2 * semi:.4f}")
    if stop_at == n_elements:
        rows.append(f"0 0 0 {2 * semi * 0.8:.4f}")
    return "\n".join(rows).encode()


def parsed_or_none(data):
    try:
        return parse_prescription(data, source="random.dat", name="random")
    except InputError:
        return None


# A stop at the rear focal point: the entrance pupil 130 times the clear apertures (f/0.02).
TELECENTRIC_STOP = (b"inf 1.0000 1.5000 4.0000\ninf 1.0000 1 4.0000\n-7.0 1.0000 1.5000 4.0000\n"
                    b"-10.0 0.0000 1 4.0000\n2.125 2.2500 1.4062 4.0000\ninf 4.2500 1 4.0000\n0 0 0 3.2000")


@settings(max_examples=800 * SCALE, **FAST)
@given(prescription_text())
@example(data=TELECENTRIC_STOP)
def test_paraxial_values_are_finite_and_agree_with_traced_marginal_rays(data):
    p = parsed_or_none(data)
    assume(p is not None)
    try:
        d = paraxial_data(p)
    except InputError:
        return  # afocal: refused cleanly
    values = [v for v in vars(d).values() if isinstance(v, float)]
    assert all(not math.isnan(v) for v in values)
    assume(d.effective_focal_length_mm > 5 and math.isfinite(d.back_focal_length_mm))
    # A ray 1e-3 of the pupil off the axis, from infinity, crosses the axis at the paraxial focus.
    # No farther than 1e-3 of the smallest clear aperture: a stop near the rear focal point images
    # to an entrance pupil far wider than any surface (f/0.02 with 2 mm radii, found at 40x the
    # examples), and 1e-3 of that pupil is no longer paraxial.
    smallest_semi_mm = min(s.semi_aperture_mm for s in p.surfaces)
    h = 1e-3 * min(d.entrance_pupil_diameter_mm / 2, smallest_semi_mm)
    traced = trace_from_scene(p, np.array([[h, 0.0, -10.0]]), np.array([[0.0, 0.0, 1.0]]))
    assume(bool(traced.passed[0]))
    o, v = traced.origins_mm[0], traced.directions[0]
    assert np.all(np.isfinite(o)) and np.all(np.isfinite(v))
    if abs(v[0]) > 1e-12:
        crossing = o[2] - o[0] * v[2] / v[0]
        assert abs(crossing - d.rear_focal_point_mm) <= 1e-3 * abs(d.effective_focal_length_mm) + 1e-6


@settings(max_examples=150 * SCALE, **FAST)
@given(prescription_text(), st.floats(0.2, 1e9), st.integers(0, 2**31))
def test_native_lens_camera_rays_are_finite_with_non_negative_weights(data, focus_m, seed):
    p = parsed_or_none(data)
    assume(p is not None)
    try:
        d = paraxial_data(p)
        assume(d.effective_focal_length_mm > 5)
        film_distance_mm(p, focus_m)
    except InputError:
        return
    import tempfile

    with tempfile.NamedTemporaryFile("wb", suffix=".dat", delete=False) as f:
        f.write(data)
    text = MINIMAL_SCENE.replace('model = "thin"', f'model = "lens"\nlens = "{f.name}"').replace(
        "f_number = 2.8\n", "").replace("focus_distance = 2.0", f"focus_distance = {focus_m!r}")
    try:
        camera = camera_for(parse_scene(text), "lens").native()
    except InputError:
        return
    rng = np.random.default_rng(seed)
    n = 2000
    raster = (rng.random((n, 2)) * [36, 24]).astype(np.float32)
    lens = rng.random((n, 2)).astype(np.float32)
    origin, direction, weight = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)
    _native.generate_rays(camera, raster, lens, origin, direction, weight)
    assert np.all(np.isfinite(origin)) and np.all(np.isfinite(direction)) and np.all(np.isfinite(weight))
    assert np.all(weight >= 0)
    os.unlink(f.name)


# ---------------------------------------------------------------- thin/pinhole cameras
@settings(max_examples=400 * SCALE, **FAST)
@given(st.floats(1.0, 2000.0), st.floats(0.5, 128.0), st.floats(1e-3, 1e9),
       st.lists(st.floats(-5, 5), min_size=6, max_size=6), st.sampled_from(["pinhole", "thin"]))
def test_ideal_cameras_give_finite_unit_rays(focal_mm, f_number, focus_m, pose, model):
    assume(focus_m * 1000 > focal_mm * (1 + 1e-9))
    position, look = pose[:3], pose[3:]
    assume(math.dist(position, look) > 1e-3)
    text = MINIMAL_SCENE.replace("focal_length_mm = 50.0", f"focal_length_mm = {focal_mm!r}").replace(
        "f_number = 2.8", f"f_number = {f_number!r}").replace("focus_distance = 2.0", f"focus_distance = {focus_m!r}")
    text = text.replace("position = [0.0, 0.0, 0.0]", f"position = {list(position)!r}").replace(
        "look_at = [0.0, 0.0, 1.0]", f"look_at = {list(look)!r}")
    try:
        scene = parse_scene(text)
    except InputError:
        return  # e.g. up parallel to the view: refused cleanly
    camera = camera_for(scene, model).native(disk_mapping=scene.render.disk_mapping)
    rng = np.random.default_rng(0)
    raster = (rng.random((64, 2)) * [36, 24]).astype(np.float32)
    origin, direction, weight = np.zeros((64, 3)), np.zeros((64, 3)), np.zeros(64, np.float32)
    _native.generate_rays(camera, raster, rng.random((64, 2)).astype(np.float32), origin, direction, weight)
    assert np.all(np.isfinite(origin)) and np.all(np.isfinite(direction))
    np.testing.assert_allclose(np.linalg.norm(direction, axis=1), 1.0, atol=1e-9)
    assert np.all(weight == 1.0)


# ---------------------------------------------------------------- parser fuzzing
@st.composite
def mutated_scene(draw):
    """The minimal scene with random edits: deleted, duplicated or replaced
    lines, random values, random bytes."""
    lines = MINIMAL_SCENE.splitlines()
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(lines) - 1))
        action = draw(st.sampled_from(["delete", "duplicate", "value", "garbage", "key"]))
        if action == "delete":
            lines.pop(i)
        elif action == "duplicate":
            lines.insert(i, lines[i])
        elif action == "value" and "=" in lines[i]:
            key = lines[i].split("=")[0]
            value = draw(st.one_of(st.just("nan"), st.just("inf"), st.just("-1"), st.just("0"), st.just('"x"'),
                                   st.just("[]"), st.just("[1, 2]"), st.just("true"), st.just("1e400"),
                                   st.floats(allow_nan=False, allow_infinity=False).map(repr)))
            lines[i] = f"{key}= {value}"
        elif action == "key":
            lines.insert(i, f"{draw(st.text('abcdefghij_', min_size=1, max_size=8))} = 1")
        else:
            lines[i] = draw(st.text(max_size=20))
        if not lines:
            lines = [""]
    return "\n".join(lines)


@settings(max_examples=800 * SCALE, **FAST)
@given(mutated_scene())
def test_scene_parser_answers_malformed_input_with_input_error_only(text):
    try:
        scene = parse_scene(text, source="fuzz.toml")
    except InputError as error:
        assert str(error).startswith("fuzz.toml")
        return
    assert scene.camera.width_px > 0


@settings(max_examples=300 * SCALE, **FAST)
@given(st.one_of(st.binary(max_size=200), st.text(max_size=200).map(str.encode),
                 prescription_text().map(lambda b: b.replace(b" ", b" x ", 1))))
def test_lens_parser_answers_malformed_input_with_input_error_only(data):
    try:
        parse_prescription(data, source="fuzz.dat", name="fuzz")
    except InputError as error:
        assert str(error).startswith("fuzz.dat")
