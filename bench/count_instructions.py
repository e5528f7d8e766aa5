"""Instructions a sample of the native render loop, counted by callgrind.

A machine whose speed drifts between runs (this project's CI machines: wall and
CPU time of one render swung 10-25 % between runs in session 46, and perf has no
hardware counters there) still counts instructions exactly, so a change to the
render loop can be weighed in instructions when its time is lost in the noise.
Instructions are not time (memory and packet coherence cost time without
instructions: the dispersive lens system's band render is 0.555 of RGB's count
and 0.52-0.535 of its samples/s), so a step that counts well is timed too.

Each configuration is rendered twice under valgrind's callgrind, one thread, at
--spp and at 1 spp, and the difference divided by the samples it added: the
set-up (camera, tables, checks, Python) drops out. Prints one JSON object:
instructions a sample per configuration, and RGB's count over spectral's (the
spectral ÷ RGB samples/s were time to follow it). With --top N
and a module built with symbols (pip install -e . -Ccmake.define.LENSCOMPARE_SYMBOLS=ON
-Cinstall.strip=false), each configuration's N functions with the most
instructions a sample (callgrind_annotate).

Configurations: showcase.toml through tests/data/lenses/dgauss_abbe.dat (the
dispersive Double Gauss of issue 15), the lens system in RGB and spectral (its
rays carrying bands), unless --model or --lens say otherwise.

Needs valgrind (apt-get install valgrind); not part of make bench.

Usage: python bench/count_instructions.py [--spp 32] [--resolution 180 120] [--model lens]
       [--lens PATH] [--top 20]
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENE = ROOT / "reference_scenes" / "showcase.toml"
DISPERSIVE_LENS = ROOT / "tests" / "data" / "lenses" / "dgauss_abbe.dat"


def _render_once(args) -> None:
    """The child: one render, nothing printed (run under callgrind)."""
    from lenscompare.render import render
    from lenscompare.scene import load_scene

    scene = load_scene(SCENE).with_camera(resolution=tuple(args.resolution))
    if args.model == "lens":
        scene = scene.with_camera(lens=str(args.lens), focal_length_mm=None)
    render(scene, model=args.model, threads=1, progress=False, spp=args.child_spp, spectral=args.spectral)


def _callgrind(args, *, spectral: bool, spp: int, out: Path) -> int:
    """Total instructions of one child render, its callgrind file written to out."""
    command = ["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}", sys.executable, __file__,
               "--child-spp", str(spp), "--model", args.model, "--lens", str(args.lens),
               "--resolution", *map(str, args.resolution)] + (["--spectral"] if spectral else [])
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   env={**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1"})
    for line in out.read_text(errors="replace").splitlines():
        if line.startswith("summary:") or line.startswith("totals:"):
            return int(line.split()[1])
    raise RuntimeError(f"{out}: no instruction total")


def _by_function(path: Path) -> dict:
    """Instructions per function (self cost) from a callgrind file."""
    text = subprocess.run(["callgrind_annotate", "--auto=no", str(path)], check=True, capture_output=True,
                          text=True).stdout
    counts = {}
    for line in text.splitlines():
        match = re.match(r"\s*([\d,]+) \([^)]*\)\s+(.*)", line)
        if not match or "PROGRAM TOTALS" in line:
            continue
        name = re.sub(r"\s*\[.*$", "", match.group(2))
        name = re.sub(r"^(\?\?\?|[^\s:]+):(?!:)", "", name, count=1).split("(")[0]
        counts[name] = counts.get(name, 0) + int(match.group(1).replace(",", ""))
    return counts


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--resolution", type=int, nargs=2, default=(180, 120))
    parser.add_argument("--model", default="lens", choices=("pinhole", "thin", "thick", "lens"))
    parser.add_argument("--lens", type=Path, default=DISPERSIVE_LENS)
    parser.add_argument("--top", type=int, default=0, help="list each configuration's N costliest functions")
    parser.add_argument("--spectral", action="store_true", help=argparse.SUPPRESS)
    parser.add_argument("--child-spp", type=int, default=0, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child_spp:
        _render_once(args)
        return
    if shutil.which("valgrind") is None:
        print("count_instructions.py: valgrind not found (apt-get install valgrind)", file=sys.stderr)
        sys.exit(2)
    added_samples = args.resolution[0] * args.resolution[1] * (args.spp - 1)
    result = {"scene": SCENE.name, "model": args.model, "lens": args.lens.name if args.model == "lens" else None,
              "resolution": list(args.resolution), "spp": args.spp, "instructions_per_sample": {}}
    with tempfile.TemporaryDirectory() as scratch:
        for spectral in (False, True):
            name = "spectral" if spectral else "rgb"
            full, setup = (Path(scratch) / f"{name}_{spp}.out" for spp in (args.spp, 1))
            per_sample = (_callgrind(args, spectral=spectral, spp=args.spp, out=full)
                          - _callgrind(args, spectral=spectral, spp=1, out=setup)) / added_samples
            result["instructions_per_sample"][name] = round(per_sample, 1)
            if args.top:
                a, b = _by_function(full), _by_function(setup)
                rows = sorted(((a.get(k, 0) - b.get(k, 0)) / added_samples, k) for k in set(a) | set(b))
                result.setdefault("top_functions", {})[name] = [[round(v, 1), k] for v, k in rows[::-1][:args.top]]
    counts = result["instructions_per_sample"]
    # What spectral ÷ RGB samples/s would be if time followed the count.
    result["spectral_over_rgb_by_count"] = round(counts["rgb"] / counts["spectral"], 4)
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
