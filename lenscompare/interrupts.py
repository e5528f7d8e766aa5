"""SIGINT and SIGTERM as an exception, held back while an output is committed.

The command line installs :func:`handling_signals`: either signal then raises
:class:`Interrupted` (a ``KeyboardInterrupt``) between two Python steps, so the
``except``/``finally`` blocks of :mod:`lenscompare.atomic` remove their
temporary files. Around the rename that commits an output the signal is only
recorded (:func:`deferred`), so an output is either the old file or the whole
new one; once the command's final output is committed (:func:`mark_finished`)
later signals are ignored and the command ends with success, because its work
is done. A render in native code sees the signal when its band of rows
returns (well under a second).
"""

from __future__ import annotations

import contextlib
import os
import signal
import sys
import threading

__all__ = ["Interrupted", "exit_quietly_on_signals", "hold_signals_until_exit", "handling_signals", "deferred",
           "mark_finished", "finished_output", "late_signal"]

_SIGNALS = (signal.SIGINT, signal.SIGTERM)


class Interrupted(KeyboardInterrupt):
    """SIGINT or SIGTERM arrived; ``exit_status`` is 128 + the signal number."""

    def __init__(self, signum: int):
        self.signum = signum
        self.exit_status = 128 + signum
        super().__init__(signal.Signals(signum).name)


class _State:
    def __init__(self):
        self.defer = 0
        self.pending: int | None = None
        self.finished: str | None = None
        self.late: int | None = None


_state = _State()


def _handler(signum, frame):  # noqa: ARG001 - the signal module's signature
    if _state.finished is not None:
        _state.late = signum  # the work is done: the command ends with success
    elif _state.defer:
        _state.pending = signum
    else:
        raise Interrupted(signum)


def _exit_quietly(signum, frame):  # noqa: ARG001 - the signal module's signature
    print(f"lenscompare: interrupted ({signal.Signals(signum).name}) while starting; nothing was written",
          file=sys.stderr)
    os._exit(128 + signum)


def exit_quietly_on_signals() -> None:
    """For the program's first second (importing numpy, Embree...): nothing
    is written yet, so SIGINT/SIGTERM end it with one line and 128 + N,
    not an import traceback. The entry points call this before importing
    the command line; :func:`handling_signals` takes over in ``main``."""
    for s in _SIGNALS:
        signal.signal(s, _exit_quietly)


def hold_signals_until_exit() -> None:
    """After the command is done: Python's shutdown resets Python-level
    handlers to the default (death by the signal, status -N; any thread
    may receive it), so SIGINT/SIGTERM are ignored instead, which shutdown
    keeps: the command's own exit status stands."""
    for s in _SIGNALS:
        signal.signal(s, signal.SIG_IGN)


@contextlib.contextmanager
def handling_signals():
    """SIGINT and SIGTERM raise :class:`Interrupted` inside the block (main thread only)."""
    global _state
    _state = _State()
    if threading.current_thread() is not threading.main_thread():
        yield
        return
    previous = {s: signal.signal(s, _handler) for s in _SIGNALS}
    try:
        yield
    finally:
        for s, handler in previous.items():
            signal.signal(s, handler)


@contextlib.contextmanager
def deferred():
    """Hold SIGINT/SIGTERM back inside the block; raise :class:`Interrupted`
    at its normal end if one arrived (unless the final output is written)."""
    _state.defer += 1
    try:
        yield
    finally:
        _state.defer -= 1
    if _state.defer == 0 and _state.pending is not None and _state.finished is None:
        signum, _state.pending = _state.pending, None
        raise Interrupted(signum)


def mark_finished(path) -> None:
    """The command's final output is committed: from now on signals are only noted."""
    _state.finished = str(path)
    if _state.pending is not None:
        _state.late, _state.pending = _state.pending, None


def finished_output() -> str | None:
    """The final output, once committed."""
    return _state.finished


def late_signal() -> int | None:
    """The signal that arrived after the final output was committed, if any."""
    return _state.late
