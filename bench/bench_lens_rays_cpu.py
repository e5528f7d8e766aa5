"""Lens-system camera rays alone: CPU nanoseconds per ray on each trace kernel,
in single precision (the render's trace) and double (the reference).

bench_lens_cpu.py times whole renders, where the lens trace is a third of the
lens model's cost and other work on a shared machine moves the ratio by a few
per cent. This times only what the lens camera adds: film point, exit-pupil
pick, aim, the trace through the Double Gauss (full aperture) and the
lens-to-world step, through the render loop's batched path
(``diagnostics.generate_lens_rays_batched``), on showcase.toml's camera. The
samples come in the render loop's order (16-pixel tiles, several samples per
pixel in a row), so the pupil tables stay cached as they do in a render. Cost
is this process's CPU time, best of ``--repeat``. Each kernel's rays are
hashed: every kernel must give the same bits within a precision. The single
trace's largest departure from the double one over these rays is printed too
(origins in mm, directions; samples blocked by one trace only), and the same
rays' cost from the lens-ray table (``lens_rays = "table"``, 16 x 64 cells,
the fastest kernel for the cells it traces), and both through the render's
own float path (``ns_per_ray_render_rows``: the packets' rows, where the
table's rays go to the world in float). Prints one JSON object. Not a test. Usage::

    flock /tmp/bench.lock .venv/bin/python bench/bench_lens_rays_cpu.py [--repeat 15]
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lenscompare._native import diagnostics  # noqa: E402
from lenscompare.cameras import camera_for  # noqa: E402
from lenscompare.cameras.lens_ray_table import TABLE_CELLS  # noqa: E402
from lenscompare.scene import load_scene  # noqa: E402
from render_order import render_order_samples  # noqa: E402

LENS = "dgauss.50mm"
WIDTH_PX, HEIGHT_PX = 240, 160
PRECISIONS = ("single", "double")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--samples-per-pixel", type=int, default=8)
    parser.add_argument("--repeat", type=int, default=15, help="timed passes per kernel; the best counts")
    args = parser.parse_args()

    scene = load_scene(ROOT / "reference_scenes" / "showcase.toml").with_camera(resolution=(WIDTH_PX, HEIGHT_PX))
    camera = camera_for(scene.with_camera(lens=LENS, f_number=None), "lens").native()
    raster, lens = render_order_samples(WIDTH_PX, HEIGHT_PX, samples_per_pixel=args.samples_per_pixel, seed=3)
    n = len(raster)
    out = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n, np.float32)
    kernels = diagnostics.lens_trace_kernels()
    best = {(precision, kernel): float("inf") for precision in PRECISIONS for kernel in kernels}
    ray_hash, rays = {}, {}
    table_best = float("inf")
    rows_out = np.zeros((n, 3), np.float32), np.zeros((n, 3), np.float32), np.zeros(n, np.float32)
    rows_best = {"table": float("inf"), "traced": float("inf")}
    # Alternating passes, so that a busy spell of the machine does not land on one kernel only.
    for _ in range(args.repeat):
        for precision, kernel in best:
            diagnostics.set_lens_trace_precision(camera, precision)
            diagnostics.set_lens_trace_kernel(camera, kernel)
            start = time.process_time()
            diagnostics.generate_lens_rays_batched(camera, raster, lens, *out)
            best[precision, kernel] = min(best[precision, kernel], time.process_time() - start)
            ray_hash[precision, kernel] = hashlib.sha1(b"".join(a.tobytes() for a in out)).hexdigest()[:16]
            rays[precision] = tuple(a.copy() for a in out)
        # The same rays from the lens-ray table ([render] lens_rays = "table"), the fastest kernel
        # for the cells it traces.
        diagnostics.set_lens_trace_precision(camera, "single")
        diagnostics.set_lens_trace_kernel(camera, kernels[-1])
        # The render's own path (float rows, as the packets take them) too, from the table and traced.
        camera.use_ray_table(*TABLE_CELLS[0])
        start = time.process_time()
        diagnostics.generate_lens_rays_batched(camera, raster, lens, *out)
        table_best = min(table_best, time.process_time() - start)
        for source in ("table", "traced"):
            if source == "traced":
                camera.use_ray_table(0, 0)
            start = time.process_time()
            diagnostics.generate_lens_ray_rows(camera, raster, lens, *rows_out)
            rows_best[source] = min(rows_best[source], time.process_time() - start)
    single, double = rays["single"], rays["double"]
    passed_single, passed_double = np.any(single[1] != 0.0, axis=1), np.any(double[1] != 0.0, axis=1)
    both = passed_single & passed_double
    print(json.dumps({
        "benchmark": "lens-system camera rays alone, CPU ns per ray (pick, aim, trace, to world)",
        "scene": "showcase",
        "lens": LENS,
        "rays": n,
        "repeat": args.repeat,
        "ns_per_ray_by_kernel": {precision: {kernel: best[precision, kernel] / n * 1e9 for kernel in kernels}
                                 for precision in PRECISIONS},
        "single_over_double_time": {kernel: best["single", kernel] / best["double", kernel] for kernel in kernels},
        "ns_per_ray_from_the_table": table_best / n * 1e9,
        "table_over_single_trace_time": table_best / best["single", kernels[-1]],
        "ns_per_ray_render_rows": {source: seconds / n * 1e9 for source, seconds in rows_best.items()},
        "render_rows_table_over_traced_time": rows_best["table"] / rows_best["traced"],
        "fraction_passed": float(np.mean(passed_double)),
        "kernels_agree_bit_for_bit": {precision: len({ray_hash[precision, k] for k in kernels}) == 1
                                      for precision in PRECISIONS},
        "single_against_double": {
            "largest_origin_difference_mm": float(np.abs(single[0][both] - double[0][both]).max() * 1e3),
            "largest_direction_difference": float(np.abs(single[1][both] - double[1][both]).max()),
            "blocked_by_one_only": int(np.sum(passed_single != passed_double)),
        },
    }, indent=2))
    return 0


if __name__ == "__main__":
    sys.exit(main())
