"""``lenscompare sweep``: a grid of renders and measurements (scenes × lenses ×
f-numbers × focus distances × models × samplers × spp × seeds), one Dask task
each, into one table (``results.parquet``) and small-multiple plots.

See "Sweeps beyond one machine" in DESIGN.md for the contract, the README's
section of the same name for the figures, and :mod:`lenscompare.cluster` for
where the tasks run and with how many threads.
"""

from __future__ import annotations

from .runner import run_sweep
from .spec import AXES, SWEEP_MEASUREMENTS, SweepSpec, find_sweep, load_sweep, parse_sweep
from .table import COLUMNS, Journal, results_frame
from .tasks import PARAMETER_COLUMNS, RUN_COLUMNS, Task, run_task, task_grid

__all__ = ["run_sweep", "find_sweep", "load_sweep", "parse_sweep", "SweepSpec", "AXES", "SWEEP_MEASUREMENTS", "COLUMNS",
           "Journal", "results_frame", "PARAMETER_COLUMNS", "RUN_COLUMNS", "Task", "run_task", "task_grid"]
