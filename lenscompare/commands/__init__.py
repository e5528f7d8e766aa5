"""Sub-commands of the command line, in the order ``--help`` lists them.

Each is a module here with ``add_parser(subparsers)`` and ``run(args)``. A
command's module is imported only when that command runs (:func:`load`,
``lenscompare.cli``): between them they import NumPy, SciPy, Matplotlib,
pandas, Dask, Mitsuba and the native module, about 1.4 s that ``lenscompare
--help`` and the light commands need not wait for.
"""

from __future__ import annotations

import importlib
from types import ModuleType

__all__ = ["COMMAND_HELP", "load"]

COMMAND_HELP = {
    "render": "render a scene with the native tracer",
    "povray": "render a scene with POV-Ray (the independent reference)",
    "mitsuba": "render a scene with Mitsuba 3 (a second independent reference)",
    "export": "write the scene in POV-Ray, Mitsuba 3 or pbrt-v4 format",
    "measure": "measure any renderer's image of a scene, with pass/fail (exit 0 / 1)",
    "report": "render every model and POV-Ray, measure, write an HTML report",
    "cost": "what accuracy costs in time: every model, sampler and sample count",
    "sweep": "a grid of renders and measurements as Dask tasks, into DIR/results.parquet",
    "plan": "which lens effects a scene needs, and the cheapest model",
    "check": "run declarative accuracy checks (exit 0 when all hold)",
    "figures": "draw the teaching figures (thin lens, thick lens, lens system, aperture, chromatic, motion)",
    "lens": "inspect lens prescriptions",
    "preview": "write an sRGB PNG preview of a linear EXR",
}
"""Each command's line in ``lenscompare --help`` (its module's parser says the same)."""


def load(name: str) -> ModuleType:
    """The module of command ``name`` (a key of :data:`COMMAND_HELP`), imported now."""
    return importlib.import_module(f"{__name__}.{name}")
