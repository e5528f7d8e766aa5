"""Sweeps on a real Dask cluster: a scheduler and two workers started as
separate processes on 127.0.0.1 with the ``dask scheduler`` and ``dask worker``
commands, a sweep sent to them with ``--scheduler``, one worker killed in the
middle, resume after an interrupted run, an unreachable scheduler, and the
local cluster's table as the reference."""

from __future__ import annotations

import json
import os
import signal
import socket
import subprocess
import sys
import textwrap
import time
from pathlib import Path

import pandas as pd
import pytest

from lenscompare.cluster import machine_cores
from lenscompare.sweep import RUN_COLUMNS

from helpers import run_cli

DASK = Path(sys.executable).with_name("dask")

# 12 tasks of a few tenths of a second each: long enough to kill a worker in
# the middle, one of them failing (wide.22mm opens only to f/2.68).
SWEEP = textwrap.dedent("""\
    scenes = ["dot_grid"]
    [axes]
    lens = ["dgauss.50mm", "wide.22mm"]
    f_number = [2.4, 5.6, 11.0]
    model = ["thin", "lens"]
    spp = [16]
    """)
TASKS = 12


def _free_port() -> int:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


def _start(args: list[str], log: Path) -> subprocess.Popen:
    return subprocess.Popen([str(DASK), *args], stdout=log.open("w"), stderr=subprocess.STDOUT,
                            start_new_session=True)


def _wait_for_workers(address: str, n: int, timeout_s: float = 120.0) -> None:
    from distributed import Client

    with Client(address, timeout=30, set_as_default=False) as client:
        client.wait_for_workers(n, timeout=timeout_s)


def _stop(process: subprocess.Popen) -> None:
    if process.poll() is None:
        os.killpg(process.pid, signal.SIGTERM)
        try:
            process.wait(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(process.pid, signal.SIGKILL)
            process.wait()


@pytest.fixture(scope="module")
def cluster(tmp_path_factory):
    """A scheduler and two single-slot workers, each its own process group."""
    logs = tmp_path_factory.mktemp("dask-logs")
    address = f"tcp://127.0.0.1:{_free_port()}"
    port = address.rsplit(":", 1)[1]
    scheduler = _start(["scheduler", "--host", "127.0.0.1", "--port", port, "--no-dashboard"], logs / "scheduler.log")
    # --no-nanny: the worker is the process itself, so killing it kills it (a
    # nanny would start a new one).
    workers = [_start(["worker", address, "--nthreads", "1", "--no-nanny", "--no-dashboard", "--name", f"w{i}",
                       "--host", "127.0.0.1"], logs / f"worker{i}.log") for i in range(2)]
    try:
        _wait_for_workers(address, 2)
        yield {"address": address, "workers": workers, "logs": logs}
    finally:
        for process in workers + [scheduler]:
            _stop(process)


@pytest.fixture(scope="module")
def local_table(tmp_path_factory):
    """The same sweep on the default local cluster: the reference table."""
    folder = tmp_path_factory.mktemp("local")
    (folder / "sweep.toml").write_text(SWEEP)
    result = run_cli("sweep", folder / "sweep.toml", "-o", folder / "out", "--workers", "2", "--no-plots", "--json")
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)
    assert (summary["tasks"], summary["run"], summary["failed"]) == (TASKS, TASKS, 1)
    assert "local cluster" in summary["cluster"]
    return pd.read_parquet(folder / "out" / "results.parquet")


def _journal_rows(path: Path) -> int:
    try:
        return path.read_bytes().count(b"\n")
    except FileNotFoundError:
        return 0


def _sweep_process(folder: Path, address: str) -> subprocess.Popen:
    (folder / "sweep.toml").write_text(SWEEP)
    return subprocess.Popen([sys.executable, "-m", "lenscompare", "sweep", str(folder / "sweep.toml"), "-o",
                             str(folder / "out"), "--scheduler", address, "--no-plots", "--json"],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)


def _journal_workers(path: Path) -> set[str]:
    try:
        lines = path.read_text().splitlines()
    except FileNotFoundError:
        return set()
    return {json.loads(line)["worker"] for line in lines if line.endswith("}")}


def _wait_for(done, process: subprocess.Popen, timeout_s: float = 120.0) -> None:
    deadline = time.monotonic() + timeout_s
    while not done():
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "the sweep wrote no rows"
        time.sleep(0.02)


def test_an_interrupted_sweep_resumes_with_only_the_missing_tasks(cluster, tmp_path, main, capsys):
    sweep = _sweep_process(tmp_path, cluster["address"])
    journal = tmp_path / "out" / "rows.jsonl"
    _wait_for(lambda: _journal_rows(journal) >= 3, sweep)
    sweep.send_signal(signal.SIGKILL)  # no chance to tidy up
    sweep.wait()
    done = _journal_rows(journal)
    assert 3 <= done < TASKS, done

    again = run_cli("sweep", tmp_path / "sweep.toml", "-o", tmp_path / "out", "--scheduler", cluster["address"],
                    "--no-plots", "--json")
    assert again.returncode == 0, again.stderr
    summary = json.loads(again.stdout)
    assert (summary["run"], summary["skipped"]) == (TASKS - done, done)
    # Each task's row once: nothing that was done ran again.
    keys = [json.loads(line)["task_key"] for line in journal.read_text().splitlines()]
    assert len(keys) == len(set(keys)) == TASKS
    # A third run renders nothing (and needs no cluster).
    assert main(["sweep", str(tmp_path / "sweep.toml"), "-o", str(tmp_path / "out"), "--scheduler", "tcp://127.0.0.1:9",
                 "--no-plots", "--json"]) == 0
    assert json.loads(capsys.readouterr().out)["run"] == 0
    assert len(pd.read_parquet(tmp_path / "out" / "results.parquet")) == TASKS


def test_a_sweep_survives_a_worker_killed_mid_sweep_and_matches_the_local_run(cluster, local_table, tmp_path):
    sweep = _sweep_process(tmp_path, cluster["address"])
    journal = tmp_path / "out" / "rows.jsonl"
    # Kill w1 once both workers have finished a task.
    _wait_for(lambda: _journal_workers(journal) == {"w0", "w1"}, sweep)
    victim = cluster["workers"][1]
    os.killpg(victim.pid, signal.SIGKILL)
    at_kill = _journal_rows(journal)
    victim.wait()
    out, err = sweep.communicate(timeout=300)
    assert sweep.returncode == 0, err
    assert at_kill < TASKS - 2, f"the sweep was nearly done ({at_kill} rows) when the worker died"
    summary = json.loads(out)
    assert summary["not_run"] == [] and summary["run"] == TASKS

    table = pd.read_parquet(tmp_path / "out" / "results.parquet")
    assert table["task"].tolist() == list(range(TASKS))
    assert set(table["worker"]) == {"w0", "w1"}
    assert set(table["threads"]) == {max(1, machine_cores() // 2)}  # 2 slots on this machine
    failed = table[table["error"].notna()]
    assert list(zip(failed["lens"], failed["model"], failed["f_number"])) == [("wide.22mm", "lens", 2.4)]
    # Identical to the local cluster's table in every column but the timing.
    pd.testing.assert_frame_equal(table.drop(columns=list(RUN_COLUMNS)), local_table.drop(columns=list(RUN_COLUMNS)))


def test_an_unreachable_scheduler_exits_1_naming_it_within_10_s(tmp_path):
    (tmp_path / "sweep.toml").write_text(SWEEP)
    address = f"tcp://127.0.0.1:{_free_port()}"  # nothing listens there
    start = time.monotonic()
    result = run_cli("sweep", tmp_path / "sweep.toml", "-o", tmp_path / "out", "--scheduler", address)
    elapsed = time.monotonic() - start
    assert result.returncode == 1, result.stderr
    assert address in result.stderr and result.stderr.count("\n") == 1, result.stderr
    assert elapsed < 10.0, elapsed


def test_report_renders_run_as_tasks_and_match_this_process(cluster):
    """What ``report --scheduler`` does with its renders: every model of every
    scene a task on the cluster; the images are this process's, bit for bit."""
    import numpy as np

    from lenscompare.cluster import open_cluster
    from lenscompare.experiment import ExperimentSettings, prepare_scene, render_scenes
    from lenscompare.scene import load_scene

    from helpers import REFERENCE_SCENES

    settings = ExperimentSettings(quick=True, povray=False, mitsuba=False)
    scenes = [prepare_scene(load_scene(REFERENCE_SCENES / "flat_field.toml"), settings)[0]]
    scenes = [s.with_render(spp=4) for s in scenes]
    here = render_scenes(scenes, settings)
    with open_cluster(cluster["address"]) as dask:
        there = render_scenes(scenes, settings, cluster=dask)
    assert [r.label for r in there[0][0]] == [r.label for r in here[0][0]] == ["pinhole", "thin", "thick", "lens"]
    for a, b in zip(here[0][0], there[0][0]):
        assert np.array_equal(a.image.pixels, b.image.pixels), a.label
        assert b.image.metadata["threads"] == max(1, machine_cores() // dask.slots_by_host["127.0.0.1"])


def test_cost_study_on_the_cluster_matches_this_process(cluster, tmp_path):
    from lenscompare.cluster import open_cluster
    from lenscompare.cost import CostSettings, run_cost_study
    from lenscompare.scene import load_scene

    from helpers import REFERENCE_SCENES

    scene = load_scene(REFERENCE_SCENES / "showcase.toml")
    settings = CostSettings(quick=True, samplers=("jittered",), models=("pinhole", "thin"), povray=False,
                            cache_dir=tmp_path / "cache")
    here = run_cost_study([scene], tmp_path / "here", settings, progress=False)
    with open_cluster(cluster["address"]) as dask:
        there = run_cost_study([scene], tmp_path / "there", settings, progress=False, cluster=dask)
    assert there["settings"]["scheduler"] == cluster["address"]
    for model in ("pinhole", "thin"):
        a, b = (r["scenes"]["showcase"]["models"][model]["jittered"]["points"] for r in (here, there))
        assert [p["relative_rmse"] for p in a] == [p["relative_rmse"] for p in b]


@pytest.mark.parametrize("command", ["report", "cost"])
def test_report_and_cost_take_a_scheduler_and_name_it_when_unreachable(command, tmp_path):
    address = f"tcp://127.0.0.1:{_free_port()}"
    result = run_cli(command, "flat_field" if command == "report" else
                     Path(__file__).parent.parent / "reference_scenes" / "flat_field.toml",
                     "-o", tmp_path / "out", "--scheduler", address)
    assert result.returncode == 1 and address in result.stderr, result.stderr
