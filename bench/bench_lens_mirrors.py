"""What the lens system's mirrored rays buy: time to a given error, traced against mirrored.

``render(..., lens_mirrors=True)`` traces a quarter of the camera samples and
reflects them into the mirror-image pixels. Each pixel is then estimated as well
as before at a fraction of the cost, but the errors of mirror-image pixels are
the same, so a measure that averages them gains less. This prints, for four
measures, the noise (standard deviation over seeds) and the render time of each
mode, and their product as the time to a given error relative to the traced
lens system (below 1: mirroring pays; above 1: it costs):

- ``image``: relative RMSE of the whole of ``showcase`` through the Double Gauss
  at full aperture (from pairs of seeds, as bench_spectral's time to 1 %);
- ``relative_illumination_20deg``: the flat field through ``wide.22mm`` at f/4,
  read at 20 degrees by :func:`lenscompare.measure.measure_vignetting` (ring
  averages normalised by the central disk, all symmetric under the mirrors);
- ``blur_disk_<depth>``: the diameter of each emissive sphere of
  ``blur_disks`` through the Double Gauss by
  :func:`lenscompare.measure.measure_blur_disks` (an on-axis disk is its own
  mirror image);
- ``distortion_k1`` and ``max_abs_distortion_percent``: ``dot_grid`` through
  ``wide.22mm`` by :func:`lenscompare.measure.measure_distortion` (the
  grid's dots lie in mirror-image pairs, and the radial fit takes them all).

Usage: python bench/bench_lens_mirrors.py [--seeds N] [--threads T]
"""

from __future__ import annotations

import argparse
import json
import os
from pathlib import Path

import numpy as np

from lenscompare.experiment import ExperimentSettings, Run, prepare_scene
from lenscompare.measure import measure_blur_disks, measure_distortion, measure_vignetting
from lenscompare.render import render
from lenscompare.scene import load_scene

SCENES = Path(__file__).resolve().parent.parent / "reference_scenes"


def _renders(scene, *, spp: int, seeds: int, threads: int, mirrored: bool) -> list:
    return [render(scene, model="lens", spp=spp, seed=seed, threads=threads, progress=False, lens_mirrors=mirrored)
            for seed in range(1, seeds + 1)]


def _image_noise(images) -> float:
    """Relative RMSE of one render, from the differences of pairs of seeds."""
    pairs = [(a.pixels.astype(np.float64), b.pixels.astype(np.float64)) for a, b in zip(images[::2], images[1::2])]
    mse = np.mean([np.mean((a - b) ** 2) / 2.0 for a, b in pairs])
    return float(np.sqrt(mse) / np.mean([np.mean(a + b) / 2.0 for a, b in pairs]))


def _measures(scene, images) -> tuple[dict, dict]:
    """Every scalar measure of the renders, one list per measure, and its expectation."""
    runs = [Run(scene, "lens", "native", image) for image in images]
    values: dict = {}
    expected: dict = {}
    if "vignetting" in scene.measure:
        for i, run in enumerate(runs):
            # The real-ray expectation once: every run has the same camera.
            entry = measure_vignetting(scene, [run], traced=i == 0)["renders"]["lens"]
            values.setdefault("relative_illumination_20deg", []).append(entry["at"]["20_deg"])
            if i == 0:
                traced = dict(zip(entry["traced"]["field_deg"], entry["traced"]["relative_illumination"]))
                expected["relative_illumination_20deg"] = traced[20.0]
    if "blur_disks" in scene.measure:
        for run in runs:
            found = measure_blur_disks(scene, [run])
            for depth_m, row in zip(found["depth_m"], found["renders"]["lens"]):
                if row is not None and row.get("measured_px") is not None:
                    values.setdefault(f"blur_disk_{depth_m:.2f}m_px", []).append(row["measured_px"])
                    expected[f"blur_disk_{depth_m:.2f}m_px"] = row["expected_px"]
    if "distortion" in scene.measure:
        for run in runs:
            found = measure_distortion(scene, [run])["renders"]["lens"]
            if found is not None:
                for name in ("k1", "max_abs_distortion_percent"):
                    values.setdefault(f"distortion_{name}", []).append(found[name])
    return values, expected


def _compare(label: str, scene, *, spp: int, seeds: int, threads: int, image: bool = False) -> dict:
    modes = {}
    for mirrored in (False, True):
        images = _renders(scene, spp=spp, seeds=seeds, threads=threads, mirrored=mirrored)
        seconds = float(np.median([image.metadata["seconds"] for image in images]))
        # (image: the scenes of point sources on black have no mean to be relative to)
        noise = {"image_relative_rmse": _image_noise(images)} if image else {}
        values, expected = _measures(scene, images)
        whole = {name: v for name, v in values.items() if len(v) == seeds}
        noise.update({name: float(np.std(v, ddof=1)) for name, v in whole.items()})
        # The mean over seeds against the expectation: both modes are unbiased per
        # pixel, but a measure is not linear in the pixels.
        mean = {name: float(np.mean(v)) for name, v in whole.items()}
        modes["mirrored" if mirrored else "traced"] = {"seconds": seconds, "noise": noise, "mean": mean,
                                                        "expected": {n: expected.get(n) for n in whole}}
    traced, mirrored = modes["traced"], modes["mirrored"]
    # Time to a given error goes as seconds x noise^2 (the noise falls as 1/sqrt(spp)).
    ratio = {name: (mirrored["seconds"] * mirrored["noise"][name] ** 2) / (traced["seconds"] * value ** 2)
             for name, value in traced["noise"].items() if name in mirrored["noise"] and value > 0}
    return {"scene": label, "spp": spp, "seeds": seeds, **modes,
            "mirrored_over_traced_seconds": mirrored["seconds"] / traced["seconds"],
            "mirrored_over_traced_time_to_error": ratio}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=32, help="renders per mode and scene (an even number)")
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--threads", type=int, default=os.cpu_count())
    args = parser.parse_args()
    if args.seeds < 4 or args.seeds % 2:
        parser.error("--seeds must be an even number of at least 4")

    settings = ExperimentSettings()
    showcase = load_scene(SCENES / "showcase.toml").with_camera(resolution=(180, 120), lens="dgauss.50mm",
                                                                 f_number=None)
    flat = load_scene(SCENES / "flat_field.toml").with_camera(lens="wide.22mm", f_number=4.0)
    disks, _ = prepare_scene(load_scene(SCENES / "blur_disks.toml"), settings)
    disks = disks.with_camera(resolution=(360, 240))
    dots = load_scene(SCENES / "dot_grid.toml").with_camera(lens="wide.22mm", f_number=4.0)
    kw = {"spp": args.spp, "seeds": args.seeds, "threads": args.threads}
    print(json.dumps({
        "benchmark": "lens_mirrors",
        "threads": args.threads,
        "results": [_compare("showcase (dgauss.50mm, full aperture)", showcase, image=True, **kw),
                    _compare("flat_field (wide.22mm, f/4)", flat, **kw),
                    _compare("blur_disks (dgauss.50mm)", disks, **kw),
                    _compare("dot_grid (wide.22mm, f/4)", dots, **kw)],
    }, indent=2))


if __name__ == "__main__":
    main()
