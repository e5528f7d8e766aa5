"""The ``lenscompare`` command line: one sub-command per module in ``commands/``.

Each command module has ``add_parser(subparsers)``, which registers its parser
with ``set_defaults(run=run)``, and ``run(args) -> int``.  This file only wires
them together and turns :class:`~lenscompare.errors.LensCompareError` into one
line on stderr and an exit status (2 bad input, 1 external failure).
"""

from __future__ import annotations

import argparse
import sys

from .commands import COMMANDS
from .errors import InputError, LensCompareError

__all__ = ["main"]


class _ArgumentParser(argparse.ArgumentParser):
    """argparse that reports bad options as InputError (exit 2, one line)."""

    def error(self, message):  # noqa: D401 - argparse API
        raise InputError(self.prog, message)


def _build_parser() -> argparse.ArgumentParser:
    parser = _ArgumentParser(
        prog="lenscompare",
        description="Render one scene through pinhole, thin, thick and full-lens "
        "cameras, compare them with POV-Ray, and measure what each costs.",
    )
    subparsers = parser.add_subparsers(
        dest="command", required=True, parser_class=_ArgumentParser
    )
    for command in COMMANDS:
        command.add_parser(subparsers)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit status."""
    try:
        args = _build_parser().parse_args(argv)
        return int(args.run(args) or 0)
    except LensCompareError as error:
        print(f"lenscompare: error: {error}", file=sys.stderr)
        return error.exit_status
    except KeyboardInterrupt:
        print("lenscompare: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
