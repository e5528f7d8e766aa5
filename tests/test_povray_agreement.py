"""The native tracer against POV-Ray, an independent implementation of the same scene.

Every reference here is rendered, while the test runs, by POV-Ray 3.7.0.10
(``povray --version``: "POV-Ray 3.7.0.10.unofficial", Debian's ``povray``
package) on the text :func:`lenscompare.povray.scene_to_pov` writes, through
:func:`lenscompare.povray.render_povray`, i.e. in a fresh folder with

    povray +Iscene.pov +Oout.exr +FE -D -V +Q9 -UA +W<w> +H<h> <sampling> +WT2

where <sampling> is ``-A`` for the thin lens (focal blur, ``blur_samples N, N``
in the file) and ``+A0.0 +AM1 +R<n> +J1.0`` for the pinhole. Each test says
which sizes and sample counts; the exact command and version line of each
reference are in its ``Image.metadata`` (``command``, ``renderer``) and are
printed when an assertion fails. On failure the images that explain it are
written to pytest's ``tmp_path``.

Kept small for CI (2 cores): the whole file runs in about 15 s.
"""

import shutil
from pathlib import Path

import numpy as np
import pytest

from lenscompare.cameras import CameraFrame
from lenscompare.image import Image, write_exr
from lenscompare.metrics import measure_blur_disk, relative_rmse, ssim
from lenscompare.optics import circle_of_confusion_mm, focus_film_distance_mm
from lenscompare.povray import render_povray
from lenscompare.render import render
from lenscompare.scene import load_scene, parse_scene

pytestmark = pytest.mark.skipif(shutil.which("povray") is None, reason="POV-Ray (povray) is not installed")

REFERENCE_SCENES = Path(__file__).resolve().parent.parent / "reference_scenes"


def provenance(image: Image) -> str:
    return f"reference: {image.metadata['renderer']}, `{image.metadata['command']}`"


def explain(ok: bool, message: str, folder, **images) -> str:
    """``message``; when not ``ok``, also write the images that explain it and say where."""
    if ok:
        return message
    for name, image in images.items():
        write_exr(folder / f"{name}.exr", image if isinstance(image, Image) else Image(image))
    return f"{message}\nimages written to {folder}"


# --- blur disks ----------------------------------------------------------------------------------------------

FOCAL_LENGTH_MM, F_NUMBER, FOCUS_M = 50.0, 1.4, 1.0
BLUR_RESOLUTION = (360, 240)  # 0.1 mm pixels on the 36 x 24 mm film
BLUR_POINTS = [  # depth (m), screen position as a fraction of the half-frame (x right, y up)
    (0.5, (-0.6, -0.45)), (0.6, (-0.15, 0.5)), (2.0, (0.3, -0.5)),
    (3.0, (0.62, 0.45)), (5.0, (-0.62, 0.4)), (10.0, (0.2, 0.05)),
]
SOURCE_FRACTION = 0.5  # each source's sharp image is half its blur disk


def blur_disk_scene():
    """Emissive spheres in front of and behind the 1 m focal plane, each disk 9-19 px wide.

    Returns the scene and, per sphere, (x_px, y_px, eq. 5 diameter in px,
    diameter of its sharp image in px).

    The lens and film are ``reference_scenes/blur_disks.toml``'s (50 mm f/1.4,
    36 x 24 mm) at half its resolution; the file's depths would give disks of
    3-9 px at this size, so the focus moves to 1 m and the depths to 0.5-10 m.
    The sources are large (sharp image = half the disk) because a tiny source
    is hit by few lens samples and its second moment is noisy (+-3 % at 256
    spp); their images are removed exactly by the second-moment correction.
    """
    width, height = BLUR_RESOLUTION
    pitch_mm = 36.0 / width
    d_prime_mm = focus_film_distance_mm(FOCUS_M * 1000.0, FOCAL_LENGTH_MM)
    half_w, half_h = 18.0 / d_prime_mm, 12.0 / d_prime_mm
    text = f"""
        [camera]
        model = "thin"
        position = [0.0, 0.0, 0.0]
        look_at = [0.0, 0.0, 1.0]
        focal_length_mm = {FOCAL_LENGTH_MM}
        f_number = {F_NUMBER}
        focus_distance = {FOCUS_M}
        resolution = [{width}, {height}]
        [materials.glow]
        type = "emissive"
        color = [1.0, 1.0, 1.0]
    """
    expected = []
    for depth_m, (fx, fy) in BLUR_POINTS:
        c_px = circle_of_confusion_mm(depth_m * 1000.0, focus_distance_mm=FOCUS_M * 1000.0,
                                      focal_length_mm=FOCAL_LENGTH_MM,
                                      aperture_diameter_mm=FOCAL_LENGTH_MM / F_NUMBER) / pitch_mm
        tan_x, tan_y = fx * half_w, fy * half_h
        radius_m = SOURCE_FRACTION * c_px * pitch_mm / 2.0 / d_prime_mm * depth_m
        text += f"""
        [[objects]]
        type = "sphere"
        center = [{tan_x * depth_m!r}, {tan_y * depth_m!r}, {depth_m!r}]
        radius = {radius_m!r}
        material = "glow"
        """
        # The sharp image of an off-axis sphere is an ellipse: 2 r d'/l across
        # the radius, 1/cos(theta) times that along it; the second moment sees
        # the mean of the squared axes.
        across = 2.0 * radius_m * d_prime_mm / depth_m / pitch_mm
        along = across * np.sqrt(1.0 + tan_x**2 + tan_y**2)
        expected.append((width / 2 * (1 + fx), height / 2 * (1 - fy), c_px, np.sqrt((across**2 + along**2) / 2)))
    return parse_scene(text.replace("\n        ", "\n"), source="blur_disk_variant.toml"), expected


def test_blur_disks_match_equation_5_and_each_other(tmp_path):
    """Blur-disk diameters: native thin lens, POV-Ray focal blur and equation 5 within 2 %.

    Reference: POV-Ray 3.7.0.10, ``povray +Iscene.pov +Oout.exr +FE -D -V +Q9
    -UA +W360 +H240 -A +WT2`` with ``blur_samples 256, 256`` (native: 256
    jittered spp). Measured (second-moment diameter corrected for pixel and source):
    native within 0.4 %, POV-Ray within 0.6 % of equation 5.
    """
    scene, expected = blur_disk_scene()
    native = render(scene, spp=256, threads=2)
    pov = render_povray(scene, spp=256, threads=2)

    rows, failures = [], []
    for (depth_m, _), (x_px, y_px, c_px, source_px) in zip(BLUR_POINTS, expected):
        window = (c_px + source_px) / 2 + 3
        measured = [measure_blur_disk(image.pixels, center_px=(x_px, y_px), window_radius_px=window,
                                      source_diameter_px=source_px).second_moment_diameter_px
                    for image in (native, pov)]
        errors = [m / c_px - 1 for m in measured] + [measured[1] / measured[0] - 1]
        rows.append(f"{depth_m:5.1f} m: eq.5 {c_px:6.2f} px, native {measured[0]:6.2f} ({errors[0]:+.2%}), "
                    f"POV-Ray {measured[1]:6.2f} ({errors[1]:+.2%}), POV/native {errors[2]:+.2%}")
        if max(abs(e) for e in errors) > 0.02:
            failures.append(rows[-1])
    message = "\n".join(rows) + "\n" + provenance(pov)
    assert not failures, explain(not failures, message, tmp_path, native=native, povray=pov)


# --- pinhole projections ---------------------------------------------------------------------------------------

PROJECTION_CAMERA = {"position": (0.3, 1.2, -2.0), "look_at": (0.1, 0.9, 3.0), "up": (0.35, 1.0, 0.1)}


def projection_scene(model):
    """20 small emissive spheres at 2.5-6.5 m, seen by a tilted, rolled camera (non-default up).

    Returns the scene and the analytic projections of the sphere centres,
    shape (20, 2), raster pixels (x right, y down, pixel centres at i + 0.5).
    """
    from types import SimpleNamespace

    width, height, focus_m = 180, 120, 4.0
    origin, right, up, forward = (np.array(v) for v in CameraFrame.of(SimpleNamespace(**PROJECTION_CAMERA)))
    d_prime_mm = focus_film_distance_mm(focus_m * 1000.0, 50.0)
    half_w, half_h = 18.0 / d_prime_mm, 12.0 / d_prime_mm
    c = PROJECTION_CAMERA
    text = f"""
        [camera]
        model = "{model}"
        position = {list(c["position"])}
        look_at = {list(c["look_at"])}
        up = {list(c["up"])}
        focal_length_mm = 50.0
        f_number = 8.0
        focus_distance = {focus_m}
        resolution = [{width}, {height}]
        [materials.glow]
        type = "emissive"
        color = [1.0, 1.0, 1.0]
    """
    rng = np.random.default_rng(1)
    projections = []
    for i, fx in enumerate(np.linspace(-0.8, 0.8, 5)):
        for j, fy in enumerate(np.linspace(-0.75, 0.75, 4)):
            depth_m = 2.5 + (4 * i + j) % 5
            sx, sy = (fx + rng.uniform(-0.02, 0.02)) * half_w, (fy + rng.uniform(-0.02, 0.02)) * half_h
            center = origin + depth_m * (forward + sx * right + sy * up)
            radius_m = depth_m * 1.1 * 0.2 / d_prime_mm  # sharp image about 2.2 px wide
            text += f"""
        [[objects]]
        type = "sphere"
        center = [{float(center[0])!r}, {float(center[1])!r}, {float(center[2])!r}]
        radius = {radius_m!r}
        material = "glow"
        """
            projections.append((width / 2 * (1 + sx / half_w), height / 2 * (1 - sy / half_h)))
    return parse_scene(text.replace("\n        ", "\n"), source=f"projection_{model}.toml"), np.array(projections)


def centroids(image, points, radius_px):
    return np.array([measure_blur_disk(image.pixels, center_px=p, window_radius_px=radius_px).centroid_px
                     for p in points])


def test_pinhole_projections_agree(tmp_path):
    """Pinhole: image centroids from POV-Ray, the native pinhole and the analytic projection within 0.05 px.

    Reference: POV-Ray 3.7.0.10, ``povray +Iscene.pov +Oout.exr +FE -D -V +Q9
    -UA +W180 +H120 +A0.0 +AM1 +R8 +J1.0 +WT2`` (65 rays per pixel; native:
    256 jittered spp). Measured: at most 0.020 px apart; from the analytic
    projection at most 0.009 px (native) and 0.022 px (POV-Ray), mean offsets
    below 0.003 px.
    Checks the field of view, the frame of a camera with a non-default up, the
    image orientation (row 0 at the top) and the pixel centres.
    """
    scene, projected = projection_scene("pinhole")
    native = render(scene, spp=256, threads=2)
    pov = render_povray(scene, spp=65, threads=2)
    assert pov.metadata["spp"] == 65
    at_native, at_pov = centroids(native, projected, 3.0), centroids(pov, projected, 3.0)
    message = (f"max |POV - native| {np.abs(at_pov - at_native).max():.4f} px, "
               f"max |native - analytic| {np.abs(at_native - projected).max():.4f} px, "
               f"max |POV - analytic| {np.abs(at_pov - projected).max():.4f} px\n{provenance(pov)}")
    ok = max(np.abs(at_pov - at_native).max(), np.abs(at_native - projected).max(),
             np.abs(at_pov - projected).max()) < 0.05
    assert ok, explain(ok, message, tmp_path, native=native, povray=pov)


def test_thin_lens_focal_blur_film_bias_is_corrected(tmp_path):
    """Thin lens: blur-disk centroids land on the analytic projections, on average within 0.01 px.

    POV-Ray's focal blur samples the film 1/32 px left of and above each pixel
    centre on average (see lenscompare.povray.export); uncorrected, the mean
    offset here reads (+0.033, +0.028) px. Reference: POV-Ray 3.7.0.10,
    ``povray +Iscene.pov +Oout.exr +FE -D -V +Q9 -UA +W180 +H120 -A +WT2`` with
    ``blur_samples 256, 256`` (native: 256 jittered spp). Measured with the
    correction: mean offset (+0.001, -0.003) px, at most 0.028 px from native.
    """
    scene, projected = projection_scene("thin")
    native = render(scene, spp=256, threads=2)
    pov = render_povray(scene, spp=256, threads=2)
    at_native, at_pov = centroids(native, projected, 6.0), centroids(pov, projected, 6.0)
    mean_pov, mean_native = (at_pov - projected).mean(axis=0), (at_native - projected).mean(axis=0)
    message = (f"mean offset POV-Ray {mean_pov} px, native {mean_native} px; max |POV - native| "
               f"{np.abs(at_pov - at_native).max():.4f} px\n{provenance(pov)}")
    ok = (np.abs(mean_pov).max() < 0.01 and np.abs(mean_native).max() < 0.01
          and np.abs(at_pov - at_native).max() < 0.08)
    assert ok, explain(ok, message, tmp_path, native=native, povray=pov)


# --- shading -------------------------------------------------------------------------------------------------

SHADING_SCENE = """
[camera]
model = "pinhole"
position = [0.0, 1.0, -3.0]
look_at = [0.0, 0.0, 0.5]
focal_length_mm = 35.0
focus_distance = 3.0
resolution = [120, 80]

[background]
color = [0.1, 0.2, 0.3]

[materials.paint]            # diffuse + emission, blue albedo 0: emission alone
type = "diffuse"
color = [0.5, 0.25, 0.0]
emission = [0.1, 0.2, 0.3]

[materials.glowing_checker]
type = "diffuse"
color = [0.6, 0.6, 0.6]
checker = { color = [0.0, 0.1, 0.2], size = 0.25 }
emission = [0.05, 0.0, 0.5]

[materials.floor]
type = "diffuse"
color = [0.8, 0.7, 0.6]
checker = { color = [0.1, 0.2, 0.3], size = 0.2 }

[materials.lamp]             # radiance above 1
type = "emissive"
color = [3.0, 2.0, 1.5]

[[objects]]
type = "rectangle"
corner = [-1.2, 0.2, 1.0]
edge1 = [1.0, 0.0, 0.0]
edge2 = [0.0, 0.8, 0.3]
material = "paint"

[[objects]]
type = "rectangle"
corner = [0.2, 0.2, 1.0]
edge1 = [1.0, 0.0, 0.2]
edge2 = [0.0, 0.8, 0.0]
material = "glowing_checker"

[[objects]]                  # floor: top face at y = 0, where the checker's 0.001 tolerance decides the phase
type = "box"
min = [-3.0, -0.5, -1.0]
max = [3.0, 0.0, 4.0]
material = "floor"

[[objects]]
type = "sphere"
center = [1.6, 0.9, 3.0]
radius = 0.3
material = "lamp"

[[lights]]
type = "point"
position = [1.0, 3.0, -2.0]
color = [0.9, 0.8, 0.7]

[[lights]]
type = "point"
position = [-2.0, 1.0, 0.5]
color = [0.3, 0.3, 0.5]
"""


def test_shading_agrees_pixel_for_pixel_away_from_edges(tmp_path):
    """Shading equals POV-Ray's to half-float precision.

    Lambert with hard shadows from two lights, the checker's phase on a floor
    at y = 0, emission on diffuse materials (also where the albedo is 0),
    radiance above 1, the background. Compared wherever the native image is flat over 3 x 3 pixels (edges and
    shadow boundaries are anti-aliasing noise, not shading). Reference:
    POV-Ray 3.7.0.10, ``povray +Iscene.pov +Oout.exr +FE -D -V +Q9 -UA +W120
    +H80 +A0.0 +AM1 +R3 +J1.0 +WT2`` (native: 64 jittered spp). Measured:
    largest difference 3.7e-4 (POV-Ray writes half floats: 3 significant digits).
    """
    scene = parse_scene(SHADING_SCENE, source="shading.toml")
    native = render(scene, spp=64, threads=2)
    pov = render_povray(scene, spp=10, threads=2)
    a, b = native.pixels, pov.pixels

    padded = np.pad(a, ((1, 1), (1, 1), (0, 0)), mode="edge")
    windows = np.stack([padded[i:i + a.shape[0], j:j + a.shape[1]] for i in range(3) for j in range(3)])
    flat = (windows.max(axis=0) - windows.min(axis=0)).max(axis=-1) < 0.01
    difference = np.abs(a - b).max(axis=-1)
    tolerance = 1e-3 * np.maximum(1.0, a.max(axis=-1))  # half floats: 2^-11 relative
    bad = flat & (difference > tolerance)
    message = (f"{bad.sum()} of {flat.sum()} flat pixels differ by more than 1e-3 (largest "
               f"{difference[flat].max():.2e})\n{provenance(pov)}")
    assert flat.mean() > 0.3, "too few flat pixels to compare"
    assert not bad.any(), explain(not bad.any(), message, tmp_path, native=native, povray=pov,
                                  difference=np.abs(a - b))
    assert b.max() == pytest.approx(3.0, rel=1e-3), "emission above 1 must survive into POV-Ray's EXR"


CHECKER_CORNER_SCENE = """
[camera]                     # 5 cm above the floor, looking down: 0.1 mm = 0.001 checker sizes per pixel
model = "pinhole"
position = [0.1, 0.05, 0.1]
look_at = [0.1, 0.0, 0.1]
up = [0.0, 0.0, 1.0]
focal_length_mm = 50.0
focus_distance = 0.06
resolution = [60, 40]

[materials.floor]
type = "diffuse"
color = [1.0, 1.0, 1.0]
checker = { color = [0.0, 0.0, 0.0], size = 0.1 }

[[objects]]                  # top face at y = 0
type = "box"
min = [-3.0, -0.5, -3.0]
max = [3.0, 0.0, 3.0]
material = "floor"

[[lights]]
type = "point"
position = [0.1, 10.0, 0.1]
color = [1.0, 1.0, 1.0]
"""


def test_checker_cube_boundaries_coincide():
    """The checker's cube boundaries agree to 0.01 px (1e-4 checker sizes); the floor at y = 0 has the same phase.

    The camera looks straight down at the cube corner x = z = 0.1 m (size
    0.1 m) from 5 cm, so a pixel spans 0.1 mm: our checker, floor(p/s +
    0.001), puts the boundaries 0.1 mm = 1 px before the corner (raster x 29,
    y 21; the image centre is (30, 20)). POV-Ray 3.7's own checker uses
    floor(q + 1e-10) and would put them on the corner; the export moves its
    pattern by 0.001 s. Reference: POV-Ray 3.7.0.10, ``povray +Iscene.pov
    +Oout.exr +FE -D -V +Q9 -UA +W60 +H40 +A0.0 +AM1 +R8 +J1.0 +WT2``.
    """
    scene = parse_scene(CHECKER_CORNER_SCENE, source="checker_corner.toml")
    for image in (render(scene, spp=64, threads=2), render_povray(scene, spp=65, threads=2)):
        white = image.pixels[..., 0]
        assert white[0, 0] == pytest.approx(0.0) and white[-1, 0] == pytest.approx(1.0)  # phase: (0, 0, 0) even
        # boundary positions from how many pixels are white along rows and columns far from the other edge
        x_below, x_above = white[30:].sum(axis=1).mean(), 60 - white[:10].sum(axis=1).mean()
        y_left, y_right = 40 - white[:, :10].sum(axis=0).mean(), white[:, 50:].sum(axis=0).mean()
        where = image.metadata.get("renderer", "native")
        assert (x_below, x_above) == pytest.approx((29.0, 29.0), abs=0.01), where
        assert (y_left, y_right) == pytest.approx((21.0, 21.0), abs=0.01), where


# --- showcase ------------------------------------------------------------------------------------------------


def test_showcase_matches_povray(tmp_path):
    """reference_scenes/showcase.toml through the thin lens: SSIM >= 0.97, relative RMSE <= 3 %.

    Reference: POV-Ray 3.7.0.10, ``povray +Iscene.pov +Oout.exr +FE -D -V +Q9
    -UA +W360 +H240 -A +WT2`` with ``blur_samples 256, 256`` (native: 256
    jittered spp). Measured: SSIM 0.999, relative RMSE 1.1 % — the noise of two
    256-sample renders (native 256 spp against native 1024 spp alone reads
    0.7 %); the means agree within 0.1 %.
    """
    scene = load_scene(REFERENCE_SCENES / "showcase.toml")
    native = render(scene, spp=256, threads=2)
    pov = render_povray(scene, spp=256, threads=2)
    a, b = native.pixels, pov.pixels
    similarity = ssim(a, b, data_range=1.0)
    error = relative_rmse(a, b)
    mean_ratio = float(b.mean() / a.mean())
    message = (f"SSIM {similarity:.4f}, relative RMSE {error:.2%}, mean POV/native {mean_ratio:.4f}\n"
               f"{provenance(pov)}")
    ok = similarity >= 0.97 and error <= 0.03 and abs(mean_ratio - 1.0) <= 0.005
    assert ok, explain(ok, message, tmp_path, native=native, povray=pov, difference=b - a)
