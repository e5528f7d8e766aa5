"""Could a lens system's rays carry bands of wavelengths, as the dispersive
thin lens's do? The measurements that decide it (issue 15; README,
"Wavelength", next steps).

A band ray is one scene ray shaded once for a stretch of the spectrum. For
the thin lens each wavelength's film point is a shift of the reference
one, so the stretches follow from the geometry. Through a lens system the
scene ray a sample sends out at a reference wavelength comes from a film
point that moves with the wavelength along a curve (lateral and
longitudinal colour), found by tracing the ray back through the glass
(LensSystemCamera::film_points_from). This study samples the film and the
exit pupil as a render does, traces each sample toward the scene at the
reference wavelength and back at every 25 nm from 380 to 780 nm, and
prints (JSON):

- passing: the share of samples the lens passes at the reference;
- valid_at_every_wavelength: of those, the share that passes back at all
  17 wavelengths (the others cross a rim or meet total internal reflection
  at some wavelength: their bands end inside the spectrum);
- one_pixel: the share whose 17 film points lie in one pixel (a single
  band ray for the whole spectrum, no splitting);
- spread_px: how far the film point moves over the spectrum (the larger of
  its x and y ranges, pixels): median, 90th and 99th percentile, max;
- fit_error_px: the film point as a quadratic in 1 / wavelength^2 through
  three back-traced wavelengths (380 nm, the reference, 780 nm), against
  the trace at the 14 others (max, 99th percentile), and the same for a
  straight line through the two ends: how few back traces would place
  every wavelength;
- ns_per_sample: the forward trace and one back trace, lens alone, one
  thread, against the forward trace alone (the render's batch trace).

Usage: python bench/study_lens_bands.py [--samples N] [--resolution W H] [--lens FILE]
"""

from __future__ import annotations

import argparse
import json
import tempfile
import time
from pathlib import Path

import numpy as np

from lenscompare._native import diagnostics
from lenscompare.cameras import camera_for
from lenscompare.render_spectral import lens_indices
from lenscompare.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "reference_scenes" / "showcase.toml"
DISPERSIVE_LENS = ROOT / "tests" / "data" / "lenses" / "dgauss_abbe.dat"
REFERENCE_NM = 587.0  # the d line (587.6 nm) rounded to the glass table's nm
WAVELENGTHS_NM = np.arange(380.0, 781.0, 25.0)


def _camera(lens: Path, resolution):
    text = SCENE.read_text().replace('model = "thin"', f'model = "lens"\nlens = "{lens}"') \
        .replace("focal_length_mm = 50.0\n", "").replace("f_number = 2.8\n", "") \
        .replace("resolution = [360, 240]", f"resolution = [{resolution[0]}, {resolution[1]}]")
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "scene.toml"
        path.write_text(text)
        camera = camera_for(load_scene(path), "lens")
    native = camera.native()
    native.set_dispersion(*lens_indices(camera.prescription))
    return camera, native


def _film_points(native, raster, lens, back_nm):
    n = len(raster)
    origin, direction = np.zeros((n, 3)), np.zeros((n, 3))
    film, alive = np.zeros((n, 2)), np.zeros(n, bool)
    start = time.perf_counter()
    diagnostics.lens_film_points_from(native, raster, lens, np.full(n, REFERENCE_NM, np.float32),
                                      np.full(n, back_nm, np.float32), origin, direction, film, alive)
    seconds = time.perf_counter() - start
    return film, alive, np.abs(direction).sum(axis=1) > 0, seconds


def _forward_seconds(native, raster, lens):
    n = len(raster)
    out = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)
    start = time.perf_counter()
    diagnostics.generate_lens_rays_batched(native, raster, lens, *out)
    return time.perf_counter() - start


def _fit_errors_px(points_px, s, fit_at):
    """Max and 99th percentile of |fit - trace| over the wavelengths not fitted, pixels."""
    basis = np.vander(s[fit_at], len(fit_at))
    coef = np.linalg.solve(basis, points_px[fit_at].reshape(len(fit_at), -1))
    fitted = (np.vander(s, len(fit_at)) @ coef).reshape(points_px.shape)
    others = np.setdiff1d(np.arange(len(s)), fit_at)
    error = np.abs(fitted[others] - points_px[others])
    return {"max": float(error.max()), "p99": float(np.quantile(error, 0.99))}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=200_000)
    parser.add_argument("--resolution", type=int, nargs=2, default=(180, 120))
    parser.add_argument("--lens", type=Path, default=DISPERSIVE_LENS)
    args = parser.parse_args()
    width, height = args.resolution
    camera, native = _camera(args.lens, (width, height))
    rng = np.random.default_rng(0)
    raster = (rng.random((args.samples, 2)) * [width, height]).astype(np.float32)
    lens = rng.random((args.samples, 2)).astype(np.float32)

    points, valid, seconds = [], [], []
    for nm in WAVELENGTHS_NM:
        film, alive, passed, s = _film_points(native, raster, lens, nm)
        points.append(film), valid.append(alive), seconds.append(s)
    forward = min(_forward_seconds(native, raster, lens) for _ in range(3))
    back = min(min(seconds), min(_film_points(native, raster, lens, 587.0)[3] for _ in range(2)))
    valid = np.array(valid)
    everywhere = valid.all(axis=0)
    mm_per_px = camera.film.width_mm / width
    # Raster pixels: film x runs against raster x (the image is inverted on the film).
    points_px = np.array(points)[:, everywhere] / mm_per_px
    pixel = np.floor(points_px + 1e6)
    one_pixel = (pixel == pixel[:1]).all(axis=(0, 2))
    spread = (points_px.max(axis=0) - points_px.min(axis=0)).max(axis=1)
    s = 1.0 / WAVELENGTHS_NM ** 2
    reference = int(np.argmin(np.abs(WAVELENGTHS_NM - REFERENCE_NM)))
    print(json.dumps({
        "study": "lens_bands",
        "lens": args.lens.name,
        "resolution": [width, height],
        "samples": args.samples,
        "reference_nm": REFERENCE_NM,
        "wavelengths_nm": {"from": 380, "to": 780, "step": 25},
        "passing": float(passed.mean()),
        "valid_at_every_wavelength": float(everywhere.sum() / passed.sum()),
        "one_pixel": float(one_pixel.mean()),
        "spread_px": {"median": float(np.median(spread)), "p90": float(np.quantile(spread, 0.9)),
                      "p99": float(np.quantile(spread, 0.99)), "max": float(spread.max())},
        "fit_error_px": {
            "quadratic_in_inverse_square_nm": _fit_errors_px(points_px, s, [0, reference, len(s) - 1]),
            "line_in_inverse_square_nm": _fit_errors_px(points_px, s, [0, len(s) - 1]),
        },
        "ns_per_sample": {"forward_and_back": 1e9 * back / args.samples, "forward": 1e9 * forward / args.samples},
    }, indent=2))


if __name__ == "__main__":
    main()
