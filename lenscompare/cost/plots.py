"""Log-log error against time per model, one line per sampler, Pareto front."""

from __future__ import annotations

from pathlib import Path

from ..atomic import atomic_output
from .study import TARGET_RELATIVE_RMSE, pareto_front

__all__ = ["plot_error_vs_time"]

SAMPLER_STYLE = {"random": ("#7f7f7f", "o"), "jittered": ("#1f77b4", "s"), "regular": ("#ff7f0e", "^"),
                 "poisson": ("#2ca02c", "D"), "sobol": ("#d62728", "v")}


def plot_error_vs_time(scene_name: str, study: dict, path: Path) -> str:
    import matplotlib  # here, not at the top: matplotlib is slow to import and only plots need it

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after use("Agg"): no display here

    models = list(study["models"])
    fig, axes = plt.subplots(1, len(models), figsize=(3.6 * len(models), 3.6), dpi=100, sharey=True)
    axes = list(axes) if len(models) > 1 else [axes]
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
        ax.grid(True, which="both", alpha=0.2)
    axes[0].set_ylabel("relative RMSE vs converged")
    axes[-1].legend(fontsize=7)
    fig.suptitle(f"{scene_name}: error against time")
    fig.tight_layout()
    with atomic_output(path) as tmp:
        fig.savefig(tmp, format="png")
    plt.close(fig)
    return path.name
