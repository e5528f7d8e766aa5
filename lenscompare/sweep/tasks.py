"""The task grid of a sweep, and what one task does on a worker.

A task is one prepared scene (:func:`lenscompare.experiment.prepare_scene`
with the axes' values applied), one native render through one model
(:func:`lenscompare.experiment.render_run`) and its measurements. Everything a
task needs travels with it (the scene value, its prescription), so a worker
reads no file.

Deterministic per task: a task's image depends only on its own parameters,
the seed among them (the ``seed`` axis or the scene's own), never on the
worker, its thread count or the order tasks finish in; so each row but its
timing (:data:`RUN_COLUMNS`) is the same on every run, and
``render(task.scene, model=task.model)`` makes its image again.
"""

from __future__ import annotations

import hashlib
import itertools
import time
from dataclasses import dataclass, replace
from pathlib import Path

from ..cluster import task_threads, worker_name
from ..errors import InputError
from ..experiment import ExperimentSettings, prepare_scene, render_run
from ..scene import Scene
from .columns import measurement_columns
from .spec import SweepSpec

__all__ = ["Task", "task_grid", "run_task", "PARAMETER_COLUMNS", "RUN_COLUMNS"]

PARAMETER_COLUMNS = ("task", "task_key", "scene", "lens", "model", "f_number", "focus_distance_m", "sampler", "spp",
                     "seed", "width_px", "height_px", "measure")
"""What a task is: the same for the same sweep file."""

RUN_COLUMNS = ("seconds", "samples_per_second", "task_seconds", "threads", "worker")
"""How a task ran: these differ between runs; every other column does not."""


@dataclass(frozen=True)
class Task:
    """One grid point, with the scene prepared as it will be rendered.

    Attributes
    ----------
    index : int
        Position in the grid (scenes outermost, then the axes in the order of
        :data:`lenscompare.sweep.spec.AXES`, each in the file's order).
    scene : Scene
        Prepared: lens, f-number, focus, sampler, spp and seed applied.
    model : str
    measure : tuple of str
    notes : tuple of str
        What :func:`~lenscompare.experiment.prepare_scene` changed.
    """

    index: int
    scene: Scene
    model: str
    measure: tuple[str, ...]
    notes: tuple[str, ...] = ()

    @property
    def key(self) -> str:
        """Identifies the task's inputs (scene content, lens file, every
        parameter), so a re-run with the same output folder skips it."""
        camera = self.scene.camera
        anonymous = replace(self.scene, source="", base_dir=Path("."), camera=replace(camera, lens=None))
        text = repr((anonymous, camera.lens.sha256 if camera.lens else None, self.model, self.measure))
        return hashlib.sha256(text.encode()).hexdigest()[:20]

    def parameters(self) -> dict:
        camera, render = self.scene.camera, self.scene.render
        return {"task": self.index, "task_key": self.key, "scene": self.scene.name,
                "lens": camera.lens.name if camera.lens else None, "model": self.model,
                "f_number": camera.f_number, "focus_distance_m": camera.focus_distance_m,
                "sampler": render.sampler, "spp": render.spp, "seed": render.seed,
                "width_px": camera.width_px, "height_px": camera.height_px, "measure": ",".join(self.measure)}


def task_grid(spec: SweepSpec) -> list[Task]:
    """Every task of the sweep, in grid order."""
    axes = spec.axes
    tasks = []
    for scene in spec.scenes:
        for lens, f_number, focus, model, sampler, spp, seed in itertools.product(
                *(axes.get(name, (None,)) for name in ("lens", "f_number", "focus_distance", "model", "sampler",
                                                       "spp", "seed"))):
            base = scene.with_camera(**{k: v for k, v in (("lens", lens), ("focus_distance_m", focus))
                                        if v is not None})
            # The experiment's own preparation (a lens for scenes without one,
            # the widest f-number the lens allows when the scene asks for a
            # faster one); an f-number from the axis is then applied as given,
            # so a lens that cannot reach it gives a row with that error.
            prepared, notes = prepare_scene(base, ExperimentSettings())
            if f_number is not None:
                prepared = prepared.with_camera(f_number=f_number)
            prepared = prepared.with_render(sampler=sampler, spp=spp, seed=seed)
            tasks.append(Task(index=len(tasks), scene=prepared, model=model or scene.camera.model,
                              measure=spec.measurements_for(scene), notes=tuple(notes)))
    return tasks


def run_task(task: Task, *, threads: int | None = None, slots_by_host: dict | None = None) -> dict:
    """Render and measure one task; return its result columns.

    Runs on a Dask worker (or in this process when ``slots_by_host`` is None).
    Never raises for a failure of the task itself: an error in the render or a
    measurement becomes the ``error`` column (``"InputError: ..."``), with the
    render's timing kept when the render succeeded.
    """
    start = time.perf_counter()
    result: dict = {"error": None}
    try:
        threads = task_threads(threads, slots_by_host) if slots_by_host is not None else threads
        result["threads"] = threads
        run = render_run(task.scene, task.model, "native", ExperimentSettings(threads=threads))
        metadata = run.image.metadata
        result.update(seconds=metadata["seconds"], samples_per_second=metadata["samples_per_second"],
                      ray_pass_fraction=metadata["ray_pass_fraction"])
        result.update(measurement_columns(task.scene, run, task.measure))
    except Exception as error:  # noqa: BLE001 - a failing task is a row, never a failed sweep
        result["error"] = _describe(error)
    result["task_seconds"] = time.perf_counter() - start
    result["worker"] = worker_name()
    return result


def _describe(error: Exception) -> str:
    """One line for the ``error`` column. Bad input names its key, not the
    scene file's path (the row names the scene), so the line is the same on
    every machine."""
    if isinstance(error, InputError) and error.key:
        return f"InputError: {error.key}: {error.problem}"
    return f"{error.__class__.__name__}: {error}"
