"""Figure: time as one more dimension of the sample (Cook et al. 1984; paper section 3).

Top: a small emissive sphere crossing the view at known speed, rendered by
the native thin lens with the shutter open: in focus, and focused elsewhere.
Its streak is the moving disk's image swept over v T projected on the film;
defocus widens the streak and softens its ends but not its length (measured
between the half-plateau crossings, :func:`lenscompare.metrics.measure_streak`).

Bottom: where one pixel's 64 samples fall in lens u x time, coloured by the
quarter of the pixel (film y) they come from, for the sobol sampler as the
render draws a whole pixel (film and lens from one Owen-scrambled Sobol'
sequence, time i / 64 Owen-scrambled: film and time one (0,m,3)-net) and for
padding (each dimension group stratified alone, paired at random). sobol puts
exactly one sample in each of the 4 x 4 x 4 film-y x lens-u x time cells (in
every pixel: tests/test_figures_motion.py); padding leaves some empty and
doubles others.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from .. import _native
from .._native import diagnostics
from ..cameras import camera_for
from ..metrics import measure_streak
from ..render import render
from ..scene import Camera, EmissiveMaterial, RenderSettings, Scene, Sphere
from . import _style

__all__ = ["MotionGeometry", "motion_geometry", "motion_figure", "streak_scene"]

STREAK_PX = (240, 61)        # width, height: odd, so the sphere's centre row is a pixel row
STREAK_SPP = 256
DEPTH_M, RADIUS_M = 4.0, 0.05
SPEED_M_PER_S, SHUTTER_S = 30.0, (0.0, 1.0 / 30.0)  # 1 m across at 4 m: about 100 px
START_X_M = -0.5
SAMPLES = 64                 # the scatter's samples per pixel
CELLS = 4                    # per axis of the film-y x lens-u x time stratification count


def streak_scene(*, focus_distance_m: float, f_number: float = 2.0) -> Scene:
    """The moving sphere, seen by a 50 mm thin lens focused at ``focus_distance_m``."""
    film_mm = (36.0, 36.0 * STREAK_PX[1] / STREAK_PX[0])
    camera = Camera(model="thin", position=(0.0, 0.0, 0.0), look_at=(0.0, 0.0, 1.0), up=(0.0, 1.0, 0.0),
                    focus_distance_m=focus_distance_m, resolution=STREAK_PX, film_mm=film_mm,
                    focal_length_mm=50.0, f_number=f_number)
    return Scene(camera=camera, render=RenderSettings(spp=STREAK_SPP, sampler="sobol", seed=1, shutter_s=SHUTTER_S),
                 background=(0.0, 0.0, 0.0), materials={"glow": EmissiveMaterial("glow", (1.0, 1.0, 1.0))},
                 objects=(Sphere((START_X_M, 0.0, DEPTH_M), RADIUS_M, "glow", velocity=(SPEED_M_PER_S, 0.0, 0.0)),),
                 lights=(), name="streak")


@functools.lru_cache(maxsize=2)  # deterministic: the same render each time a process draws the figure
def _streak(focus_distance_m: float) -> np.ndarray:
    image = render(streak_scene(focus_distance_m=focus_distance_m), progress=False).pixels[..., 1]
    image.setflags(write=False)  # shared by the cache
    return image


def _path_px(scene: Scene) -> tuple[np.ndarray, np.ndarray]:
    """The sphere centre's raster positions when the shutter opens and closes."""
    camera = camera_for(scene, "thin")
    sphere = scene.objects[0]
    ends = [np.asarray(sphere.center) + np.asarray(sphere.velocity) * t for t in scene.render.shutter_s]
    return tuple(camera.project_px(camera.frame.camera_from_world(p)) for p in ends)


def pixel_samples(sampler_code: int, *, spp: int = SAMPLES, seed: int = 1, pixel_index: int = 0):
    """One pixel's film, lens and time samples as the render draws them."""
    film = np.zeros((spp, 2), dtype=np.float32)
    lens = np.zeros((spp, 2), dtype=np.float32)
    time = np.zeros(spp, dtype=np.float32)
    diagnostics.pixel_samples(sampler_code, seed, pixel_index, film, lens, time)
    return film, lens, time


def occupied_cells(film: np.ndarray, lens: np.ndarray, time: np.ndarray, cells: int = CELLS) -> int:
    """How many of the cells^3 film-y x lens-u x time cells hold a sample."""
    index = np.stack([film[:, 1], lens[:, 0], time], axis=1)
    return len({tuple(row) for row in np.minimum((index * cells).astype(int), cells - 1)})


@dataclass(frozen=True)
class MotionGeometry:
    """What the figure draws.

    Attributes
    ----------
    expected_length_px, defocused_expected_px : float
        v T projected on the film: the sphere centre's path over the shutter,
        in focus and focused at ``defocus_focus_m`` (the film then sits
        farther back, so the image, the streak with it, is larger).
    sharp, defocused : ndarray
        The streak in focus (focus at the sphere) and focused at
        ``defocus_focus_m`` (green channel, linear).
    sharp_length_px, defocused_length_px : float
        Their measured half-plateau lengths.
    start_px, end_px : ndarray
        The centre's raster positions at open and close.
    samples : dict of str to (film, lens, time)
        ``"sobol"`` and ``"padded"``: one pixel's 64 samples.
    occupied : dict of str to int
        Occupied film-y x lens-u x time cells (of CELLS**3) for each.
    """

    expected_length_px: float
    defocused_expected_px: float
    start_px: np.ndarray
    end_px: np.ndarray
    defocus_focus_m: float
    sharp: np.ndarray | None = None
    defocused: np.ndarray | None = None
    sharp_length_px: float = float("nan")
    defocused_length_px: float = float("nan")
    samples: dict = field(default_factory=dict)
    occupied: dict = field(default_factory=dict)


def motion_geometry(*, defocus_focus_m: float = 0.8, images: bool = True) -> MotionGeometry:
    """The figure's numbers; ``images`` False skips the renders."""
    start, end = _path_px(streak_scene(focus_distance_m=DEPTH_M))
    defocused_ends = _path_px(streak_scene(focus_distance_m=defocus_focus_m))
    samples = {"sobol": pixel_samples(_native.SAMPLER_SOBOL), "padded": pixel_samples(diagnostics.SAMPLER_SOBOL_PADDED)}
    occupied = {name: occupied_cells(*s) for name, s in samples.items()}
    kwargs = {}
    if images:
        sharp, defocused = _streak(DEPTH_M), _streak(defocus_focus_m)
        kwargs = dict(sharp=sharp, defocused=defocused,
                      sharp_length_px=measure_streak(sharp, start_px=start, end_px=end).length_px,
                      defocused_length_px=measure_streak(defocused, start_px=defocused_ends[0],
                                                         end_px=defocused_ends[1], margin_px=20.0).length_px)
    return MotionGeometry(expected_length_px=float(np.linalg.norm(end - start)),
                          defocused_expected_px=float(np.linalg.norm(defocused_ends[1] - defocused_ends[0])),
                          start_px=start, end_px=end,
                          defocus_focus_m=defocus_focus_m, samples=samples, occupied=occupied, **kwargs)


def motion_figure(geometry: MotionGeometry):
    """The figure (a :class:`matplotlib.figure.Figure`)."""
    g = geometry
    with _style.figure_style():
        fig = _style.new_figure(10.0, 6.4)
        grid = fig.add_gridspec(3, 2, height_ratios=[1.0, 1.0, 3.4])
        streaks = [("sharp", f"in focus (4 m): streak {g.sharp_length_px:.1f} px", g.expected_length_px),
                   ("defocused", f"focused at {g.defocus_focus_m:g} m: streak {g.defocused_length_px:.1f} px",
                    g.defocused_expected_px)]
        for row, (name, title, expected) in enumerate(streaks):
            image = getattr(g, name)
            if image is None:
                continue
            ax = fig.add_subplot(grid[row, :])
            ax.imshow(image, cmap="gray", vmin=0.0, vmax=float(image.max()), interpolation="nearest", gid=f"streak-{name}")
            ax.set_title(f"{title}; v T projected {expected:.1f} px", fontsize=9)
            ax.set_xticks([])
            ax.set_yticks([])
        colours = list(_style.BUNDLES) + [_style.FOCUS_PLANE]  # four film-y quarters
        titles = {"sobol": "sobol: film, lens one sequence, time i / spp", "padded": "padded: each stratified alone, paired at random"}
        for col, name in enumerate(("sobol", "padded")):
            film, lens, time = g.samples[name]
            ax = fig.add_subplot(grid[2, col])
            quarter = np.minimum((film[:, 1] * CELLS).astype(int), CELLS - 1)
            for q in range(CELLS):
                ax.plot(lens[quarter == q, 0], time[quarter == q], "o", ms=4.5, color=colours[q], gid=f"samples-{name}-{q}",
                        label=f"film y in [{q / CELLS:g}, {(q + 1) / CELLS:g})")
            for k in range(1, CELLS):
                ax.axvline(k / CELLS, color=_style.MUTED, lw=0.6)
                ax.axhline(k / CELLS, color=_style.MUTED, lw=0.6)
            ax.set_xlim(0, 1)
            ax.set_ylim(0, 1)
            ax.set_aspect("equal")
            ax.set_xlabel("lens sample u")
            ax.set_ylabel("time (fraction of the shutter)")
            ax.set_title(f"{titles[name]}\n{g.occupied[name]} of {CELLS ** 3} film y \u00d7 lens u \u00d7 time cells hold a "
                         f"sample ({SAMPLES} spp)", fontsize=8.5)
            if col == 1:
                ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=7.5, frameon=False)
        # supxlabel: constrained layout keeps room for it below the axes' labels
        fig.supxlabel("top: a 0.05 m emissive sphere at 4 m, 30 m/s, shutter 1/30 s, 50 mm f/2, native thin lens, "
                      f"{STREAK_SPP} spp sobol; bottom: one pixel's samples", x=0.99, ha="right", fontsize=7,
                      color=_style.MUTED)
    return fig
