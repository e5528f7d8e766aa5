"""Sweep files (TOML, "Sweeps beyond one machine" in DESIGN.md) into a frozen
:class:`SweepSpec`.

```toml
scenes = ["dot_grid", "flat_field"]      # shipped names or paths (relative to this file)
measure = ["distortion", "vignetting"]   # default: each scene's own `measure`
[axes]                                   # every axis optional: a missing one keeps the scene's value
lens = ["dgauss.50mm", "wide.22mm"]      # shipped names or lens files
f_number = [2.8, 8.0]
focus_distance = [2.0, 5.0]              # m
model = ["thin", "lens"]
sampler = ["sobol"]
spp = [16]
seed = [0]
```

Everything is checked here, before a task runs: unknown keys, wrong types,
empty or repeated axis values, scenes and lenses that cannot be found; the
error names the file and the key (``axes.f_number[2]``). What depends on a
combination (a lens that cannot reach an f-number or a focus) is the task's
to find out; its row then holds the error.
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from pathlib import Path

from .._schema import Table, parse_toml, read_toml_text
from ..errors import InputError
from ..lenses import Prescription, resolve_lens
from ..limits import MAX_F_NUMBER, MAX_SEED, MAX_SPP, MIN_F_NUMBER
from ..reference_scenes import find_scene, shipped_scene_names
from ..scene import MODELS, SAMPLERS, Scene, load_scene

__all__ = ["SweepSpec", "find_sweep", "load_sweep", "parse_sweep", "AXES", "SWEEP_MEASUREMENTS"]

AXES = ("lens", "f_number", "focus_distance", "model", "sampler", "spp", "seed")

SWEEP_MEASUREMENTS = ("blur_disks", "distortion", "vignetting")
"""What a task measures on its one image. ``similarity`` needs a second image
(a reference) and is the report's and the cost study's job."""


@dataclass(frozen=True)
class SweepSpec:
    """A parsed sweep file.

    Attributes
    ----------
    source : str
        The sweep file, for messages.
    scenes : tuple of Scene
        Loaded scenes, in the file's order.
    measure : tuple of str or None
        Measurements for every scene; None: each scene's own (those a task can
        make, see :data:`SWEEP_MEASUREMENTS`).
    axes : dict of str to tuple
        Values per axis present in the file (``lens`` as prescriptions,
        ``focus_distance`` in m), in the file's order.
    """

    source: str
    scenes: tuple[Scene, ...]
    measure: tuple[str, ...] | None
    axes: dict

    def measurements_for(self, scene: Scene) -> tuple[str, ...]:
        wanted = self.measure if self.measure is not None else scene.measure
        return tuple(m for m in wanted if m in SWEEP_MEASUREMENTS)


def find_sweep(value: str | os.PathLike) -> Path:
    """The sweep file ``value`` means: that file when it exists, else the
    shipped sweep of that bare name (``example``: ``lenscompare/sweep/example.toml``)."""
    path = Path(value)
    shipped = Path(__file__).resolve().parent / f"{path.name}.toml"
    if not path.exists() and path.name == os.fspath(value) and shipped.is_file():
        return shipped
    return path


def load_sweep(path: str | os.PathLike) -> SweepSpec:
    """Read and check a sweep file (a path, or a shipped sweep's name, see
    :func:`find_sweep`).

    Raises
    ------
    InputError
        The file is unreadable or breaks the format; the message names the file
        and the key.
    """
    source = os.fspath(find_sweep(path))
    text = read_toml_text(source, what="sweep file")  # capped: /dev/zero is refused, not read
    return parse_sweep(text, source=source, base_dir=Path(source).resolve().parent)


def parse_sweep(text: str, *, source: str = "<sweep>", base_dir: Path | None = None) -> SweepSpec:
    """Check sweep TOML text; see :func:`load_sweep`. Relative scene and lens
    paths are looked up in ``base_dir`` first."""
    root = Table(parse_toml(text, source=source), source=source)
    root.check_keys(["description", "scenes", "measure", "axes"])
    root.string("description", default="")
    scenes = tuple(_load_scene(root, i, name, base_dir) for i, name in enumerate(_strings(root, "scenes")))
    names = [s.name for s in scenes]
    for i, name in enumerate(names):
        if name in names[:i]:
            raise root.error(f"scenes[{i}]", f"a second scene named {name!r} (scene names identify rows)")
    measure = None
    if root.has("measure"):
        measure = _strings(root, "measure", choices=SWEEP_MEASUREMENTS,
                           why="; similarity needs a second image: use report or cost")
    return SweepSpec(source=source, scenes=scenes, measure=measure, axes=_read_axes(root.table("axes"), base_dir))


def _load_scene(root: Table, i: int, value: str, base_dir: Path | None) -> Scene:
    path = find_scene(value, base_dir)
    if not path.exists():
        raise root.error(f"scenes[{i}]", f"no scene file {value!r} and no shipped scene of that name (shipped: "
                                         + ", ".join(shipped_scene_names()) + ")")
    return load_scene(path)


def _read_axes(t: Table, base_dir: Path | None) -> dict:
    t.check_keys(AXES)
    axes: dict = {}
    if t.has("lens"):
        axes["lens"] = tuple(_lens(t, i, name, base_dir) for i, name in enumerate(_strings(t, "lens")))
    if t.has("f_number"):
        axes["f_number"] = _numbers(t, "f_number", minimum=MIN_F_NUMBER, maximum=MAX_F_NUMBER)
    if t.has("focus_distance"):
        axes["focus_distance"] = _numbers(t, "focus_distance")
    if t.has("model"):
        axes["model"] = _strings(t, "model", choices=MODELS)
    if t.has("sampler"):
        axes["sampler"] = _strings(t, "sampler", choices=SAMPLERS)
    if t.has("spp"):
        axes["spp"] = _integers(t, "spp", minimum=1, maximum=MAX_SPP)
    if t.has("seed"):
        axes["seed"] = _integers(t, "seed", minimum=0, maximum=MAX_SEED)
    return axes


def _lens(t: Table, i: int, name: str, base_dir: Path | None) -> Prescription:
    return resolve_lens(name, base_dir=base_dir, source=t.source, key=t.path(f"lens[{i}]"))


def _array(t: Table, name: str) -> list:
    value = t.data[name]
    if not isinstance(value, list) or not value:
        raise t.error(name, f"expected a non-empty array, got {value!r}")
    for i, item in enumerate(value):
        if item in value[:i]:
            raise t.error(f"{name}[{i}]", f"{item!r} is already in the array (each value once)")
    return value


def _strings(t: Table, name: str, *, choices=None, why: str = "") -> tuple[str, ...]:
    if not t.has(name):
        raise t.error(name, "missing (required)")
    values = _array(t, name)
    for i, v in enumerate(values):
        if not isinstance(v, str):
            raise t.error(f"{name}[{i}]", f"expected a string, got {v!r}")
        if choices is not None and v not in choices:
            raise t.error(f"{name}[{i}]", f"expected one of {', '.join(map(repr, choices))}, got {v!r}{why}")
    return tuple(values)


def _numbers(t: Table, name: str, *, minimum: float | None = None,
             maximum: float | None = None) -> tuple[float, ...]:
    values = _array(t, name)
    item = Table({f"{name}[{i}]": v for i, v in enumerate(values)}, source=t.source, key=t.key)
    return tuple(item.number(f"{name}[{i}]", positive=True, minimum=minimum, maximum=maximum)
                 for i in range(len(values)))


def _integers(t: Table, name: str, *, minimum: int, maximum: int) -> tuple[int, ...]:
    values = _array(t, name)
    item = Table({f"{name}[{i}]": v for i, v in enumerate(values)}, source=t.source, key=t.key)
    return tuple(item.integer(f"{name}[{i}]", minimum=minimum, maximum=maximum) for i in range(len(values)))
