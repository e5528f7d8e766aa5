"""The window a blur spot is measured in: one rule for predicted spots (traced
rays) and measured ones (pixels), so that the two can be compared.

A second moment weighs a faint, wide halo of aberrated light heavily, though
the eye (and any contrast measure) reads such a halo as veiling glare, not as
blur. The rule keeps the spot's core and its near flare: the window radius is
twice the spot's own second-moment diameter measured inside that window (a
uniform disk of diameter d fits in radius d / 2, so 2 d holds it with a wide
margin), and never less than :data:`MIN_WINDOW_PX` (the margin
:func:`lenscompare.measure.measure_blur_disks` adds for pixels and sampling).
It is found by fixed-point iteration from a wide window, which only shrinks.
"""

from __future__ import annotations

import math
from collections.abc import Callable

__all__ = ["MIN_WINDOW_PX", "WINDOW_PER_DIAMETER", "settled_window_px"]

MIN_WINDOW_PX = 4.0
WINDOW_PER_DIAMETER = 2.0


def settled_window_px(diameter_in_px: Callable[[float], float], *, start_px: float = math.inf,
                      max_rounds: int = 30) -> tuple[float, float]:
    """The window radius the rule settles on, and the spot diameter inside it.

    Parameters
    ----------
    diameter_in_px : callable
        Second-moment diameter (px) of the spot measured within a window of
        the given radius (px) about its centroid; ``math.inf`` for no window.
    start_px : float, optional
        The first window (default: none).
    max_rounds : int, optional
        Iterations at most (the window settles to 0.1 % in a few).

    Returns
    -------
    (window_px, diameter_px) : tuple of float
    """
    window = start_px
    diameter = diameter_in_px(window)
    for _ in range(max_rounds):
        next_window = max(MIN_WINDOW_PX, WINDOW_PER_DIAMETER * diameter)
        if next_window >= window * (1.0 - 1e-3):  # settled (the window never grows back)
            break
        window = next_window
        diameter = diameter_in_px(window)
    return window, diameter
