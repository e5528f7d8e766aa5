"""Why the postfilter's pinhole pass keeps min(spp, 16) film samples: its
error against the converged thin lens with fewer samples.

For showcase and showcase at f/1.4 focused at 1.9 m: relative RMSE against
the thin lens at 2048 spp (seed 11) in the edge band
(lenscompare.postfilter.edge_band), elsewhere and over the whole frame, for
the postfilter of pinhole passes of 4, 8, 16 and 1024 samples (mean over
seeds 0-2; 1024: seed 11) and for the thin lens at 64 spp (seeds 0-2).

Prints one JSON object {scene: {row: {band_relative_rmse,
elsewhere_relative_rmse, whole}}}.

Usage: python bench/study_pinhole_spp.py [--threads T]
"""

from __future__ import annotations

import argparse
import json
import os

import numpy as np

from lenscompare.cameras import camera_for
from lenscompare.metrics import relative_rmse
from lenscompare.postfilter import depth_buffer_m, edge_band, edge_band_error, signed_coc_px, spread
from lenscompare.reference_scenes import shipped_scene
from lenscompare.render import render
from lenscompare.scene import load_scene

KEYS = ("band_relative_rmse", "elsewhere_relative_rmse", "whole")


def error_rows(reference, images, band) -> list[dict]:
    """Each image's relative RMSE against reference: in the edge band, elsewhere and whole."""
    rows = []
    for image in images:
        row = edge_band_error(reference, image, band)
        row["whole"] = relative_rmse(reference, image)
        rows.append(row)
    return rows


def errors(reference, images, band):
    rows = error_rows(reference, images, band)
    return {k: float(np.mean([r[k] for r in rows])) for k in KEYS}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    args = parser.parse_args()
    showcase = load_scene(shipped_scene("showcase"))
    out = {}
    for name, scene in (("showcase", showcase),
                        ("showcase_f1.4_focus_1.9m", showcase.with_camera(f_number=1.4, focus_distance_m=1.9))):
        reference = render(scene, model="thin", spp=2048, seed=11, threads=args.threads, progress=False).pixels
        depth = depth_buffer_m(scene, camera_for(scene, "pinhole"), threads=args.threads)
        thin = camera_for(scene, "thin")
        band = edge_band(depth, signed_coc_px(depth, thin))
        rows = {}
        for spp in (4, 8, 16, 1024):
            seeds = (11,) if spp == 1024 else (0, 1, 2)
            images = [spread(render(scene, model="pinhole", spp=spp, seed=s, threads=args.threads,
                                    progress=False).pixels, depth, thin, threads=args.threads)[0] for s in seeds]
            rows[f"postfilter_pinhole_{spp}spp"] = errors(reference, images, band)
        rows["thin_64spp"] = errors(reference, [render(scene, model="thin", spp=64, seed=s, threads=args.threads,
                                                       progress=False).pixels for s in (0, 1, 2)], band)
        out[name] = rows
    print(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
