"""Outputs (issue 13, classes 4, 9 and 10): an unwritable output is found
before the work; an OS error while writing is one line; SIGINT/SIGTERM leave
no temporary file and report success exactly when the output was written; a
killed run's temporary is swept by the next; messages a careless user meets."""

from __future__ import annotations

import os
import random
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from lenscompare import atomic, commands, interrupts
from lenscompare.atomic import atomic_output, check_output_file, is_temporary_name, sweep_stale_temporaries
from lenscompare.errors import ExternalError, InputError
from lenscompare.image import Image, read_exr, write_exr

from helpers import MINIMAL_SCENE, REPO

ROOT = os.geteuid() == 0


@pytest.fixture
def unwritable(tmp_path):
    """A folder this process cannot create files in: a read-only one when not
    root (root ignores permission bits), else sysfs (read-only even for root)."""
    if not ROOT:
        folder = tmp_path / "read-only"
        folder.mkdir()
        folder.chmod(0o555)
        yield folder
        folder.chmod(0o755)
        return
    if not Path("/sys/kernel").is_dir():
        pytest.skip("needs a folder root cannot write (/sys/kernel)")
    yield Path("/sys/kernel")


def one_error_line(err: str) -> str:
    lines = err.splitlines()
    assert len(lines) == 1 and lines[0].startswith("lenscompare: error: ") and "Traceback" not in err, err
    return lines[0]


def _forbid(monkeypatch, module, name):
    def work(*args, **kwargs):
        raise AssertionError(f"{name} ran although the output cannot be written")

    monkeypatch.setattr(module, name, work)


# ------------------------------------------------------------- class 4
def _command_cases(scene: Path, exr: Path, folder: Path):
    from lenscompare import cost, report
    from lenscompare.sweep import runner

    return {
        "mitsuba": (["mitsuba", str(scene), "-o", str(folder / "x.exr")], commands.load("mitsuba"),
                    "render_mitsuba"),
        "export": (["export", str(scene), "--to", "pbrt", "-o", str(folder / "x.pbrt")], commands.load("export"),
                   "scene_to_pbrt"),
        "sweep": (["sweep", "example", "-o", str(folder / "sweep")], runner, "task_grid"),
        "render": (["render", str(scene), "-o", str(folder / "x.exr")], commands.load("render"), "render"),
        "povray": (["povray", str(scene), "-o", str(folder / "x.exr")], commands.load("povray"), "render_povray"),
        "preview": (["preview", str(exr), "-o", str(folder / "x.png")], commands.load("preview"), "read_exr"),
        "report": (["report", str(scene), "-o", str(folder / "report"), "--quick"], report, "render_scenes"),
        "cost": (["cost", str(scene), "-o", str(folder / "cost"), "--quick"], cost, "study_scene"),
        "check --junit": (["check", str(REPO / "lenscompare" / "checks" / "default.toml"), "--junit",
                           str(folder / "junit.xml")], commands.load("check"), "run_check"),
    }


@pytest.mark.parametrize("command", ["render", "povray", "mitsuba", "export", "preview", "report", "cost", "sweep",
                                     "check --junit"])
def test_an_unwritable_output_is_exit_2_before_any_work(tmp_path, unwritable, main, capsys, monkeypatch, command):
    scene = tmp_path / "s.toml"
    scene.write_text(MINIMAL_SCENE)
    exr = tmp_path / "in.exr"
    write_exr(exr, Image(np.ones((4, 6, 3), np.float32)))
    argv, module, work = _command_cases(scene, exr, unwritable)[command]
    _forbid(monkeypatch, module, work)
    assert main(argv) == 2
    line = one_error_line(capsys.readouterr().err)
    assert ("cannot write" in line or "cannot create folder" in line) and any(
        reason in line for reason in ("Permission denied", "Read-only", "Operation not permitted")), line


def test_an_os_error_while_writing_is_one_line_exit_1_and_leaves_nothing(tmp_path, main, capsys, monkeypatch):
    scene = tmp_path / "s.toml"
    scene.write_text(MINIMAL_SCENE)
    out = tmp_path / "out.exr"
    out.write_bytes(b"a good old render")

    class FullDisk:
        def __init__(self, *args):
            pass

        def __enter__(self):
            return self

        def __exit__(self, *exc):
            return False

        def write(self, path):
            Path(path).write_bytes(b"half")
            raise OSError(28, "No space left on device")

    from lenscompare import image

    monkeypatch.setattr(image.OpenEXR, "File", FullDisk)
    assert main(["render", str(scene), "-o", str(out)]) == 1
    assert "No space left on device" in one_error_line(capsys.readouterr().err)
    assert out.read_bytes() == b"a good old render"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.exr", "s.toml"]


def test_the_output_path_is_checked_for_what_it_is(tmp_path):
    (tmp_path / "file").write_text("")
    with pytest.raises(InputError, match="is not a folder"):
        check_output_file(tmp_path / "file" / "x.exr")
    with pytest.raises(InputError, match="is a folder, expected a file name"):
        check_output_file(tmp_path)
    with pytest.raises(InputError, match="does not exist"):
        check_output_file(tmp_path / "no" / "x.exr")
    with pytest.raises(InputError, match="lies outside the output folder"):
        with atomic_output(tmp_path / "out" / ".." / "x.exr", within=tmp_path / "out"):
            pass
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


# ------------------------------------------------------------- class 9: signals, in process
class SignalAt:
    """Sends ``signum`` to this process at one step of the final write."""

    def __init__(self, monkeypatch, signum, where):
        self.signum = signum
        real_replace = os.replace
        from lenscompare import image

        real_file = image.OpenEXR.File

        def replace(src, dst):
            if where == "rename":
                os.kill(os.getpid(), signum)  # arrives while the rename is the commit
            real_replace(src, dst)
            if where == "after rename":
                os.kill(os.getpid(), signum)

        class File(real_file):
            def write(self, path):
                if where == "writing":
                    os.kill(os.getpid(), signum)  # arrives while the EXR is being written
                return super().write(path)

        monkeypatch.setattr(atomic.os, "replace", replace)
        monkeypatch.setattr(image.OpenEXR, "File", File)


@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
@pytest.mark.parametrize("where", ["writing", "rename", "after rename"])
def test_a_signal_around_the_final_write(tmp_path, main, capsys, monkeypatch, signum, where):
    scene = tmp_path / "s.toml"
    scene.write_text(MINIMAL_SCENE)
    out = tmp_path / "out.exr"
    out.write_bytes(b"a good old render")
    SignalAt(monkeypatch, signum, where)
    status = main(["render", str(scene), "-o", str(out), "--json"])
    captured = capsys.readouterr()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.exr", "s.toml"]  # never a temporary left
    if where == "writing":  # before the commit: the command fails, the old file stays
        assert status == 128 + signum
        assert "before the work was done; no partial file is left" in one_error_line(captured.err)
        assert out.read_bytes() == b"a good old render" and captured.out == ""
    else:  # the output is written: success, and the whole command's output
        assert status == 0
        assert read_exr(out).pixels.shape == (24, 36, 3) and '"output"' in captured.out
        assert f"{signal.Signals(signum).name} arrived after {out} was written" in captured.err


def test_signals_are_the_default_again_after_main(main, tmp_path):
    before = signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)
    main(["lens", "info", "dgauss.50mm"])
    assert (signal.getsignal(signal.SIGTERM), signal.getsignal(signal.SIGINT)) == before


# ------------------------------------------------------------- class 9: real signals and SIGKILL
RENDER_SCENE = MINIMAL_SCENE.replace("resolution = [36, 24]", "resolution = [480, 320]").replace(
    "film_mm = [36.0, 24.0]", "film_mm = [36.0, 24.0]").replace("spp = 4", "spp = 24")


def test_real_sigterm_and_sigint_at_random_moments_leave_old_or_new_output_and_no_temporary(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(RENDER_SCENE)
    out = tmp_path / "out.exr"
    rng = random.Random(13)
    start = time.perf_counter()
    subprocess.run([sys.executable, "-m", "lenscompare", "render", str(scene), "-o", str(out)], check=True)
    whole_s = time.perf_counter() - start
    outcomes = set()
    for i in range(4):  # the exact windows are tested in process above; these are real signals end to end
        out.write_bytes(b"a good old render")
        process = subprocess.Popen([sys.executable, "-m", "lenscompare", "render", str(scene), "-o", str(out)],
                                   stderr=subprocess.PIPE, text=True)
        time.sleep(rng.uniform(0.5, 1.1) * whole_s)  # mostly near the end: the render and the write
        signum = (signal.SIGTERM, signal.SIGINT)[i % 2]
        process.send_signal(signum)
        _, err = process.communicate(timeout=120)
        assert "Traceback" not in err
        assert not [p for p in tmp_path.iterdir() if is_temporary_name(p.name)]
        if process.returncode == 0:
            assert read_exr(out).pixels.shape == (320, 480, 3)
            outcomes.add("written")
        else:
            assert process.returncode == 128 + signum and out.read_bytes() == b"a good old render"
            outcomes.add("interrupted")
    assert outcomes  # which ones this machine hit is timing; each kind is checked when it happens


def _dead_pid() -> int:
    child = subprocess.Popen([sys.executable, "-c", "pass"])
    child.wait()
    return child.pid


def test_a_temporary_left_by_a_killed_run_is_swept_by_the_next_write(tmp_path):
    host = atomic._HOST
    dead = tmp_path / f".out.exr.lctmp{_dead_pid()}-{host}-0a1b2c3d.tmp.exr"
    alive = tmp_path / f".out.exr.lctmp{os.getppid()}-{host}-0a1b2c3d.tmp.exr"  # a live process's: kept
    other_host = tmp_path / f".out.exr.lctmp{_dead_pid()}-ffffff-0a1b2c3d.tmp.exr"  # maybe alive elsewhere: kept
    old_style = tmp_path / ".out.exr.k2j4h6g8.tmp.exr"  # before the pid was in the name: swept when an hour old
    young_old_style = tmp_path / ".b.exr.k2j4h6g9.tmp.exr"
    user_file = tmp_path / ".notes.tmp"
    for path in (dead, alive, other_host, old_style, young_old_style, user_file):
        path.write_bytes(b"x")
    os.utime(old_style, (time.time() - 7200, time.time() - 7200))
    write_exr(tmp_path / "out.exr", Image(np.zeros((2, 3, 3), np.float32)))
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        p.name for p in (alive, other_host, young_old_style, user_file, tmp_path / "out.exr"))
    assert sweep_stale_temporaries(tmp_path) == []


def test_a_sigkilled_render_leaves_at_most_its_temporary_and_the_next_run_removes_it(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(RENDER_SCENE)
    out = tmp_path / "out.exr"
    process = subprocess.Popen([sys.executable, "-m", "lenscompare", "render", str(scene), "-o", str(out)])
    deadline = time.time() + 120
    while time.time() < deadline and not any(is_temporary_name(p.name) for p in tmp_path.iterdir()) \
            and process.poll() is None:
        time.sleep(0.002)
    process.kill()  # SIGKILL: nothing can clean up
    process.wait()
    left = [p for p in tmp_path.iterdir() if is_temporary_name(p.name)]
    assert len(left) <= 1
    subprocess.run([sys.executable, "-m", "lenscompare", "render", str(scene), "-o", str(out), "--spp", "1"],
                   check=True)
    assert not [p for p in tmp_path.iterdir() if is_temporary_name(p.name)]


# ------------------------------------------------------------- class 10: messages
def test_a_closed_stdout_ends_quietly(tmp_path):
    process = subprocess.Popen([sys.executable, "-m", "lenscompare", "lens", "info", "dgauss.50mm"],
                               stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    process.stdout.close()  # `| head -0`: the reader is gone before the first line
    err = process.stderr.read()
    assert process.wait(timeout=60) == 141 and err == ""


def test_lens_info_prints_no_endless_digits(tmp_path, main, capsys):
    lens = tmp_path / "flat.dat"
    lens.write_text("1e200 5 1.5 20\n-1e200 5 1 20\n0 5 0 10\n")
    assert main(["lens", "info", str(lens)]) == 0
    lines = capsys.readouterr().out.splitlines()
    assert max(len(line) for line in lines) < 90 and any("1e+200" in line for line in lines)


def test_preview_of_a_folder_or_device_says_what_it_is(tmp_path, main, capsys):
    assert main(["preview", str(tmp_path), "-o", str(tmp_path / "x.png")]) == 2
    assert "is a folder, expected an OpenEXR image" in one_error_line(capsys.readouterr().err)
    assert main(["preview", "/dev/zero", "-o", str(tmp_path / "x.png")]) == 2
    assert "is not a regular file" in one_error_line(capsys.readouterr().err)


def test_more_threads_than_cores_run_quietly(tmp_path):
    scene = tmp_path / "s.toml"
    scene.write_text(MINIMAL_SCENE)
    result = subprocess.run([sys.executable, "-m", "lenscompare", "render", str(scene), "-o", str(tmp_path / "o.exr"),
                             "--threads", "1000"], capture_output=True, text=True, timeout=120)
    assert result.returncode == 0 and result.stderr == ""  # no "TBB Warning"


@pytest.mark.parametrize("where", ["scene", "option"])
def test_a_missing_lens_names_where_it_was_asked_for_and_the_shipped_lenses(tmp_path, main, capsys, where):
    scene = tmp_path / "s.toml"
    scene.write_text(MINIMAL_SCENE.replace('model = "thin"', 'model = "thin"\nlens = "nosuch.dat"')
                     if where == "scene" else MINIMAL_SCENE)
    argv = ["render", str(scene), "-o", str(tmp_path / "o.exr")] + (["--lens", "nosuch.dat"] if where == "option"
                                                                    else [])
    assert main(argv) == 2
    line = one_error_line(capsys.readouterr().err)
    assert (f"{scene}: camera.lens" if where == "scene" else "--lens:") in line
    assert "'nosuch.dat'" in line and "dgauss.50mm, fisheye.10mm, landscape.125mm, telephoto.250mm, wide.22mm" in line


def test_interrupted_is_a_keyboard_interrupt_with_the_shell_status():
    error = interrupts.Interrupted(signal.SIGTERM)
    assert isinstance(error, KeyboardInterrupt) and error.exit_status == 143 and str(error) == "SIGTERM"


def test_an_os_error_inside_atomic_output_names_the_file(tmp_path):
    with pytest.raises(ExternalError, match=r"cannot write '.*x\.txt': boom"):
        with atomic_output(tmp_path / "x.txt"):
            raise OSError("boom")
    assert list(tmp_path.iterdir()) == []
