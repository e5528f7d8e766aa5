"""Scene files: the reference scenes load; every schema break is one clear error."""

import math

import pytest

from lenscompare.errors import InputError
from lenscompare.scene import Box, DiffuseMaterial, Sphere, load_scene, parse_scene

from helpers import REFERENCE_SCENES


@pytest.mark.parametrize("path", sorted(REFERENCE_SCENES.glob("*.toml")), ids=lambda p: p.stem)
def test_reference_scenes_load(path):
    scene = load_scene(path)
    assert scene.objects
    assert scene.camera.width_px / scene.camera.height_px == pytest.approx(
        scene.camera.film_mm[0] / scene.camera.film_mm[1])


def test_minimal_scene_values(minimal_scene_text):
    scene = parse_scene(minimal_scene_text, source="m.toml")
    assert scene.camera.focus_distance_m == 2.0
    assert scene.camera.up == (0.0, 1.0, 0.0)  # default
    assert scene.render.spp == 4 and scene.render.sampler == "jittered"  # file value, then default
    assert isinstance(scene.objects[0], Sphere) and isinstance(scene.objects[1], Box)
    assert isinstance(scene.materials["grey"], DiffuseMaterial)
    assert scene.background == (0.0, 0.0, 0.0)


def test_scene_values_are_frozen(minimal_scene_text):
    scene = parse_scene(minimal_scene_text)
    with pytest.raises(AttributeError):
        scene.camera.f_number = 1.0


# (replace this, with that) -> the key the message must name
BAD_SCENES = {
    "unknown top-level key": ('name = "minimal"', 'name = "minimal"\ncolour = 1', "colour"),
    "unknown camera key": ("f_number = 2.8", "f_number = 2.8\nfocal_lenght_mm = 35.0", "camera.focal_lenght_mm"),
    "unknown object key": ('radius = 0.1', 'radius = 0.1\nradius_mm = 3', "objects[0].radius_mm"),
    "wrong type": ("f_number = 2.8", 'f_number = "fast"', "camera.f_number"),
    "wrong vector length": ("position = [0.0, 0.0, 0.0]", "position = [0.0, 0.0]", "camera.position"),
    "missing material": ('material = "glow"', 'material = "glowing"', "objects[0].material"),
    "missing required key": ("focus_distance = 2.0\n", "", "camera.focus_distance"),
    "unknown model": ('model = "thin"', 'model = "fisheye"', "camera.model"),
    "NaN radius": ("radius = 0.1", "radius = nan", "objects[0].radius"),
    "infinite position": ("center = [0.0, 0.0, 2.0]", "center = [0.0, inf, 2.0]", "objects[0].center"),
    "zero radius": ("radius = 0.1", "radius = 0.0", "objects[0].radius"),
    "negative f-number": ("f_number = 2.8", "f_number = -2.8", "camera.f_number"),
    "negative focal length": ("focal_length_mm = 50.0", "focal_length_mm = -50.0", "camera.focal_length_mm"),
    "zero film": ("film_mm = [36.0, 24.0]", "film_mm = [0.0, 24.0]", "camera.film_mm"),
    "zero resolution": ("resolution = [36, 24]", "resolution = [0, 24]", "camera.resolution"),
    "fractional resolution": ("resolution = [36, 24]", "resolution = [36.5, 24]", "camera.resolution"),
    "zero spp": ("spp = 4", "spp = 0", "render.spp"),
    "unknown sampler": ("spp = 4", 'spp = 4\nsampler = "sobolish"', "render.sampler"),
    "look_at equals position": ("look_at = [0.0, 0.0, 1.0]", "look_at = [0.0, 0.0, 0.0]", "camera.look_at"),
    "up along the view": ("look_at = [0.0, 0.0, 1.0]", "look_at = [0.0, 0.0, 1.0]\nup = [0.0, 0.0, 2.0]",
                          "camera.up"),
    "focus inside the focal length": ("focus_distance = 2.0", "focus_distance = 0.05", "camera.focus_distance"),
    "focus at the focal length": ("focus_distance = 2.0", "focus_distance = 0.05000", "camera.focus_distance"),
    "film aspect differs": ("resolution = [36, 24]", "resolution = [36, 36]", "camera.resolution"),
    "box inside out": ("max = [1.0, 1.0, 3.1]", "max = [1.0, -2.0, 3.1]", "objects[1].max"),
    "negative colour": ("color = [0.5, 0.5, 0.5]", "color = [0.5, -0.5, 0.5]", "materials.grey.color"),
    "unknown light type": ('type = "point"', 'type = "spot"', "lights[0].type"),
    "unknown material type": ('type = "emissive"', 'type = "glass"', "materials.glow.type"),
}


@pytest.mark.parametrize("case", sorted(BAD_SCENES), ids=str)
def test_bad_scene_names_file_and_key(case, minimal_scene_text):
    this, that, key = BAD_SCENES[case]
    assert this in minimal_scene_text, "the test's replacement does not apply"
    text = minimal_scene_text.replace(this, that, 1)
    with pytest.raises(InputError) as info:
        parse_scene(text, source="bad.toml")
    message = str(info.value)
    assert message.startswith("bad.toml: "), message
    assert key in message, message
    assert info.value.exit_status == 2


def test_not_toml(minimal_scene_text):
    with pytest.raises(InputError, match=r"bad.toml: not valid TOML"):
        parse_scene("[camera\nmodel=", source="bad.toml")


def test_unreadable_file(tmp_path):
    with pytest.raises(InputError, match=r"no such scene file"):
        load_scene(tmp_path / "missing.toml")


def test_checker_and_emission(minimal_scene_text):
    text = minimal_scene_text.replace('color = [0.5, 0.5, 0.5]',
                                      'color = [0.5, 0.5, 0.5]\nchecker = { color = [0.1, 0.1, 0.1], size = 0.2 }\n'
                                      'emission = [0.0, 0.1, 0.0]')
    grey = parse_scene(text).materials["grey"]
    assert grey.checker.size_m == 0.2 and grey.emission == (0.0, 0.1, 0.0)
    with pytest.raises(InputError, match=r"materials.grey.checker.size"):
        parse_scene(text.replace("size = 0.2", "size = -1"))
    assert math.isfinite(grey.checker.color[0])
