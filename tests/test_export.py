"""``lenscompare export``: POV-Ray SDL, Mitsuba 3 XML (rendered by Mitsuba here, to
the same image as ``lenscompare mitsuba``) and pbrt-v4 text (checked by a parser
written from pbrt-v4's documented file format: pbrt itself is not installable here).
"""

import json
import re

import numpy as np
import pytest

from helpers import REFERENCE_SCENES, run_cli
from lenscompare.mitsuba import render_mitsuba
from lenscompare.pbrt import scene_to_pbrt
from lenscompare.povray import scene_to_pov
from lenscompare.scene import load_scene


def test_povray_export_is_the_text_povray_renders(tmp_path):
    out = tmp_path / "showcase.pov"
    result = run_cli("export", REFERENCE_SCENES / "showcase.toml", "--to", "povray", "-o", out, "--spp", "32")
    assert result.returncode == 0, result.stderr
    assert out.read_text() == scene_to_pov(load_scene(REFERENCE_SCENES / "showcase.toml"), spp=32)


def test_exported_mitsuba_xml_renders_to_the_same_image_as_lenscompare_mitsuba(tmp_path):
    """The exported files, loaded by Mitsuba's own ``load_file`` from another folder, render
    (same seed and spp) to exactly the image ``lenscompare mitsuba`` gives; checker meshes included."""
    mitsuba = pytest.importorskip("mitsuba")
    scene = load_scene(REFERENCE_SCENES / "lit_showcase.toml").with_camera(resolution=(90, 60))
    source = tmp_path / "scene.toml"
    source.write_text((REFERENCE_SCENES / "lit_showcase.toml").read_text().replace("[360, 240]", "[90, 60]"))
    out = tmp_path / "export" / "lit.xml"
    out.parent.mkdir()
    result = run_cli("export", source, "--to", "mitsuba", "-o", out, "--spp", "16", "--seed", "3", "--json")
    assert result.returncode == 0, result.stderr
    files = json.loads(result.stdout)["files"]
    assert str(out) in files and any(f.endswith("object0_odd.ply") for f in files)
    mitsuba.set_variant("scalar_rgb")
    theirs = np.array(mitsuba.render(mitsuba.load_file(str(out))))
    ours = render_mitsuba(scene, spp=16, seed=3).pixels
    assert theirs.shape == ours.shape == (60, 90, 3)
    assert np.array_equal(theirs, ours)
    assert theirs.mean() > 0.01  # lit, not black


# --- pbrt-v4 -------------------------------------------------------------------------------------------------
# The pbrt-v4 scene format (pbrt-v4 "File format" documentation, and src/pbrt/parser.cpp and
# cameras.cpp of mmp/pbrt-v4 for the parameter names): '#' comments; directives by name; a
# parameter is a quoted "type name" followed by one value or a [ bracketed ] list.

DIRECTIVE_ARGS = {  # directive: numbers it takes, or None for a quoted name followed by parameters
    "LookAt": 9, "Translate": 3, "Scale": 3, "Rotate": 4, "Transform": 16, "ConcatTransform": 16,
    "Camera": None, "Sampler": None, "Film": None, "PixelFilter": None, "Integrator": None, "Shape": None,
    "LightSource": None, "AreaLightSource": None, "Material": None, "Texture": None,
    "WorldBegin": 0, "AttributeBegin": 0, "AttributeEnd": 0, "ReverseOrientation": 0,
}
PARAM_TYPES = {"integer": 1, "float": 1, "point2": 2, "vector2": 2, "point3": 3, "vector3": 3, "normal3": 3,
               "normal": 3, "rgb": 3, "spectrum": 1, "blackbody": 1, "bool": 1, "string": 1, "texture": 1}
PLUGIN_PARAMS = {  # (directive, plugin): the parameters pbrt-v4 documents that this export uses
    ("Camera", "perspective"): {"fov", "lensradius", "focaldistance"},
    ("Camera", "realistic"): {"lensfile", "aperturediameter", "focusdistance"},
    ("Film", "rgb"): {"xresolution", "yresolution", "filename", "diagonal"},
    ("PixelFilter", "box"): {"xradius", "yradius"},
    ("Sampler", "independent"): {"pixelsamples", "seed"},
    ("Integrator", "path"): {"maxdepth"},
    ("Shape", "sphere"): {"radius"},
    ("Shape", "trianglemesh"): {"indices", "P"},
    ("LightSource", "point"): {"from", "I"},
    ("LightSource", "infinite"): {"L"},
    ("AreaLightSource", "diffuse"): {"L", "twosided"},
    ("Material", "diffuse"): {"reflectance"},
    ("Texture", "checkerboard"): {"dimension", "tex1", "tex2"},
}
TOKEN = re.compile(r'"[^"]*"|\[|\]|[^\s\[\]"]+')


def parse_pbrt(text):
    """Directives as (name, positional args, {param name: (type, values)}); raises AssertionError on bad syntax."""
    tokens = TOKEN.findall("\n".join(line.split("#", 1)[0] for line in text.splitlines()))
    statements, i = [], 0
    while i < len(tokens):
        name = tokens[i]
        assert name in DIRECTIVE_ARGS, f"unknown directive {name!r}"
        i += 1
        count = DIRECTIVE_ARGS[name]
        if count is not None:
            args = [float(t) for t in tokens[i:i + count]]
            assert len(args) == count, name
            statements.append((name, args, {}))
            i += count
            continue
        args = [tokens[i].strip('"')]  # the plugin (Texture: name, then value type, then class)
        i += 1
        if name == "Texture":
            args += [tokens[i].strip('"'), tokens[i + 1].strip('"')]
            i += 2
        params = {}
        while i < len(tokens) and tokens[i].startswith('"'):
            kind, pname = tokens[i].strip('"').split()
            assert kind in PARAM_TYPES, f"{name}: unknown parameter type {kind!r}"
            i += 1
            if tokens[i] == "[":
                end = tokens.index("]", i)
                values, i = tokens[i + 1:end], end + 1
            else:
                values, i = [tokens[i]], i + 1
            assert values and len(values) % PARAM_TYPES[kind] == 0, f"{name} {pname}: {len(values)} values"
            if kind in ("string", "texture"):
                assert all(v.startswith('"') for v in values), pname
                values = [v.strip('"') for v in values]
            elif kind == "bool":
                assert all(v in ("true", "false") for v in values), pname
            elif kind == "integer":
                values = [int(v) for v in values]
            else:
                values = [float(v) for v in values]
            assert pname not in params, f"{name}: {pname} given twice"
            params[pname] = (kind, values)
        statements.append((name, args, params))
    return statements


def check_pbrt(text, files):
    statements = parse_pbrt(text)
    names = [s[0] for s in statements]
    assert names.count("WorldBegin") == 1
    world = names.index("WorldBegin")
    assert {"Camera", "Film", "Sampler", "LookAt"} <= set(names[:world])
    depth, textures = 0, set()
    for name, args, params in statements:
        depth += {"AttributeBegin": 1, "AttributeEnd": -1}.get(name, 0)
        assert depth >= 0
        if DIRECTIVE_ARGS[name] is None:
            plugin = args[2] if name == "Texture" else args[0]
            assert set(params) <= PLUGIN_PARAMS[(name, plugin)], (name, plugin, set(params))
        if name == "Texture":
            textures.add(args[0])
        for kind, values in params.values():
            if kind == "texture":
                assert set(values) <= textures, f"texture {values} used before it is defined"
        if (name, args[:1]) == ("Shape", ["trianglemesh"]):
            indices, points = params["indices"][1], params["P"][1]
            assert len(indices) % 3 == 0 and max(indices) < len(points) // 3
        if (name, args[:1]) == ("Camera", ["realistic"]):
            lens = files[params["lensfile"][1][0]]
            rows = [line.split() for line in lens.splitlines() if line.strip() and not line.startswith("#")]
            assert rows and all(len(r) == 4 for r in rows)
            assert sum(float(r[0]) == 0 for r in rows) == 1  # one aperture stop
    assert depth == 0
    return statements


@pytest.mark.parametrize("name, model", [("lit_showcase", "thin"), ("blur_disks", "pinhole"),
                                         ("flat_field", "thin"), ("lit_showcase", "lens"),
                                         ("mesh_bunny", "thin")])
def test_pbrt_text_follows_pbrt_v4_syntax(name, model):
    scene = load_scene(REFERENCE_SCENES / f"{name}.toml")
    if model == "lens":
        scene = scene.with_camera(lens="dgauss.50mm", f_number=4.0)
    exported = scene_to_pbrt(scene, model=model)
    statements = check_pbrt(exported.text, exported.files)
    shapes = [s for s in statements if s[0] == "Shape"]
    assert len(shapes) == len(scene.objects)
    camera = next(s for s in statements if s[0] == "Camera")
    if model == "thin":
        # the shorter (vertical) side's field of view, and the thin lens in metres
        d_prime_mm = 50.0 * scene.camera.focus_distance_m * 1000 / (scene.camera.focus_distance_m * 1000 - 50.0)
        assert camera[2]["fov"][1][0] == pytest.approx(2 * np.degrees(np.arctan(12 / d_prime_mm)), rel=1e-9)
        assert camera[2]["lensradius"][1][0] == pytest.approx(0.05 / scene.camera.f_number / 2)


def test_pbrt_parser_rejects_what_pbrt_rejects():
    """The checker can fail: a wrong count, an unknown type, an undefined texture, unbalanced attributes."""
    good = scene_to_pbrt(load_scene(REFERENCE_SCENES / "lit_showcase.toml"))
    check_pbrt(good.text, good.files)
    for bad in (good.text.replace('"float radius" [ 0.35 ]', '"float radius" [ 0.35 1 ]').replace(
                    '"point3 from" [ 3.0 5.0 -2.0 ]', '"point3 from" [ 3.0 5.0 ]'),
                good.text.replace('"rgb L"', '"colour L"'),
                good.text.replace('"texture reflectance" [ "checker0" ]', '"texture reflectance" [ "nope" ]'),
                good.text.replace("AttributeEnd", "", 1),
                good.text.replace('"float fov"', '"float angle"')):
        with pytest.raises((AssertionError, ValueError, KeyError)):
            check_pbrt(bad, good.files)


def test_export_refusals(tmp_path):
    scene = REFERENCE_SCENES / "showcase.toml"  # lights without inverse-square falloff
    for fmt in ("mitsuba", "pbrt"):
        result = run_cli("export", scene, "--to", fmt, "-o", tmp_path / "x.out")
        assert result.returncode == 2 and "lights[0].falloff" in result.stderr and not (tmp_path / "x.out").exists()
    result = run_cli("export", scene, "--to", "pbrt", "-o", tmp_path / "missing" / "x.pbrt")
    assert result.returncode == 2 and "-o" in result.stderr
    result = run_cli("export", scene, "--to", "povray", "-o", tmp_path / "x.pov", "--model", "lens")
    assert result.returncode == 2 and "POV-Ray" in result.stderr
