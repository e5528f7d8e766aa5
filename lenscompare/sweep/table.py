"""The sweep's results: a journal of finished rows, and ``results.parquet``.

Each finished row is appended to ``DIR/rows.jsonl`` (one JSON object a line,
flushed and synced) the moment it arrives, so a sweep that is killed, or whose
worker or client dies, loses no finished row; a re-run with the same ``DIR``
reads the journal and runs only the tasks it lacks. A line cut short by a kill
is dropped (that task runs again). ``results.parquet`` is written from the
journal atomically (a temporary file, then a rename), every few seconds while
the sweep runs and at its end: one row per task of the current sweep, in grid
order.
"""

from __future__ import annotations

import fcntl
import json
import os
from pathlib import Path

import pandas as pd

from ..atomic import atomic_output
from ..errors import InputError
from .columns import MEASUREMENT_COLUMNS
from .tasks import PARAMETER_COLUMNS, RUN_COLUMNS

__all__ = ["Journal", "results_frame", "write_results", "COLUMNS"]

RESULT_COLUMNS = ("error", "ray_pass_fraction")
COLUMNS = PARAMETER_COLUMNS + RESULT_COLUMNS + RUN_COLUMNS + tuple(MEASUREMENT_COLUMNS)
"""Every column of ``results.parquet``, in order."""

_INTEGER_COLUMNS = ("task", "spp", "seed", "width_px", "height_px", "threads", "distortion_dots_matched",
                    "blur_disks_found")


class Journal:
    """``DIR/rows.jsonl``: append-only, one finished row a line.

    Opening it takes an exclusive lock, so two sweeps cannot write one folder.
    """

    def __init__(self, path: Path):
        self.path = Path(path)
        self._file = open(self.path, "a+b")  # noqa: SIM115 - closed by close()
        try:
            fcntl.flock(self._file, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            self._file.close()
            raise InputError("-o", f"{self.path.parent} is in use by another sweep (its journal "
                                   f"{self.path.name} is locked)") from None
        self.rows = self._read()

    def _read(self) -> dict[str, dict]:
        """Finished rows by task key; a cut-short last line is cut off the file."""
        self._file.seek(0)
        data = self._file.read()
        complete = data[: data.rfind(b"\n") + 1]
        if len(complete) != len(data):
            self._file.truncate(len(complete))
        rows = {}
        for number, line in enumerate(complete.splitlines(), start=1):
            try:
                row = json.loads(line)
                rows[row["task_key"]] = row
            except (ValueError, KeyError, TypeError):
                raise InputError(self.path, f"line {number}: not a finished row (a damaged journal; remove the "
                                            "line, and its task runs again)") from None
        return rows

    def append(self, row: dict) -> None:
        """Record one finished row durably."""
        self._file.seek(0, os.SEEK_END)
        self._file.write(json.dumps(row).encode() + b"\n")
        self._file.flush()
        os.fsync(self._file.fileno())
        self.rows[row["task_key"]] = row

    def close(self) -> None:
        self._file.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()


def results_frame(rows) -> pd.DataFrame:
    """The rows as a table with every column of :data:`COLUMNS`, in task order."""
    frame = pd.DataFrame(sorted(rows, key=lambda r: r["task"]), columns=list(COLUMNS))
    for name in _INTEGER_COLUMNS:
        frame[name] = frame[name].astype("Int64")
    for name, (_, kind) in MEASUREMENT_COLUMNS.items():
        if kind == "list":  # a list per row, empty where the task has none
            frame[name] = [list(v) if isinstance(v, list) else [] for v in frame[name]]
        elif name not in _INTEGER_COLUMNS:
            frame[name] = frame[name].astype("float64")
    for name in ("f_number", "focus_distance_m", "seconds", "samples_per_second", "task_seconds",
                 "ray_pass_fraction"):
        frame[name] = frame[name].astype("float64")
    frame["error"] = frame["error"].astype("string")
    return frame


def write_results(rows, path: Path) -> pd.DataFrame:
    """Write ``results.parquet`` atomically; return the table."""
    frame = results_frame(rows)
    with atomic_output(path) as tmp:
        frame.to_parquet(tmp, engine="pyarrow", index=False)
    return frame

