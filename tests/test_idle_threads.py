"""bench/idle_threads.py: the wait before a timed render lasts while another thread is
busy and ends when it stops (benchmarks would otherwise time a render that shares a core
with a spinning peer's worker)."""

from __future__ import annotations

import sys
import threading
import time
from pathlib import Path

import pytest

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "bench"))
from idle_threads import wait_for_idle_threads  # noqa: E402

pytestmark = pytest.mark.skipif(not Path("/proc/self/task").is_dir(), reason="needs Linux's /proc")


def test_returns_after_one_look_when_no_other_thread_works():
    assert wait_for_idle_threads(window_s=0.01) < 0.1


def test_waits_while_another_thread_spins_and_not_past_it():
    spin_s = 0.25

    def spin():  # a worker that spins, as Dr.Jit's do after a render
        end = time.perf_counter() + spin_s
        while time.perf_counter() < end:
            time.sleep(0)  # hands the GIL over, so that the waiting thread can look; still busy

    worker = threading.Thread(target=spin)
    worker.start()
    time.sleep(0.02)
    # 50 ms looks: on a loaded machine (more busy processes than cores) the
    # spinner can get no CPU at all in a 10 ms look and would count as idle.
    waited = wait_for_idle_threads(window_s=0.05, timeout_s=2.0)
    worker.join()
    assert 0.15 < waited < 1.0
