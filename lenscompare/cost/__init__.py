"""``lenscompare cost``: what accuracy costs in time, per model and sampler."""

from __future__ import annotations

import datetime
import html
import json
import os
import platform
import time

from .. import __version__
from ..atomic import atomic_output, prepare_output_dir, unique_file_names
from ..cluster import Cluster
from ..experiment import ExperimentSettings, check_renderable
from ..progress import progress_bar
from ..scene import Scene
from .findings import findings
from .plots import plot_error_vs_time
from .study import CostSettings, povray_series_wanted, prepared_for_cost, study_scene, study_series

__all__ = ["CostSettings", "run_cost_study", "time_table_rows"]


def run_cost_study(scenes: list[Scene], out_dir, settings: CostSettings | None = None, *,
                   progress: bool | None = None, cluster: Cluster | None = None, stems: dict[str, str] | None = None,
                   final: bool = False) -> dict:
    """Run the study and write ``results.json``, ``index.html`` and plots into ``out_dir``.

    With a ``cluster``, every render is a task there. Plots are named by
    ``stems`` (scene name -> file name; default
    :func:`lenscompare.atomic.unique_file_names`), never by the raw name;
    ``final``: ``index.html`` is the command's last output.
    """
    settings = settings or CostSettings()
    # Every input problem surfaces here, before the folder is made or a render starts.
    prepared_scenes = [prepared_for_cost(scene, settings) for scene in scenes]
    for prepared in prepared_scenes:
        check_renderable(prepared.with_render(spp=settings.reference_spp),
                         ExperimentSettings(lens=settings.lens, povray=settings.povray), models=settings.models)
    out = prepare_output_dir(out_dir)
    stems = stems or unique_file_names(s.name for s in scenes)
    start = time.perf_counter()
    renders = sum(sum(len(study_series(model, settings)) for model in settings.models) * len(settings.spp_values)
                  * settings.timing_rounds
                  + (len(settings.povray_spp_values) if povray_series_wanted(p, settings) else 0)
                  for p in prepared_scenes)
    results = {"settings": {"quick": settings.quick, "lens": settings.lens, "samplers": list(settings.samplers),
                            "spp_values": list(settings.spp_values), "reference_spp": settings.reference_spp,
                            "threads": settings.threads or os.cpu_count(), "target_relative_rmse": 0.01,
                            "timing_repeats": settings.timing_rounds,
                            "scheduler": cluster.address if cluster else None},
               "scenes": {}, "findings": []}
    with progress_bar(renders, description="cost study", unit="render", enabled=progress) as bar:
        for scene, prepared in zip(scenes, prepared_scenes):
            study = study_scene(prepared, settings, progress=bar, cluster=cluster)
            study["plot"] = plot_error_vs_time(prepared.name, study, out / f"{stems[scene.name]}.cost.png")
            results["scenes"][prepared.name] = study
            results["findings"] += findings(prepared.name, study)
    results["total_seconds"] = time.perf_counter() - start
    results["provenance"] = {"created": datetime.datetime.now(datetime.timezone.utc).isoformat(timespec="seconds"),
                             "lenscompare": __version__, "machine": platform.machine(), "cpu_count": os.cpu_count()}
    with atomic_output(out / "results.json") as tmp:
        tmp.write_text(json.dumps(results, indent=2))
    with atomic_output(out / "index.html", final=final) as tmp:
        tmp.write_text(_page(results), encoding="utf-8")
    return results


def time_table_rows(results: dict):
    """(scene, model, sampler-or-POV-Ray, seconds to 1 %, extrapolated) rows."""
    for name, study in results["scenes"].items():
        for model, series in study["models"].items():
            for sampler, s in series.items():
                t = s["seconds_to_1_percent"]
                yield name, model, sampler, t["seconds"], t["extrapolated"]
        composite = study.get("composite")
        if composite and "seconds_to_1_percent" in composite:
            t = composite["seconds_to_1_percent"]
            yield name, f"composite ({'+'.join(composite['effects'])})", "jittered", t["seconds"], t["extrapolated"]
        pov = study.get("povray")
        if pov and "seconds_to_1_percent" in pov:
            yield name, "thin", "POV-Ray focal blur", pov["seconds_to_1_percent"]["seconds"], \
                pov["seconds_to_1_percent"]["extrapolated"]


def _composite_row(name: str, composite: dict) -> str:
    """One table row: the composite's parts with their times, and its error against the lens system."""
    if "error" in composite:
        return (f"<tr><td>{html.escape(name)}</td><td colspan='4'>no composite: "
                f"{html.escape(composite['error'])}</td></tr>")
    parts = composite["part_seconds"]
    times = ", ".join(f"{p} {parts[p]:.3g}" for p in composite["effects"])
    return (f"<tr><td>{html.escape(name)}</td><td>{html.escape(' + '.join(composite['effects']))}</td>"
            f"<td>{html.escape(times)} (at {parts['spp']} spp)</td><td>{composite['maps_seconds']:.3g}</td>"
            f"<td>{100 * composite['error_vs_lens']['relative_rmse']:.2f} %</td></tr>")


def _page(results: dict) -> str:
    rows = "".join(f"<tr><td>{html.escape(s)}</td><td>{html.escape(m)}</td><td>{html.escape(k)}</td>"
                   f"<td>{'–' if t is None else f'{t:.3g}'}{' (extrapolated)' if x and t else ''}</td></tr>"
                   for s, m, k, t, x in time_table_rows(results))
    plots = "".join(f"<h3>{html.escape(n)}</h3><img src='{html.escape(s['plot'])}' style='max-width:100%'>"
                    for n, s in results["scenes"].items())
    items = "".join(f"<li>{html.escape(f)}</li>" for f in results["findings"])
    composites = "".join(_composite_row(n, s["composite"]) for n, s in results["scenes"].items() if s.get("composite"))
    return (f"<!doctype html><html lang='en'><head><meta charset='utf-8'><title>lenscompare cost study</title>"
            f"<style>body{{font-family:system-ui,sans-serif;max-width:1200px;margin:2em auto}}"
            f"td,th{{border:1px solid #ddd;padding:.2em .6em}}table{{border-collapse:collapse}}</style></head><body>"
            f"<h1>What accuracy costs in time</h1><section id='findings'><h2>Findings</h2><ul>{items}</ul></section>"
            f"<section id='time-to-1-percent'><h2>Time to reach 1 % relative RMSE</h2><table><tr><th>scene</th>"
            f"<th>model</th><th>sampler</th><th>seconds</th></tr>{rows}</table></section>"
            f"<section id='composites'><h2>Composites: each part's time, and the error against the lens system</h2>"
            f"<table><tr><th>scene</th><th>parts</th><th>seconds per part</th><th>maps traced (s)</th>"
            f"<th>relative RMSE vs lens</th></tr>{composites}</table></section>"
            f"<section id='plots'><h2>Error against time</h2>{plots}</section></body></html>")
