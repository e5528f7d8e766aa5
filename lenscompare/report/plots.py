"""Report figures (matplotlib, Agg): blur against depth, distortion and
relative illumination against field angle, time per render."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np

from ..atomic import atomic_output

__all__ = ["plot_blur", "plot_distortion", "plot_vignetting", "plot_times", "plain_text"]

COLOURS = {"pinhole": "#7f7f7f", "thin": "#1f77b4", "thick": "#2ca02c", "lens": "#d62728",
           "pinhole (POV-Ray)": "#bcbd22", "thin (POV-Ray)": "#17becf",
           "pinhole (Mitsuba)": "#8c564b", "thin (Mitsuba)": "#e377c2"}
_SUFFIX = {"povray": " (POV-Ray)", "mitsuba": " (Mitsuba)"}


def plain_text(text: str) -> str:
    """A string from an input file (a scene name) as matplotlib shows it
    literally: ``$`` would start mathematics (and a bad formula raises),
    control characters become U+FFFD."""
    return "".join(c if c.isprintable() else "\ufffd" for c in str(text)).replace("$", r"\$")


# Drawn at the size the page shows them (100 % zoom): 7 x 4.2 in at 100 dpi is
# 700 x 420 px, with text no smaller than 9 pt.
_FONT = {"font.size": 10, "legend.fontsize": 9, "axes.titlesize": 11, "xtick.labelsize": 9, "ytick.labelsize": 9}


def _figure(width=7.0, height=4.2):
    import matplotlib  # here, not at the top: matplotlib is slow to import and only plots need it

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt  # after use("Agg"): no display here

    plt.rcParams.update(_FONT)
    fig, ax = plt.subplots(figsize=(width, height), dpi=100)
    ax.grid(True, alpha=0.3)
    return plt, fig, ax


def _save(plt, fig, path: Path) -> str:
    with warnings.catch_warnings():  # a scene name in a script the font lacks: boxes, not stderr noise
        warnings.filterwarnings("ignore", message="Glyph .* missing")
        fig.tight_layout()
        with atomic_output(path) as tmp:
            fig.savefig(tmp, format="png")
    plt.close(fig)
    return path.name


def plot_blur(blur: dict, path: Path, *, title: str) -> str:
    plt, fig, ax = _figure()
    for label, rows in blur["renders"].items():
        rows = [r for r in rows if r]
        if not rows:
            continue
        ax.plot([r["depth_m"] for r in rows], [r["measured_px"] for r in rows], "o",
                color=COLOURS.get(label), label=f"{label} (measured)", alpha=0.85)
        if rows[0]["expected_from"] != "equation 5":
            ax.plot([r["depth_m"] for r in rows], [r["expected_px"] for r in rows], "x", ms=9,
                    color=COLOURS.get(label), label=f"{label} (expected: {rows[0]['expected_from']})")
    thin = [r for r in blur["renders"].get("thin", []) if r]
    if thin:
        order = np.argsort([r["depth_m"] for r in thin])
        ax.plot([thin[i]["depth_m"] for i in order], [thin[i]["eq5_px"] for i in order], "-", color="black",
                lw=1, label="equation 5")
    ax.set_xscale("log")
    ax.set_xlabel("depth along the view axis (m)")
    ax.set_ylabel("blur-disk diameter (px)")
    ax.set_title(plain_text(title))
    ax.legend()
    return _save(plt, fig, path)


def plot_distortion(distortion: dict, path: Path, *, title: str, published=None) -> str:
    plt, fig, ax = _figure()
    for label, data in distortion["renders"].items():
        if data:
            ax.plot(data["field_deg"], data["distortion_percent"], ".", color=COLOURS.get(label),
                    label=f"{label}" + (f" (f/{data['f_number']:g})" if data.get("f_number") else ""), alpha=0.8)
    if published:
        ax.plot(*zip(*published), "kx", ms=9, label="optiland: Double Gauss chief ray, object at infinity")
    ax.axhline(0, color="black", lw=0.8)
    ax.set_xlabel("field angle (deg)")
    ax.set_ylabel("radial distortion (%)")
    ax.set_title(plain_text(title))
    ax.legend()
    return _save(plt, fig, path)


def plot_vignetting(vignetting: dict, path: Path, *, title: str, published=None) -> str:
    plt, fig, ax = _figure()
    for label, data in vignetting["renders"].items():
        if not data:  # the image held no flat field to measure
            continue
        aperture = f" (f/{data['f_number']:g})" if data.get("f_number") else ""
        ax.plot(data["field_deg"], data["relative_illumination"], "-", color=COLOURS.get(label),
                label=f"{label}{aperture}, rendered")
        if data.get("traced"):
            ax.plot(data["traced"]["field_deg"], data["traced"]["relative_illumination"], "o", mfc="none", ms=8,
                    color=COLOURS.get(label), label=f"{label}{aperture}, real-ray trace")
    if published:
        ax.plot(*zip(*published), "kx", ms=9, label="optiland: Double Gauss at f/2.03 (wide open), infinity")
    ax.set_ylim(0, 1.1)
    ax.set_xlabel("field angle (deg)")
    ax.set_ylabel("relative illumination")
    ax.set_title(plain_text(title))
    ax.legend()
    return _save(plt, fig, path)


def plot_times(rows: list[dict], path: Path) -> str:
    plt, fig, ax = _figure(7.0, 0.25 * len(rows) + 1.2)
    labels = [plain_text(f"{r['scene']}: {r['model']}" + _SUFFIX.get(r["renderer"], "")) for r in rows]
    ax.barh(labels, [r["seconds"] for r in rows],
            color=[COLOURS.get(r["model"] + _SUFFIX.get(r["renderer"], "")) for r in rows])
    ax.invert_yaxis()
    ax.set_xscale("log")
    ax.set_xlabel("render time (s)")
    ax.tick_params(axis="y", labelsize=9)
    return _save(plt, fig, path)
