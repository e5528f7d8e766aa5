"""Sweeps in one process: sweep files (bad ones exit 2 naming the key), the
task grid, one task's row, the journal and the table. The Dask side (a real
scheduler and workers) is in test_sweep_cluster.py."""

from __future__ import annotations

import json
import math
import textwrap
from pathlib import Path

import pandas as pd
import pytest

from lenscompare.errors import InputError
from lenscompare.scene import load_scene
from lenscompare.sweep import COLUMNS, Journal, parse_sweep, results_frame, run_task, task_grid
from lenscompare.sweep.columns import MEASUREMENT_COLUMNS
from lenscompare.sweep.table import write_results

from helpers import REFERENCE_SCENES

GOOD = textwrap.dedent("""\
    scenes = ["dot_grid", "flat_field"]
    measure = ["distortion", "vignetting"]
    [axes]
    lens = ["dgauss.50mm", "wide.22mm"]
    f_number = [2.8, 8.0]
    focus_distance = [2.0, 5.0]
    model = ["thin", "lens"]
    sampler = ["sobol"]
    spp = [16]
    seed = [0]
    """)


def test_the_design_example_parses_into_its_full_grid():
    spec = parse_sweep(GOOD, source="sweep.toml")
    tasks = task_grid(spec)
    assert len(tasks) == 2 * 2 * 2 * 2 * 2
    first = tasks[0].parameters()
    assert (first["scene"], first["lens"], first["f_number"], first["focus_distance_m"], first["model"],
            first["sampler"], first["spp"], first["seed"]) == ("dot_grid", "dgauss.50mm", 2.8, 2.0, "thin", "sobol",
                                                               16, 0)
    # The model varies fastest (axis order: lens, f_number, focus_distance, model, ...).
    assert [t.model for t in tasks[:4]] == ["thin", "lens", "thin", "lens"]
    assert len({t.key for t in tasks}) == len(tasks)
    assert [t.index for t in tasks] == list(range(len(tasks)))


def test_a_missing_axis_keeps_the_scenes_own_value():
    tasks = task_grid(parse_sweep('scenes = ["dot_grid"]\n[axes]\nmodel = ["thin", "lens"]\n'))
    scene = load_scene(REFERENCE_SCENES / "dot_grid.toml")
    assert len(tasks) == 2
    for task in tasks:
        p = task.parameters()
        assert p["f_number"] == scene.camera.f_number
        assert p["focus_distance_m"] == scene.camera.focus_distance_m
        assert (p["spp"], p["sampler"], p["seed"]) == (scene.render.spp, scene.render.sampler, scene.render.seed)
        assert p["measure"] == "distortion"  # the scene's own
        # dot_grid names no lens: the experiment's default, as the report uses.
        assert p["lens"] == "dgauss.50mm"


def test_the_task_key_follows_every_input():
    base = task_grid(parse_sweep('scenes = ["dot_grid"]\n'))[0]
    assert base.key == task_grid(parse_sweep('scenes = ["dot_grid"]\n'))[0].key
    # The scene's own values, given as axes, are the same task.
    assert base.key == task_grid(parse_sweep('scenes = ["dot_grid"]\n[axes]\nspp = [64]\nmodel = ["thin"]\n'))[0].key
    for change in ('spp = [5]', 'seed = [1]', 'f_number = [8.1]', 'model = ["lens"]', 'lens = ["wide.22mm"]',
                   'sampler = ["sobol"]', 'focus_distance = [5.5]'):
        other = task_grid(parse_sweep(f'scenes = ["dot_grid"]\n[axes]\n{change}\n'))[0]
        assert other.key != base.key, change


BAD = [
    ('scenes = ["dot_grid"]\nspeed = 1\n', "speed", "unknown key"),
    ('[axes]\nmodel = ["thin"]\n', "scenes", "missing"),
    ('scenes = []\n', "scenes", "non-empty"),
    ('scenes = ["no_such_scene"]\n', "scenes[0]", "no scene file"),
    ('scenes = ["dot_grid", "dot_grid"]\n', "scenes[1]", "already"),
    ('scenes = ["dot_grid"]\nmeasure = ["similarity"]\n', "measure[0]", "similarity needs a second image"),
    ('scenes = ["dot_grid"]\n[axes]\naperture = [2]\n', "axes.aperture", "unknown key"),
    ('scenes = ["dot_grid"]\n[axes]\nf_number = [2.8, -4]\n', "axes.f_number[1]", "positive"),
    ('scenes = ["dot_grid"]\n[axes]\nf_number = ["f/8"]\n', "axes.f_number[0]", "expected a number"),
    ('scenes = ["dot_grid"]\n[axes]\nf_number = 8\n', "axes.f_number", "non-empty array"),
    ('scenes = ["dot_grid"]\n[axes]\nfocus_distance = [nan]\n', "axes.focus_distance[0]", "finite"),
    ('scenes = ["dot_grid"]\n[axes]\nmodel = ["thin", "fisheye"]\n', "axes.model[1]", "expected one of"),
    ('scenes = ["dot_grid"]\n[axes]\nsampler = ["halton"]\n', "axes.sampler[0]", "expected one of"),
    ('scenes = ["dot_grid"]\n[axes]\nspp = [16, 0]\n', "axes.spp[1]", ">= 1"),
    ('scenes = ["dot_grid"]\n[axes]\nspp = [1.5]\n', "axes.spp[0]", "integer"),
    ('scenes = ["dot_grid"]\n[axes]\nseed = [0, 0]\n', "axes.seed[1]", "already"),
    ('scenes = ["dot_grid"]\n[axes]\nlens = ["dgauss.50mm", "zoom.24-70mm"]\n', "axes.lens[1]", "no shipped lens"),
    ('scenes = ["dot_grid"\n', None, "not valid TOML"),
]


@pytest.mark.parametrize("text, key, words", BAD, ids=[b[1] or "toml" for b in BAD])
def test_a_bad_sweep_file_exits_2_naming_the_key(tmp_path, main, capsys, text, key, words):
    sweep = tmp_path / "bad.toml"
    sweep.write_text(text)
    assert main(["sweep", str(sweep), "-o", str(tmp_path / "out")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert f"{sweep}: " in err and words in err, err
    if key is not None:
        assert f"{sweep}: {key}: " in err, err
    assert not (tmp_path / "out").exists()  # nothing started


def test_scene_and_lens_paths_are_relative_to_the_sweep_file(tmp_path):
    (tmp_path / "sub").mkdir()
    (tmp_path / "sub" / "grid.toml").write_text((REFERENCE_SCENES / "dot_grid.toml").read_text())
    (tmp_path / "sub" / "mine.dat").write_text((REFERENCE_SCENES.parent / "lenscompare" / "lenses" / "data"
                                               / "dgauss.50mm.dat").read_text())
    sweep = tmp_path / "sub" / "s.toml"
    sweep.write_text('scenes = ["grid.toml"]\n[axes]\nlens = ["mine.dat"]\n')
    from lenscompare.sweep import load_sweep

    spec = load_sweep(sweep)
    assert spec.scenes[0].name == "dot_grid" and spec.axes["lens"][0].name == "mine"


SMALL = textwrap.dedent("""\
    scenes = ["flat_field"]
    [axes]
    lens = ["wide.22mm"]
    f_number = [2.0, 4.0]
    model = ["lens"]
    spp = [2]
    """)


@pytest.fixture(scope="module")
def small_rows():
    tasks = task_grid(parse_sweep(SMALL))
    return tasks, [{**t.parameters(), **run_task(t, threads=1)} for t in tasks]


def test_a_task_that_fails_is_a_row_holding_its_error(small_rows):
    tasks, rows = small_rows
    failed, ok = rows
    # wide.22mm opens to f/2.68: f/2 is refused, as `lenscompare render` refuses it.
    assert failed["error"].startswith("InputError: camera.f_number: f/2 is faster than wide.22mm allows")
    assert "vignetting_corner_percent" not in failed and failed["f_number"] == 2.0
    assert ok["error"] is None and ok["seconds"] > 0 and ok["samples_per_second"] > 0
    # wide.22mm at f/4: its traced relative illumination and the render agree.
    assert ok["traced_relative_illumination"] and 5 < ok["vignetting_corner_percent"] < 95
    traced = dict(zip(ok["traced_field_deg"], ok["traced_relative_illumination"]))
    assert ok["relative_illumination_20deg"] == pytest.approx(traced[20.0], abs=0.05)


def test_a_tasks_row_does_not_depend_on_its_thread_count():
    task = task_grid(parse_sweep('scenes = ["dot_grid"]\n[axes]\nlens = ["wide.22mm"]\nf_number = [5.6]\n'
                                 'model = ["lens"]\nspp = [2]\n'))[0]
    one, two = (run_task(task, threads=n) for n in (1, 2))
    assert (one["threads"], two["threads"]) == (1, 2) and one["distortion_dots_matched"] > 100
    for column in COLUMNS:
        if column not in ("seconds", "samples_per_second", "task_seconds", "threads", "worker"):
            assert _same(one.get(column), two.get(column)), column


def _same(a, b) -> bool:
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


def test_the_table_has_every_column_typed_and_survives_parquet(small_rows, tmp_path):
    _, rows = small_rows
    frame = write_results(list(reversed(rows)), tmp_path / "results.parquet")
    back = pd.read_parquet(tmp_path / "results.parquet")
    assert list(back.columns) == list(COLUMNS)
    assert back["task"].tolist() == [0, 1]  # grid order, whatever the order of arrival
    for name, (_, kind) in MEASUREMENT_COLUMNS.items():
        dtype = str(back[name].dtype)
        assert dtype == ("object" if kind == "list" else "Int64" if name.endswith(("_matched", "_found"))
                         else "float64"), (name, dtype)
    assert str(back["spp"].dtype) == "Int64" and back["f_number"].dtype == "float64"
    assert pd.isna(back["error"][1]) and back["error"][0].startswith("InputError")
    assert list(back["relative_illumination"][1]) == rows[1]["relative_illumination"]
    assert len(back["relative_illumination"][0]) == 0  # the failed row: an empty curve
    pd.testing.assert_frame_equal(back, frame, check_dtype=False)


def test_the_journal_keeps_finished_rows_and_drops_a_cut_line(tmp_path):
    path = tmp_path / "rows.jsonl"
    with Journal(path) as journal:
        journal.append({"task_key": "a", "task": 0, "value": math.nan})
        journal.append({"task_key": "b", "task": 1})
    with open(path, "ab") as f:
        f.write(b'{"task_key": "c", "ta')  # killed mid-write
    with Journal(path) as journal:
        assert set(journal.rows) == {"a", "b"} and math.isnan(journal.rows["a"]["value"])
        journal.append({"task_key": "c", "task": 2})
    lines = path.read_text().splitlines()
    assert [json.loads(line)["task_key"] for line in lines] == ["a", "b", "c"]


def test_two_sweeps_cannot_share_a_journal(tmp_path):
    with Journal(tmp_path / "rows.jsonl"):
        with pytest.raises(InputError, match="in use by another sweep"):
            Journal(tmp_path / "rows.jsonl")


def test_a_damaged_journal_line_is_named(tmp_path):
    (tmp_path / "rows.jsonl").write_text('{"task_key": "a", "task": 0}\nnot json\n')
    with pytest.raises(InputError, match="line 2"):
        Journal(tmp_path / "rows.jsonl")


def test_results_frame_of_no_rows_has_the_columns():
    assert list(results_frame([]).columns) == list(COLUMNS)


@pytest.mark.parametrize("options, option", [(["--workers", "0"], "--workers"), (["--threads", "0"], "--threads"),
                                              (["--workers", "2", "--scheduler", "tcp://127.0.0.1:9"], "--workers")])
def test_bad_cluster_options_exit_2_naming_the_option(tmp_path, main, capsys, options, option):
    sweep = tmp_path / "s.toml"
    sweep.write_text('scenes = ["flat_field"]\n')
    assert main(["sweep", str(sweep), "-o", str(tmp_path / "out"), *options]) == 2
    err = capsys.readouterr().err
    # Named by the option checks (``--workers: ...``) or by its bounded type
    # (``argument --threads: expected an integer from 1 ...``).
    assert err.startswith("lenscompare: error: ") and err.count("\n") == 1, err
    assert f"{option}: " in err and "Traceback" not in err, err


def test_the_shipped_example_is_found_by_name_and_is_the_issue_grid():
    from lenscompare.sweep import load_sweep

    # The issue's grid: the four classic lenses (the shipped dispersive one is not in it).
    classics = ["dgauss.50mm", "fisheye.10mm", "telephoto.250mm", "wide.22mm"]
    spec = load_sweep("example")
    assert [s.name for s in spec.scenes] == ["dot_grid", "flat_field"]
    assert sorted(lens.name for lens in spec.axes["lens"]) == classics
    assert (len(spec.axes["f_number"]), len(spec.axes["focus_distance"]), len(spec.axes["model"])) == (5, 3, 3)
    assert len(task_grid(spec)) == 2 * len(classics) * 5 * 3 * 3


def test_a_finished_sweep_runs_nothing_and_a_changed_one_sets_old_rows_aside(tmp_path):
    """The journal is the record: with every task in it no cluster is opened;
    rows of tasks a changed sweep file no longer has stay in the journal but
    not in the table. (Rows made here, in-process; the Dask side is in
    test_sweep_cluster.py.)"""
    from lenscompare.sweep import run_sweep

    text = 'scenes = ["flat_field"]\n[axes]\nmodel = ["thin", "thick"]\nf_number = [4.0, 8.0]\nspp = [1]\n'
    tasks = task_grid(parse_sweep(text))
    with Journal(tmp_path / "rows.jsonl") as journal:
        for task in reversed(tasks):
            journal.append({**task.parameters(), **run_task(task, threads=1)})
    summary = run_sweep(parse_sweep(text), tmp_path, scheduler="tcp://127.0.0.1:9")  # never contacted
    assert (summary["tasks"], summary["run"], summary["skipped"], summary["other_rows"]) == (4, 0, 4, 0)
    assert summary["cluster"] is None
    table = pd.read_parquet(tmp_path / "results.parquet")
    assert table["task"].tolist() == [0, 1, 2, 3] and table["model"].tolist() == ["thin", "thick"] * 2
    assert {Path(p).name for p in summary["plots"]} >= {"vignetting_corner_percent_vs_f_number.png",
                                                       "seconds_vs_model.png"}

    fewer = text.replace('f_number = [4.0, 8.0]', 'f_number = [8.0]')
    summary = run_sweep(parse_sweep(fewer), tmp_path, scheduler="tcp://127.0.0.1:9", plots=False)
    assert (summary["tasks"], summary["run"], summary["other_rows"]) == (2, 0, 2)
    table = pd.read_parquet(tmp_path / "results.parquet")
    assert table["task"].tolist() == [0, 1] and set(table["f_number"]) == {8.0}  # renumbered by this sweep
