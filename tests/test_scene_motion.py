"""Motion keys of scene files: velocity (camera, objects) and [render] shutter,
bounded like every other key; a bad value is exit 2 naming the file and key."""

import pytest

from lenscompare.errors import InputError
from lenscompare.scene import parse_scene

from helpers import run_cli

# (replace this, with that) -> the key the message must name
BAD_MOTION = {
    "negative shutter": ("spp = 4", "spp = 4\nshutter = [-0.01, 0.01]", "render.shutter"),
    "shutter closes before it opens": ("spp = 4", "spp = 4\nshutter = [0.02, 0.01]", "render.shutter"),
    "NaN shutter": ("spp = 4", "spp = 4\nshutter = [0.0, nan]", "render.shutter"),
    "one-number shutter": ("spp = 4", "spp = 4\nshutter = 0.01", "render.shutter"),
    "shutter of a year": ("spp = 4", "spp = 4\nshutter = [0.0, 3.2e7]", "render.shutter"),
    "NaN object velocity": ("radius = 0.1", "radius = 0.1\nvelocity = [nan, 0.0, 0.0]", "objects[0].velocity"),
    "faster than light": ("radius = 0.1", "radius = 0.1\nvelocity = [4e8, 0.0, 0.0]", "objects[0].velocity"),
    "camera velocity inf": ("f_number = 2.8", "f_number = 2.8\nvelocity = [0.0, inf, 0.0]", "camera.velocity"),
    "velocity of two numbers": ("f_number = 2.8", "f_number = 2.8\nvelocity = [1.0, 2.0]", "camera.velocity"),
    "moves out of bounds": ("spp = 4", "spp = 4\nshutter = [0.0, 80000.0]", "objects[0].velocity"),
}


@pytest.mark.parametrize("case", sorted(BAD_MOTION), ids=str)
def test_bad_motion_keys_name_file_and_key(case, minimal_scene_text):
    this, that, key = BAD_MOTION[case]
    text = minimal_scene_text.replace(this, that, 1)
    if case == "moves out of bounds":  # 2e5 m/s for 8e4 s: 1.6e10 m, beyond 1e9 m
        text = text.replace("radius = 0.1", "radius = 0.1\nvelocity = [2e5, 0.0, 0.0]", 1)
    with pytest.raises(InputError) as info:
        parse_scene(text, source="bad.toml")
    message = str(info.value)
    assert message.startswith("bad.toml: ") and key in message, message
    assert info.value.exit_status == 2


def test_motion_keys_parse(minimal_scene_text):
    text = (minimal_scene_text.replace("spp = 4", "spp = 4\nshutter = [0.0, 0.02]", 1)
            .replace("radius = 0.1", "radius = 0.1\nvelocity = [1.0, 0.0, -2.0]", 1)
            .replace("f_number = 2.8", "f_number = 2.8\nvelocity = [0.0, 0.5, 0.0]", 1))
    scene = parse_scene(text, source="m.toml")
    assert scene.render.shutter_s == (0.0, 0.02)
    assert scene.objects[0].velocity == (1.0, 0.0, -2.0) and scene.objects[1].velocity == (0.0, 0.0, 0.0)
    assert scene.camera.velocity == (0.0, 0.5, 0.0)


def test_cli_refuses_a_bad_shutter_with_exit_2_and_no_traceback(minimal_scene_text, tmp_path):
    scene = tmp_path / "bad.toml"
    scene.write_text(minimal_scene_text.replace("spp = 4", "spp = 4\nshutter = [0.5, 0.1]", 1))
    result = run_cli("render", scene, "-o", tmp_path / "out.exr")
    assert result.returncode == 2
    assert "bad.toml" in result.stderr and "render.shutter" in result.stderr
    assert "Traceback" not in result.stderr and len(result.stderr.strip().splitlines()) == 1
    assert not (tmp_path / "out.exr").exists()
