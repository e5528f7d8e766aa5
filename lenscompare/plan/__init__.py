"""Simulate only the effects a scene calls for: predict each effect's size
without rendering, pick the cheapest render that simulates every effect above
tolerance, and predict the time that saves.

Effects are the unit: each effect names the cheapest part that simulates it
(``Effect.needed_by``). The render is the pinhole when nothing is needed, the
thin lens for defocus alone, the composite of the needed effects when one of
them is a composite part (distortion, vignetting; in a spectral render
lateral colour too), and the full lens system
when a needed effect has no part (or the composite cannot stand in for the
lens on this film). Post-filter effects (diffraction) go on any render. The
image-based depth of field (``postfilter``) stands in for the thin lens when
the blur jump across the scene's occlusion edges is within tolerance."""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..errors import InputError
from ..cameras import COLOR_PARTS, COMPOSITE_EFFECTS, camera_for
from ..cameras.base import lens_f_number
from ..cameras.lens_ray_table import TOLERANCE_PX as RAY_TABLE_TOLERANCE_PX
from ..image import Image
from ..postfilter import pinhole_pass_spp, postfilter_suffices
from ..render import render
from ..scene import MODELS, Scene
from .effects import COLOR_EFFECTS, EFFECTS, Effect, ideal_camera

__all__ = ["Plan", "plan_scene", "render_planned", "auto_lens_options", "renders_color", "MODEL_ORDER",
           "MIRROR_AVERAGING_MEASURES"]

# Measures that average over points placed symmetrically about the film's centre lines (a
# radial profile, a grid of dots): with mirrored lens rays their mirror images' noise is one
# noise, and the measure gains nothing or takes longer to a given error than traced
# (bench_lens_mirrors.py: relative illumination 1.0-1.2x, distortion's k1 1.5-1.7x), so
# --model auto leaves the mirrors off. Blur disks gain from them (0.24-0.71x) and keep them.
MIRROR_AVERAGING_MEASURES = frozenset({"distortion", "vignetting"})

# Cheapest first. Effects name one of these (or "pinhole": a post-filter on
# any render) as the cheapest part that simulates them.
MODEL_ORDER = ("pinhole", "thin", "thick", "composite", "lens")


@dataclass(frozen=True)
class Plan:
    """The chosen render and why.

    Attributes
    ----------
    model : str
        ``pinhole``, ``postfilter``, ``thin``, ``thick``, ``composite`` or ``lens``.
    effects : dict of str to Effect
        Every effect's predicted size.
    needed : dict of str to bool
        Whether each effect is above its tolerance.
    simulated : tuple of str
        The effects the chosen render simulates (post-filters included when applied).
    composite_effects : tuple of str
        The composite's parts (empty unless ``model`` is ``composite``).
    postfilter_edge_error : dict or None
        The predicted blur jump across occlusion edges
        (:class:`lenscompare.postfilter.EdgeError`), when defocus alone was needed.
    """

    model: str
    effects: dict[str, Effect]
    needed: dict[str, bool]
    tolerance_px: float
    tolerance_percent: float
    predicted_seconds: dict[str, float]
    simulated: tuple[str, ...] = ()
    composite_effects: tuple[str, ...] = ()
    note: str = ""
    postfilter_edge_error: dict | None = None

    def to_json(self) -> dict:
        saved = None
        if self.predicted_seconds:
            # a lens-system plan renders as lens_auto where that was timed (rays from the table, mirrored)
            chosen = "lens_auto" if self.model == "lens" and "lens_auto" in self.predicted_seconds else self.model
            saved = self.predicted_seconds.get("lens", math.nan) - self.predicted_seconds.get(chosen, math.nan)
        data = {
            "model": self.model,
            "effects": {name: {"needed": self.needed[name], "magnitude": e.magnitude, "unit": e.unit,
                               "detail": e.detail, "simulated_from": e.needed_by} for name, e in self.effects.items()},
            "simulated": list(self.simulated),
            "tolerance": {"px": self.tolerance_px, "percent": self.tolerance_percent},
            "predicted_seconds": self.predicted_seconds,
            "time_saved_seconds_vs_lens": saved,
            "postfilter_edge_error": self.postfilter_edge_error,
        }
        if self.note:
            data["note"] = self.note
        return data


def renders_color(scene: Scene) -> bool:
    """Whether the scene's render samples wavelength (``[render] spectral``),
    so that its models can show colour."""
    return scene.render.spectral


def _color_note(scene: Scene, effects: dict[str, Effect], needed: dict[str, bool]) -> str:
    """What an RGB render leaves out of the colour effects above tolerance ("" when nothing)."""
    left = [name for name in COLOR_EFFECTS if needed.get(name)]
    if not left or renders_color(scene):
        return ""
    sizes = ", ".join(f"{name} {effects[name].magnitude:.3g} px" for name in left)
    return f"{sizes} above tolerance, left out: only a spectral render ([render] spectral) shows colour"


def _choose(scene: Scene, effects: dict[str, Effect], needed: dict[str, bool]) -> tuple[str, tuple[str, ...], str]:
    """(model, the composite's effects, a note) for the effects above tolerance."""
    shown = renders_color(scene)
    wanted = [name for name, e in effects.items() if needed[name] and e.needed_by != "pinhole"
              and (shown or name not in COLOR_EFFECTS)]
    model = max((effects[name].needed_by for name in wanted), key=MODEL_ORDER.index, default="pinhole")
    if model == "lens" and scene.camera.lens is None:  # cannot happen: no prescription, no lens effects
        model = "thin"
    if model != "composite":
        return model, (), ""
    # The colour parts are wanted only when the render is spectral (above).
    parts = tuple(name for name in COMPOSITE_EFFECTS + COLOR_PARTS if name in wanted)
    try:  # the parts exist, but may not cover this film (a fisheye's corners)
        camera_for(scene, "composite", effects=parts)
    except InputError as error:
        return "lens", (), f"no composite: {error.problem}"
    return "composite", parts, ""


def _simulated(model: str, parts: tuple[str, ...], effects: dict[str, Effect], needed: dict[str, bool], *,
               color: bool) -> tuple:
    """The effects the chosen render simulates, post-filters (applied when needed) included;
    the colour effects only when the render is spectral (``color``)."""
    if model == "postfilter":  # the thin lens's defocus, from an image
        model = "thin"
    if model == "composite":
        inside = set(parts)
    elif model == "lens":  # every geometric effect
        inside = {name for name, e in effects.items() if e.needed_by != "pinhole"}
    else:
        inside = {name for name, e in effects.items()
                  if e.needed_by != "pinhole" and MODEL_ORDER.index(e.needed_by) <= MODEL_ORDER.index(model)}
    inside |= {name for name, e in effects.items() if e.needed_by == "pinhole" and needed[name]}
    if not color:
        inside -= set(COLOR_EFFECTS)
    return tuple(name for name in effects if name in inside)


def plan_scene(scene: Scene, *, tolerance_px: float = 0.5, tolerance_percent: float = 2.0,
               measure_costs: bool = True, threads: int | None = None) -> Plan:
    """The cheapest render that simulates every effect of ``scene`` above tolerance.

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
    model, parts, note = _choose(scene, effects, needed)
    # The image-based depth of field stands in for the thin lens where its occlusion edges allow.
    edge_error = None
    # Its depth buffer is one instant, and its pinhole pass one focus for every colour.
    if model == "thin" and not needed["motion_blur"] and not (renders_color(scene) and needed["longitudinal_color"]):
        suffices, edge_error = postfilter_suffices(scene, defocus_needed=needed["defocus"],
                                                   tolerance_px=tolerance_px, camera=camera, threads=threads)
        model = "postfilter" if suffices else model
    costs = predicted_seconds(scene, threads=threads, composite_effects=parts if model == "composite" else None,
                              lens_options=auto_lens_options(scene, tolerance_px=tolerance_px) if model == "lens"
                              else None) if measure_costs else {}
    # at most min(spp, 16) pinhole samples (the refined pass draws fewer: a bound); the spread costs ms
    if "pinhole" in costs:
        costs["postfilter"] = costs["pinhole"] * pinhole_pass_spp(scene.render.spp) / scene.render.spp
    note = "; ".join(filter(None, (note, _color_note(scene, effects, needed))))
    return Plan(model, effects, needed, tolerance_px, tolerance_percent, costs,
                simulated=_simulated(model, parts, effects, needed, color=renders_color(scene)),
                composite_effects=parts, note=note,
                postfilter_edge_error=edge_error.to_json() if edge_error else None)


def predicted_seconds(scene: Scene, *, threads: int | None = None,
                      composite_effects: tuple[str, ...] | None = None,
                      lens_options: dict | None = None) -> dict[str, float]:
    """Each model's predicted time for the scene's full render, from an 8-spp
    render of a small copy (samples per second scale with pixels and spp);
    with ``composite_effects``, the composite of those effects too; with
    ``lens_options`` (:func:`auto_lens_options`), the lens system rendered
    with them as ``lens_auto``, beside the traced ``lens``."""
    w, h = scene.camera.resolution
    scale = max(1, int(math.sqrt(w * h / 20000)))
    small = scene.with_camera(resolution=(max(1, w // scale), max(1, h // scale)))
    if small.camera.width_px * scene.camera.height_px != small.camera.height_px * scene.camera.width_px:
        small = scene
    models = [m for m in MODELS if m != "lens" or scene.camera.lens]
    if composite_effects is not None:
        models.append("composite")
    if lens_options and scene.camera.lens:
        models.append("lens_auto")
    render(small, model="pinhole", spp=1, threads=threads, progress=False)  # warm up threads and caches
    out = {}
    for model in models:
        options = {"composite": {"effects": composite_effects}, "lens_auto": lens_options}.get(model, {})
        try:
            rate = max(render(small, model="lens" if model == "lens_auto" else model, spp=8, threads=threads,
                              progress=False, **options)
                       .metadata["samples_per_second"] for _ in range(2))
        except InputError:
            continue  # the scene lacks what this model needs
        out[model] = w * h * scene.render.spp / rate
    return out


def auto_lens_options(scene: Scene, *, tolerance_px: float, **render_options) -> dict:
    """The render options ``--model auto`` adds for a lens-system plan: rays from
    the table where the plan's tolerance allows, mirrored unless the scene
    measures what mirrors make noisier; what the scene or ``render_options``
    set stays theirs."""
    options = {}
    if (render_options.get("lens_rays") is None and scene.render.lens_rays is None
            and tolerance_px >= RAY_TABLE_TOLERANCE_PX):
        # The lens system's rays from a table: checked before the render to stay within
        # RAY_TABLE_TOLERANCE_PX of the traced ones (else it traces), inside the plan's tolerance.
        options["lens_rays"] = "table"
    if (render_options.get("lens_mirrors") is None and scene.render.lens_mirrors is None
            and not MIRROR_AVERAGING_MEASURES.intersection(scene.measure)):
        options["lens_mirrors"] = True
    return options


def render_planned(scene: Scene, *, tolerance_px: float = 0.5, tolerance_percent: float = 2.0,
                   plan: Plan | None = None, **render_options) -> Image:
    """``--model auto``: the cheapest render that simulates every effect above tolerance.

    The plan is made from the scene alone (no timing renders), unless the
    caller made it already (``plan``), and stored in
    ``image.metadata["plan"]``; ``render_options`` go to
    :func:`lenscompare.render.render`. A lens-system plan takes its rays
    from a table (``lens_rays = "table"``) unless the scene or the caller
    says otherwise or ``tolerance_px`` is below the table's own bound, and
    mirrors them (``lens_mirrors``: each pixel as accurate, mirror-image
    pixels' noise correlated) unless the scene or the caller says otherwise
    or the scene measures something that averages mirror-image pixels
    (:data:`MIRROR_AVERAGING_MEASURES`).
    """
    if plan is None:
        plan = plan_scene(scene, tolerance_px=tolerance_px, tolerance_percent=tolerance_percent,
                          measure_costs=False)
    open_s, close_s = scene.render.shutter_s
    if not plan.needed["motion_blur"] and close_s > open_s:
        # Streaks under tolerance: the instant in the middle of the shutter, without sampling time.
        scene = scene.with_render(shutter_s=(0.5 * (open_s + close_s),) * 2)
    if render_options.get("diffraction") is None:  # a post-filter on any model's image: on when needed
        render_options["diffraction"] = plan.needed["diffraction"]
    if plan.model == "lens":  # at the plan's tolerance: a plan made elsewhere (the report's) keeps its own
        render_options.update(auto_lens_options(scene, tolerance_px=plan.tolerance_px, **render_options))
    if plan.model in ("thin", "thick", "postfilter", "composite"):
        # The f-number the plan sized their blur at: a scene naming a lens and no f-number
        # gets its lens's own, wide open, as the lens system renders it (ideal_camera).
        scene = scene.with_camera(f_number=lens_f_number(scene))
    if plan.model == "composite":
        image = render(scene, model="composite", effects=plan.composite_effects, **render_options)
    else:
        image = render(scene, model=plan.model, **render_options)  # an explicit model: [render] effects unused
    image.metadata["plan"] = plan.to_json()
    return image
