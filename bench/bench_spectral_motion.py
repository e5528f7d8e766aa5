"""Spectral renders through a moving dispersive thin lens: band rays against drawn wavelengths.

A camera that moves during the shutter keeps the band rays of a still one
(native/src/render_tile_bands.h: a translation moves every wavelength's ray
alike). This prints, for ``showcase`` through the thin lens derived from the
Double Gauss with Abbe numbers, the camera moving at 0.5 m/s over a 0.04 s
shutter: ns per sample (1e9 over the render loop's samples/s, one thread, best
of ``--repeat``), relative RMSE at ``--spp`` (one pair of seeds; bench_spectral pools three),
and the time to a given error over the RGB render's (ns per sample times RMSE
squared), for the band rays (``bands``), drawn hero wavelengths
(``render(sample_wavelengths=True)``, the path a moving camera took before
session 30: ``drawn``) and RGB.

Usage: python bench/bench_spectral_motion.py [--spp N] [--repeat R]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from lenscompare.render import render
from lenscompare.scene import load_scene

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "reference_scenes" / "showcase.toml"
DISPERSIVE_LENS = ROOT / "tests" / "data" / "lenses" / "dgauss_abbe.dat"
MODES = {"bands": {"spectral": True}, "drawn": {"spectral": True, "sample_wavelengths": True},
         "rgb": {"spectral": False}}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    scene = load_scene(SCENE).with_camera(resolution=(180, 120), lens=str(DISPERSIVE_LENS), focal_length_mm=None,
                                          velocity=(0.5, 0.0, 0.0)).with_render(shutter_s=(0.0, 0.04))
    best = {name: 0.0 for name in MODES}
    for _ in range(args.repeat):  # alternating, each keeping its best
        for name, kw in MODES.items():
            image = render(scene, model="thin", spp=args.spp, threads=1, progress=False, **kw)
            best[name] = max(best[name], image.metadata["samples_per_second"])
    out = {"benchmark": "spectral_motion", "scene": SCENE.name, "lens": DISPERSIVE_LENS.name,
           "camera_velocity_m_per_s": [0.5, 0.0, 0.0], "shutter_s": [0.0, 0.04], "spp": args.spp, "modes": {}}
    for name, kw in MODES.items():
        a, b = (render(scene, model="thin", spp=args.spp, seed=s, progress=False, **kw).pixels.astype(np.float64)
                for s in (1, 2))
        rmse = float(np.sqrt(np.mean((a - b) ** 2) / 2.0) / np.mean(0.5 * (a + b)))
        out["modes"][name] = {"ns_per_sample": 1e9 / best[name], "relative_rmse": rmse}
    rgb = out["modes"]["rgb"]
    for name in ("bands", "drawn"):
        mode = out["modes"][name]
        mode["time_to_error_over_rgb"] = (mode["ns_per_sample"] * mode["relative_rmse"] ** 2
                                          / (rgb["ns_per_sample"] * rgb["relative_rmse"] ** 2))
    print(json.dumps(out, indent=2))


if __name__ == "__main__":
    main()
