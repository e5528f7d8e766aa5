"""``lenscompare sweep SWEEP.toml -o DIR [--scheduler ADDRESS] [--workers N]``."""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import ExternalError
from ..limits import MAX_THREADS
from ..sweep import load_sweep, run_sweep
from . import COMMAND_HELP
from ._options import THREADS, integer_option

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser(
        "sweep", help=COMMAND_HELP["sweep"],
        description="Render and measure every combination of the sweep file's scenes and axes (lens, f-number, "
                    "focus distance, model, sampler, spp, seed), one Dask task each, on a local cluster or the "
                    "one at --scheduler. Finished rows are journalled in DIR/rows.jsonl as they arrive; a re-run "
                    "with the same DIR runs only the missing tasks.")
    p.add_argument("sweep", metavar="SWEEP.toml")
    p.add_argument("-o", "--output", required=True, metavar="DIR")
    p.add_argument("--scheduler", metavar="ADDRESS", help="an existing Dask scheduler, tcp://HOST:PORT (default: a "
                                                          "local cluster)")
    p.add_argument("--workers", type=integer_option(minimum=1, maximum=MAX_THREADS), default=None,
                   help="workers of the local cluster (default: one per core)")
    p.add_argument("--threads", type=THREADS, default=None,
                   help="native threads per render (default: the worker machine's cores over its Dask slots)")
    p.add_argument("--no-plots", action="store_true", help="write the table only")
    p.add_argument("--json", action="store_true", help="print the summary as one JSON object")
    p.set_defaults(run=run)


def run(args) -> int:
    spec = load_sweep(args.sweep)
    summary = run_sweep(spec, args.output, scheduler=args.scheduler, workers=args.workers, threads=args.threads,
                        plots=not args.no_plots)
    if args.json:
        print(json.dumps(summary))
    else:
        print(f"{summary['tasks']} tasks: {summary['run']} run, {summary['skipped']} already done, "
              f"{summary['failed']} with an error in their row; {summary['seconds']:.0f} s"
              + (f" on the {summary['cluster']}" if summary["cluster"] else ""))
        if summary["other_rows"]:
            print(f"{summary['other_rows']} rows in the journal are of tasks not in this sweep file (left out of "
                  "the table)")
        print(f"Table: {Path(summary['table']).resolve()}")
    if summary["not_run"]:
        raise ExternalError(f"{len(summary['not_run'])} tasks could not be run ("
                            f"{summary['not_run'][0]['why']}); run the same command again to retry them")
    return 0
