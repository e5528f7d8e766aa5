"""Small multiples of a sweep's table: each measurement (and render time)
against each axis that varies, one panel per lens, one line per model.

A point is the median over the other axes' values (focus distances, seeds,
...) and the band their range, so a flat band says the other axes do not
matter for that measurement. Failed tasks are absent (their rows hold the
error).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..atomic import atomic_output
from .columns import SCALAR_MEASUREMENTS

__all__ = ["write_plots", "plot_against", "AXIS_COLUMNS"]

AXIS_COLUMNS = {"f_number": "f-number", "focus_distance_m": "focus distance (m)", "lens": "lens",
                "model": "model", "sampler": "sampler", "spp": "samples per pixel", "seed": "seed"}
_NUMERIC = {"f_number", "focus_distance_m", "spp", "seed"}
_LOG_X = {"spp", "focus_distance_m", "f_number"}

COLOURS = {"pinhole": "#7f7f7f", "thin": "#1f77b4", "thick": "#2ca02c", "lens": "#d62728"}
_CYCLE = ["#9467bd", "#8c564b", "#e377c2", "#17becf", "#bcbd22", "#ff7f0e"]

_Y_COLUMNS = {**SCALAR_MEASUREMENTS, "seconds": ("render time", "seconds")}


def _plain(value) -> str:
    """A scene or lens name as matplotlib shows it literally (``$`` would start
    its mathematics, and a bad formula raises)."""
    return "".join(c if c.isprintable() else "\ufffd" for c in str(value)).replace("$", r"\$")


def write_plots(frame, folder: Path) -> list[str]:
    """One PNG per (measurement, varying axis): ``{measurement}_vs_{axis}.png``
    in ``folder`` (created). Returns the file paths."""
    ok = frame[frame["error"].isna()]
    # An axis the sweep varies: more than one value within a scene.
    axes = [a for a in AXIS_COLUMNS if len(ok) and ok.groupby("scene")[a].nunique().max() > 1]
    written = []
    for y in _Y_COLUMNS:
        if y not in ok or ok[y].notna().sum() == 0:
            continue
        for x in axes:
            folder.mkdir(parents=True, exist_ok=True)
            written.append(str(plot_against(ok, y=y, x=x, path=folder / f"{y}_vs_{x}.png")))
    return written


def plot_against(frame, *, y: str, x: str, path: Path) -> Path:
    """``y`` against ``x``: a panel per lens (per scene when ``x`` is the lens),
    a line per model (per scene when ``x`` is the model), median and range
    over the other axes; points without lines for a categorical ``x``."""
    import matplotlib  # here, not at the top: matplotlib is slow to import and only plots need it

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after use("Agg"): no display here

    rows = frame[frame[y].notna()]
    panel_by = "scene" if x == "lens" else "lens"
    line_by = "scene" if x == "model" else "model"
    panels = list(dict.fromkeys(rows[panel_by]))
    columns = min(4, len(panels))
    n_rows = -(-len(panels) // columns)
    plt.rcParams.update({"font.size": 10, "legend.fontsize": 9, "axes.titlesize": 11})
    fig, grid = plt.subplots(n_rows, columns, figsize=(max(5.0, 3.3 * columns), 2.9 * n_rows + 0.9), dpi=100, squeeze=False,
                             sharey=True)
    axes = list(grid.ravel())
    for extra in axes[len(panels):]:
        extra.remove()
    categories = list(dict.fromkeys(rows[x])) if x not in _NUMERIC else None
    for ax, panel in zip(axes, panels):
        in_panel = rows[rows[panel_by] == panel]
        for i, (line, group) in enumerate(in_panel.groupby(line_by, sort=False)):
            stats = group.groupby(x, sort=True)[y].agg(["median", "min", "max"])
            xs = stats.index.to_numpy() if categories is None else np.array([categories.index(v) for v in stats.index])
            colour = COLOURS.get(line, _CYCLE[i % len(_CYCLE)])
            if categories is None:
                ax.plot(xs, stats["median"], "o-", color=colour, label=_plain(line), lw=1.2, ms=3.5)
                if (stats["max"] > stats["min"]).any():
                    ax.fill_between(xs, stats["min"], stats["max"], color=colour, alpha=0.15, lw=0)
            else:  # no order between categories: points, and the range as a bar
                ax.errorbar(xs, stats["median"], yerr=[stats["median"] - stats["min"], stats["max"] - stats["median"]],
                            fmt="o", color=colour, label=_plain(line), ms=4, capsize=3, lw=1)
        ax.set_title(_plain(panel))
        ax.set_xlabel(AXIS_COLUMNS[x])
        ax.grid(True, alpha=0.3)
        if categories is not None:
            ax.set_xticks(range(len(categories)), categories, rotation=30, ha="right")
        elif x in _LOG_X:
            ax.set_xscale("log")
            values = sorted(in_panel[x].unique())
            ax.set_xticks(values, [f"{v:g}" for v in values])
            ax.minorticks_off()
    for ax in axes[:len(panels)]:
        if ax.get_subplotspec().is_first_col():
            ax.set_ylabel(_Y_COLUMNS[y][1])
    legend = {}
    for ax in axes[:len(panels)]:
        legend.update(zip(*reversed(ax.get_legend_handles_labels())))
    top = 1.0 - 0.62 / fig.get_figheight()  # title and legend rows, in figure fractions
    fig.suptitle(f"{_Y_COLUMNS[y][0]} against {AXIS_COLUMNS[x]}", x=0.01, y=0.995, ha="left", va="top", fontsize=11)
    fig.legend(legend.values(), legend.keys(), loc="upper left", bbox_to_anchor=(0.0, 1.0 - 0.3 / fig.get_figheight()),
               ncols=min(6, len(legend)), frameon=False)
    spread = "band" if categories is None else "bar"
    fig.text(0.01, 0.005, f"points: median over the other axes; {spread}: their range", fontsize=8, color="#555")
    fig.tight_layout(rect=(0, 0.03, 1, top))
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
    return path
