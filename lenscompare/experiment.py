"""One home for "an experiment": a scene, the models to render it through and
the settings, in; runs (one image per model and renderer), out.

The report, the cost study, the checks and sweeps all build on this module, so
a scene is prepared (lens, f-number, resolution, samples) and rendered the same
way wherever it is measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .cameras import camera_for
from .cluster import Cluster, run_calls
from .errors import ExternalError, InputError
from .image import Image
from .lenses import paraxial_data, resolve_lens
from .limits import check_render_budget
from .mitsuba import MITSUBA_MODELS, render_mitsuba
from .povray import MAX_POVRAY_SPP, POVRAY_MODELS, pov_camera, render_povray
from .povray import unsupported as povray_unsupported
from .render import render
from .scene import MODELS, Scene

__all__ = ["ExperimentSettings", "Run", "prepare_scene", "check_renderable", "render_run", "render_models",
           "render_scenes", "POVRAY_MODELS", "MITSUBA_MODELS", "REFERENCE_POVRAY_SPP", "REFERENCE_MITSUBA_SPP",
           "RENDERER_NAMES"]

RENDERER_NAMES = {"povray": "POV-Ray", "mitsuba": "Mitsuba"}
"""The reference renderers, as render labels name them ("thin (Mitsuba)")."""


REFERENCE_POVRAY_SPP = 256

REFERENCE_MITSUBA_SPP = 64
"""Mitsuba renders with at least this many samples: its ``independent`` sampler
is noisier than the native jittered one (blur disks at 16 spp: off by up to
25 %), and its ``scalar_rgb`` variant is slow, so not POV-Ray's 256."""
"""POV-Ray's focal blur at fewer samples comes out measurably small (2-6 % at
64, DESIGN.md); the POV-Ray reference is rendered with at least this many."""


@dataclass(frozen=True)
class ExperimentSettings:
    """How much work an experiment does.

    Attributes
    ----------
    lens : str
        Lens (shipped name or path) for scenes that name none.
    quick : bool
        Half resolution and a quarter of the samples (CI).
    threads : int or None
        Worker threads for every render (None: all cores).
    povray : bool
        Also render the POV-Ray reference of the models it has.
    mitsuba : bool
        Also render the Mitsuba 3 reference of the models it has (at
        :data:`REFERENCE_MITSUBA_SPP` samples or more).
    """

    lens: str = "dgauss.50mm"
    quick: bool = False
    threads: int | None = None
    povray: bool = True
    mitsuba: bool = True

    def resolution(self, scene: Scene) -> tuple[int, int]:
        w, h = scene.camera.resolution
        return (w // 2, h // 2) if self.quick and w % 2 == 0 and h % 2 == 0 else (w, h)

    def spp(self, scene: Scene) -> int:
        return max(4, scene.render.spp // 4) if self.quick else scene.render.spp

    def povray_spp(self, scene: Scene) -> int:
        return max(REFERENCE_POVRAY_SPP, self.spp(scene))

    def mitsuba_spp(self, scene: Scene) -> int:
        return max(REFERENCE_MITSUBA_SPP, self.spp(scene))


@dataclass(frozen=True)
class Run:
    """One render of a prepared scene: which model, which renderer, the image."""

    scene: Scene
    model: str
    renderer: str  # "native", "povray" or "mitsuba"
    image: Image

    @property
    def label(self) -> str:
        return f"{self.model} ({RENDERER_NAMES[self.renderer]})" if self.renderer in RENDERER_NAMES else self.model

    @property
    def seconds(self) -> float:
        return float(self.image.metadata.get("seconds", math.nan))


def prepare_scene(scene: Scene, settings: ExperimentSettings) -> tuple[Scene, list[str]]:
    """The scene as an experiment renders it: through the settings' lens (unless
    the scene names one), at an f-number the real lens can reach, at the
    settings' resolution and samples. Returns the scene and notes on what was
    changed."""
    notes = []
    camera = scene.camera
    changes = {"resolution": settings.resolution(scene)}
    if camera.lens is None:
        changes["lens"] = resolve_lens(settings.lens, source="--lens", key=None)
        notes.append(f"all models share the lens {changes['lens'].name} (thin and thick use its focal length)")
    prepared = scene.with_camera(**changes)
    lens = prepared.camera.lens
    own_f_number = paraxial_data(lens).f_number
    if camera.f_number is None or camera.f_number < own_f_number:
        f_number = math.ceil(own_f_number * 1000) / 1000  # rounded up to three decimals
        notes.append(f"f-number set to f/{f_number:g}, the widest {lens.name} allows"
                     + (f" (the scene asks for f/{camera.f_number:g})" if camera.f_number else ""))
        prepared = prepared.with_camera(f_number=f_number)
    return replace(prepared, render=replace(prepared.render, spp=settings.spp(scene))), notes


def check_renderable(scene: Scene, settings: ExperimentSettings, *, models=MODELS) -> None:
    """Refuse, before any render or file, a prepared scene that one of the
    models (or POV-Ray, when asked) cannot render, or that is too large:
    a long run must not stop with exit 2 halfway, its outputs half written.

    Raises
    ------
    InputError
        As the render would (a lens that cannot focus there, too many samples...).
    """
    width, height = scene.camera.resolution
    check_render_budget(width, height, max(scene.render.spp, settings.povray_spp(scene) if settings.povray else 1),
                        adaptive=scene.render.adaptive, source=scene.source)
    for model in models:
        camera_for(scene, model)
    for model in (m for m in POVRAY_MODELS if m in models and settings.povray):
        if povray_unsupported(scene, model) is not None:  # left out with a note, not refused
            continue
        pov_camera(scene, model)
        if settings.povray_spp(scene) > MAX_POVRAY_SPP:
            raise InputError(scene.source, f"POV-Ray's reference would take {settings.povray_spp(scene):,} samples, "
                             f"more than its limit {MAX_POVRAY_SPP:,} (or leave POV-Ray out)", key="render.spp")


def render_run(scene: Scene, model: str, renderer: str, settings: ExperimentSettings) -> Run:
    """One render of a prepared scene; POV-Ray at reference quality."""
    if renderer == "povray":
        image = render_povray(scene, model=model, spp=settings.povray_spp(scene), threads=settings.threads)
    elif renderer == "mitsuba":
        image = render_mitsuba(scene, model=model, spp=settings.mitsuba_spp(scene))
    else:
        image = render(scene, model=model, threads=settings.threads, progress=False)
    return Run(scene, model, renderer, image)


def render_models(scene: Scene, settings: ExperimentSettings, *, models=MODELS, progress=None,
                  cluster: Cluster | None = None) -> tuple[list[Run], list[str]]:
    """Every model natively, then POV-Ray and Mitsuba for the models they have (when asked).

    A POV-Ray or Mitsuba failure (or a scene Mitsuba cannot render, such as
    lights without inverse-square falloff) becomes a note, not an error: the
    native runs stand. ``progress`` (a progress bar) advances once per render.
    With a ``cluster`` (:func:`lenscompare.cluster.open_cluster`) the renders
    run there as tasks, each with its worker's thread count unless
    ``settings.threads`` is given.
    """
    return render_scenes([scene], settings, models=models, progress=progress, cluster=cluster)[0]


def render_scenes(scenes: list[Scene], settings: ExperimentSettings, *, models=MODELS, progress=None,
                  cluster: Cluster | None = None) -> list[tuple[list[Run], list[str]]]:
    """:func:`render_models` for several scenes at once (on a cluster, every
    render of every scene is a task from the start)."""
    jobs = [(i, model, "native") for i in range(len(scenes)) for model in models]
    out = [([], []) for _ in scenes]
    for i, scene in enumerate(scenes):
        for model in (m for m in POVRAY_MODELS if m in models and settings.povray):
            problem = povray_unsupported(scene, model)
            if problem is None:
                jobs.append((i, model, "povray"))
            else:  # no reference for what POV-Ray cannot render: say so
                out[i][1].append(f"no POV-Ray {model} render of {scene.name}: {problem[0]}: {problem[1]}")
    jobs += [(i, model, "mitsuba") for i in range(len(scenes)) for model in MITSUBA_MODELS
             if model in models and settings.mitsuba]
    jobs.sort(key=lambda job: job[0])  # scene by scene, natives first (a stable sort)
    results = run_calls(cluster, _render_run_with_threads, [((scenes[i], model, renderer, settings), {})
                                                            for i, model, renderer in jobs],
                        threads=settings.threads, catch=(ExternalError, InputError), progress=progress)
    for (i, model, renderer), result in zip(jobs, results):
        if isinstance(result, ExternalError) and renderer == "povray":
            out[i][1].append(f"POV-Ray {model} render of {scenes[i].name} failed: {result}")
        elif isinstance(result, (ExternalError, InputError)) and renderer == "mitsuba":
            out[i][1].append(f"Mitsuba {model} render of {scenes[i].name}: not rendered ({result})")
        elif isinstance(result, Exception):  # a native or POV-Ray input error is the caller's
            raise result
        else:
            out[i][0].append(result)
    return out


def _render_run_with_threads(scene: Scene, model: str, renderer: str, settings: ExperimentSettings, *,
                             threads: int | None) -> Run:
    return render_run(scene, model, renderer, replace(settings, threads=threads))
