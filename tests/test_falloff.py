"""Point lights with ``falloff = "inverse_square"``: the native shading and the
POV-Ray export against the analytic radiance of a lit Lambert patch.

A pinhole looks square at a large diffuse plane; one inverse-square light sits
in front of it off the axis. The radiance of the patch at a point p is, by the
contract (Lambert with no 1/pi, as for ``falloff = "none"``),

    L(p) = albedo * I * cos(theta) / d^2,   d = |light - p|, cos(theta) = n . (light - p) / d,

computed here in NumPy and averaged over each pixel on a 16 x 16 grid of
sub-pixel centres, which is exactly where the native ``regular`` sampler puts
256 samples.
"""

import shutil

import numpy as np
import pytest

from lenscompare.cameras import camera_for
from lenscompare.povray import render_povray
from lenscompare.render import render
from lenscompare.scene import parse_scene

ALBEDO, INTENSITY = 0.6, 2.5
LIGHT_M = np.array([0.4, 0.3, 1.2])
PLANE_Z_M = 2.0

LIT_PATCH = f"""
[camera]
model = "pinhole"
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, 1.0]
focal_length_mm = 35.0
focus_distance = {PLANE_Z_M}
resolution = [90, 60]

[materials.paint]
type = "diffuse"
color = [{ALBEDO}, {ALBEDO}, {ALBEDO}]

[[objects]]
type = "rectangle"
corner = [-5.0, -5.0, {PLANE_Z_M}]
edge1 = [10.0, 0.0, 0.0]
edge2 = [0.0, 10.0, 0.0]
material = "paint"

[[lights]]
type = "point"
position = [{LIGHT_M[0]}, {LIGHT_M[1]}, {LIGHT_M[2]}]
color = [{INTENSITY}, {INTENSITY}, {INTENSITY}]
falloff = "FALLOFF"
"""


def analytic_patch(scene, *, inverse_square=True, sub=16) -> np.ndarray:
    """L averaged over every pixel of the pinhole's film (rows top to bottom), (h, w)."""
    camera = camera_for(scene, "pinhole")
    w, h = camera.film.resolution
    half_w, half_h = camera.screen_half_extent
    sx = ((np.arange(w * sub) + 0.5) / (w * sub) * 2 - 1) * half_w
    sy = (1 - (np.arange(h * sub) + 0.5) / (h * sub) * 2) * half_h
    x, y = np.meshgrid(sx * PLANE_Z_M, sy * PLANE_Z_M)
    to_light = LIGHT_M - np.stack([x, y, np.full_like(x, PLANE_Z_M)], axis=-1)
    d = np.linalg.norm(to_light, axis=-1)
    cos_theta = -to_light[..., 2] / d  # the plane faces the camera: n = -z
    radiance = ALBEDO * INTENSITY * cos_theta / (d * d if inverse_square else 1.0)
    return radiance.reshape(h, sub, w, sub).mean(axis=(1, 3))


def lit_patch(falloff):
    return parse_scene(LIT_PATCH.replace("FALLOFF", falloff), source="lit_patch.toml")


def test_native_inverse_square_matches_the_analytic_patch():
    scene = lit_patch("inverse_square")
    image = render(scene, spp=256, sampler="regular", threads=2).pixels[..., 0]
    expected = analytic_patch(scene)
    assert np.abs(image / expected - 1).max() < 1e-4
    # the falloff matters here: d runs from 0.8 m to 2.5 m, so without it the patch differs by half on average
    assert np.abs(image / analytic_patch(scene, inverse_square=False) - 1).mean() > 0.3


def test_native_no_falloff_is_unchanged():
    scene = lit_patch("none")
    image = render(scene, spp=256, sampler="regular", threads=2).pixels[..., 0]
    assert np.abs(image / analytic_patch(scene, inverse_square=False) - 1).max() < 1e-4


@pytest.mark.skipif(shutil.which("povray") is None, reason="POV-Ray (povray) is not installed")
def test_povray_inverse_square_matches_the_analytic_patch():
    """POV-Ray 3.7.0.10 (``fade_distance 1e-4 fade_power 2``, colour I / (2 D²)) against
    the same analytic patch, to its half-float output (2^-11 relative)."""
    scene = lit_patch("inverse_square")
    pov = render_povray(scene, spp=82, threads=2).pixels[..., 0]
    ratio = pov / analytic_patch(scene)
    # measured: largest 7.7e-4 (half floats), mean -2.6e-6 (no bias from the fade approximation)
    assert np.abs(ratio - 1).max() < 1.5e-3 and abs((ratio - 1).mean()) < 5e-5


def test_falloff_key_is_validated(minimal_scene_text):
    from lenscompare.errors import InputError

    text = minimal_scene_text + 'falloff = "linear"\n'
    with pytest.raises(InputError, match=r"lights\[0\]\.falloff.*'none', 'inverse_square'"):
        parse_scene(text, source="s.toml")
    assert parse_scene(minimal_scene_text).lights[0].falloff == "none"
