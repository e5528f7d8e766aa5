"""The per-packet cull of shadow rays (native/src/packet_bounds.h) and the per-tile cull of camera rays
(native/src/cameras/camera_pencil.h) only skip primitives no ray can reach: renders with them and without
them (LENSCOMPARE_PACKET_CULL=0 turns both off) are the same bit for bit, on the reference scenes and on
scenes built to sit at their edges."""
import numpy as np
import pytest

from helpers import REFERENCE_SCENES
from lenscompare.render import render
from lenscompare.scene import load_scene, parse_scene

HEADER = '''name = "cull"
[camera]
model = "thin"
position = [0.0, 1.0, -2.0]
look_at = [0.0, 0.2, 2.0]
focal_length_mm = 35.0
f_number = 2.0
focus_distance = 4.0
film_mm = [36.0, 24.0]
resolution = [72, 48]
[materials.m]
type = "diffuse"
color = [0.7, 0.6, 0.5]
[[objects]]
type = "rectangle"
corner = [-4.0, 0.0, -1.0]
edge1 = [8.0, 0.0, 0.0]
edge2 = [0.0, 0.0, 9.0]
material = "m"
'''


def sphere(centre, radius):
    return (f'[[objects]]\ntype = "sphere"\ncenter = [{centre[0]!r}, {centre[1]!r}, {centre[2]!r}]\n'
            f'radius = {radius!r}\nmaterial = "m"\n')


def light(position):
    return (f'[[lights]]\ntype = "point"\nposition = [{position[0]!r}, {position[1]!r}, {position[2]!r}]\n'
            'color = [20.0, 20.0, 20.0]\nfalloff = "inverse_square"\n')


def edge_scenes():
    rng = np.random.default_rng(5)
    lamp = np.array([0.5, 3.0, 2.0])
    # Small spheres strewn between the floor and the light, many of them grazing some shadow ray
    draws = zip(rng.uniform(0.05, 0.95, 24), rng.uniform(-2, 2, 24), rng.uniform(0, 6, 24),
                rng.uniform(0.005, 0.05, 24))
    strewn = "".join(sphere([float(v) for v in lamp * t + (1 - t) * np.array([x, 0.0, z])], float(r))
                     for t, x, z, r in draws)
    return {
        "strewn": HEADER + strewn + light([float(v) for v in lamp]),
        # The light on the floor's plane (its shadow rays run along it), and one inside a sphere
        "light_in_plane": HEADER + sphere((0.0, 0.4, 2.0), 0.4) + light((3.0, 0.0, 2.0)),
        "light_inside_sphere": HEADER + sphere((0.0, 2.0, 2.0), 0.5) + light((0.0, 2.0, 2.0)) + light((2, 2, 0)),
        # A sphere touching the light, a tiny one and a huge one whose surface passes near the scene
        "touching_tiny_huge": HEADER + sphere((1.3, 2.3, 2.0), 0.3) + sphere((0.2, 0.5, 1.5), 1e-4)
        + sphere((0.0, -1e4 - 5.0, 0.0), 1e4) + light((1.0, 2.3, 2.0)),
    }


def box(lo, hi):
    return (f'[[objects]]\ntype = "box"\nmin = [{lo[0]!r}, {lo[1]!r}, {lo[2]!r}]\n'
            f'max = [{hi[0]!r}, {hi[1]!r}, {hi[2]!r}]\nmaterial = "m"\n')


def camera_edge_scenes():
    """Scenes for the camera rays' per-tile cull: primitives straddling tiles, the lens and the camera."""
    rng = np.random.default_rng(8)
    # Small spheres and boxes over the whole view, many across a tile's edge (72 x 48 px, 16 px tiles)
    strewn = "".join(sphere((float(x), float(y), float(z)), float(r)) for x, y, z, r in
                     zip(rng.uniform(-2, 2, 20), rng.uniform(0, 2, 20), rng.uniform(0.5, 6, 20),
                         rng.uniform(0.01, 0.15, 20)))
    strewn += "".join(box((float(x), float(y), float(z)), (float(x + s), float(y + s), float(z + s))) for x, y, z, s in
                      zip(rng.uniform(-2, 2, 6), rng.uniform(0, 1.5, 6), rng.uniform(1, 6, 6),
                          rng.uniform(0.05, 0.4, 6)))
    lamp = light((0.5, 3.0, 2.0))
    wide = HEADER.replace("f_number = 2.0", "f_number = 1.0").replace("focus_distance = 4.0", "focus_distance = 0.6")
    blades = wide.replace('resolution = [72, 48]', 'resolution = [72, 48]\naperture_blades = 5')
    return {
        "strewn_f2": HEADER + strewn + lamp,
        "strewn_f1_focused_near": wide + strewn + lamp,
        "strewn_five_blades": blades + strewn + lamp,
        # The camera (at 0, 1, -2) inside a sphere and inside a box, lit from inside both
        "camera_inside": HEADER + sphere((0.0, 1.0, -2.0), 0.5) + box((-6.0, -0.5, -3.0), (6.0, 6.0, 12.0))
        + light((0.0, 1.5, -2.0)) + lamp,
        # A sphere across the lens plane, and one just behind it
        "across_the_lens": HEADER + sphere((0.3, 1.0, -2.0), 0.4) + sphere((0.0, 1.0, -2.6), 0.5) + lamp,
    }


@pytest.mark.parametrize("model", ["pinhole", "thin"])
@pytest.mark.parametrize("name", list(camera_edge_scenes()))
def test_the_camera_cull_changes_no_bit_at_its_edges(monkeypatch, name, model):
    culled, tested = render_both(monkeypatch, parse_scene(camera_edge_scenes()[name]), model=model, spp=8,
                                 threads=2)
    assert np.isfinite(culled).all()
    assert np.array_equal(culled, tested)


@pytest.mark.parametrize("table_mirrored", [False, True])
@pytest.mark.parametrize("name", list(camera_edge_scenes()) + ["faces_through_the_lens"])
def test_the_lens_systems_tile_cull_changes_no_bit(monkeypatch, name, table_mirrored):
    """A lens system's tiles cull the boxes' faces from a box round its first surface (and the
    ray table's origins), once per tile; with the cull off its packets cull them from their own
    origins. Boxes whose faces' planes pass through the lens (one 7 mm under its centre, which
    the top rows' rays from the lens's lower part meet from below), and the camera inside a box."""
    scenes = dict(camera_edge_scenes())
    scenes["faces_through_the_lens"] = (HEADER + box((-3.0, 0.993, -1.95), (3.0, 3.0, 6.0))
                                        + box((0.5, 0.0, -2.0), (2.0, 0.9, 3.0)) + light((0.5, 0.95, 2.0)))
    scene = parse_scene(scenes[name]).with_camera(lens="dgauss.50mm", focal_length_mm=None, f_number=None)
    options = dict(lens_rays="table", lens_mirrors=True) if table_mirrored else {}
    culled, tested = render_both(monkeypatch, scene, model="lens", spp=8, threads=2, **options)
    assert np.isfinite(culled).all()
    # (A sphere across the lens plane holds the whole lens system: black.)
    assert culled.mean() > 0.0 or name == "across_the_lens"
    assert np.array_equal(culled, tested)


def render_both(monkeypatch, scene, **options):
    images = {}
    for cull in ("1", "0"):
        monkeypatch.setenv("LENSCOMPARE_PACKET_CULL", cull)
        images[cull] = render(scene, progress=False, **options).pixels
    return images["1"], images["0"]


@pytest.mark.parametrize("name", list(edge_scenes()))
def test_the_cull_changes_no_bit_at_its_edges(monkeypatch, name):
    culled, tested = render_both(monkeypatch, parse_scene(edge_scenes()[name]), model="thin", spp=16, threads=2)
    assert np.isfinite(culled).all()
    assert np.array_equal(culled, tested)


@pytest.mark.parametrize("model", ["pinhole", "thin"])
def test_the_cull_changes_no_bit_on_lit_showcase(monkeypatch, model):
    scene = load_scene(REFERENCE_SCENES / "lit_showcase.toml").with_camera(resolution=(96, 64))
    culled, tested = render_both(monkeypatch, scene, model=model, spp=16, threads=2)
    assert culled.mean() > 0.01  # lit, with shadows to cull for
    assert np.array_equal(culled, tested)


@pytest.mark.parametrize("model", ["pinhole", "thin"])
@pytest.mark.parametrize("name", ["strewn_f2", "strewn_f1_focused_near", "camera_inside"])
def test_the_camera_cull_changes_no_bit_with_drawn_wavelengths(monkeypatch, name, model):
    """A spectral render whose four wavelengths share one ray (drawn, not integrated) culls its tiles too."""
    culled, tested = render_both(monkeypatch, parse_scene(camera_edge_scenes()[name]), model=model, spp=8,
                                 threads=2, spectral=True, sample_wavelengths=True)
    assert np.isfinite(culled).all()
    assert culled.mean() > 0.0
    assert np.array_equal(culled, tested)


@pytest.mark.parametrize("model", ["thin", "thick"])
@pytest.mark.parametrize("name", ["strewn_f2", "strewn_f1_focused_near", "strewn_five_blades", "camera_inside"])
def test_the_camera_cull_changes_no_bit_through_a_dispersive_lens(monkeypatch, name, model):
    """A thin or thick lens with its prescription's dispersion sends each wavelength toward its own plane of
    focus; its tiles' pencil spans them all (ThinLensCamera::pencil)."""
    lens = REFERENCE_SCENES.parent / "tests" / "data" / "lenses" / "biconvex_bk7.abbe.dat"
    scene = parse_scene(camera_edge_scenes()[name]).with_camera(lens=str(lens), focal_length_mm=None, f_number=4.0)
    culled, tested = render_both(monkeypatch, scene, model=model, spp=8, threads=2, spectral=True)
    assert np.isfinite(culled).all()
    assert culled.mean() > 0.0
    assert np.array_equal(culled, tested)


@pytest.mark.parametrize("model", ["pinhole", "thin"])
@pytest.mark.parametrize("name", ["strewn_f2", "strewn_f1_focused_near", "camera_inside"])
def test_a_moving_cameras_swept_cull_changes_no_bit(monkeypatch, name, model):
    """A camera moving 0.4 m over the shutter culls its tiles by the pencil
    swept along its path: the same image bit for bit as without culling, in RGB
    and through the dispersive thin lens's band rays."""
    scene = parse_scene(camera_edge_scenes()[name]).with_camera(velocity=(4.0, -2.0, 8.0)).with_render(
        shutter_s=(0.0, 0.04))
    culled, tested = render_both(monkeypatch, scene, model=model, spp=8, threads=2)
    assert np.isfinite(culled).all() and culled.mean() > 0.0
    assert np.array_equal(culled, tested)
    if model == "thin":
        lens = str(REFERENCE_SCENES.parent / "tests" / "data" / "lenses" / "dgauss_abbe.dat")
        culled, tested = render_both(monkeypatch, scene.with_camera(lens=lens, focal_length_mm=None), model=model,
                                     spp=8, threads=2, spectral=True)
        assert np.array_equal(culled, tested)


def own_primitive_scenes():
    """Scenes for the shadow rays of packets whose lanes are all on one own sphere or quad
    (Scene::single_own_primitive): the primitive, and a box's other faces, are then not tested."""
    lamp = light((0.5, 3.0, 2.0))
    boxes = box((-1.0, 0.0, 1.5), (-0.4, 0.6, 2.1)) + box((0.6, 0.0, 2.5), (1.4, 1.2, 3.3))
    return {
        # Boxes on the floor lit from above, from the side (some faces behind the light) and from low
        "boxes_lit_three_ways": HEADER + boxes + lamp + light((3.0, 0.3, 2.9)) + light((-2.5, 0.05, 1.0)),
        # A light a hair off the floor's plane (inside the plane drop's margin) and one a hair off a box's face
        "light_a_hair_off_a_plane": HEADER + boxes + light((1.0, 2e-4, 2.0)) + light((1.4005, 0.6, 2.9)),
        # The camera inside a box room: its walls are met from inside, and a light outside stays out
        "room_lit_from_outside": HEADER + sphere((0.3, 0.6, 1.0), 0.3)
        + box((-3.0, -0.5, -3.0), (3.0, 3.0, 5.0)) + light((0.0, 2.0, 1.0)) + light((0.0, 2.0, 8.0)),
        # Large spheres filling packets, lit from outside, and one with the light inside it
        "big_spheres": HEADER + sphere((-0.6, 0.6, 2.0), 0.6) + sphere((0.8, 0.5, 2.5), 0.5)
        + sphere((0.0, 2.2, 3.0), 0.5) + light((0.0, 2.2, 3.0)) + lamp,
    }


@pytest.mark.parametrize("model", ["pinhole", "thin"])
@pytest.mark.parametrize("name", list(own_primitive_scenes()))
def test_shadow_rays_skip_the_primitive_they_start_on_with_no_bit_changed(monkeypatch, name, model):
    culled, tested = render_both(monkeypatch, parse_scene(own_primitive_scenes()[name]), model=model, spp=8,
                                 threads=2)
    assert np.isfinite(culled).all() and culled.mean() > 0.0
    assert np.array_equal(culled, tested)


def test_a_light_outside_a_box_room_lights_nothing_inside(monkeypatch):
    """The room's faces are met from inside, and the light outside is behind the planes of those faces'
    lanes it could reach (in front of the far wall only): those lanes skip their own face, never the far wall,
    so the light adds nothing."""
    monkeypatch.setenv("LENSCOMPARE_PACKET_CULL", "1")
    room = own_primitive_scenes()["room_lit_from_outside"]
    inside_only = room.replace(light((0.0, 2.0, 8.0)), "")
    both = render(parse_scene(room), model="thin", spp=8, threads=2, progress=False).pixels
    alone = render(parse_scene(inside_only), model="thin", spp=8, threads=2, progress=False).pixels
    assert alone.mean() > 0.01
    assert np.array_equal(both, alone)


@pytest.mark.parametrize("model", ["pinhole", "thin"])
def test_peers_lit_is_the_same_with_and_without_the_culls(monkeypatch, model):
    """bench_peers.py's lit scene: boxes on a slab before a wall, three lights, spheres; its packets mostly
    lie on one quad or sphere."""
    scene = load_scene(REFERENCE_SCENES.parent / "bench" / "scenes" / "peers_lit.toml").with_camera(
        resolution=(96, 64))
    culled, tested = render_both(monkeypatch, scene, model=model, spp=16, threads=2)
    assert culled.mean() > 0.01
    assert np.array_equal(culled, tested)
