"""The cost study: time-to-error interpolation, Pareto front, the reference
cache, and a small study end to end."""

import math

import pytest

from lenscompare.cost import CostSettings, run_cost_study
from lenscompare.cost.study import fitted_slope, pareto_front, time_to_error
from lenscompare.scene import load_scene

from helpers import REFERENCE_SCENES


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
