"""``type = "mesh"``: OBJ and PLY read by trimesh, into Embree triangles, POV-Ray
``mesh2``, Mitsuba and pbrt; malformed files are exit 2 naming the file and line."""

import shutil

import numpy as np
import pytest

from helpers import MINIMAL_SCENE, REFERENCE_SCENES, run_cli
from lenscompare.errors import InputError
from lenscompare.meshes import read_mesh
from lenscompare.metrics import ssim
from lenscompare.povray import render_povray
from lenscompare.render import render
from lenscompare.scene import load_scene

TETRA_OBJ = """# a tetrahedron
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
f 1 3 2
f 1 2 4
f 1 4 3
f 2 3 4
"""
TETRA_PLY = """ply
format ascii 1.0
element vertex 4
property float x
property float y
property float z
element face 4
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
0 1 0
0 0 1
3 0 2 1
3 0 1 3
3 0 3 2
3 1 2 3
"""


def test_obj_and_ply_give_the_same_triangles(tmp_path):
    (tmp_path / "t.obj").write_text(TETRA_OBJ)
    (tmp_path / "t.ply").write_text(TETRA_PLY)
    (v1, f1), (v2, f2) = read_mesh(tmp_path / "t.obj"), read_mesh(tmp_path / "t.ply")
    assert v1.shape == (4, 3) and f1.shape == (4, 3)
    assert np.array_equal(v1[f1], v2[f2])


def test_scene_mesh_is_scaled_then_translated(tmp_path):
    (tmp_path / "t.obj").write_text(TETRA_OBJ)
    text = MINIMAL_SCENE + ('\n[[objects]]\ntype = "mesh"\nfile = "t.obj"\nscale = 2.0\n'
                            'translate = [1.0, 0.0, 5.0]\nmaterial = "grey"\n')
    (tmp_path / "s.toml").write_text(text)
    mesh = load_scene(tmp_path / "s.toml").objects[-1]
    assert mesh.vertices_m.tolist() == [[1, 0, 5], [3, 0, 5], [1, 2, 5], [1, 0, 7]]


@pytest.mark.parametrize("name, text, line, words", [
    ("bad.obj", TETRA_OBJ.replace("v 1 0 0", "v 1 zero 0"), "line 3", "three finite numbers"),
    ("bad.obj", TETRA_OBJ.replace("f 1 2 4", "f 1 2 9"), "line 7", "vertex 9 does not exist"),
    ("bad.obj", TETRA_OBJ.replace("f 1 4 3", "f 1 4"), "line 8", "at least three vertices"),
    ("bad.ply", TETRA_PLY.replace("3 0 1 3", "3 0 1 7"), "line 15", "vertex indices below 4"),
    ("bad.ply", TETRA_PLY.replace("0 1 0\n", "0 one 0\n"), "line 12", "expected numbers"),
    ("bad.ply", TETRA_PLY.replace("element face 4", "element face four"), "line 7", "element NAME COUNT"),
])
def test_malformed_mesh_is_exit_2_naming_file_and_line(tmp_path, name, text, line, words):
    (tmp_path / name).write_text(text)
    with pytest.raises(InputError) as error:
        read_mesh(tmp_path / name)
    assert error.value.key == line and words in error.value.problem, str(error.value)
    if name != "bad.obj" or "zero" not in text:
        return  # the command line once (a subprocess costs seconds): the same error, one line, exit 2
    scene = tmp_path / "s.toml"
    scene.write_text(MINIMAL_SCENE + f'\n[[objects]]\ntype = "mesh"\nfile = "{name}"\nmaterial = "grey"\n')
    result = run_cli("render", scene, "-o", tmp_path / "out.exr")
    assert result.returncode == 2 and "Traceback" not in result.stderr
    assert f"{name}: {line}:" in result.stderr and len(result.stderr.strip().splitlines()) == 1, result.stderr


def test_missing_or_unknown_mesh_file_names_the_key(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(MINIMAL_SCENE + '\n[[objects]]\ntype = "mesh"\nfile = "nope.obj"\nmaterial = "grey"\n')
    result = run_cli("render", scene, "-o", tmp_path / "out.exr")
    assert result.returncode == 2 and "objects[2].file" in result.stderr and "nope.obj" in result.stderr
    (tmp_path / "m.stl").write_text("solid x\nendsolid x\n")
    with pytest.raises(InputError, match="OBJ or PLY"):
        read_mesh(tmp_path / "m.stl")


def test_a_two_triangle_mesh_renders_as_the_rectangle_it_spans(tmp_path):
    """The same quad as a mesh (Embree triangles) and as a rectangle (Embree quad): the same image."""
    (tmp_path / "q.obj").write_text("v -1 -1 3\nv 1 -1 3\nv 1 1 3.5\nv -1 1 3.5\nf 1 2 3\nf 1 3 4\n")
    base = MINIMAL_SCENE.split("[[objects]]")[0].replace("resolution = [36, 24]", "resolution = [72, 48]")
    quad = ('[[objects]]\ntype = "rectangle"\ncorner = [-1.0, -1.0, 3.0]\nedge1 = [2.0, 0.0, 0.0]\n'
            'edge2 = [0.0, 2.0, 0.5]\nmaterial = "grey"\n')
    mesh = '[[objects]]\ntype = "mesh"\nfile = "q.obj"\nmaterial = "grey"\n'
    lights = MINIMAL_SCENE[MINIMAL_SCENE.index("[[lights]]"):]
    images = []
    for objects in (quad, mesh):
        (tmp_path / "s.toml").write_text(base + objects + lights)
        images.append(render(load_scene(tmp_path / "s.toml"), spp=16, threads=2).pixels)
    assert images[0].max() > 0.1
    assert np.abs(images[0] - images[1]).max() < 1e-5


@pytest.fixture(scope="module")
def bunny():
    return load_scene(REFERENCE_SCENES / "mesh_bunny.toml").with_camera(resolution=(180, 120))


def test_bunny_scene_ships_a_real_mesh_with_its_source(bunny):
    mesh = next(o for o in bunny.objects if getattr(o, "file", None) and o.file.name == "bunny.ply")
    assert mesh.triangles.shape == (3000, 3)
    header = (REFERENCE_SCENES / "bunny.ply").read_text().split("end_header")[0]
    assert "Stanford" in header and "Turk" in header and "CGAL" in header


@pytest.mark.skipif(shutil.which("povray") is None, reason="POV-Ray (povray) is not installed")
def test_bunny_agrees_with_povray_mesh2(bunny):
    """native against POV-Ray (mesh2), 180 x 120, 128 samples each: SSIM >= 0.97 (measured 0.99)."""
    a = render(bunny, spp=128, threads=2).pixels
    b = render_povray(bunny, spp=128, threads=2).pixels
    assert ssim(a, b, data_range=float(a.max() - a.min())) >= 0.97
    assert abs(b.mean() / a.mean() - 1) < 0.01


def test_bunny_agrees_with_mitsuba(bunny):
    """native against Mitsuba 3 (PLY meshes), 180 x 120, 128 samples each: SSIM >= 0.97 (measured 0.99)."""
    pytest.importorskip("mitsuba")
    from lenscompare.mitsuba import render_mitsuba

    a = render(bunny, spp=128, threads=2).pixels
    b = render_mitsuba(bunny, spp=128).pixels
    value = ssim(a, b, data_range=float(a.max() - a.min()))
    assert value >= 0.97 and abs(b.mean() / a.mean() - 1) < 0.01, (value, b.mean() / a.mean())
