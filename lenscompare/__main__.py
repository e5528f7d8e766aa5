"""``python -m lenscompare``: as the console script (see console.py)."""

import sys

from . import interrupts

# Guarded: Dask's worker processes are spawned and import the main module again.
if __name__ == "__main__":
    interrupts.exit_quietly_on_signals()

    from .cli import main  # after the handlers, on purpose

    status = main()
    interrupts.hold_signals_until_exit()
    sys.exit(status)
