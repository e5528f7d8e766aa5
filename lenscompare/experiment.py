"""One home for "an experiment": a scene, the models to render it through and
the settings, in; runs (one image per model and renderer), out.

The report, the cost study, the checks and sweeps all build on this module, so
a scene is prepared (lens, f-number, resolution, samples) and rendered the same
way wherever it is measured.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .errors import ExternalError, InputError
from .image import Image
from .lenses import paraxial_data, resolve_lens
from .mitsuba import MITSUBA_MODELS, render_mitsuba
from .povray import POVRAY_MODELS, render_povray, unsupported as povray_unsupported
from .render import render
from .scene import MODELS, Scene

__all__ = ["ExperimentSettings", "Run", "prepare_scene", "render_run", "render_models", "POVRAY_MODELS",
           "MITSUBA_MODELS", "REFERENCE_POVRAY_SPP", "REFERENCE_MITSUBA_SPP", "RENDERER_NAMES"]

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


def render_run(scene: Scene, model: str, renderer: str, settings: ExperimentSettings) -> Run:
    """One render of a prepared scene; POV-Ray at reference quality."""
    if renderer == "povray":
        image = render_povray(scene, model=model, spp=settings.povray_spp(scene), threads=settings.threads)
    elif renderer == "mitsuba":
        image = render_mitsuba(scene, model=model, spp=settings.mitsuba_spp(scene))
    else:
        image = render(scene, model=model, threads=settings.threads, progress=False)
    return Run(scene, model, renderer, image)


def render_models(scene: Scene, settings: ExperimentSettings, *, models=MODELS, progress=None
                  ) -> tuple[list[Run], list[str]]:
    """Every model natively, then POV-Ray and Mitsuba for the models they have (when asked).

    A POV-Ray or Mitsuba failure (or a scene Mitsuba cannot render, such as
    lights without inverse-square falloff) becomes a note, not an error: the
    native runs stand.
    ``progress`` (a progress bar) advances once per render.
    """
    runs, notes = [], []
    for model in models:
        runs.append(render_run(scene, model, "native", settings))
        if progress:
            progress.update(1)
    for model in (m for m in POVRAY_MODELS if m in models and settings.povray):
        problem = povray_unsupported(scene, model)
        if problem is not None:  # no reference for what POV-Ray cannot render: say so
            notes.append(f"no POV-Ray {model} render of {scene.name}: {problem[0]}: {problem[1]}")
            if progress:
                progress.update(1)
            continue
        try:
            runs.append(render_run(scene, model, "povray", settings))
        except ExternalError as error:
            notes.append(f"POV-Ray {model} render of {scene.name} failed: {error}")
        finally:
            if progress:
                progress.update(1)
    for model in (m for m in MITSUBA_MODELS if m in models and settings.mitsuba):
        try:
            runs.append(render_run(scene, model, "mitsuba", settings))
        except (ExternalError, InputError) as error:
            notes.append(f"Mitsuba {model} render of {scene.name}: not rendered ({error})")
        finally:
            if progress:
                progress.update(1)
    return runs, notes
