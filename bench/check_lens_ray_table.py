"""The lens-ray table (``[render] lens_rays = "table"``) against the trace,
lens by lens: for every shipped lens (Double Gauss also at f/8 and f/1000)
and the hard-case test lenses (a bladed stop is refused outright: not round), the same film and pupil
samples through the traced and the interpolated batch rays at each grid the
render may use, and how far the rays that leave the lens differ: direction
error in pixels' angles (percentiles), the share of samples that pass one way
only, the weight sum against the traced, the grid's build seconds, and what
the render's own check (lenscompare.cameras.lens_ray_table) decides. Prints
one JSON object; tests/test_lens_ray_table.py's bounds sit above these
figures. Not a test.

Usage: python bench/check_lens_ray_table.py [--samples N]
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import numpy as np

from lenscompare.cameras import camera_for
from lenscompare.cameras.lens_ray_table import TABLE_CELLS, batch_rays, use_ray_table
from lenscompare.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "reference_scenes" / "showcase.toml"
TEST_LENSES = ROOT / "tests" / "data" / "lenses"
CASES = [("dgauss.50mm", None, 0), ("dgauss.50mm", 8.0, 0), ("dgauss.50mm", 1000.0, 0), ("wide.22mm", None, 0), ("fisheye.10mm", None, 0), ("telephoto.250mm", None, 0),
         *((str(TEST_LENSES / f"{name}.dat"), None, 0) for name in
           ("cemented_zero_layer", "planoconvex_flat_front", "planoconvex_nearly_flat_front", "tir_prism"))]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--samples", type=int, default=1 << 17)
    args = parser.parse_args()
    rng = np.random.default_rng(7)
    results = {"benchmark": "lens_ray_table", "samples": args.samples, "lenses": {}}
    for lens, f_number, blades in CASES:
        scene = load_scene(SCENE).with_camera(lens=lens, f_number=f_number, aperture_blades=blades,
                                              focal_length_mm=None)
        model = camera_for(scene, "lens")
        camera = model.native()
        width, height = scene.camera.resolution
        raster = np.column_stack([rng.uniform(0, width, args.samples),
                                  rng.uniform(0, height, args.samples)]).astype(np.float32)
        lens_sample = rng.uniform(0, 1, (args.samples, 2)).astype(np.float32)
        _, *traced = batch_rays(camera, raster, lens_sample)
        pixel_angle = (model.film.width_mm / width) / model.focal_length_mm
        grids = {}
        for cells in TABLE_CELLS:
            start = time.perf_counter()
            camera.use_ray_table(*cells)
            build_s = time.perf_counter() - start
            _, *table = batch_rays(camera, raster, lens_sample)
            both = (table[1] > 0) & (traced[1] > 0)
            error = np.linalg.norm(table[0][both] - traced[0][both], axis=1) / pixel_angle
            grids[f"{cells[0]}x{cells[1]}"] = {
                "direction_error_px": {f"p{q}": float(np.percentile(error, q)) for q in (50, 99, 99.9)}
                | {"max": float(error.max())},
                "passing_one_way_only": float(np.mean((table[1] > 0) != (traced[1] > 0))),
                "weight_sum_over_traced": float(table[1].sum() / traced[1].sum()),
                "build_seconds": build_s,
            }
        camera.use_ray_table(0, 0)
        name = Path(lens).stem if lens.endswith(".dat") else lens
        key = name + (f" f/{f_number:g}" if f_number else "") + (f" {blades} blades" if blades else "")
        results["lenses"][key] = {"grids": grids, "render_check": use_ray_table(model, camera)}
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
