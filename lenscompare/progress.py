"""Progress bars: shown on a terminal, silent otherwise (CI, pipes, tests)."""

from __future__ import annotations

import os
import sys

from tqdm import tqdm

__all__ = ["progress_bar", "progress_enabled"]


def progress_enabled() -> bool:
    """True when stderr is a terminal and we are not in CI."""
    return sys.stderr.isatty() and not os.environ.get("CI")


def progress_bar(total: int, *, description: str, unit: str = "row", enabled: bool | None = None):
    """A tqdm bar on stderr (disabled unless :func:`progress_enabled`)."""
    if enabled is None:
        enabled = progress_enabled()
    return tqdm(total=total, desc=description, unit=unit, disable=not enabled, leave=False, file=sys.stderr)
