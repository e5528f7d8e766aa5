"""Running a sweep's tasks on a Dask cluster, resuming from its journal.

Robust like a batch system: a task that fails is a row holding its error; a
worker that dies takes no finished row with it (rows are journalled as they
arrive on this side) and Dask runs its unfinished task elsewhere; a re-run with
the same output folder runs only the tasks the journal lacks. A task Dask
itself gives up on (its worker died under it three times, or the cluster went
away) is left out of the table and counted in ``not_run``; the next run tries
it again.
"""

from __future__ import annotations

import asyncio
import time
from pathlib import Path

from ..atomic import prepare_output_dir
from ..cluster import check_cluster_options, open_cluster
from ..errors import InputError
from ..progress import progress_bar
from .plots import write_plots
from .spec import SweepSpec
from .table import Journal, write_results
from .tasks import run_task, task_grid

__all__ = ["run_sweep", "TABLE_FLUSH_S"]

TABLE_FLUSH_S = 5.0
"""While tasks finish, ``results.parquet`` is rewritten at most this often."""


def run_sweep(spec: SweepSpec, out_dir, *, scheduler: str | None = None, workers: int | None = None,
              threads: int | None = None, progress: bool | None = None, plots: bool = True) -> dict:
    """Run every task of ``spec`` that ``out_dir`` lacks; write the table and plots.

    Parameters
    ----------
    spec : SweepSpec
    out_dir : path
        Created if missing. ``rows.jsonl`` (the journal), ``results.parquet``
        and ``plots/*.png`` are written into it.
    scheduler : str, optional
        Address of an existing Dask scheduler; default a local cluster.
    workers : int, optional
        Workers of the local cluster (default: one per core).
    threads : int, optional
        Native threads per render (default: the machine's cores over its Dask
        slots, see :mod:`lenscompare.cluster`).
    plots : bool
        Draw the plots (``plots/``).

    Returns
    -------
    dict
        ``tasks`` (in the sweep), ``run`` (this time), ``skipped`` (found in
        the journal), ``failed`` (rows with an error), ``not_run`` (tasks Dask
        gave up on, with why), ``other_rows`` (journal rows of tasks not in
        this sweep), ``seconds``, ``cluster``, ``table``, ``plots``.
    """
    check_cluster_options(scheduler, workers)
    if threads is not None and threads < 1:
        raise InputError("--threads", f"expected a positive integer, got {threads}")
    out = prepare_output_dir(out_dir)  # exit 2 naming -o when it cannot be made or written, before any task
    start = time.perf_counter()
    tasks = task_grid(spec)
    summary = {"tasks": len(tasks), "run": 0, "not_run": [], "cluster": None}
    with Journal(out / "rows.jsonl") as journal:
        todo = [t for t in tasks if t.key not in journal.rows]
        summary["skipped"] = len(tasks) - len(todo)
        if todo:
            with open_cluster(scheduler, workers=workers) as cluster:
                summary["cluster"] = cluster.describe()
                _run_tasks(cluster, todo, tasks, journal, out, threads=threads, progress=progress, summary=summary)
        rows = _current_rows(tasks, journal)
        # Rows of tasks this sweep no longer has (its file changed): kept in
        # the journal, left out of the table.
        summary["other_rows"] = len(set(journal.rows) - {t.key for t in tasks})
    frame = write_results(rows, out / "results.parquet")
    summary["failed"] = int(frame["error"].notna().sum())
    summary["table"] = str(out / "results.parquet")
    summary["plots"] = write_plots(frame, out / "plots") if plots else []
    summary["seconds"] = time.perf_counter() - start
    return summary


def _run_tasks(cluster, todo, tasks, journal: Journal, out: Path, *, threads, progress, summary) -> None:
    # distributed is imported by open_cluster already; as_completed is its.
    from distributed import as_completed  # noqa: PLC0415 - imported on use, see lenscompare.cluster

    futures = {cluster.client.submit(run_task, task, threads=threads, slots_by_host=cluster.slots_by_host,
                                     pure=False): task for task in todo}
    flushed = time.monotonic()
    with progress_bar(len(todo), description="sweep", unit="task", enabled=progress) as bar:
        for future in as_completed(futures, loop=cluster.client.loop):
            task = futures.pop(future)
            try:
                result = future.result()
            except (Exception, asyncio.CancelledError) as error:  # Dask gave up on it; the next run retries
                why = f"{error.__class__.__name__}: {error}".splitlines()[0]
                summary["not_run"].append({"task": task.index, "why": why})
            else:
                journal.append({**task.parameters(), **result})
                summary["run"] += 1
            finally:
                bar.update(1)
            if time.monotonic() - flushed > TABLE_FLUSH_S:
                write_results(_current_rows(tasks, journal), out / "results.parquet")
                flushed = time.monotonic()


def _current_rows(tasks, journal: Journal) -> list[dict]:
    """The journal's rows of this sweep's tasks, their parameters as this
    sweep names them (a reordered sweep file renumbers the tasks)."""
    return [{**journal.rows[t.key], **t.parameters()} for t in tasks if t.key in journal.rows]
