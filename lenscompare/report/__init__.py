"""``lenscompare report``: render every scene through every model and POV-Ray,
measure what each model does, and write ``index.html`` + ``results.json``."""

from __future__ import annotations

import datetime
import json
import os
import platform
import time
from pathlib import Path

import numpy as np
import skimage

from .. import __version__, measure
from ..atomic import atomic_output, prepare_output_dir, unique_file_names
from ..cluster import Cluster
from ..cost import CostSettings, run_cost_study, time_table_rows
from ..errors import InputError
from ..experiment import (
    MITSUBA_MODELS,
    POVRAY_MODELS,
    ExperimentSettings,
    check_renderable,
    prepare_scene,
    render_scenes,
)
from ..figures import write_teaching_figures
from ..lenses import load_prescription
from ..mitsuba import mitsuba_version
from ..plan import auto_lens_options, plan_scene, render_planned
from ..povray import povray_version
from ..progress import progress_bar
from ..scene import MODELS, Scene
from . import plots
from .chromatic import chromatic_section
from .chromatic_measure import measure_lateral_color, measure_longitudinal_color
from .html import render_page
from .save import save_runs

__all__ = ["build_report"]

# Published Double Gauss values (../shared/data/lenses/README.md, optiland 0.6.3).
DGAUSS_DISTORTION = [(10.0, -0.221), (20.0, -1.07)]
DGAUSS_RELATIVE_ILLUMINATION = [(10.0, 0.70), (20.0, 0.29)]


def build_report(scenes: list[Scene], out_dir: str | os.PathLike, settings: ExperimentSettings | None = None, *,
                 progress: bool | None = None, cluster: Cluster | None = None, final: bool = False) -> dict:
    """Render, measure and write the report; return the results dictionary.

    Parameters
    ----------
    scenes : list of Scene
    out_dir : path
        Created if missing; ``index.html``, ``results.json``, ``renders/`` and
        ``plots/`` are written into it (each file atomically), and nothing
        outside it: scene names become safe file names
        (:func:`lenscompare.atomic.unique_file_names`).
    settings : ExperimentSettings, optional
        Lens, quick mode, threads, whether to run POV-Ray.
    cluster : Cluster, optional
        Run every render as a task there (:func:`lenscompare.cluster.open_cluster`);
        measurements, plots and pages are made here.
    final : bool, optional
        ``index.html`` is the command's last output (see
        :func:`lenscompare.atomic.atomic_output`).
    """
    settings = settings or ExperimentSettings()
    start = time.perf_counter()
    # Every input problem surfaces here, before the folder is made or a render starts.
    prepared = [prepare_scene(s, settings) for s in scenes]
    for scene, _ in prepared:
        check_renderable(scene, settings)
    out = prepare_output_dir(out_dir)
    for sub in ("renders", "plots", "figures"):
        (out / sub).mkdir(exist_ok=True)
    stems = unique_file_names(s.name for s in scenes)

    renders_per_scene = (len(MODELS) + (len(POVRAY_MODELS) if settings.povray else 0)
                         + (len(MITSUBA_MODELS) if settings.mitsuba else 0))
    results = {"settings": {"lens": settings.lens, "quick": settings.quick, "threads": settings.threads,
                            "povray": settings.povray, "mitsuba": settings.mitsuba,
                            "scheduler": cluster.address if cluster else None},
               "scenes": {}, "renders": [], "notes": []}
    with progress_bar(renders_per_scene * len(scenes), description="report", unit="render",
                      enabled=progress) as bar:
        rendered = render_scenes([scene for scene, _ in prepared], settings, progress=bar, cluster=cluster)
        for (scene, notes), (runs, render_notes) in zip(prepared, rendered):
            summaries = save_runs(runs, out, stem=stems[scene.name])
            results["scenes"][scene.name] = _measure_scene(scene, runs, summaries, out, notes + render_notes,
                                                           settings, stem=stems[scene.name])
            results["renders"].extend(summaries)

    results["time_plot"] = "plots/" + plots.plot_times(results["renders"], out / "plots" / "times.png")
    results["cost"] = _cost_section(scenes, out, settings, stems, cluster)
    results["teaching_figures"] = _teaching_figures(out, settings, results["notes"])
    results["chromatic"] = chromatic_section(
        {scene.name: (scene, results["scenes"][scene.name]["plan"]) for scene, _ in prepared},
        figure=results["teaching_figures"].get("chromatic"),
        measured=_measure_chromatic([scene for scene, _ in prepared], settings))
    results["total_seconds"] = time.perf_counter() - start
    results["provenance"] = _provenance(scenes, prepared, settings)
    with atomic_output(out / "results.json") as tmp:
        tmp.write_text(json.dumps(_finite(results), indent=2, default=_json_default, allow_nan=False))
    with atomic_output(out / "index.html", final=final) as tmp:
        tmp.write_text(render_page(results), encoding="utf-8")
    return results


def _measure_scene(scene: Scene, runs, summaries: list[dict], out: Path, notes: list[str],
                   settings: ExperimentSettings, *, stem: str) -> dict:
    by_label = {r.label: r for r in runs}
    camera = scene.camera
    entry = {"description": scene.description, "notes": notes, "measure": list(scene.measure),
             # What was rendered (the description is the scene file's own and may name other settings).
             "rendered": {"lens": camera.lens.name, "f_number": camera.f_number,
                          "focus_distance_m": camera.focus_distance_m, "resolution": list(camera.resolution),
                          "spp": scene.render.spp,
                          "povray_spp": settings.povray_spp(scene) if settings.povray else None,
                          "mitsuba_spp": settings.mitsuba_spp(scene) if settings.mitsuba else None},
             "renders": summaries}
    entry["plan"] = _plan_against_measured(scene, by_label, settings)
    lens_is_dgauss = scene.camera.lens.sha256 == load_prescription("dgauss.50mm").sha256
    if "blur_disks" in scene.measure:
        entry["blur_disks"] = measure.measure_blur_disks(scene, runs)
        entry["blur_disks"]["plot"] = "plots/" + plots.plot_blur(
            entry["blur_disks"], out / "plots" / f"{stem}.blur.png", title=f"{scene.name}: blur disks")
    if "distortion" in scene.measure:
        entry["distortion"] = measure.measure_distortion(scene, runs)
        entry["distortion"]["plot"] = "plots/" + plots.plot_distortion(
            entry["distortion"], out / "plots" / f"{stem}.distortion.png", title=f"{scene.name}: distortion",
            published=DGAUSS_DISTORTION if lens_is_dgauss else None)
    if "vignetting" in scene.measure:
        entry["vignetting"] = measure.measure_vignetting(scene, runs)
        entry["vignetting"]["plot"] = "plots/" + plots.plot_vignetting(
            entry["vignetting"], out / "plots" / f"{stem}.vignetting.png",
            title=f"{scene.name}: relative illumination",
            published=DGAUSS_RELATIVE_ILLUMINATION if lens_is_dgauss else None)
    # Similarity: against POV-Ray, and against the full lens system.
    entry["vs_povray"] = {m: measure.compare_images(by_label[f"{m} (POV-Ray)"].image.pixels, by_label[m].image.pixels)
                          for m in POVRAY_MODELS if f"{m} (POV-Ray)" in by_label}
    entry["vs_mitsuba"] = {m: measure.compare_images(by_label[f"{m} (Mitsuba)"].image.pixels,
                                                     by_label[m].image.pixels)
                           for m in MITSUBA_MODELS if f"{m} (Mitsuba)" in by_label}
    entry["vs_lens"] = {m: measure.compare_images(by_label["lens"].image.pixels, by_label[m].image.pixels)
                        for m in ("pinhole", "thin", "thick")}
    return entry


def _plan_against_measured(scene: Scene, by_label: dict, settings: ExperimentSettings) -> dict:
    """The planner's predictions for this scene beside what the renders show.

    A plan for a render the report does not make anyway (a composite, the
    postfilter, the lens system as --model auto renders it: rays from the
    table, mirrored) is rendered here, at the scene's spp. Time saved is measured
    twice: at equal spp, and at equal noise, scaling the chosen render's time
    by its mean per-pixel variance over the lens system's (Monte Carlo noise
    variance falls as 1/spp, so that is the time it needs to be as noisy).
    """
    planned = plan_scene(scene, measure_costs=False)
    plan = planned.to_json()
    seconds = {label: run.seconds for label, run in by_label.items()}
    plan["render_seconds"] = {m: seconds.get(m) for m in MODELS}
    chosen = by_label.get(plan["model"])
    if plan["model"] == "lens":
        plan["lens_options"] = auto_lens_options(scene, tolerance_px=planned.tolerance_px)
        if plan["lens_options"]:
            chosen = None  # the report's lens system is traced: render the faster one auto renders
    chosen_image = chosen.image if chosen is not None else None
    if chosen is None and "lens" in by_label:
        chosen_image = render_planned(scene, plan=planned, threads=settings.threads, progress=False)
    chosen_seconds = None if chosen_image is None else chosen_image.metadata["seconds"]
    full = by_label.get("lens")
    plan["chosen_seconds"] = chosen_seconds
    plan["time_saved_seconds"] = None if chosen_seconds is None or full is None else full.seconds - chosen_seconds
    plan["noise_variance_ratio_vs_lens"] = plan["time_saved_at_equal_noise_seconds"] = None
    if full is not None and chosen_image is not None and chosen_image.variance is not None \
            and full.image.variance is not None and float(np.mean(full.image.variance)) > 0:
        ratio = float(np.mean(chosen_image.variance)) / float(np.mean(full.image.variance))
        plan["noise_variance_ratio_vs_lens"] = ratio
        plan["time_saved_at_equal_noise_seconds"] = full.seconds - chosen_seconds * ratio
    return plan


def _measure_chromatic(scenes: list[Scene], settings: ExperimentSettings) -> dict[str, dict]:
    """Lateral and longitudinal colour measured on spectral renders of
    monochromatic dots (report/chromatic_measure.py) for each scene whose lens disperses;
    scenes with the same camera share one render. Rendered here, not on the
    cluster: it is one small image per camera."""
    measured, by_camera = {}, {}
    for scene in scenes:
        camera = scene.camera
        key = (camera.lens.sha256, camera.film_mm, camera.resolution, camera.f_number, camera.focus_distance_m,
               camera.focus_mode, camera.aperture_blades, camera.aperture_rotation_deg)
        if key not in by_camera:
            by_camera[key] = (measure_lateral_color(scene, threads=settings.threads),
                              measure_longitudinal_color(scene, threads=settings.threads))
        result, disk = by_camera[key]
        if result is not None:
            measured[scene.name] = {"lateral_color_px": result.corner_px,
                                    "longitudinal_color_px": None if disk is None else disk[0],
                                    "fields_deg": list(result.field_deg), "measured_px": list(result.measured_px),
                                    "predicted_px": list(result.predicted_px), "seconds": result.seconds}
    return measured


def _cost_section(scenes, out: Path, settings: ExperimentSettings, stems: dict[str, str],
                  cluster: Cluster | None) -> dict | None:
    """A small cost study on the showcase scene (or the first scene), and on
    the moving showcase when the report has it (what motion blur costs)."""
    scene = next((s for s in scenes if s.name == "showcase"), scenes[0] if scenes else None)
    if scene is None:
        return None
    studied = [scene] + [s for s in scenes if s.name == "moving_showcase" and s is not scene]
    cost = CostSettings(quick=True, lens=settings.lens, threads=settings.threads, povray=settings.povray,
                        samplers=("random", "jittered", "sobol"))
    results = run_cost_study(studied, out / "cost", cost, progress=False, cluster=cluster,
                             stems={s.name: stems[s.name] for s in studied})
    return {"index": "cost/index.html", "findings": results["findings"],
            "plot": f"cost/{results['scenes'][scene.name]['plot']}",
            "time_to_1_percent": [list(row) for row in time_table_rows(results)]}


def _teaching_figures(out: Path, settings: ExperimentSettings, notes: list[str]) -> dict:
    try:
        files = write_teaching_figures(out / "figures", lens=settings.lens)
    except Exception as error:  # a figure must not sink the report; say so in it
        notes.append(f"teaching figures failed: {error}")
        return {}
    return {name: str(Path(path).resolve().relative_to(out.resolve())) for name, path in files.items()}


def _provenance(scenes, prepared, settings) -> dict:
    info = {
        "created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
        "lenscompare": __version__, "python": platform.python_version(), "numpy": np.__version__,
        "scikit-image": skimage.__version__, "machine": platform.machine(), "processor": platform.processor(),
        "cpu_count": os.cpu_count(), "threads": settings.threads or os.cpu_count(),
        "scenes": {s.name: {"source": s.source, "spp": p.render.spp, "sampler": p.render.sampler,
                            "seed": p.render.seed, "resolution": list(p.camera.resolution),
                            "lens": p.camera.lens.name, "f_number": p.camera.f_number}
                   for s, (p, _) in zip(scenes, prepared)},
        # The prescriptions the renders used, as loaded with their scenes (never re-read).
        "lenses": {p.camera.lens.name: {"sha256": p.camera.lens.sha256, "source": p.camera.lens.source}
                   for p, _ in prepared},
    }
    if settings.povray:
        try:
            info["povray"] = povray_version()
        except Exception as error:  # noqa: BLE001 - recorded, not fatal
            info["povray"] = f"unavailable ({error})"
    if settings.mitsuba:
        try:
            info["mitsuba"] = f"Mitsuba {mitsuba_version()} scalar_rgb"
        except Exception as error:  # noqa: BLE001 - recorded, not fatal
            info["mitsuba"] = f"unavailable ({error})"
    return info


def _finite(value):
    """Strict JSON has no Infinity or NaN: those become null (e.g. the PSNR of
    identical images)."""
    if isinstance(value, dict):
        return {k: _finite(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_finite(v) for v in value]
    if isinstance(value, (float, np.floating)) and not np.isfinite(value):
        return None
    return value


def _json_default(value):
    if isinstance(value, (np.floating, np.integer)):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    return str(value)
