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
set-up (camera, tables, checks, Python) drops out. A configuration is a model
and options joined by commas: "lens", "lens,spectral" (its rays carrying
bands), "lens,table" (lens_rays = "table"), "lens,mirrors", "pinhole", "thin".
Prints one JSON object: instructions a sample per configuration and the first
configuration's count over each one's (what the samples/s ratio would be, were
time to follow the count). With --top N and a module built with symbols (pip
install -e . -Ccmake.define.LENSCOMPARE_SYMBOLS=ON -Cinstall.strip=false), each
configuration's N functions with the most instructions a sample.

The scene: showcase.toml, the lens system through tests/data/lenses/dgauss_abbe.dat
(the dispersive Double Gauss of issue 15) unless --lens says otherwise.

With --events, each configuration is run under cachegrind instead, with its
cache and branch simulation, and the JSON gains per sample what costs time
beside the instructions: first-level data-cache misses (reads and writes) and
mispredicted branches (conditional and indirect), as cachegrind's model
counts them (a 32 KB 8-way L1 and one last level: it says where the misses
are, not what they cost). The set-up is subtracted the same way.

Needs valgrind (apt-get install valgrind); not part of make bench.

Usage: python bench/count_instructions.py [CONFIG ...] [--spp 32] [--resolution 180 120]
       [--lens PATH] [--top 20] [--events]
  e.g. python bench/count_instructions.py lens lens,spectral      (issue 15's ratio; the default)
       python bench/count_instructions.py pinhole lens,table      (issue 20's)
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


OPTIONS = ("spectral", "table", "mirrors")


def _parse_config(text: str) -> tuple[str, set]:
    model, *options = text.split(",")
    if model not in ("pinhole", "thin", "thick", "lens") or not set(options) <= set(OPTIONS):
        print(f"count_instructions.py: {text!r}: a model (pinhole, thin, thick, lens) and options "
              f"from {', '.join(OPTIONS)}, joined by commas", file=sys.stderr)
        sys.exit(2)
    return model, set(options)


def _render_once(args) -> None:
    """The child: one render, nothing printed (run under valgrind)."""
    from lenscompare.render import render
    from lenscompare.scene import load_scene

    model, options = _parse_config(args.configs[0])
    scene = load_scene(SCENE).with_camera(resolution=tuple(args.resolution))
    if model == "lens":
        scene = scene.with_camera(lens=str(args.lens), focal_length_mm=None)
    render(scene, model=model, threads=1, progress=False, spp=args.child_spp, spectral="spectral" in options,
           lens_rays="table" if "table" in options else None, lens_mirrors="mirrors" in options)


# cachegrind's events (--events) and the names they go by in the JSON.
EVENTS = {"Ir": "instructions", "D1mr": "l1_read_misses", "D1mw": "l1_write_misses",
          "Bcm": "conditional_branch_misses", "Bim": "indirect_branch_misses"}


def _valgrind(args, config: str, *, spp: int, out: Path) -> dict:
    """Totals of one child render by event name (callgrind: instructions
    only; --events: cachegrind's), its output file written to out."""
    tool = (["--tool=cachegrind", "--cache-sim=yes", "--branch-sim=yes", f"--cachegrind-out-file={out}"]
            if args.events else ["--tool=callgrind", f"--callgrind-out-file={out}"])
    command = ["valgrind", *tool, sys.executable, __file__, config, "--child-spp", str(spp), "--lens", str(args.lens),
               "--resolution", *map(str, args.resolution)]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL,
                   # A fixed hash seed: Python's set-up then runs the same instructions in both renders
                   # (with a random one the count a sample moved by about 1 % between runs, session 47).
                   env={**os.environ, "OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "PYTHONHASHSEED": "0"})
    names = ["Ir"]
    for line in out.read_text(errors="replace").splitlines():
        if line.startswith("events:"):
            names = line.split()[1:]
        if line.startswith("summary:") or line.startswith("totals:"):
            return dict(zip(names, map(int, line.split()[1:])))
    raise RuntimeError(f"{out}: no totals")


def _by_function(path: Path) -> dict:
    """Instructions per function (self cost) from a callgrind file."""
    text = subprocess.run(["callgrind_annotate", "--auto=no", str(path)], check=True, capture_output=True,
                          text=True).stdout
    counts = {}
    for line in text.splitlines():
        match = re.match(r"\s*([\d,]+) \([^)]*\)\s+(.*)", line)
        if not match or "PROGRAM TOTALS" in line:
            continue
        name = re.sub(r"\s*\[.*$", "", match.group(2)).replace("(anonymous namespace)", "{anonymous}")
        name = re.sub(r"^(\?\?\?|[^\s:]+):(?!:)", "", name, count=1).split("(")[0]
        counts[name] = counts.get(name, 0) + int(match.group(1).replace(",", ""))
    return counts


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("configs", nargs="*", default=["lens", "lens,spectral"])
    parser.add_argument("--spp", type=int, default=32)
    parser.add_argument("--resolution", type=int, nargs=2, default=(180, 120))
    parser.add_argument("--lens", type=Path, default=DISPERSIVE_LENS)
    parser.add_argument("--top", type=int, default=0, help="list each configuration's N costliest functions")
    parser.add_argument("--events", action="store_true",
                        help="cachegrind: cache misses and mispredicted branches a sample too")
    parser.add_argument("--child-spp", type=int, default=0, help=argparse.SUPPRESS)
    args = parser.parse_args()
    for config in args.configs:
        _parse_config(config)
    if args.top and args.events:
        print("count_instructions.py: --top reads callgrind's files, --events cachegrind's: one at a time",
              file=sys.stderr)
        sys.exit(2)
    if args.child_spp:
        _render_once(args)
        return
    if shutil.which("valgrind") is None:
        print("count_instructions.py: valgrind not found (apt-get install valgrind)", file=sys.stderr)
        sys.exit(2)
    added_samples = args.resolution[0] * args.resolution[1] * (args.spp - 1)
    result = {"scene": SCENE.name, "lens": args.lens.name, "resolution": list(args.resolution), "spp": args.spp,
              "instructions_per_sample": {}}
    with tempfile.TemporaryDirectory() as scratch:
        for index, config in enumerate(args.configs):
            full, setup = Path(scratch) / f"{index}_full.out", Path(scratch) / f"{index}_setup.out"
            totals = _valgrind(args, config, spp=args.spp, out=full)
            setup_totals = _valgrind(args, config, spp=1, out=setup)
            per_sample = {event: (totals[event] - setup_totals[event]) / added_samples for event in totals}
            result["instructions_per_sample"][config] = round(per_sample["Ir"], 1)
            if args.events:
                result.setdefault("events_per_sample", {})[config] = {
                    name: round(per_sample[event], 3) for event, name in EVENTS.items()}
            if args.top:
                a, b = _by_function(full), _by_function(setup)
                rows = sorted(((a.get(k, 0) - b.get(k, 0)) / added_samples, k) for k in set(a) | set(b))
                result.setdefault("top_functions", {})[config] = [[round(v, 1), k] for v, k in rows[::-1][:args.top]]
    counts = result["instructions_per_sample"]
    first = args.configs[0]
    # What each samples/s ratio to the first configuration would be, were time to follow the count.
    result["count_ratio_to_first"] = {config: round(counts[first] / counts[config], 4) for config in args.configs}
    print(json.dumps(result, indent=1))


if __name__ == "__main__":
    main()
