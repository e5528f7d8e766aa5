"""Diffraction: the pupil's Fraunhofer PSF against the Airy closed form, the
N-gon's star, the pixel footprint, and the PSF applied to rendered images."""

import json
import math

import numpy as np
import pytest
from scipy import signal

from lenscompare.cameras import camera_for
from lenscompare.diffraction import DiffractionAperture, convolve_image, diffract, diffraction_aperture, \
    diffraction_kernel
from lenscompare.errors import InputError
from lenscompare.image import read_exr
from lenscompare.optics.diffraction import (AIRY_FIRST_ZERO, BAND_NM, airy_encircled_energy, airy_intensity,
                                            channel_weights, colour_matching_functions, pupil_psf)
from lenscompare.render import render
from lenscompare.scene import parse_scene

from helpers import camera_scene_text, run_cli, sphere_text

MONO = dict(wavelengths_nm=[550.0], weights=[[1.0]])


def pixel_integrated_airy(radius_px, *, pitch_mm, working_f_number, sub=12):
    """The Airy pattern integrated over each pixel of a (2R+1)² grid (independent of the FFT)."""
    offsets = (np.arange(sub) + 0.5) / sub - 0.5
    yy, xx = np.mgrid[-radius_px:radius_px + 1, -radius_px:radius_px + 1].astype(float)
    total = np.zeros_like(xx)
    for a in offsets:
        for b in offsets:
            total += airy_intensity(np.hypot(xx + a, yy + b) * pitch_mm, wavelength_nm=550.0,
                                    working_f_number=working_f_number)
    # Normalised density: π / (4 (λN)²) at the centre, per unit area.
    lam_n_px = 550e-6 * working_f_number / pitch_mm
    return total / sub ** 2 * math.pi / (4.0 * lam_n_px ** 2)


@pytest.mark.parametrize("working_f_number,pitch_mm", [(22.0, 0.004), (8.0, 0.002), (2.8, 0.004), (32.0, 0.001)])
def test_circular_pupil_gives_the_airy_pattern_pixel_by_pixel(working_f_number, pitch_mm):
    aperture = DiffractionAperture(working_f_number=working_f_number, blades=0, rotation_deg=0.0,
                                   pixel_pitch_mm=pitch_mm)
    kernel = diffraction_kernel(aperture, **MONO)[..., 0]
    r = kernel.shape[0] // 2
    near = min(r, 40)
    expected = pixel_integrated_airy(near, pitch_mm=pitch_mm, working_f_number=working_f_number)
    got = kernel[r - near:r + near + 1, r - near:r + near + 1]
    assert np.abs(got - expected).max() < 0.01 * expected.max()
    # Energy: what the kernel holds is what the Airy pattern holds within its square.
    assert kernel.sum() == pytest.approx(1.0, abs=0.02)


def radial_profile(image, centre, *, step=0.25, r_max):
    yy, xx = np.mgrid[0:image.shape[0], 0:image.shape[1]]
    r = np.hypot(xx + 0.5 - centre[0], yy + 0.5 - centre[1])
    edges = np.arange(0.0, r_max + step, step)
    index = np.digitize(r.ravel(), edges) - 1
    ok = (index >= 0) & (index < len(edges) - 1)
    sums = np.bincount(index[ok], weights=image.ravel()[ok], minlength=len(edges) - 1)
    counts = np.bincount(index[ok], minlength=len(edges) - 1)
    return edges[:-1] + step / 2, sums / np.maximum(counts, 1)


def encircled(image, centre, radius, sub=8):
    """Flux within a circle, pixels cut by its edge counted by the fraction inside."""
    offsets = (np.arange(sub) + 0.5) / sub
    yy, xx = np.mgrid[0:image.shape[0], 0:image.shape[1]]
    inside = np.zeros(image.shape)
    for a in offsets:
        for b in offsets:
            inside += np.hypot(xx + a - centre[0], yy + b - centre[1]) <= radius
    return float(np.sum(image * inside / sub ** 2))


POINT_SCENE = dict(f_number=32.0, focus_distance=2.0, resolution=(160, 160), film_mm=(0.16, 0.16), spp=64)


def point_render(*, blades=0, rotation_deg=0.0, pitch_mm=0.001, **extra):
    """A sphere at the focus distance imaged to half a pixel (1 µm pixels), 160 px square."""
    text = camera_scene_text(**{**POINT_SCENE, "film_mm": (160 * pitch_mm, 160 * pitch_mm)})
    text = text.replace("film_mm = ", f"aperture_blades = {blades}\naperture_rotation_deg = {rotation_deg}\n"
                                      "film_mm = ", 1)
    scene = parse_scene(text + sphere_text((0.0, 0.0, 2.0), 1e-5))
    return scene, render(scene, threads=2, **extra)


def test_rendered_point_through_a_circle_has_the_airy_dark_ring_and_energy():
    """Monochromatic 550 nm, f/32 focused at 2 m (N_w = 32.8): the first
    minimum within 2 % of 1.22 λ N_w, 83.8 % ± 1.5 % of the flux inside it."""
    scene, image = point_render()
    sharp = image.pixels[..., 1].astype(float)
    flux = sharp.sum()
    yy, xx = np.mgrid[0:sharp.shape[0], 0:sharp.shape[1]]
    centre = ((sharp * (xx + 0.5)).sum() / flux, (sharp * (yy + 0.5)).sum() / flux)
    aperture = diffraction_aperture(scene, image.camera)
    assert aperture.working_f_number == pytest.approx(32.0 * (1 + 50.0 / (2000.0 - 50.0)), rel=1e-9)
    blurred, _, info = diffract(image.pixels, None, aperture, **MONO)
    psf = blurred[..., 1].astype(float)
    zero_px = AIRY_FIRST_ZERO * 550e-6 * aperture.working_f_number / camera_for(scene).pixel_pitch_mm
    r, profile = radial_profile(psf, centre, r_max=1.5 * zero_px)
    near = (r > 0.8 * zero_px) & (r < 1.2 * zero_px)
    i = np.flatnonzero(near)[np.argmin(profile[near])]
    a, b, _ = np.polyfit(r[i - 3:i + 4], profile[i - 3:i + 4], 2)
    first_minimum_px = -b / (2 * a)
    assert first_minimum_px == pytest.approx(zero_px, rel=0.02)
    energy = encircled(psf, centre, zero_px) / flux
    assert energy == pytest.approx(0.838, abs=0.015)
    # Independent of the measurement above: the closed form says the same.
    assert float(airy_encircled_energy(zero_px * 1e-3, wavelength_nm=550.0,
                                       working_f_number=aperture.working_f_number)) == pytest.approx(0.8378, abs=1e-4)
    assert info["airy_diameter_px_550nm"] == pytest.approx(2 * zero_px)


def spike_angles(psf, centre, *, r_min, r_max, bins=360, prominence=1.0):
    """Directions (degrees, y up) of the star's spikes: peaks of the log of
    the intensity × r³ (the falloff flattened), averaged over an annulus."""
    yy, xx = np.mgrid[0:psf.shape[0], 0:psf.shape[1]]
    x, y = xx + 0.5 - centre[0], -(yy + 0.5 - centre[1])
    r, a = np.hypot(x, y), np.degrees(np.arctan2(y, x)) % 360
    ring = (r > r_min) & (r < r_max)
    index = (a[ring] / 360 * bins).astype(int) % bins
    profile = np.log(np.bincount(index, weights=(psf[ring] * r[ring] ** 3), minlength=bins)
                     / np.maximum(np.bincount(index, minlength=bins), 1))
    tripled = np.concatenate([profile] * 3)
    peaks, _ = signal.find_peaks(tripled, prominence=prominence)
    peaks = peaks[(peaks >= bins) & (peaks < 2 * bins)] - bins
    return (peaks + 0.5) * 360 / bins


@pytest.mark.parametrize("blades", [3, 5, 6, 7, 8, 9])
def test_polygon_psf_is_a_star_of_2n_spikes_for_odd_n_and_n_for_even(blades):
    psf = pupil_psf(blades, 10.0, samples_across=128, spacing=0.25)
    n = psf.intensity.shape[0]
    # The PSF grid has rows along +y: flip it to image rows for spike_angles.
    spikes = spike_angles(psf.intensity[::-1], (n / 2, n / 2), r_min=3 / psf.spacing, r_max=20 / psf.spacing)
    assert len(spikes) == (2 * blades if blades % 2 else blades)
    circle = pupil_psf(0, 0.0, samples_across=128, spacing=0.25)
    assert len(spike_angles(circle.intensity, (n / 2, n / 2), r_min=3 / psf.spacing, r_max=20 / psf.spacing)) == 0


def test_rendered_pentagon_star_has_ten_spikes_square_to_its_edges():
    """The spikes run along the edges' normals (both ways), in the picture's
    own orientation (a vertically flipped star would sit 20° off)."""
    blades, rotation = 5, 10.0
    scene, image = point_render(blades=blades, rotation_deg=rotation, pitch_mm=0.002)  # λN_w = 9 px
    sharp = image.pixels[..., 1].astype(float)
    yy, xx = np.mgrid[0:sharp.shape[0], 0:sharp.shape[1]]
    centre = ((sharp * (xx + 0.5)).sum() / sharp.sum(), (sharp * (yy + 0.5)).sum() / sharp.sum())
    blurred, _, _ = diffract(image.pixels, None, diffraction_aperture(scene, image.camera), **MONO)
    spikes = spike_angles(blurred[..., 1].astype(float), centre, r_min=27, r_max=77)  # 3-8.5 λN_w
    assert len(spikes) == 2 * blades
    normals = (90.0 + rotation + 180.0 / blades + 360.0 / blades * np.arange(blades))
    expected = np.sort(np.concatenate([normals, normals + 180]) % 360)
    off = (np.sort(spikes)[:, None] - expected[None, :] + 180) % 360 - 180
    assert np.abs(off).min(axis=1).max() < 3.0


def test_psf_narrower_than_a_pixel_stays_in_the_pixel():
    """f/1.4 on 10 µm pixels: λN = 0.8 µm; the pixel footprint holds all but
    the little that the Airy pattern puts across its edges."""
    aperture = DiffractionAperture(working_f_number=1.4, blades=6, rotation_deg=0.0, pixel_pitch_mm=0.010)
    kernel = diffraction_kernel(aperture, **MONO)[..., 0]
    r = kernel.shape[0] // 2
    expected = pixel_integrated_airy(1, pitch_mm=0.010, working_f_number=1.4, sub=40)[1, 1]  # hexagon ~ circle
    assert kernel[r, r] == pytest.approx(expected, abs=0.01)
    assert kernel[r, r] > 0.95


def test_red_blurs_more_than_blue_and_the_weights_are_colour_matching_functions():
    import colour  # here: colour-science takes seconds to import, and only this test needs it

    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"]
    np.testing.assert_allclose(colour_matching_functions(BAND_NM), [cmfs[w] for w in BAND_NM], atol=2e-6)
    weights = channel_weights(BAND_NM)
    assert weights.shape == (3, len(BAND_NM)) and np.allclose(weights.sum(axis=1), 1.0)
    peak_nm = [BAND_NM[i] for i in weights.argmax(axis=1)]
    assert 590 <= peak_nm[0] <= 620 and 530 <= peak_nm[1] <= 560 and 440 <= peak_nm[2] <= 460
    aperture = DiffractionAperture(working_f_number=16.0, blades=0, rotation_deg=0.0, pixel_pitch_mm=0.002)
    kernel = diffraction_kernel(aperture)
    r = kernel.shape[0] // 2
    centre = kernel[r, r]
    assert centre[2] > centre[1] > centre[0]


def test_uniform_image_stays_uniform_and_a_point_keeps_its_energy():
    aperture = DiffractionAperture(working_f_number=22.0, blades=7, rotation_deg=3.0, pixel_pitch_mm=0.004)
    kernel = diffraction_kernel(aperture)
    flat = np.full((90, 120, 3), 0.25, np.float32)
    out, _, info = diffract(flat, None, aperture)
    np.testing.assert_allclose(out, 0.25, rtol=2e-5)
    assert 0 <= info["energy_beyond_kernel"] < 0.01
    point = np.zeros((401, 401, 3), np.float32)
    point[200, 200] = 1.0
    spread = convolve_image(point, kernel)
    np.testing.assert_allclose(spread.sum(axis=(0, 1)), kernel.sum(axis=(0, 1)), rtol=1e-3)  # float32 FFT
    np.testing.assert_allclose(spread[200 - 20:200 + 21, 200 - 20:200 + 21],
                               kernel[kernel.shape[0] // 2 - 20:kernel.shape[0] // 2 + 21,
                                      kernel.shape[0] // 2 - 20:kernel.shape[0] // 2 + 21], atol=1e-6)


def test_render_with_diffraction_is_the_same_for_any_thread_count_and_records_it():
    text = camera_scene_text(f_number=16.0, resolution=(96, 64), film_mm=(0.384, 0.256), spp=8)
    scene = parse_scene(text + sphere_text((0.0, 0.0, 2.0), 1e-4))
    one, two = (render(scene, threads=t, diffraction=True) for t in (1, 2))
    np.testing.assert_array_equal(one.pixels, two.pixels)
    info = one.metadata["diffraction"]
    assert info["wavelengths_nm"] == [400.0, 700.0, 31] and info["aperture_blades"] == 0
    assert one.pixels[..., 1].max() < 0.5 * render(scene, threads=1).pixels[..., 1].max()


def test_command_line_diffraction_flag_and_a_pinhole_without_aperture(tmp_path):
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(camera_scene_text(resolution=(48, 32), spp=4) + sphere_text((0.0, 0.0, 2.0), 0.01))
    out = tmp_path / "out.exr"
    result = run_cli("render", scene_file, "-o", out, "--diffraction", "--json")
    assert result.returncode == 0, result.stderr
    assert json.loads(result.stdout)["diffraction"]["working_f_number"] > 2.8
    assert "diffraction" in read_exr(out).metadata
    # A pinhole with no f-number has no aperture to diffract.
    text = camera_scene_text(model="pinhole", resolution=(48, 32), spp=4).replace("f_number = 2.8\n", "")
    text = text.replace("[render]\n", "[render]\ndiffraction = true\n")
    scene_file.write_text(text)
    result = run_cli("render", scene_file, "-o", out)
    assert result.returncode == 2 and "render.diffraction" in result.stderr
    assert len(result.stderr.strip().splitlines()) == 1
    with pytest.raises(InputError, match="render.diffraction"):
        render(parse_scene(text), diffraction=True)


def test_an_absurdly_large_psf_stays_finite_and_bounded():
    """f/2000 on 1 µm pixels (an Airy disk 2.7 mm, 2700 px wide): the PSF grid
    stays within its FFT limit, the kernel within 512 px, the image finite
    and its flux kept (the veil takes what the kernel cannot hold)."""
    aperture = DiffractionAperture(working_f_number=2000.0, blades=5, rotation_deg=0.0, pixel_pitch_mm=0.001)
    kernel = diffraction_kernel(aperture)
    assert kernel.shape[0] <= 2 * 512 + 1 and np.isfinite(kernel).all()
    image = np.zeros((48, 64, 3), np.float32)
    image[20, 30] = 1.0
    out, _, info = diffract(image, None, aperture)
    assert np.isfinite(out).all() and out.min() >= -1e-6
    np.testing.assert_allclose(out.sum(axis=(0, 1)), 1.0, rtol=0.02)
