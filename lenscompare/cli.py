"""The ``lenscompare`` command line: one sub-command per module in ``commands/``.

Each command module has ``add_parser(subparsers)``, which registers its parser
with ``set_defaults(run=run)``, and ``run(args) -> int``.  This file only wires
them together and turns :class:`~lenscompare.errors.LensCompareError` into one
line on stderr and an exit status (2 bad input, 1 external failure).  Only the
command being run has its module imported and its whole parser built; the
others are a name and a line of help (``commands.COMMAND_HELP``), so that
``lenscompare --help`` and a light command do not wait for every command's
imports (session 41: ``lenscompare --help`` 1.7 -> 0.05 s, ``lens info`` 1.7 -> 0.2 s with SciPy's import deferred).
"""

from __future__ import annotations

import argparse
import os
import signal
import sys

from . import interrupts
from .commands import COMMAND_HELP, load
from .errors import InputError, LensCompareError

__all__ = ["main"]


class _ArgumentParser(argparse.ArgumentParser):
    """argparse that reports bad options as InputError (exit 2, one line)."""

    def error(self, message):  # noqa: D401 - argparse API
        raise InputError(self.prog, message)


def _build_parser(argv: list[str]) -> argparse.ArgumentParser:
    """The parser for ``argv``: the whole parser of the command it names (its
    first word that is not an option), a name and a line of help for the others."""
    parser = _ArgumentParser(
        prog="lenscompare",
        description="Render one scene through pinhole, thin, thick and full-lens "
        "cameras, compare them with POV-Ray, and measure what each costs.",
    )
    subparsers = parser.add_subparsers(
        dest="command", required=True, parser_class=_ArgumentParser
    )
    chosen = next((word for word in argv if not word.startswith("-")), None)
    for name, help_line in COMMAND_HELP.items():
        if name == chosen:
            load(name).add_parser(subparsers)
        else:
            subparsers.add_parser(name, help=help_line)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Run the command line; return the exit status.

    Exit 0 success, 1 an outside failure, 2 bad input, 128 + N after signal N
    (130 SIGINT, 143 SIGTERM: no output written, no temporary file left),
    141 when the reader of stdout went away (``| head``). Every failure is one
    line on stderr, never a traceback.
    """
    with interrupts.handling_signals():
        try:
            argv = sys.argv[1:] if argv is None else list(argv)
            args = _build_parser(argv).parse_args(argv)
            status = int(args.run(args) or 0)
        except LensCompareError as error:
            return _fail(str(error), error.exit_status)
        except interrupts.Interrupted as interrupt:
            return _fail(f"interrupted ({interrupt}) before the work was done; no partial file is left",
                         interrupt.exit_status)
        except KeyboardInterrupt:  # outside main's signal handling (e.g. another thread)
            return _fail("interrupted", 130)
        except BrokenPipeError:
            return _stdout_gone()
        except MemoryError:
            return _fail("out of memory (see the README's limits)", 1)
        except OSError as error:  # an outside failure the commands did not name
            where = f"{error.filename}: " if error.filename else ""
            return _fail(f"{where}{error.strerror or error}", 1)
        late = interrupts.late_signal()
        if late is not None:
            print(f"lenscompare: {signal.Signals(late).name} arrived after {interrupts.finished_output()} was "
                  "written; the output is complete", file=sys.stderr)
        try:
            sys.stdout.flush()
        except BrokenPipeError:
            return _stdout_gone()
        return status


def _fail(message: str, status: int) -> int:
    print(f"lenscompare: error: {message}", file=sys.stderr)
    return status


def _stdout_gone() -> int:
    """The reader closed the pipe (``lenscompare lens info X | head -1``): end
    quietly, as a shell tool killed by SIGPIPE would (status 141)."""
    # Python would flush stdout again at exit and print the error it raises.
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, sys.stdout.fileno())
    return 128 + signal.SIGPIPE


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
