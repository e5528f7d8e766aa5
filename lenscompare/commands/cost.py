"""``lenscompare cost SCENES... -o DIR``: the cost study."""

from __future__ import annotations

import contextlib
from pathlib import Path

from ..cost import CostSettings, run_cost_study
from ..cluster import open_cluster
from ..lenses import resolve_lens
from . import COMMAND_HELP
from ._options import SCENE_HELP, THREADS, integer_option, load_scene_argument

__all__ = ["add_parser", "run"]

# Each repeat renders the whole grid again.
MAX_TIMING_REPEATS = 20


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "cost", help=COMMAND_HELP["cost"],
        description="For each model, sampler and sample count: wall time and error against a converged reference "
                    "(cached), model error against the full lens system, POV-Ray focal blur as a row.")
    p.add_argument("scenes", nargs="+", metavar="SCENE.toml", help=SCENE_HELP)
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--quick", action="store_true", help="quarter resolution, up to 64 spp (CI)")
    p.add_argument("--lens", default="dgauss.50mm")
    p.add_argument("--no-povray", action="store_true")
    p.add_argument("--cache", metavar="DIR", help="reference cache (default ~/.cache/lenscompare)")
    p.add_argument("--threads", type=THREADS, default=None,
                   help="threads per render (default and at most: every core; on a cluster, its machine's cores over "
                        "its Dask slots)")
    p.add_argument("--timing-repeats", type=integer_option(minimum=1, maximum=MAX_TIMING_REPEATS), default=1,
                   metavar="N",
                   help="render every point N times, in rounds over the whole grid, and time it by its fastest "
                        "round (for a machine whose speed varies; default 1)")
    p.add_argument("--scheduler", metavar="ADDRESS",
                   help="run the renders as tasks on the Dask cluster of this scheduler (tcp://HOST:PORT)")
    p.set_defaults(run=run)


def run(args) -> int:
    resolve_lens(args.lens, source="--lens", key=None)  # a bad --lens fails now, not after the first scene
    scenes = [load_scene_argument(p) for p in args.scenes]
    settings = CostSettings(quick=args.quick, lens=args.lens, threads=args.threads, povray=not args.no_povray,
                            cache_dir=Path(args.cache) if args.cache else None, timing_repeats=args.timing_repeats)
    with open_cluster(args.scheduler) if args.scheduler else contextlib.nullcontext() as cluster:
        results = run_cost_study(scenes, args.output, settings, cluster=cluster, final=True)
    for line in results["findings"]:
        print(line)
    print(f"Cost study written in {results['total_seconds']:.0f} s: open {Path(args.output).resolve() / 'index.html'}")
    return 0
