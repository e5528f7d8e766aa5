"""Simulate only the effects a scene calls for: predict each effect's size
without rendering, pick the cheapest model whose omitted effects all stay
under tolerance, and predict the time that saves."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError
from ..image import Image
from ..render import render
from ..scene import MODELS, Scene
from .effects import EFFECTS, Effect, ideal_camera

__all__ = ["Plan", "plan_scene", "render_planned", "MODEL_ORDER"]

# Cheapest first; each model simulates the effects of those before it.
MODEL_ORDER = ("pinhole", "thin", "thick", "lens")


@dataclass(frozen=True)
class Plan:
    model: str
    effects: dict[str, Effect]
    needed: dict[str, bool]
    tolerance_px: float
    tolerance_percent: float
    predicted_seconds: dict[str, float]

    def to_json(self) -> dict:
        saved = None
        if self.predicted_seconds:
            saved = self.predicted_seconds.get("lens", math.nan) - self.predicted_seconds.get(self.model, math.nan)
        return {
            "model": self.model,
            "effects": {name: {"needed": self.needed[name], "magnitude": e.magnitude, "unit": e.unit,
                               "detail": e.detail, "simulated_from": e.needed_by} for name, e in self.effects.items()},
            "tolerance": {"px": self.tolerance_px, "percent": self.tolerance_percent},
            "predicted_seconds": self.predicted_seconds,
            "time_saved_seconds_vs_lens": saved,
        }


def plan_scene(scene: Scene, *, tolerance_px: float = 0.5, tolerance_percent: float = 2.0,
               measure_costs: bool = True, threads: int | None = None) -> Plan:
    """The cheapest model that renders ``scene`` within tolerance.

    Parameters
    ----------
    tolerance_px : float
        Largest effect, in pixels (blur-disk diameter, distortion shift), that
        may be left out.
    tolerance_percent : float
        Largest relative-illumination drop at the corners, in percent.
    measure_costs : bool
        Render each model at 1 spp on a small copy of the scene to predict
        each model's time for the full render.
    """
    for name, value in (("--tolerance-px", tolerance_px), ("--tolerance-percent", tolerance_percent)):
        if not (value >= 0 and math.isfinite(value)):
            raise InputError(name, f"expected a number >= 0, got {value}")
    camera = ideal_camera(scene)
    effects = {e.name: e for e in (effect(scene, camera) for effect in EFFECTS)}
    limit = {"px": tolerance_px, "%": tolerance_percent}
    needed = {name: e.magnitude > limit[e.unit] for name, e in effects.items()}
    model = "pinhole"
    for name, e in effects.items():
        if needed[name] and MODEL_ORDER.index(e.needed_by) > MODEL_ORDER.index(model):
            model = e.needed_by
    if model == "lens" and scene.camera.lens is None:  # cannot happen: no prescription, no lens effects
        model = "thin"
    costs = predicted_seconds(scene, threads=threads) if measure_costs else {}
    return Plan(model, effects, needed, tolerance_px, tolerance_percent, costs)


def predicted_seconds(scene: Scene, *, threads: int | None = None) -> dict[str, float]:
    """Each model's predicted time for the scene's full render, from a 1-spp
    render of a small copy (samples per second scale with pixels and spp)."""
    w, h = scene.camera.resolution
    scale = max(1, int(math.sqrt(w * h / 20000)))
    small = scene.with_camera(resolution=(max(1, w // scale), max(1, h // scale)))
    if small.camera.width_px * scene.camera.height_px != small.camera.height_px * scene.camera.width_px:
        small = scene
    models = [m for m in MODELS if m != "lens" or scene.camera.lens]
    render(small, model="pinhole", spp=1, threads=threads, progress=False)  # warm up threads and caches
    out = {}
    for model in models:
        try:
            rate = max(render(small, model=model, spp=8, threads=threads, progress=False)
                       .metadata["samples_per_second"] for _ in range(2))
        except InputError:
            continue  # the scene lacks what this model needs
        out[model] = w * h * scene.render.spp / rate
    return out


def render_planned(scene: Scene, *, tolerance_px: float = 0.5, tolerance_percent: float = 2.0,
                   **render_options) -> Image:
    """``--model auto``: render with the cheapest model within tolerance.

    The plan is made from the scene alone (no timing renders) and stored in
    ``image.metadata["plan"]``; ``render_options`` go to
    :func:`lenscompare.render.render`.
    """
    plan = plan_scene(scene, tolerance_px=tolerance_px, tolerance_percent=tolerance_percent, measure_costs=False)
    open_s, close_s = scene.render.shutter_s
    if not plan.needed["motion_blur"] and close_s > open_s:
        # Streaks under tolerance: the instant in the middle of the shutter, without sampling time.
        scene = scene.with_render(shutter_s=(0.5 * (open_s + close_s),) * 2)
    if render_options.get("diffraction") is None:  # a post-filter on any model's image: on when needed
        render_options["diffraction"] = plan.needed["diffraction"]
    image = render(scene, model=plan.model, **render_options)
    image.metadata["plan"] = plan.to_json()
    return image
