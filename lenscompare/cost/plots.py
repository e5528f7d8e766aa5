"""Log-log error against time per model, one line per sampler, Pareto front."""

from __future__ import annotations

import warnings
from pathlib import Path

from ..atomic import atomic_output
from .study import TABLE_MIRRORED_SERIES, TABLE_SERIES, TARGET_RELATIVE_RMSE, pareto_front

__all__ = ["plot_error_vs_time"]

SAMPLER_STYLE = {"random": ("#7f7f7f", "o"), "jittered": ("#1f77b4", "s"), "regular": ("#ff7f0e", "^"),
                 "poisson": ("#2ca02c", "D"), "sobol": ("#d62728", "v"), TABLE_SERIES: ("#9467bd", "P"),
                 TABLE_MIRRORED_SERIES: ("#8c564b", "X")}


def plot_error_vs_time(scene_name: str, study: dict, path: Path) -> str:
    """Write the plot to ``path``; return its file name."""
    with warnings.catch_warnings():  # an image with no error left (a uniform scene) has nothing to log-scale
        warnings.filterwarnings("ignore", message="Data has no positive values")
        return _plot_error_vs_time(scene_name, study, path)


def _plot_error_vs_time(scene_name: str, study: dict, path: Path) -> str:
    import matplotlib  # here, not at the top: matplotlib is slow to import and only plots need it

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after use("Agg"): no display here
    import matplotlib.ticker  # with pyplot: only plots need it

    models = list(study["models"])
    # Two panels a row, 3.5 in each at 100 dpi: read at 100 % zoom on a 700 px column.
    columns = min(2, len(models))
    rows = -(-len(models) // columns)
    plt.rcParams.update({"font.size": 10, "legend.fontsize": 9, "axes.titlesize": 11})
    fig, axes = plt.subplots(rows, columns, figsize=(3.5 * columns, 3.2 * rows + 0.5), dpi=100, sharey=True,
                             squeeze=False)
    axes = list(axes.ravel())
    for extra in axes[len(models):]:
        extra.remove()
    axes = axes[:len(models)]
    for ax, model in zip(axes, models):
        everything = []
        for sampler, series in study["models"][model].items():
            colour, marker = SAMPLER_STYLE.get(sampler, ("black", "x"))
            t = [p["seconds"] for p in series["points"]]
            e = [p["relative_rmse"] for p in series["points"]]
            ax.loglog(t, e, marker=marker, color=colour, label=sampler, lw=1, ms=4)
            everything += [(ti, ei, sampler) for ti, ei in zip(t, e)]
        if model == "thin" and study.get("povray") and study["povray"].get("points"):
            pts = study["povray"]["points"]
            ax.loglog([p["seconds"] for p in pts], [p["relative_rmse"] for p in pts], "k--", marker="*",
                      label="POV-Ray", lw=1)
        front = pareto_front(everything)
        ax.loglog([f[0] for f in front], [f[1] for f in front], color="gold", lw=4, alpha=0.4, zorder=0,
                  label="Pareto front")
        ax.axhline(TARGET_RELATIVE_RMSE, color="black", lw=0.6, ls=":")
        ax.set_title(model)
        ax.set_xlabel("wall time (s)")
        # Within one decade matplotlib labels the minor ticks too, and they overlap at this width.
        ax.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        ax.grid(True, which="both", alpha=0.2)
    for ax in axes[::columns]:
        ax.set_ylabel("relative RMSE vs converged")
    # One legend for every panel (POV-Ray appears only beside the thin lens).
    handles = {}
    for ax in axes:
        for handle, label in zip(*ax.get_legend_handles_labels()):
            handles.setdefault(label, handle)
    # As many columns as the figure's width holds at the longest label ("jittered, ray table, mirrored").
    legend_columns = max(1, min(len(handles), int(3.5 * columns / 2.3)))
    legend_rows = -(-len(handles) // legend_columns)
    fig.legend(handles.values(), handles.keys(), loc="lower center", ncol=legend_columns, frameon=False)
    # A scene name is shown literally: "$" would start matplotlib's mathematics.
    fig.suptitle("".join(c if c.isprintable() else "\ufffd" for c in f"{scene_name}: error against time")
                 .replace("$", r"\$"))
    with warnings.catch_warnings():  # a scene name in a script the font lacks: boxes, not stderr noise
        warnings.filterwarnings("ignore", message="Glyph .* missing")
        fig.tight_layout(rect=(0, (0.22 * legend_rows + 0.15) / fig.get_figheight(), 1, 1))
        with atomic_output(path) as tmp:
            fig.savefig(tmp, format="png")
    plt.close(fig)
    return path.name
