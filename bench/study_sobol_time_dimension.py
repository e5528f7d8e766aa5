"""Which Sobol' dimension should carry time: stratification of the pairs and triples that matter.

Film takes Sobol' dimensions 0-1 and lens 2-3 (fixed: static images must not
change); time may take any further dimension. For each candidate dimension 4-13
this prints, at 16, 64 and 256 points (a pixel's first 2^m points):

- ``cells``: how many cells of a sqrt(N) x sqrt(N) grid film-x, film-y, lens-u
  and lens-v, each against time, fill (N is perfect);
- ``t``: the t-value of each pair with time, of film x time and lens x time
  (3-D), and of film x lens x time (5-D): the first 2^m points are a
  (t, m, s)-net, every elementary box of volume 2^(t-m) holding 2^t points
  (0 is perfect);
- ``cells64_lens_time_4x4x4`` and ``cells64_film_time_4x4x4`` (64 is perfect).

The points are SciPy's unscrambled Sobol' points, which read the same
direction-number file as native/src/sampler_sobol.cpp (Joe & Kuo,
new-joe-kuo-6.21201); the Owen scramble the renderer adds keeps every count.
The image-error side of the choice is bench/bench_motion.py.

Usage: python bench/study_sobol_time_dimension.py
"""

from __future__ import annotations

import itertools
import json

import numpy as np
from scipy.stats import qmc

FILM, LENS = (0, 1), (2, 3)
CANDIDATES = range(4, 14)
POINTS = qmc.Sobol(d=max(CANDIDATES) + 1, scramble=False).random(256)  # any 2^m prefix is the same point set


def box_index(dims, m: int, bits) -> np.ndarray:
    """Each of the first 2^m points' elementary box, `bits[k]` bits deep in dimension dims[k]."""
    index = np.zeros(2 ** m, dtype=np.int64)
    for d, b in zip(dims, bits):
        index = (index << b) | np.floor(POINTS[:2 ** m, d] * 2 ** b).astype(np.int64)
    return index


def t_value(dims, m: int) -> int:
    """Smallest t with every elementary box of volume 2^(t-m) holding 2^t of the first 2^m points."""
    s = len(dims)
    for t in range(m + 1):
        # every split of m - t bits over the s dimensions (stars and bars)
        splits = ([b - a - 1 for a, b in zip((-1,) + c, c + (m - t + s - 1,))]
                  for c in itertools.combinations(range(m - t + s - 1), s - 1))
        if all(np.bincount(box_index(dims, m, bits), minlength=2 ** (m - t)).min() == 2 ** t for bits in splits):
            return t
    return m


def cells(dims, m: int, bits) -> int:
    return int(len(np.unique(box_index(dims, m, bits))))


def study(time: int) -> dict:
    row = {}
    for m in (4, 6, 8):
        h = m // 2
        names = (("film_x", FILM[0]), ("film_y", FILM[1]), ("lens_u", LENS[0]), ("lens_v", LENS[1]))
        row[f"spp{2 ** m}"] = {
            "cells": {name: cells((d, time), m, (h, h)) for name, d in names},
            "t": {**{name: t_value((d, time), m) for name, d in names},
                  "film_time": t_value(FILM + (time,), m), "lens_time": t_value(LENS + (time,), m),
                  "film_lens_time": t_value(FILM + LENS + (time,), m)}}
    row["cells64_lens_time_4x4x4"] = cells(LENS + (time,), 6, (2, 2, 2))
    row["cells64_film_time_4x4x4"] = cells(FILM + (time,), 6, (2, 2, 2))
    return row


def main():
    result = {"film_lens_t": {f"spp{2 ** m}": t_value(FILM + LENS, m) for m in (4, 6, 8)},
              "time_dimension": {d: study(d) for d in CANDIDATES}}
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
