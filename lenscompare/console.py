"""The ``lenscompare`` console script: quiet signal handling first, then the
command line (importing it takes about a second)."""

import sys

from . import interrupts

interrupts.exit_quietly_on_signals()

from .cli import main  # noqa: E402 - after the handlers, on purpose

__all__ = ["main", "run"]


def run() -> None:
    """Entry point of the console script."""
    status = main()
    interrupts.hold_signals_until_exit()
    sys.exit(status)
