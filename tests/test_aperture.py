"""N-blade apertures: the samples, the thin and thick lens rays, and the bokeh of a defocused point.

The polygon is sampled by mapping the square to the disk (polar or concentric)
and the disk to the polygon's triangle fan (native/src/aperture.h); checked
here against the polygon's own geometry (lenscompare.optics.aperture) and
against equation 5 for the size of the blur.
"""

import math

import numpy as np
import pytest
from scipy import ndimage, stats
from skimage import measure

from lenscompare import _native
from lenscompare.cameras import CameraFrame, camera_for
from lenscompare.errors import InputError
from lenscompare.experiment import ExperimentSettings, render_models
from lenscompare.optics import (aperture_vertices, circle_of_confusion_mm, focus_film_distance_mm, inside_aperture,
                                polygon_apothem, polygon_circumradius, second_moment_diameter_ratio)
from lenscompare.mitsuba import scene_to_mitsuba
from lenscompare.pbrt import scene_to_pbrt
from lenscompare.povray import scene_to_pov
from lenscompare.render import render
from lenscompare.scene import parse_scene

from helpers import camera_scene_text, sphere_text
from test_camera_pinhole import rays

MAPPINGS = {"concentric": _native.DISK_CONCENTRIC, "polar": _native.DISK_POLAR}


def aperture_points(u, *, blades, rotation_deg=0.0, mapping="concentric"):
    u = np.ascontiguousarray(u, dtype=np.float32)
    out = np.zeros((len(u), 2))
    _native.diagnostics.map_to_aperture(u, MAPPINGS[mapping], blades, rotation_deg, out)
    return out


def with_aperture(text, blades, rotation_deg=0.0):
    return text.replace("film_mm = ", f"aperture_blades = {blades}\naperture_rotation_deg = {rotation_deg!r}\n"
                                      "film_mm = ", 1)


def test_polygon_geometry_has_the_circles_area_and_its_orientation():
    for blades in (3, 5, 6, 9, 32):
        v = aperture_vertices(blades, 0.0, radius=2.0)
        area = 0.5 * abs(np.sum(v[:, 0] * np.roll(v[:, 1], -1) - np.roll(v[:, 0], -1) * v[:, 1]))
        assert area == pytest.approx(math.pi * 4.0, rel=1e-12)
        np.testing.assert_allclose(v[0], [0.0, polygon_circumradius(blades, radius=2.0)], atol=1e-12)
    # Rotation turns counter-clockwise; the apothem bounds the inside.
    v = aperture_vertices(5, 90.0)
    np.testing.assert_allclose(v[0], [-polygon_circumradius(5), 0.0], atol=1e-12)
    a = polygon_apothem(6)
    assert inside_aperture(0.0, a * 0.999, blades=6, rotation_deg=30.0)  # hexagon, edge on top after 30 deg
    assert not inside_aperture(0.0, a * 1.001, blades=6, rotation_deg=30.0)


@pytest.mark.parametrize("mapping", ["concentric", "polar"])
@pytest.mark.parametrize("blades", [3, 5, 6, 9])
def test_polygon_samples_are_uniform_and_inside(blades, mapping):
    rotation = 17.0
    u = np.random.default_rng(blades).random((120_000, 2))
    p = aperture_points(u, blades=blades, rotation_deg=rotation, mapping=mapping)
    # Every sample inside the polygon (to rounding of the float disk point).
    grown = inside_aperture(p[:, 0] / (1 + 1e-6), p[:, 1] / (1 + 1e-6), blades=blades, rotation_deg=rotation)
    assert grown.all()
    # Uniform: counts in the grid cells wholly inside agree with the area (chi-square).
    r = polygon_circumradius(blades)
    bins = 20
    edges = np.linspace(-r, r, bins + 1)
    counts, _, _ = np.histogram2d(p[:, 0], p[:, 1], bins=[edges, edges])
    cx, cy = np.meshgrid(edges, edges, indexing="ij")
    corner_inside = inside_aperture(cx, cy, blades=blades, rotation_deg=rotation)
    whole = corner_inside[:-1, :-1] & corner_inside[1:, :-1] & corner_inside[:-1, 1:] & corner_inside[1:, 1:]
    expected = len(p) * (edges[1] - edges[0]) ** 2 / math.pi
    chi2 = np.sum((counts[whole] - expected) ** 2 / expected)
    assert stats.chi2.sf(chi2, whole.sum() - 1) > 1e-4
    # Centred, with the second moment of the uniform polygon, R^2 (2 + cos(2 pi / N)) / 6.
    assert np.abs(p.mean(axis=0)).max() < 0.01
    assert np.mean(np.sum(p * p, axis=1)) == pytest.approx(r * r * (2 + math.cos(2 * math.pi / blades)) / 6,
                                                           rel=0.01)
    # ... so its second-moment diameter (4 sqrt(var_x/2 + var_y/2)) against the circle's 2:
    assert 4 * math.sqrt(np.mean(np.sum(p * p, axis=1)) / 2) / 2 == pytest.approx(
        second_moment_diameter_ratio(blades), rel=0.005)


@pytest.mark.parametrize("mapping", ["concentric", "polar"])
def test_the_map_is_continuous_so_neighbouring_strata_stay_neighbours(mapping):
    n = 400
    g = (np.arange(n) + 0.5) / n
    u = np.stack(np.meshgrid(g, g, indexing="ij"), axis=-1).reshape(-1, 2)
    p = aperture_points(u, blades=7, rotation_deg=5.0, mapping=mapping).reshape(n, n, 2)
    step = max(np.linalg.norm(np.diff(p, axis=0), axis=-1).max(), np.linalg.norm(np.diff(p, axis=1), axis=-1).max())
    # A jump across a fan triangle's border would be of the order of the polygon (~1); steps are ~ 2 pi / n.
    assert step < 12.0 / n


def edge_integral_rmse(sampler, *, blades, trials=300, spp=64):
    """RMS error of the fraction of the aperture beyond a slanted line, from
    one pixel's lens samples (the integral a defocused edge computes)."""
    exact_u = np.random.default_rng(9).random((2_000_000, 2))
    beyond = lambda p: p[:, 0] * math.cos(0.4) + p[:, 1] * math.sin(0.4) > 0.3  # noqa: E731
    exact = beyond(aperture_points(exact_u, blades=blades)).mean()
    errors = []
    for pixel in range(trials):
        film, lens = np.zeros((spp, 2), np.float32), np.zeros((spp, 2), np.float32)
        _native.diagnostics.pixel_samples(sampler, 3, pixel, film, lens)
        errors.append(beyond(aperture_points(lens, blades=blades)).mean() - exact)
    return float(np.sqrt(np.mean(np.square(errors))))


def test_stratified_samplers_keep_their_advantage_on_the_polygon():
    """The polygon keeps the samplers' stratification: a stratified sampler
    beats independent samples on the polygon by as much as on the circle."""
    ratio = {}
    for blades in (0, 6):
        random = edge_integral_rmse(_native.SAMPLER_RANDOM, blades=blades)
        ratio[blades] = {name: random / edge_integral_rmse(code, blades=blades)
                         for name, code in (("jittered", _native.SAMPLER_JITTERED), ("sobol", _native.SAMPLER_SOBOL))}
    for name in ("jittered", "sobol"):
        assert ratio[6][name] > 2.0, ratio
        assert ratio[6][name] > 0.75 * ratio[0][name], ratio


def test_thin_lens_rays_leave_the_polygon_and_meet_at_the_focus_point():
    text = with_aperture(camera_scene_text(f_number=2.0, focus_distance=3.0, look_at=(0.2, 0.1, 1.0)), 5, 20.0)
    text = text.replace("film_mm = ", "principal_plane_gap_mm = 7.0\nfilm_mm = ", 1)
    scene = parse_scene(text)
    value = camera_for(scene, "thin")
    assert (value.aperture_blades, value.aperture_rotation_deg) == (5, 20.0)
    origin_w, right, up, forward = (np.array(v) for v in CameraFrame.of(scene.camera))
    lens = np.random.default_rng(4).random((4000, 2))
    radius_m = 50.0 / 2.0 / 2.0 / 1000.0
    for model in ("thin", "thick"):
        camera = camera_for(scene, model).native()
        origin, direction, weight = rays(camera, np.tile([100.0, 60.0], (len(lens), 1)), lens)
        offset = origin - origin_w
        x, y = offset @ right / radius_m, offset @ up / radius_m
        assert inside_aperture(x / (1 + 1e-6), y / (1 + 1e-6), blades=5, rotation_deg=20.0).all()
        # ... and fill it: the farthest sample reaches nearly to the vertices.
        assert np.hypot(x, y).max() > 0.98 * polygon_circumradius(5)
        t = (3.0 - offset @ forward) / (direction @ forward)
        hits = origin + direction * t[:, None]
        assert np.max(np.linalg.norm(hits - hits.mean(axis=0), axis=1)) < 1e-9
        assert np.all(weight == 1.0)


# --- the bokeh of a defocused point -------------------------------------------------------------------------

F_MM, N, FOCUS_M = 50.0, 1.4, 2.0
WIDTH, HEIGHT, PITCH_MM = 280, 160, 0.01


def fitted_polygon(window, plateau, centre, normal_angles):
    """Vertices of the polygon traced by the half-plateau contour of a blob:
    lines fitted to the middle of each edge (the corners are rounded by the
    source's own size), then intersected. ``centre`` (x, y up) and the edges'
    outward normal angles say where to look."""
    smooth = ndimage.gaussian_filter(window, 3.0)  # sampling noise; shifts no straight edge
    contour = max(measure.find_contours(smooth, 0.5 * plateau), key=len)
    x, y = contour[:, 1] + 0.5 - centre[0], -(contour[:, 0] + 0.5) - centre[1]
    angle = np.arctan2(y, x)
    half_edge = math.pi / len(normal_angles)
    lines = []
    for a in normal_angles:
        near = np.abs((angle - a + math.pi) % (2 * math.pi) - math.pi) < 0.6 * half_edge
        pts = np.stack([x[near], y[near]], axis=1)
        mean = pts.mean(axis=0)
        direction = np.linalg.svd(pts - mean)[2][0]  # total least squares
        lines.append((mean, direction))
    vertices = []
    for (p0, d0), (p1, d1) in zip(lines[-1:] + lines[:-1], lines):  # edges k - 1 and k meet at vertex k
        s = np.linalg.solve(np.stack([d0, -d1], axis=1), p1 - p0)
        vertices.append(p0 + s[0] * d0)
    return np.array(vertices)


@pytest.mark.parametrize("blades,rotation_deg", [(5, 17.0), (6, 0.0)])
def test_bokeh_of_a_defocused_point_is_the_predicted_polygon(blades, rotation_deg):
    """Two emissive spheres, one in front of the plane of focus and one
    behind: each blob is the N-gon of area pi (c/2)^2 (c from eq. 5), upright
    behind focus and turned by 180 degrees in front of it."""
    d_prime = focus_film_distance_mm(FOCUS_M * 1000.0, F_MM)
    points = [(-0.0127, 0.0, 1.0), (0.2535, 0.0, 20.0)]  # camera space, m: image x about -65 and +65 px
    expected_c_px = [circle_of_confusion_mm(z * 1000.0, focus_distance_mm=FOCUS_M * 1000.0, focal_length_mm=F_MM,
                                            aperture_diameter_mm=F_MM / N) / PITCH_MM for *_, z in points]
    # Each sphere images to a quarter of its blob: enough light per pixel, and
    # the half-plateau contour still follows the polygon's edges.
    radii_m = [c / 4 / 2 * PITCH_MM * z / d_prime for c, (*_, z) in zip(expected_c_px, points)]
    text = camera_scene_text(f_number=N, focus_distance=FOCUS_M, resolution=(WIDTH, HEIGHT),
                             film_mm=(WIDTH * PITCH_MM, HEIGHT * PITCH_MM), spp=256)
    text = with_aperture(text, blades, rotation_deg).replace("spp = 256", 'spp = 256\nsampler = "sobol"')
    text += "".join(sphere_text(p, r) for p, r in zip(points, radii_m))
    image = render(parse_scene(text), threads=2).pixels[..., 0]

    for (x, y, z), c in zip(points, expected_c_px):
        centre = np.array([WIDTH / 2 + x * d_prime / z / PITCH_MM, y * d_prime / z / PITCH_MM - HEIGHT / 2])
        half = int(0.75 * c) + 4
        col, row = int(centre[0]), int(-centre[1])
        window = image[row - half:row + half, col - half:col + half]
        origin = np.array([col - half, -(row - half)])  # window's top-left in (x, y up)
        # Area: flux over the plateau, the brightness where the source's image lies wholly inside the blob.
        apothem_px = polygon_apothem(blades) * c / 2
        yy, xx = np.mgrid[0:2 * half, 0:2 * half]
        r_px = np.hypot(xx + 0.5 - (centre[0] - origin[0]), -(yy + 0.5) - (centre[1] - origin[1]))
        plateau = np.median(window[r_px < apothem_px - c / 8 - 3])
        area = window.sum() / plateau
        assert area == pytest.approx(math.pi * (c / 2) ** 2, rel=0.02)
        # Vertices: upright behind focus, turned by 180 degrees in front of it.
        turn = 0.0 if z > FOCUS_M else 180.0
        expected = aperture_vertices(blades, rotation_deg + turn, radius=c / 2)
        expected_angles = np.degrees(np.arctan2(expected[:, 1], expected[:, 0]))
        normals = np.radians(expected_angles + 180.0 / blades)
        vertices = fitted_polygon(window, plateau, centre - origin, list(normals))
        angles = np.degrees(np.arctan2(vertices[:, 1], vertices[:, 0]))
        np.testing.assert_allclose((angles - expected_angles + 180) % 360 - 180, 0.0, atol=2.0)
        shoelace = 0.5 * abs(np.sum(vertices[:, 0] * np.roll(vertices[:, 1], -1)
                                    - np.roll(vertices[:, 0], -1) * vertices[:, 1]))
        assert shoelace == pytest.approx(math.pi * (c / 2) ** 2, rel=0.02)


# --- the scene keys, and POV-Ray -------------------------------------------------------------------------------

@pytest.mark.parametrize("value", ["1", "2", "33", "-1", "2.5", '"six"', "true"])
def test_bad_blade_counts_are_refused_naming_the_key(value):
    text = camera_scene_text().replace("film_mm = ", f"aperture_blades = {value}\nfilm_mm = ", 1)
    with pytest.raises(InputError, match="camera.aperture_blades"):
        parse_scene(text)


def test_rotation_must_be_a_finite_number():
    text = camera_scene_text().replace("film_mm = ", "aperture_rotation_deg = nan\nfilm_mm = ", 1)
    with pytest.raises(InputError, match="camera.aperture_rotation_deg"):
        parse_scene(text)


def test_povray_refuses_a_polygon_and_the_experiment_notes_why():
    scene = parse_scene(with_aperture(camera_scene_text(resolution=(36, 24), spp=1), 6))
    with pytest.raises(InputError, match="camera.aperture_blades.*circular aperture only"):
        scene_to_pov(scene, model="thin")
    scene_to_pov(scene, model="pinhole")  # no aperture, nothing to refuse
    runs, notes = render_models(scene, ExperimentSettings(povray=True), models=("thin",))
    assert [r.renderer for r in runs] == ["native"]
    assert any("no POV-Ray thin render" in n and "aperture_blades" in n for n in notes)
    # The other renderers' round lenses refuse it too; diffraction as well.
    for export in (scene_to_mitsuba, scene_to_pbrt):
        with pytest.raises(InputError, match="camera.aperture_blades"):
            export(scene, model="thin")
    diffracting = parse_scene(camera_scene_text(resolution=(36, 24), spp=1).replace("[render]\n",
                                                                                    "[render]\ndiffraction = true\n"))
    for export in (scene_to_pov, scene_to_mitsuba, scene_to_pbrt):
        with pytest.raises(InputError, match="render.diffraction"):
            export(diffracting, model="thin")
