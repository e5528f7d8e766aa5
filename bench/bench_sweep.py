"""Sweep scaling on a local Dask cluster, and Dask's own cost per task.

Prints one JSON object: the example sweep (lenscompare/sweep/example.toml, 360
tasks) on a local cluster of 1 and of 2 single-threaded workers (wall time from
the first submit to the last result; the cluster's start-up apart), the
speed-up, and the round trip of an empty task against the median task.
``--every K`` runs every K-th task only (quicker, for a look).

Usage: python bench/bench_sweep.py [--sweep FILE] [--every K] [--repeat N]
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import time
from pathlib import Path

from lenscompare.cluster import machine_cores, open_cluster
from lenscompare.sweep import load_sweep, run_task, task_grid

EXAMPLE = Path(__file__).resolve().parent.parent / "lenscompare" / "sweep" / "example.toml"


def _empty():
    return None


def _run(tasks, workers: int) -> dict:
    """Every task on a fresh local cluster of ``workers`` one-thread workers."""
    opened = time.perf_counter()
    with open_cluster(workers=workers) as cluster:
        client = cluster.client
        client.submit(_empty, pure=False).result()  # every worker up (the first task waits for one)
        client.wait_for_workers(workers)
        started = time.perf_counter()
        futures = [client.submit(run_task, t, threads=1, slots_by_host=cluster.slots_by_host, pure=False)
                   for t in tasks]
        results = client.gather(futures)
        seconds = time.perf_counter() - started
        overhead = _empty_round_trips(client) if workers == 1 else None
    return {"workers": workers, "seconds": seconds, "startup_seconds": started - opened, "results": results,
            "overhead": overhead}


def _empty_round_trips(client, n: int = 200) -> dict:
    """An empty task's round trip, one at a time (latency), and n at once
    (Dask's per-task cost when the queue is full)."""
    trips = []
    for _ in range(n):
        start = time.perf_counter()
        client.submit(_empty, pure=False).result()
        trips.append(time.perf_counter() - start)
    start = time.perf_counter()
    client.gather([client.submit(_empty, pure=False) for _ in range(n)])
    batch = (time.perf_counter() - start) / n
    return {"round_trip_ms_median": 1e3 * statistics.median(trips), "round_trip_ms_p90": 1e3 * sorted(trips)[
        int(0.9 * n)], "queued_ms_per_task": 1e3 * batch}


def _medians_by_scene_and_model(tasks, results) -> dict:
    """Median task seconds per "scene model" (tasks that ended in an error left out)."""
    groups = {}
    for task, r in zip(tasks, results):
        if r["error"] is None:
            parameters = task.parameters()
            groups.setdefault(f"{parameters['scene']} {parameters['model']}", []).append(r["task_seconds"])
    return {key: statistics.median(seconds) for key, seconds in sorted(groups.items())}


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--sweep", default=str(EXAMPLE))
    parser.add_argument("--every", type=int, default=1, help="run every K-th task only")
    parser.add_argument("--repeat", type=int, default=1, help="alternate 1 and 2 workers this many times")
    args = parser.parse_args()
    tasks = task_grid(load_sweep(args.sweep))[:: args.every]
    load_before = os.getloadavg()
    runs = {1: [], 2: []}
    for _ in range(args.repeat):
        for workers in (1, 2):
            runs[workers].append(_run(tasks, workers))
    best = {w: min(runs[w], key=lambda r: r["seconds"]) for w in runs}
    task_seconds = [r["task_seconds"] for r in best[1]["results"]]
    median_task = statistics.median(task_seconds)
    overhead = best[1]["overhead"]
    print(json.dumps({
        "benchmark": "sweep_scaling",
        "sweep": Path(args.sweep).name, "tasks": len(tasks), "failed_tasks": sum(
            r["error"] is not None for r in best[1]["results"]),
        "cores": machine_cores(), "load_average_before": load_before, "load_average_after": os.getloadavg(),
        "seconds_1_worker": [r["seconds"] for r in runs[1]], "seconds_2_workers": [r["seconds"] for r in runs[2]],
        "speedup_2_over_1": best[1]["seconds"] / best[2]["seconds"],
        "cluster_startup_seconds": [r["startup_seconds"] for r in runs[1] + runs[2]],
        "median_task_seconds": median_task, "mean_task_seconds": statistics.fmean(task_seconds),
        "median_task_seconds_by_scene_and_model": _medians_by_scene_and_model(tasks, best[1]["results"]),
        "empty_task": overhead,
        "overhead_percent_of_median_task": 100.0 * overhead["round_trip_ms_median"] / 1e3 / median_task,
    }, indent=2))


if __name__ == "__main__":
    main()
