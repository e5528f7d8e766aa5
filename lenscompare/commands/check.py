"""``lenscompare check [CONFIG] [--junit FILE]``: accuracy checks for CI."""

from __future__ import annotations

from ..atomic import check_output_file
from ..checks import DEFAULT_CONFIG, load_checks, run_check, write_junit
from . import COMMAND_HELP
from ._options import THREADS

__all__ = ["add_parser", "run"]


def add_parser(subparsers) -> None:
    p = subparsers.add_parser("check", help=COMMAND_HELP["check"],
                              description="Run the checks of CONFIG (default: the shipped config); exit 0 when all "
                                          "hold, 1 when any fails, 2 for a bad config.")
    p.add_argument("config", nargs="?", metavar="CONFIG.toml")
    p.add_argument("--junit", metavar="FILE", help="also write JUnit XML")
    p.add_argument("--threads", type=THREADS, default=None, help="worker threads (default and at most: all cores)")
    p.set_defaults(run=run)


def run(args) -> int:
    checks = load_checks(args.config or DEFAULT_CONFIG)
    if args.junit:
        check_output_file(args.junit, option="--junit")  # before the checks run, not after
    results = []
    for check in checks:
        result = run_check(check, threads=args.threads)
        results.append(result)
        print(f"{'PASS' if result.passed else 'FAIL'}  {check.name}: {result.message} ({result.seconds:.1f} s)")
    if args.junit:
        write_junit(args.junit, results)
    failed = sum(not r.passed for r in results)
    print(f"{len(results) - failed} passed, {failed} failed")
    return 1 if failed else 0
