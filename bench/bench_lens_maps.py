"""How long the composite camera's traced maps take, per shipped lens.

The composite (issue 14) reads a lens through radial maps (distortion and
relative illumination against film radius) and, in spectral renders, a
lateral-colour map per wavelength; both are traced once per process in
NumPy (lenscompare/lenses/maps.py), so their time is a fixed cost of every
composite render and of the report. Prints one JSON object: per lens and
focus distance, the seconds of ``radial_maps`` and ``lateral_color_map``
(fastest of ``--repeat`` rounds, the memo cleared before each), on a
36 x 24 mm film.

Usage: python bench/bench_lens_maps.py [--repeat R]
"""

from __future__ import annotations

import argparse
import json
import math
import time

from lenscompare.lenses import load_prescription, paraxial_data
from lenscompare.lenses import maps
from lenscompare.lenses.focus import film_distance_mm
from machine import describe as describe_machine

LENSES = ("dgauss.50mm", "wide.22mm", "fisheye.10mm", "telephoto.250mm", "landscape.125mm")
DISPERSIVE = "tests/data/lenses/dgauss_abbe.dat"  # the Double Gauss with Abbe numbers
FILM_HALF_DIAGONAL_MM = math.hypot(18.0, 12.0)
FOCUS_DISTANCES_M = (math.inf, 3.0)


def _time_maps(lens, focus_distance_m: float, repeat: int) -> dict:
    film_z_mm = lens.total_track_mm + film_distance_mm(lens, focus_distance_m)
    arguments = dict(film_z_mm=film_z_mm, paraxial_scale_mm=paraxial_data(lens).effective_focal_length_mm,
                     focus_distance_m=focus_distance_m, film_half_diagonal_mm=FILM_HALF_DIAGONAL_MM)
    radial, color = [], []
    for _ in range(repeat):
        maps._CACHE.clear(), maps._COLOR_CACHE.clear()  # each round traces anew
        start = time.perf_counter()
        maps.radial_maps(lens, **arguments)
        middle = time.perf_counter()
        maps.lateral_color_map(lens, **arguments)
        radial.append(middle - start), color.append(time.perf_counter() - middle)
    return {"radial_maps_s": min(radial), "lateral_color_map_s": min(color)}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeat", type=int, default=3)
    args = parser.parse_args()
    results = {}
    for name in (*LENSES, DISPERSIVE):
        lens = load_prescription(name)
        for focus_distance_m in FOCUS_DISTANCES_M:
            results[f"{lens.name} at {focus_distance_m:g} m"] = _time_maps(lens, focus_distance_m, args.repeat)
    print(json.dumps({"machine": describe_machine(), "film_half_diagonal_mm": FILM_HALF_DIAGONAL_MM,
                      "repeat": args.repeat, "lenses": results}, indent=2))


if __name__ == "__main__":
    main()
