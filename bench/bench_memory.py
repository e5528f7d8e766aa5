"""Peak memory per pixel of a render and its EXR write (uniform and adaptive),
the figures lenscompare.limits uses to refuse a render the machine cannot hold.

Each case runs in a fresh process and reports its peak resident size; the
baseline (imports and a 1-pixel render) is subtracted. Prints JSON.
"""

from __future__ import annotations

import json
import subprocess
import sys
import tempfile
from pathlib import Path

CHILD = r"""
import resource, sys
from pathlib import Path
from lenscompare.image import write_exr
from lenscompare.render import render
from lenscompare.scene import load_scene
width, height, adaptive = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3] == "1"
scene = load_scene(sys.argv[4]).with_camera(resolution=(width, height), film_mm=(36.0, 36.0 * height / width))
image = render(scene, model="thin", spp=4, adaptive=adaptive, progress=False)
write_exr(Path(sys.argv[5]), image)
print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024)
"""

SCENE = Path(__file__).resolve().parent.parent / "lenscompare" / "reference_scenes" / "showcase.toml"


def peak_bytes(width: int, height: int, adaptive: bool, folder: str) -> int:
    out = subprocess.run([sys.executable, "-c", CHILD, str(width), str(height), "1" if adaptive else "0", str(SCENE),
                          str(Path(folder) / "out.exr")], capture_output=True, text=True, check=True)
    return int(out.stdout.split()[-1])


def main() -> None:
    results = {"scene": "showcase (thin lens, 4 spp)", "cases": []}
    with tempfile.TemporaryDirectory() as folder:
        for adaptive in (False, True):
            base = peak_bytes(3, 2, adaptive, folder)
            for width, height in ((1500, 1000), (3000, 2000)):
                peak = peak_bytes(width, height, adaptive, folder)
                results["cases"].append({"adaptive": adaptive, "width_px": width, "height_px": height,
                                         "peak_bytes": peak, "baseline_bytes": base,
                                         "bytes_per_pixel": round((peak - base) / (width * height), 1)})
    print(json.dumps(results, indent=2))


if __name__ == "__main__":
    main()
