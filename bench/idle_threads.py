"""Wait until this process's other threads stop using the CPU, before a timed render.

Dr.Jit's worker threads (Mitsuba 3's ``llvm_ad_rgb`` and ``scalar_rgb``) spin in
``TaskQueue::pop`` for about 20 ms after a render returns (``perf record -a``, session
35). On a 2-core machine a native render started in that window shares a core with the
spinning worker: a native render straight after one of Mitsuba's took 1.196x the time of
the one after it (median of 12 pairs, ``peers_lit``, thin lens); after a 0.1 s pause,
0.992x. Benchmarks that alternate renderers call ``wait_for_idle_threads()`` before
each timed render so that no renderer pays for the one before it.

Reads ``/proc/self/task/*/schedstat`` (Linux; elsewhere it returns at once): the first
field is the thread's time on a CPU in nanoseconds.
"""

from __future__ import annotations

import threading
import time
from pathlib import Path

TASKS = Path("/proc/self/task")


def _busy_ns_of_other_threads() -> int | None:
    """Nanoseconds on a CPU, summed over this process's threads other than the caller's."""
    if not TASKS.is_dir():
        return None
    own = str(threading.get_native_id())
    total = 0
    for task in TASKS.iterdir():
        if task.name == own:
            continue
        try:
            total += int((task / "schedstat").read_text().split()[0])
        except (OSError, ValueError, IndexError):
            continue  # the thread ended while we looked
    return total


def wait_for_idle_threads(*, window_s: float = 0.01, busy_fraction: float = 0.05,
                          timeout_s: float = 1.0) -> float:
    """Sleep until the other threads together use under ``busy_fraction`` of one core.

    Parameters
    ----------
    window_s : float, keyword-only
        Length of each look, in seconds.
    busy_fraction : float, keyword-only
        The other threads' CPU time over a window, as a fraction of the window, below
        which they count as idle.
    timeout_s : float, keyword-only
        Give up after this long (a thread that never idles: its cost is then the
        next render's).

    Returns
    -------
    float
        Seconds waited.
    """
    start = time.perf_counter()
    before = _busy_ns_of_other_threads()
    if before is None:
        return 0.0
    while time.perf_counter() - start < timeout_s:
        time.sleep(window_s)
        after = _busy_ns_of_other_threads()
        if after - before < busy_fraction * window_s * 1e9:
            break
        before = after
    return time.perf_counter() - start
