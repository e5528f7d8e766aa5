"""The look every teaching figure shares: colours, line styles, fonts, output.

Figures are built on :class:`matplotlib.figure.Figure` directly (no pyplot, so
no global state and no display) and rendered with the Agg backend to bytes.
Global ``rcParams`` are never changed: :func:`figure_style` applies the
project's settings only for the duration of a ``with`` block.

Colours are from the Okabe-Ito palette, which colour-blind readers can tell
apart.  Meaning, kept the same in every figure:

- optical axis: grey dash-dot;
- glass: pale blue fill, dark blue outline; aperture stop: black;
- film: near-black, thick; principal planes and pupils: reddish purple;
- plane of focus: bluish green, dashed;
- bundles / object points: vermillion, then blue, then orange;
- in the thick-lens figure, real (traced) rays are blue and the
  thick-lens construction is vermillion.
"""

from __future__ import annotations

import contextlib
import io

import matplotlib
from matplotlib.figure import Figure

__all__ = [
    "AXIS", "GLASS_FILL", "GLASS_EDGE", "STOP", "FILM", "CARDINAL", "FOCUS_PLANE",
    "BUNDLES", "REAL_RAY", "MODEL_RAY", "MUTED", "DPI", "LABEL_BOX",
    "figure_style", "new_figure", "height_for_aspect", "figure_bytes", "draw_axis_line", "mm",
]

AXIS = "#8c8c8c"
GLASS_FILL = "#d4e6f4"
GLASS_EDGE = "#2f5d80"
STOP = "#000000"
FILM = "#1a1a1a"
CARDINAL = "#CC79A7"
FOCUS_PLANE = "#009E73"
BUNDLES = ("#D55E00", "#0072B2", "#E69F00")
REAL_RAY = "#0072B2"
MODEL_RAY = "#D55E00"
MUTED = "#595959"

DPI = 150

# Behind a label that sits on rays: white, a little transparent, no frame.
LABEL_BOX = {"boxstyle": "round,pad=0.15", "fc": "white", "ec": "none", "alpha": 0.85}

_RC = {
    "font.family": "DejaVu Sans",
    "font.size": 9.0,
    "axes.titlesize": 10.0,
    "axes.titleweight": "bold",
    "axes.titlelocation": "left",
    "axes.labelsize": 8.5,
    "axes.labelcolor": MUTED,
    "axes.edgecolor": "#b0b0b0",
    "axes.linewidth": 0.6,
    "xtick.labelsize": 8.0,
    "ytick.labelsize": 8.0,
    "xtick.color": MUTED,
    "ytick.color": MUTED,
    "legend.fontsize": 8.0,
    "legend.frameon": False,
    "figure.titlesize": 12.0,
    "figure.titleweight": "bold",
    "svg.fonttype": "path",   # text as outlines: the SVG needs no fonts
    "svg.hashsalt": "lenscompare",  # stable ids: same input, same SVG
    "path.simplify": False,
}


@contextlib.contextmanager
def figure_style():
    """Apply the figures' matplotlib settings inside a ``with`` block only."""
    with matplotlib.rc_context(_RC):
        yield


def new_figure(width_in: float, height_in: float) -> Figure:
    """A white figure with constrained layout (call inside :func:`figure_style`)."""
    return Figure(figsize=(width_in, height_in), layout="constrained", facecolor="white")


def height_for_aspect(width_in: float, x_span: float, y_span: float, *, extra_in: float,
                      low_in: float = 3.0, high_in: float = 7.5) -> float:
    """Figure height that fits an equal-aspect drawing of ``x_span`` by ``y_span``.

    ``extra_in`` is room for the titles, legend and tick labels; the drawing
    gets about 88 % of the width (the rest is the y-axis labels).
    """
    return min(high_in, max(low_in, 0.88 * width_in * y_span / x_span + extra_in))


def figure_bytes(figure: Figure, fmt: str) -> bytes:
    """The figure rendered as ``"png"`` or ``"svg"`` bytes (Agg, no display)."""
    buffer = io.BytesIO()
    # No date in the metadata, so the same input gives the same file.
    metadata = {"Date": None} if fmt == "svg" else {}
    with figure_style():
        figure.savefig(buffer, format=fmt, dpi=DPI, facecolor="white", metadata=metadata)
    return buffer.getvalue()


def draw_axis_line(ax, x_min: float, x_max: float) -> None:
    """The optical axis, grey dash-dot, behind everything else."""
    ax.plot([x_min, x_max], [0.0, 0.0], color=AXIS, lw=0.8, ls=(0, (8, 3, 1.5, 3)),
            zorder=0.5, gid="optical-axis")


def mm(value: float, digits: int = 2) -> str:
    """A length for a label: ``"51.28 mm"`` (a proper minus sign when negative)."""
    return f"{value:.{digits}f} mm".replace("-", "\u2212")
