"""The render's single-precision lens trace against the double-precision
reference, lens by lens: for every shipped lens and the hard-case test lenses
(a cemented layer of zero thickness, flat and nearly flat fronts, a prism at
total internal reflection, a stop at f/64), the same film and pupil samples
through both batch traces (the camera's fastest kernel), and the largest
differences of the rays that leave the lens. Prints one JSON object; the
bounds tests/lens_batch_check.py asserts sit above these figures. Not a test.

Usage: python bench/check_lens_trace_single.py [--samples N]
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from lenscompare._native import diagnostics  # noqa: E402
from lenscompare.cameras import camera_for  # noqa: E402

from test_camera_lens import lens_scene  # noqa: E402  (the tests' scene around a lens)

TEST_LENSES = ROOT / "tests" / "data" / "lenses"
CASES = [("dgauss.50mm", None), ("dgauss.50mm", 64.0), ("wide.22mm", None), ("fisheye.10mm", None),
         ("telephoto.250mm", None)] + [
    (str(TEST_LENSES / f"{name}.dat"), None) for name in (
        "thin_singlet", "biconvex_stop_front", "cemented_zero_layer", "planoconvex_flat_front",
        "planoconvex_nearly_flat_front", "tir_prism")]


def traced(camera, raster, lens, precision):
    diagnostics.set_lens_trace_precision(camera, precision)
    out = np.zeros((len(raster), 3)), np.zeros((len(raster), 3)), np.zeros(len(raster), np.float32)
    diagnostics.generate_lens_rays_batched(camera, raster, lens, *out)
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples", type=int, default=200_000)
    args = parser.parse_args()
    rng = np.random.default_rng(5)
    raster = (rng.random((args.samples, 2)) * [360, 240]).astype(np.float32)
    lens = rng.random((args.samples, 2)).astype(np.float32)
    rows = {}
    for name, f_number in CASES:
        scene = lens_scene(name, f_number=f_number, focus_distance=10.0 if "telephoto" in name else 2.0)
        camera = camera_for(scene, "lens").native()
        single, double = traced(camera, raster, lens, "single"), traced(camera, raster, lens, "double")
        passed_single, passed_double = np.any(single[1] != 0, axis=1), np.any(double[1] != 0, axis=1)
        both = passed_single & passed_double
        rows[f"{Path(name).stem if name.endswith('.dat') else name}" + (f" f/{f_number:g}" if f_number else "")] = {
            "passed": int(passed_double.sum()),
            "blocked_by_one_only": int(np.sum(passed_single != passed_double)),
            "largest_origin_difference_mm": float(np.abs(single[0][both] - double[0][both]).max() * 1e3),
            "largest_direction_difference": float(np.abs(single[1][both] - double[1][both]).max()),
            "all_finite": bool(all(np.isfinite(a).all() for a in single)),
        }
    print(json.dumps({"samples_per_lens": args.samples, "kernel": diagnostics.lens_trace_kernel(camera),
                      "lenses": rows}, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
