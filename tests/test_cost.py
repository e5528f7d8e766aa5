"""The cost study: time-to-error interpolation, Pareto front, the reference
cache, and a small study end to end."""

import math

import pytest

from lenscompare.cost import CostSettings, run_cost_study, time_table_rows
from lenscompare.cost.study import (TABLE_MIRRORED_SERIES, TABLE_SERIES, fitted_slope, pareto_front,
                                    povray_series_wanted, time_to_error)
from lenscompare.scene import load_scene

from helpers import REFERENCE_SCENES, run_cli


def test_time_to_error_interpolates_log_log():
    points = [{"spp": 1, "seconds": 1.0, "relative_rmse": 0.1}, {"spp": 100, "seconds": 100.0, "relative_rmse": 0.001}]
    t = time_to_error(points, 0.01)
    assert t == {"seconds": pytest.approx(10.0), "extrapolated": False}


def test_time_to_error_extrapolates_and_flags_it():
    points = [{"spp": 1, "seconds": 1.0, "relative_rmse": 0.4}, {"spp": 4, "seconds": 4.0, "relative_rmse": 0.2}]
    t = time_to_error(points, 0.01)
    assert t["extrapolated"] and t["seconds"] == pytest.approx(4.0 * 20 ** 2)


def test_fitted_slope_of_plain_monte_carlo():
    points = [{"spp": n, "relative_rmse": 0.3 / math.sqrt(n)} for n in (1, 4, 16, 64)]
    assert fitted_slope(points) == pytest.approx(-0.5)


def test_pareto_front_keeps_only_undominated_points():
    front = pareto_front([(1, 0.5, "a"), (2, 0.6, "b"), (3, 0.1, "c"), (4, 0.2, "d")])
    assert [label for *_, label in front] == ["a", "c"]


def test_small_study_end_to_end_and_reference_cache(tmp_path):
    scene = load_scene(REFERENCE_SCENES / "showcase.toml")
    settings = CostSettings(quick=True, samplers=("random", "jittered"), models=("pinhole", "thin"), povray=False,
                            cache_dir=tmp_path / "cache")
    first = run_cost_study([scene], tmp_path / "a", settings)
    study = first["scenes"]["showcase"]
    assert not study["references"]["thin"]["cached"]
    for model in ("pinhole", "thin"):
        for sampler in ("random", "jittered"):
            series = study["models"][model][sampler]
            errors = [p["relative_rmse"] for p in series["points"]]
            assert errors[-1] < errors[0] and all(p["seconds"] > 0 for p in series["points"])
            assert series["slope"] < -0.3
    assert study["model_error_vs_lens"] == {}  # no lens model in this study
    assert (tmp_path / "a" / "index.html").is_file() and (tmp_path / "a" / "showcase.cost.png").is_file()
    second = run_cost_study([scene], tmp_path / "b", settings)
    assert second["scenes"]["showcase"]["references"]["thin"]["cached"]


# --- the reference cache key --------------------------------------------------


def _key(scene, **settings):
    from lenscompare.cost.references import reference_key

    return reference_key(scene, "lens", **{"spp": 1024, "sampler": "jittered", "seed": 3, **settings})


def test_reference_key_follows_the_tracer_fingerprint(monkeypatch):
    """The key changes with the tracer (native build, camera/render sources),
    stays put while it does not, and does not care for ``__version__``, which
    stayed 0.1.0 through many tracer changes."""
    import lenscompare
    from lenscompare.cost import references

    scene = load_scene(REFERENCE_SCENES / "showcase.toml").with_camera(lens="dgauss.50mm", f_number=4.0)
    key = _key(scene)
    assert _key(scene) == key
    assert _key(scene, seed=4) != key and _key(scene.with_camera(f_number=5.6)) != key
    monkeypatch.setattr(lenscompare, "__version__", "99.0")
    assert _key(scene) == key
    monkeypatch.setattr(references, "tracer_fingerprint", lambda: "0" * 64)
    other = _key(scene)
    assert other != key
    assert _key(scene) == other
    monkeypatch.setattr(references, "tracer_fingerprint", lambda: "1" * 64)
    assert _key(scene) not in (key, other)


def test_tracer_fingerprint_is_the_native_module_and_the_rendering_sources(tmp_path):
    """One changed byte of the compiled module, or of a camera or render
    source, changes the fingerprint; a report or metrics source does not. The
    process's fingerprint is that of the loaded ``_native`` file."""
    from pathlib import Path

    from lenscompare import _native
    from lenscompare.cost import references

    native = tmp_path / "_native.so"
    native.write_bytes(Path(_native.__file__).read_bytes())
    package = tmp_path / "lenscompare"
    files = {"render.py": "RENDER = 1\n", "cameras/lens.py": "LENS = 1\n", "report/html.py": "HTML = 1\n",
             "metrics/blur_disk.py": "BLUR = 1\n"}
    for name, text in files.items():
        (package / name).parent.mkdir(parents=True, exist_ok=True)
        (package / name).write_text(text)
    base = references.fingerprint_files(native, package)
    assert references.fingerprint_files(native, package) == base

    def changed(path, data: bytes) -> str:
        original = path.read_bytes()
        path.write_bytes(data)
        try:
            return references.fingerprint_files(native, package)
        finally:
            path.write_bytes(original)

    blob = bytearray(native.read_bytes())
    blob[len(blob) // 2] ^= 1
    assert changed(native, bytes(blob)) != base
    assert changed(package / "render.py", b"RENDER = 2\n") != base
    assert changed(package / "cameras/lens.py", b"LENS = 2\n") != base
    assert changed(package / "report/html.py", b"HTML = 2\n") == base
    assert changed(package / "metrics/blur_disk.py", b"BLUR = 2\n") == base
    (package / "lenses").mkdir()
    (package / "lenses" / "trace.py").write_text("NEW = 1\n")  # a new module counts
    assert references.fingerprint_files(native, package) != base

    import lenscompare

    assert references.tracer_fingerprint() is references.tracer_fingerprint()  # computed once
    assert references.tracer_fingerprint() == references.fingerprint_files(
        Path(_native.__file__), Path(lenscompare.__file__).resolve().parent)


def test_study_with_the_lens_system_gains_the_composite_rows(tmp_path):
    scene = load_scene(REFERENCE_SCENES / "flat_field.toml").with_camera(f_number=8.0)
    settings = CostSettings(quick=True, samplers=("jittered",), models=("pinhole", "lens"), povray=False,
                            cache_dir=tmp_path / "cache")
    results = run_cost_study([scene], tmp_path / "a", settings)
    composite = results["scenes"]["flat_field"]["composite"]
    assert composite["planned"] and "vignetting" in composite["effects"]
    assert set(composite["part_seconds"]) == {"spp", *composite["effects"]}
    # Vignetting as a weight, not as noise: the flat field converges at once, and matches the lens system.
    assert composite["points"][-1]["relative_rmse"] < 1e-3 and composite["seconds_to_1_percent"]["seconds"] > 0
    assert composite["error_vs_lens"]["relative_rmse"] < 0.02
    rows = [row for row in time_table_rows(results) if row[1].startswith("composite")]
    assert len(rows) == 1 and "composites" in (tmp_path / "a" / "index.html").read_text()
    # The lens system's rays from a table: a series of its own, scored against the traced lens's image.
    lens = results["scenes"]["flat_field"]["models"]["lens"]
    assert set(lens) == {"jittered", TABLE_SERIES, TABLE_MIRRORED_SERIES}
    traced, table, mirrored = (lens[k]["points"][-1] for k in ("jittered", TABLE_SERIES, TABLE_MIRRORED_SERIES))
    for fast in (table, mirrored):
        assert fast["spp"] == traced["spp"] and fast["relative_rmse"] < 2 * traced["relative_rmse"] + 1e-3
    assert mirrored["relative_rmse"] != table["relative_rmse"]  # the mirrors are on: another image
    for series in (TABLE_SERIES, TABLE_MIRRORED_SERIES):
        assert any(row[1] == "lens" and row[2] == series for row in time_table_rows(results))


def test_quick_study_times_pov_ray_on_still_scenes_only():
    """POV-Ray renders a moving scene as the mean of sub-frames: a quick study
    leaves it out there (it would take most of the study), a full one does not."""
    moving = load_scene(REFERENCE_SCENES / "moving_showcase.toml")
    still = load_scene(REFERENCE_SCENES / "showcase.toml")
    assert not povray_series_wanted(moving, CostSettings(quick=True))
    assert povray_series_wanted(moving, CostSettings(quick=False))
    assert povray_series_wanted(still, CostSettings(quick=True))
    assert not povray_series_wanted(still, CostSettings(quick=True, povray=False))


def test_timing_repeats_time_each_point_by_its_fastest_round(tmp_path):
    """Rounds over the grid: every point keeps each round's seconds and the
    fastest as its time; its image (the same seed) and so its error do not change."""
    scene = load_scene(REFERENCE_SCENES / "showcase.toml")
    base = dict(quick=True, samplers=("random",), models=("pinhole",), povray=False, cache_dir=tmp_path / "cache")
    once = run_cost_study([scene], tmp_path / "a", CostSettings(**base), progress=False)
    thrice = run_cost_study([scene], tmp_path / "b", CostSettings(**base, timing_repeats=3), progress=False)
    assert thrice["settings"]["timing_repeats"] == 3
    points_once = once["scenes"]["showcase"]["models"]["pinhole"]["random"]["points"]
    points = thrice["scenes"]["showcase"]["models"]["pinhole"]["random"]["points"]
    for p, q in zip(points, points_once):
        assert len(p["seconds_by_round"]) == 3 and p["seconds"] == min(p["seconds_by_round"])
        assert p["relative_rmse"] == q["relative_rmse"]
    assert "seconds_by_round" not in points_once[0]


def test_cost_refuses_a_bad_timing_repeat_count(tmp_path):
    result = run_cli("cost", str(REFERENCE_SCENES / "showcase.toml"), "-o", str(tmp_path / "out"),
                     "--timing-repeats", "0")
    assert result.returncode == 2 and "--timing-repeats" in result.stderr
    assert not (tmp_path / "out").exists()
