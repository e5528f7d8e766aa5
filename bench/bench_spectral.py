"""Spectral renders against RGB ones: speed and time to a given noise.

Prints one JSON object (issue 15's goals):
- samples/s of the thin lens on showcase.toml, spectral over RGB (goal >= 0.8);
  once as the file has it (no lens: the four hero wavelengths share one ray)
  and once derived from a Double Gauss with Abbe numbers (dispersive: the
  plane of focus per wavelength);
- samples/s of the lens system (that Double Gauss), spectral over RGB
  (goal >= 0.6), with a ray per wavelength (4 per sample, the default) and
  with the hero's ray alone (secondaries terminated);
- time to 1 % relative RMSE on showcase through that lens system, spectral
  over RGB (goal <= 2), for both ways of handling the secondaries; and the
  same for the thin lens derived from it.

Relative RMSE: the RMS difference of two renders with different seeds,
divided by sqrt(2) (each render's own error, with no reference image needed),
over the image's mean. It falls as 1/sqrt(spp) for these samplers at these
counts (checked at two spp), so the time to 1 % is
seconds(spp) * (rmse(spp) / 0.01)^2.

Usage: python bench/bench_spectral.py [--spp N] [--threads T] [--repeat R] [--resolution W H]
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import numpy as np

from lenscompare.render import render
from lenscompare.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "reference_scenes" / "showcase.toml"
DISPERSIVE_LENS = ROOT / "tests" / "data" / "lenses" / "dgauss_abbe.dat"  # Double Gauss with Abbe numbers


def _best_samples_per_second(runs: dict, repeat: int) -> dict:
    """Each named render's best samples/s over repeat rounds, the renders alternated within a round."""
    best = {name: 0.0 for name in runs}
    for _ in range(repeat):
        for name, run in runs.items():
            best[name] = max(best[name], run().metadata["samples_per_second"])
    return best


def _time_to_one_percent(run, spp: int) -> dict:
    """Seconds to 1 % relative RMSE, from two renders of different seeds at spp."""
    a, b = run(spp=spp, seed=1), run(spp=spp, seed=2)
    rmse = float(np.sqrt(np.mean((a.pixels.astype(np.float64) - b.pixels) ** 2) / 2.0))
    relative = rmse / float(np.mean(0.5 * (a.pixels + b.pixels)))
    seconds = 0.5 * (a.metadata["seconds"] + b.metadata["seconds"])
    return {"spp": spp, "relative_rmse": relative, "seconds": seconds,
            "seconds_to_1_percent": seconds * (relative / 0.01) ** 2}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--noise-spp", type=int, default=64, help="spp of the time-to-1 %% renders")
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--repeat", type=int, default=3, help="renders per configuration (the best counts)")
    parser.add_argument("--resolution", type=int, nargs=2, default=(180, 120))
    args = parser.parse_args()

    showcase = load_scene(SCENE).with_camera(resolution=tuple(args.resolution))
    lens_scene = showcase.with_camera(lens=str(DISPERSIVE_LENS), focal_length_mm=None)

    def runner(scene, model, spectral, trace=True, spp=args.spp, seed=0):
        return lambda **kw: render(scene, model=model, spectral=spectral, trace_secondaries=trace,
                                   threads=args.threads, progress=False, **{"spp": spp, "seed": seed, **kw})

    sps = _best_samples_per_second({
        "thin_rgb": runner(showcase, "thin", False),
        "thin_spectral": runner(showcase, "thin", True),
        "thin_dispersive_rgb": runner(lens_scene, "thin", False),
        "thin_dispersive_spectral": runner(lens_scene, "thin", True),
        "lens_rgb": runner(lens_scene, "lens", False),
        "lens_spectral_traced": runner(lens_scene, "lens", True),
        "lens_spectral_terminated": runner(lens_scene, "lens", True, False),
    }, args.repeat)
    noise = {
        "rgb": _time_to_one_percent(runner(lens_scene, "lens", False), args.noise_spp),
        "spectral_traced": _time_to_one_percent(runner(lens_scene, "lens", True), args.noise_spp),
        "spectral_terminated": _time_to_one_percent(runner(lens_scene, "lens", True, False), args.noise_spp),
        "thin_rgb": _time_to_one_percent(runner(lens_scene, "thin", False), args.noise_spp),
        "thin_spectral_traced": _time_to_one_percent(runner(lens_scene, "thin", True), args.noise_spp),
    }
    rgb_time = noise["rgb"]["seconds_to_1_percent"]
    print(json.dumps({
        "benchmark": "spectral",
        "scene": showcase.name,
        "lens": DISPERSIVE_LENS.name,
        "resolution": list(args.resolution),
        "spp": args.spp,
        "threads": args.threads,
        "samples_per_second": sps,
        "thin_spectral_over_rgb": sps["thin_spectral"] / sps["thin_rgb"],
        "thin_dispersive_spectral_over_rgb": sps["thin_dispersive_spectral"] / sps["thin_dispersive_rgb"],
        "goal_thin_spectral_over_rgb": 0.8,
        "lens_spectral_over_rgb": sps["lens_spectral_traced"] / sps["lens_rgb"],
        "lens_spectral_terminated_over_rgb": sps["lens_spectral_terminated"] / sps["lens_rgb"],
        "goal_lens_spectral_over_rgb": 0.6,
        "time_to_1_percent_rmse": noise,
        "spectral_over_rgb_time_to_1_percent": noise["spectral_traced"]["seconds_to_1_percent"] / rgb_time,
        "spectral_terminated_over_rgb_time_to_1_percent":
            noise["spectral_terminated"]["seconds_to_1_percent"] / rgb_time,
        "thin_spectral_over_rgb_time_to_1_percent":
            noise["thin_spectral_traced"]["seconds_to_1_percent"] / noise["thin_rgb"]["seconds_to_1_percent"],
        "goal_spectral_over_rgb_time_to_1_percent": 2.0,
    }, indent=2))


if __name__ == "__main__":
    main()
