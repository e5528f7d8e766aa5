"""The postfilter's per-pixel pinhole sample counts (lenscompare.postfilter.samples)
against a uniform 16-sample pinhole pass: error against the converged thin lens.

For showcase, showcase at f/1.4 focused at 1.9 m, and blur_disks: relative
RMSE against the thin lens at 2048 spp (seed 11), over the whole frame, in
the edge band (lenscompare.postfilter.edge_band) and elsewhere, mean and
standard deviation over seeds 0 to ``--seeds`` - 1, of

- ``uniform_16``: the spread of a uniform 16-sample pinhole pass (the
  default model);
- ``per_pixel``: ``render(model="postfilter", spp=64,
  postfilter_per_pixel_spp=True)`` (its counts' mean is ``mean_spp``);
- ``uniform_mean``: a uniform pass of round(mean_spp) samples, the same cost
  spent evenly (a control: is the allocation better than fewer samples?).

``*_sd`` is the seed-to-seed standard deviation (the measurement's noise).
blur_disks tells nothing here: its spheres keep n (depth steps) and its
background is black, so both passes give the same image.
Prints one JSON object {scene: {row: figures}}.

Usage: python bench/study_pinhole_counts.py [--threads T] [--seeds S]
"""

from __future__ import annotations

import argparse
import json
import os

import numpy as np

from lenscompare.cameras import camera_for
from lenscompare.postfilter import depth_buffer_m, edge_band, signed_coc_px, spread
from lenscompare.reference_scenes import shipped_scene
from lenscompare.render import render
from lenscompare.scene import load_scene
from study_pinhole_spp import error_rows  # bench/ is the script's directory

KEYS = ("whole", "band_relative_rmse", "elsewhere_relative_rmse")


def errors(reference, images, band):
    rows = error_rows(reference, images, band)
    out = {}
    for k in KEYS:
        values = [r[k] for r in rows if r[k] is not None]
        if values:
            out[k] = round(float(np.mean(values)), 5)
            out[k + "_sd"] = round(float(np.std(values, ddof=1)), 5) if len(values) > 1 else None
    return out


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    parser.add_argument("--seeds", type=int, default=4)
    args = parser.parse_args()
    showcase = load_scene(shipped_scene("showcase"))
    seeds = range(args.seeds)
    out = {}
    for name, scene in (("showcase", showcase),
                        ("showcase_f1.4_focus_1.9m", showcase.with_camera(f_number=1.4, focus_distance_m=1.9)),
                        ("blur_disks", load_scene(shipped_scene("blur_disks")))):
        reference = render(scene, model="thin", spp=2048, seed=11, threads=args.threads, progress=False).pixels
        depth = depth_buffer_m(scene, camera_for(scene, "pinhole"), threads=args.threads)
        thin = camera_for(scene, "thin")
        band = edge_band(depth, signed_coc_px(depth, thin))

        def uniform(spp):
            return [spread(render(scene, model="pinhole", spp=spp, seed=s, threads=args.threads,
                                  progress=False).pixels, depth, thin, threads=args.threads)[0] for s in seeds]

        per_pixel = [render(scene, model="postfilter", spp=64, seed=s, threads=args.threads, progress=False,
                            postfilter_per_pixel_spp=True)
                     for s in seeds]
        mean_spp = per_pixel[0].metadata["postfilter"]["pinhole_mean_spp"]
        out[name] = {"mean_spp": round(mean_spp, 3), "band_fraction": round(float(band.mean()), 4),
                     "uniform_16": errors(reference, uniform(16), band),
                     "per_pixel": errors(reference, [i.pixels for i in per_pixel], band),
                     f"uniform_mean_{round(mean_spp)}": errors(reference, uniform(round(mean_spp)), band)}
        print(json.dumps({name: out[name]}), flush=True)
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
