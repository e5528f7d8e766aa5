"""Whole renders through random lens prescriptions: finite pixels or a clean refusal.

The hypothesis tests (tests/test_hard_inputs.py) check the lens camera's rays
and the paraxial data of random prescriptions; this renders whole images
through them, with what a render builds beside the rays: the exit pupil, the
centre calibration, the tile pencils, and at random the ray table, mirrored
rays, a spectral render and a bladed stop. Each prescription has 1-4 singlets
and a stop (radii inf, 1e9 or 1.05-400 x the clear radius; thicknesses 0.5-12
mm, gaps 0-10 mm; n 1.4-1.95); those with a focal length under 5 mm are
skipped. With ``--planner`` each scene is planned and rendered as
``--model auto`` renders it (``render_planned``, a tolerance of 0.1, 0.5 or
2 px, spectral at random): the planner sizes every effect through the lens
first. Every render must give finite, non-negative pixels or an InputError
(the scene or lens refused, exit 2 on the command line); anything else is
printed and counted as bad. Runs for ``--seconds``; prints one JSON object.
Not a test. Usage::

    python bench/check_random_lenses.py [--seed 1] [--seconds 150] [--planner]
"""

from __future__ import annotations

import argparse
import json
import math
import random
import sys
import tempfile
import time
import traceback
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from lenscompare.errors import InputError  # noqa: E402
from lenscompare.lenses import paraxial_data, parse_prescription  # noqa: E402
from lenscompare.plan import render_planned  # noqa: E402
from lenscompare.render import render  # noqa: E402
from lenscompare.scene import parse_scene  # noqa: E402

SCENE = """\
[camera]
model = "lens"
lens = "{lens}"
position = [0.0, 0.0, 0.0]
look_at = [0.0, 0.0, 1.0]
up = [0.0, 1.0, 0.0]
focus_distance = {focus_m!r}
film_mm = [36.0, 24.0]
resolution = [24, 16]
{blades}
[render]
spp = 4

[materials.glow]
type = "emissive"
color = [1.0, 1.0, 1.0]

[[objects]]
type = "sphere"
center = [0.0, 0.0, 2.0]
radius = 0.5
material = "glow"
"""


def random_prescription(rng: random.Random) -> bytes:
    """A lens file: 1-4 singlets of one clear radius, and a stop among them or behind them."""
    rows = []
    elements = rng.randint(1, 4)
    stop_at = rng.randint(0, elements)
    semi_mm = rng.uniform(2.0, 15.0)
    for i in range(elements):
        if i == stop_at:
            rows.append(f"0 {rng.uniform(0, 8):.4f} 0 {2 * semi_mm * rng.uniform(0.02, 1.0):.4f}")
        front = rng.choice([math.inf, 1e9, rng.uniform(semi_mm * 1.05, 400.0)])
        back = rng.choice([math.inf, -1e9, rng.uniform(-400.0, -semi_mm * 1.05)])
        front = front if rng.random() < 0.5 or front == math.inf else -front
        rows.append(f"{front} {rng.uniform(0.5, 12):.4f} {rng.uniform(1.4, 1.95):.4f} {2 * semi_mm:.4f}")
        rows.append(f"{back} {rng.uniform(0, 10):.4f} 1 {2 * semi_mm:.4f}")
    if stop_at == elements:
        rows.append(f"0 0 0 {2 * semi_mm * 0.8:.4f}")
    return "\n".join(rows).encode()


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seed", type=int, default=1)
    parser.add_argument("--seconds", type=float, default=150.0)
    parser.add_argument("--planner", action="store_true", help="plan each scene and render what the plan asks")
    args = parser.parse_args()

    rng = random.Random(args.seed)
    start = time.time()
    rendered = refused = bad = 0
    models: dict[str, int] = {}
    while time.time() - start < args.seconds:
        data = random_prescription(rng)
        try:
            if not paraxial_data(parse_prescription(data, source="random.dat", name="random")
                                 ).effective_focal_length_mm > 5:
                continue
        except InputError:
            continue
        if args.planner:
            options = dict(spectral=rng.random() < 0.3, tolerance_px=rng.choice([0.1, 0.5, 2.0]))
        else:
            options = dict(lens_rays=rng.choice([None, "table"]), lens_mirrors=rng.random() < 0.3,
                           spectral=rng.random() < 0.25)
        blades = rng.choice([0, 0, 5, 6])
        focus_m = rng.choice([0.2, 0.5, 2.0, 10.0, 1e6])
        with tempfile.TemporaryDirectory() as folder:
            lens = Path(folder) / "random.dat"
            lens.write_bytes(data)
            text = SCENE.format(lens=lens, focus_m=focus_m,
                                blades=f"aperture_blades = {blades}\n" if blades else "")
            try:
                if args.planner:
                    image = render_planned(parse_scene(text), tolerance_px=options["tolerance_px"], spp=4, threads=2,
                                           progress=False, spectral=options["spectral"])
                    model = image.metadata["plan"]["model"]
                    models[model] = models.get(model, 0) + 1
                else:
                    image = render(parse_scene(text), spp=4, threads=2, progress=False, seed=rng.randint(0, 1000),
                                   **options)
                rendered += 1
                if not (np.all(np.isfinite(image.pixels)) and np.all(image.pixels >= 0)):
                    bad += 1
                    print("non-finite or negative pixels:", options, blades, focus_m, data, file=sys.stderr)
            except InputError:
                refused += 1
            except Exception:  # what this looks for: anything but a clean refusal
                bad += 1
                print("exception:", options, blades, focus_m, data, file=sys.stderr)
                traceback.print_exc()
    print(json.dumps({"check": "renders through random lens prescriptions", "seed": args.seed,
                      "seconds": args.seconds, "planner": args.planner, "rendered": rendered, "refused": refused,
                      "bad": bad, "planned_models": models}, indent=2))
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
