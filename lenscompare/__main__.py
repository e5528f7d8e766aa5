"""``python -m lenscompare``: as the console script (see console.py)."""

import sys

from . import interrupts

interrupts.exit_quietly_on_signals()

from .cli import main  # noqa: E402 - after the handlers, on purpose

status = main()
interrupts.hold_signals_until_exit()
sys.exit(status)
