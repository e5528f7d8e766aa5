"""POV-Ray export (scene -> .pov text) and runner errors.

The text is checked number by number against the camera it must describe (the
native camera frame, film distance, aperture); whether POV-Ray then draws the
same picture is tests/test_povray_agreement.py's job.
"""

import math
import re
import shutil

import numpy as np
import pytest

import lenscompare.povray.runner as runner
from lenscompare.cameras import CameraFrame
from lenscompare.errors import ExternalError, InputError
from lenscompare.optics import focus_film_distance_mm
from lenscompare.povray import pov_camera, povray_version, render_povray, scene_to_pov
from lenscompare.povray.export import FOCAL_BLUR_FILM_BIAS_PX, format_number
from lenscompare.povray.runner import pinhole_antialias_depth
from lenscompare.scene import parse_scene

needs_povray = pytest.mark.skipif(shutil.which("povray") is None, reason="POV-Ray (povray) is not installed")

SCENE = """
[camera]
model = "thin"
position = [0.25, 1.5, -2.0]
look_at = [0.0, 0.5, 3.0]
up = [0.2, 1.0, 0.0]
focal_length_mm = 35.0
f_number = 2.8
focus_distance = 2.5
film_mm = [36.0, 24.0]
resolution = [60, 40]

[render]
spp = 48

[background]
color = [0.02, 0.03, 0.05]

[materials.lamp]
type = "emissive"
color = [4.0, 3.25, 1.5]

[materials.chart]
type = "diffuse"
color = [0.75, 0.5, 0.25]
checker = { color = [0.05, 0.0, 0.125], size = 0.25 }

[materials.glowing_paint]
type = "diffuse"
color = [0.5, 0.0, 0.25]
emission = [0.125, 0.25, 0.0]

[[objects]]
type = "sphere"
center = [0.0, 0.5, 3.0]
radius = 0.5
material = "lamp"

[[objects]]
type = "box"
min = [-4.0, -0.1, -1.0]
max = [4.0, 0.0, 12.0]
material = "chart"

[[objects]]
type = "rectangle"
corner = [-1.0, 0.0, 5.0]
edge1 = [2.0, 0.0, 0.5]
edge2 = [0.0, 1.5, 0.0]
material = "glowing_paint"

[[lights]]
type = "point"
position = [3.0, 5.0, -2.0]
color = [0.9, 0.8, 0.7]
"""


@pytest.fixture
def scene():
    return parse_scene(SCENE, source="export.toml")


def vectors(text, keyword):
    """Every ``keyword <a, b, c>`` in the text, as arrays."""
    pattern = rf"\b{keyword}\s*<([^>]*)>"
    return [np.array([float(v) for v in m.split(",")]) for m in re.findall(pattern, text)]


def camera_block(text):
    return re.search(r"camera \{(.*?)\n\}", text, re.S).group(1)


def test_starts_with_version_and_linear_no_ambient_globals(scene):
    text = scene_to_pov(scene)
    assert text.startswith("#version 3.7;\n")
    code = re.sub(r"//[^\n]*", "", text)
    assert "global_settings { assumed_gamma 1.0 ambient_light 0 }" in text
    for word in ("radiosity", "photons", "fade_distance", "area_light", "spotlight", "parallel"):
        assert word not in code
    assert "background { rgb <0.02, 0.03, 0.05> }" in text


def test_thin_lens_camera_numbers(scene):
    text = camera_block(scene_to_pov(scene, model="thin", spp=300))
    origin, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    d_prime = focus_film_distance_mm(2500.0, 35.0)
    (location,), (right_v,), (up_v,), (direction,) = (vectors(text, k) for k in ("location", "right", "up",
                                                                                  "direction"))
    np.testing.assert_allclose(location, [0.25, 1.5, -2.0])
    # right and up: the native frame scaled to film / d' (a pixel at screen x in
    # [-0.5, 0.5] looks along direction + x right)
    np.testing.assert_allclose(right_v, right * 36.0 / d_prime, rtol=1e-15, atol=1e-15)
    np.testing.assert_allclose(up_v, up * 24.0 / d_prime, rtol=1e-15, atol=1e-15)
    # direction: the view axis, aimed 1/32 px right and down against POV-Ray's focal-blur film bias
    bias = FOCAL_BLUR_FILM_BIAS_PX
    np.testing.assert_allclose(direction, forward + right_v * bias / 60 - up_v * bias / 40, rtol=1e-15, atol=1e-15)
    # the horizontal field of view, in a comment
    angle = math.degrees(2 * math.atan(18.0 / d_prime))
    assert f"horizontal field of view {format_number(angle)} deg" in text
    # aperture 2 f / N in metres; the focal plane at |focal_point - location| / |direction| = 2.5 m
    assert re.search(r"\baperture ([0-9.e-]+)", text).group(1) == format_number(2 * 35.0 / 2.8 / 1000)
    (focal_point,) = vectors(text, "focal_point")
    assert np.linalg.norm(focal_point - location) / np.linalg.norm(direction) == pytest.approx(2.5, rel=1e-14)
    np.testing.assert_allclose(np.cross(focal_point - location, forward), 0.0, atol=1e-15)  # on the axis
    assert "blur_samples 300, 300" in text


def test_pinhole_has_no_focal_blur_and_shares_the_frame(scene):
    pinhole, thin = (camera_block(scene_to_pov(scene, model=m)) for m in ("pinhole", "thin"))
    for word in ("aperture", "focal_point", "blur_samples"):
        assert word not in pinhole
    _, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    np.testing.assert_allclose(vectors(pinhole, "direction")[0], forward, rtol=1e-15, atol=1e-15)
    for key in ("location", "right", "up"):
        np.testing.assert_array_equal(vectors(pinhole, key)[0], vectors(thin, key)[0])


def test_spp_defaults_to_the_scene(scene):
    assert "blur_samples 48, 48" in scene_to_pov(scene)


def test_pov_camera_reports_the_thin_lens():
    camera = pov_camera(parse_scene(SCENE))
    assert camera.film_distance_mm == pytest.approx(35.0 * 2500.0 / (2500.0 - 35.0))
    assert camera.aperture_diameter_mm == pytest.approx(12.5)
    assert camera.pov_aperture_m == pytest.approx(0.025)


@pytest.mark.parametrize("model", ["thick", "lens"])
def test_thick_and_lens_are_refused(scene, model):
    with pytest.raises(InputError, match="POV-Ray has no thick-lens / lens-system camera") as info:
        scene_to_pov(scene, model=model)
    assert info.value.exit_status == 2
    # refused before any binary is looked for
    with pytest.raises(InputError, match="no thick-lens"):
        render_povray(scene, model=model, povray="lenscompare-no-such-povray")


def test_materials(scene):
    text = scene_to_pov(scene)
    # emissive: radiance above 1 kept as is
    assert ("texture { pigment { rgb <4.0, 3.25, 1.5> } finish { emission 1 diffuse 0 ambient 0 specular 0 "
            "phong 0 reflection 0 } }") in text
    # Lambert, POV-Ray's checker in the material's phase (even cubes = colour)
    # (moved by -0.001 size: POV-Ray 3.7's checker is floor(q + 1e-10), ours floor(p/s + 0.001))
    assert ("pigment { checker rgb <0.75, 0.5, 0.25> rgb <0.05, 0, 0.125> scale 0.25 "
            "translate <-0.00025, -0.00025, -0.00025> }") in text
    assert "finish { emission 0 diffuse 1 brilliance 1 ambient 0 specular 0 phong 0 reflection 0 }" in text
    # diffuse + emission: lit and emissive textures averaged at double colour
    assert "average texture_map" in text
    assert "[1 pigment { rgb <1.0, 0, 0.5> } finish { emission 0 diffuse 1" in text
    assert "[1 pigment { rgb <0.25, 0.5, 0> } finish { emission 1 diffuse 0" in text


def test_objects_and_lights(scene):
    text = scene_to_pov(scene)
    assert re.search(r"sphere \{ <0, 0.5, 3.0>, 0.5 texture \{ LC_Material\d \} \}", text)
    assert re.search(r"box \{ <-4.0, -0.1, -1.0>, <4.0, 0, 12.0> texture \{ LC_Material\d \} \}", text)
    # the rectangle: two triangles, split as Embree splits the quad p0 p1 p2 p3
    mesh = re.search(r"mesh \{ (.*) \}", text).group(1)
    corners = [np.array([-1.0, 0.0, 5.0]), np.array([1.0, 0.0, 5.5]), np.array([1.0, 1.5, 5.5]),
               np.array([-1.0, 1.5, 5.0])]
    triangles = [[np.array([float(v) for v in p.split(",")]) for p in re.findall(r"<([^>]*)>", t)]
                 for t in re.findall(r"triangle \{([^}]*)\}", mesh)]
    np.testing.assert_array_equal(triangles, [[corners[0], corners[1], corners[3]],
                                              [corners[2], corners[3], corners[1]]])
    assert "light_source { <3.0, 5.0, -2.0> rgb <0.9, 0.8, 0.7> }" in text


def test_material_names_become_identifiers():
    renamed = SCENE.replace("[materials.glowing_paint]", '[materials."glowing paint ü"]')
    text = scene_to_pov(parse_scene(renamed.replace('"glowing_paint"', '"glowing paint ü"')))
    declared = re.findall(r"#declare (\S+) =", text)
    assert all(re.fullmatch(r"[A-Za-z_][A-Za-z0-9_]*", name) for name in declared)
    assert len(set(declared)) == 3


@pytest.mark.parametrize("value", [0.1, 1 / 3, -2.5e-7, 1e20, 0.0, 123456789.123])
def test_numbers_round_trip(value):
    assert float(format_number(value)) == value


def test_pinhole_antialias_depth():
    assert [pinhole_antialias_depth(s) for s in (1, 2, 3, 5, 10, 17, 18, 82, 10_000)] == [1, 1, 2, 2, 3, 4, 5, 9, 9]


# --- runner errors ---------------------------------------------------------------------------------------------


def test_missing_povray_is_an_external_error(scene):
    with pytest.raises(ExternalError, match="POV-Ray is not installed") as info:
        render_povray(scene, povray="lenscompare-no-such-povray")
    assert info.value.exit_status == 1


@needs_povray
def test_failing_scene_reports_povrays_words(scene, monkeypatch):
    monkeypatch.setattr(runner, "scene_to_pov", lambda *a, **k: "#version 3.7;\nsphere { <0, 0, 1>, }\n")
    with pytest.raises(ExternalError) as info:
        render_povray(scene, spp=1)
    message = str(info.value)
    assert info.value.exit_status == 1
    assert "POV-Ray failed" in message
    assert "Parse Error" in message  # POV-Ray's own words
    assert "scene.pov' line 2" in message


@needs_povray
def test_runner_returns_an_image_like_a_native_render(scene):
    # smoke test: POV-Ray runs, returns our Image layout (H, W, 3) float32, linear
    image = render_povray(scene.with_camera(resolution=(6, 4)), model="pinhole", spp=2)
    assert image.pixels.shape == (4, 6, 3)
    assert image.pixels.dtype == np.float32
    assert image.metadata["renderer"].startswith("POV-Ray 3.7")
    assert image.metadata["spp"] == 2


@needs_povray
def test_timeout_stops_povray(scene):
    with pytest.raises(ExternalError, match="did not finish within"):
        render_povray(scene, spp=4096, timeout_s=0.05)


@needs_povray
def test_povray_version_line():
    assert povray_version().startswith("POV-Ray 3.7")


def test_povray_version_of_a_missing_binary_is_an_external_error():
    with pytest.raises(ExternalError, match="not installed"):
        povray_version("lenscompare-no-such-povray")


def test_adaptive_focal_blur_sets_min_max_and_variance(scene):
    """POV-Ray's own adaptive focal blur (the benchmark gives it a fair run):
    blur_samples MIN, MAX and a variance threshold; MIN never above MAX."""
    text = scene_to_pov(scene, model="thin", spp=256, blur_adaptive=(4, 1 / 1024))
    assert "blur_samples 4, 256 variance 0.0009765625" in text
    assert "blur_samples 8, 8" in scene_to_pov(scene, model="thin", spp=8, blur_adaptive=(16, 0.01)).replace(
        " variance 0.01", "")
    with pytest.raises(InputError, match="thin-lens"):
        render_povray(scene, model="pinhole", spp=8, blur_adaptive=(4, 0.01))
