"""The installed package runs its main job: build a wheel, install it in a fresh
virtual environment outside the source tree, and run ``lenscompare report``
and ``lenscompare check`` from a folder outside the source tree, so that they
can only use what the wheel ships (scenes, check config, lenses, schema).

Slow for a unit test: about 2 minutes on two cores when the wheel's build
folder is cold (build/{wheel_tag}; kept, so later runs only check it), most of
it the native build (~50 s), the quick report (~25 s) and the default checks
(~30 s); installing the dependencies from pip's cache takes ~12 s. Marked ``wheel``: ``pytest -m "not wheel"``
leaves it out.
"""

from __future__ import annotations

import importlib.util
import json
import os
import subprocess
import sys
import time
import venv

import pytest

from helpers import REPO

pytestmark = pytest.mark.wheel


def _build_python() -> str:
    """The worktree's .venv python (it has scikit-build-core, nanobind, cmake, ninja)."""
    candidate = REPO / ".venv" / "bin" / "python"
    return str(candidate) if candidate.exists() else sys.executable


def _clean_env() -> dict:
    """The environment without anything that would put the source tree on sys.path."""
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME", "VIRTUAL_ENV")}
    env["PIP_DISABLE_PIP_VERSION_CHECK"] = "1"
    return env


def _run(args, *, cwd, timeout, env=None) -> subprocess.CompletedProcess:
    result = subprocess.run([str(a) for a in args], cwd=cwd, capture_output=True, text=True, timeout=timeout,
                            env=env or _clean_env())
    return result


@pytest.fixture(scope="module")
def installed(tmp_path_factory):
    """A fresh venv (outside the source tree) with the wheel installed; returns its bin folder."""
    for module in ("scikit_build_core", "nanobind"):
        if importlib.util.find_spec(module) is None:
            pytest.skip(f"{module} is not installed (make install installs it)")
    root = tmp_path_factory.mktemp("wheel")
    assert not root.resolve().is_relative_to(REPO)
    dist = root / "dist"
    timings = {}

    start = time.perf_counter()
    # The default build folder, build/{wheel_tag}, never the editable install's build/dev:
    # it is kept between runs, so a second run only relinks what changed.
    built = _run([_build_python(), "-m", "pip", "wheel", ".", "--no-deps", "--no-build-isolation", "--no-cache-dir",
                  "-w", dist],
                 cwd=REPO, timeout=1200)
    assert built.returncode == 0, built.stdout[-3000:] + built.stderr[-3000:]
    wheels = list(dist.glob("lenscompare-*.whl"))
    assert len(wheels) == 1, wheels
    timings["build wheel"] = time.perf_counter() - start

    start = time.perf_counter()
    env_dir = root / "venv"
    # No pip of its own (ensurepip costs seconds): this pip installs into it. Dependencies
    # come from the index (pip's cache); --no-compile skips byte-compiling them all.
    venv.EnvBuilder(with_pip=False, clear=True).create(env_dir)
    bin_dir = env_dir / "bin"
    pip = _run([_build_python(), "-m", "pip", "--python", bin_dir / "python", "install", "-q", "--no-compile",
                wheels[0]], cwd=root, timeout=1200)
    assert pip.returncode == 0, pip.stdout[-3000:] + pip.stderr[-3000:]
    timings["fresh venv + install"] = time.perf_counter() - start

    yield bin_dir, root, wheels[0], timings
    print("\nwheel test timings: " + ", ".join(f"{k} {v:.0f} s" for k, v in timings.items()))


def test_wheel_ships_the_runtime_files(installed):
    import zipfile

    _, _, wheel, _ = installed
    names = set(zipfile.ZipFile(wheel).namelist())
    assert "lenscompare/reference_scenes/bunny.ply" in names  # the mesh_bunny scene's mesh
    for scene in ("blur_disks", "dot_grid", "flat_field", "showcase", "lit_showcase", "mesh_bunny"):
        assert f"lenscompare/reference_scenes/{scene}.toml" in names
    for lens in ("dgauss.50mm", "wide.22mm", "fisheye.10mm", "telephoto.250mm"):
        assert f"lenscompare/lenses/data/{lens}.dat" in names
    assert "lenscompare/checks/default.toml" in names
    assert "lenscompare/sweep/example.toml" in names
    assert "lenscompare/report/results.schema.json" in names
    assert any(n.startswith("lenscompare/_native.") for n in names)


def test_installed_report_and_check_run_outside_the_source_tree(installed):
    jsonschema = pytest.importorskip("jsonschema")
    bin_dir, root, _, timings = installed
    work = root / "work"
    work.mkdir()

    # The package imported is the installed one, not the source tree.
    where = _run([bin_dir / "python", "-c", "import lenscompare; print(lenscompare.__file__)"], cwd=work, timeout=60)
    assert where.returncode == 0, where.stderr
    assert str(root) in where.stdout and str(REPO) not in where.stdout, where.stdout

    start = time.perf_counter()
    report = _run([bin_dir / "lenscompare", "report", "--quick", "-o", "out"], cwd=work, timeout=900)
    timings["report --quick"] = time.perf_counter() - start
    assert report.returncode == 0, report.stdout[-3000:] + report.stderr[-3000:]
    out = work / "out"
    assert (out / "index.html").is_file() and (out / "results.json").is_file()
    results = json.loads((out / "results.json").read_text())
    assert set(results["scenes"]) == {"blur_disks", "dot_grid", "flat_field", "showcase", "lit_showcase", "mesh_bunny",
                                        "far_landscape", "moving_showcase"}
    # the wheel's own Mitsuba (a dependency) rendered the scenes it can
    assert results["scenes"]["lit_showcase"]["vs_mitsuba"]["thin"]["ssim"] > 0.95

    # The schema as the wheel ships it, read as a user would.
    schema_text = _run([bin_dir / "python", "-c",
                        "from importlib import resources; "
                        "print(resources.files('lenscompare.report').joinpath('results.schema.json').read_text())"],
                       cwd=work, timeout=60)
    assert schema_text.returncode == 0, schema_text.stderr
    schema = json.loads(schema_text.stdout)
    jsonschema.Draft202012Validator.check_schema(schema)
    errors = [f"{'/'.join(map(str, e.absolute_path))}: {e.message}"
              for e in jsonschema.Draft202012Validator(schema).iter_errors(results)]
    assert not errors, errors[:10]

    start = time.perf_counter()
    check = _run([bin_dir / "lenscompare", "check"], cwd=work, timeout=900)
    timings["check"] = time.perf_counter() - start
    assert check.returncode == 0, check.stdout + check.stderr
    assert "5 passed, 0 failed" in check.stdout
