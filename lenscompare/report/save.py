"""The report's files for each run: the EXR and an sRGB PNG preview."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..experiment import Run
from ..image import Image, write_exr, write_png_preview

__all__ = ["save_runs", "preview_exposure"]


def save_runs(runs: list[Run], out_dir: Path, *, stem: str) -> list[dict]:
    """Write ``renders/<stem>.<model>[.povray|.mitsuba].exr`` and ``.png`` for every run;
    return each run's summary (model, renderer, spp, seconds, files, camera).

    ``stem`` is the scene's file name (:func:`lenscompare.atomic.safe_file_name`
    of its ``name``): a scene name never becomes a path, and every file is
    refused unless it lies inside ``out_dir``.

    All runs of a scene share one preview exposure (the native thin lens's, or
    the first run's), so the previews compare.
    """
    if not runs:
        return []
    exposure_from = next((r for r in runs if r.label == "thin"), runs[0])
    exposure = preview_exposure(exposure_from.image)
    summaries = []
    for run in runs:
        name = f"{stem}.{run.model}" + ("" if run.renderer == "native" else f".{run.renderer}")
        exr, png = out_dir / "renders" / f"{name}.exr", out_dir / "renders" / f"{name}.png"
        write_exr(exr, run.image, within=out_dir)
        write_png_preview(png, run.image, exposure=exposure, within=out_dir)
        m = run.image.metadata
        summaries.append({"scene": run.scene.name, "model": run.model, "renderer": run.renderer, "spp": m.get("spp"),
                          "seconds": m.get("seconds"), "samples_per_second": m.get("samples_per_second"),
                          "exr": str(exr.relative_to(out_dir)), "png": str(png.relative_to(out_dir)),
                          "camera": m.get("camera", {})})
    return summaries


def preview_exposure(image: Image) -> float:
    """One exposure per scene for the PNG previews: 1 unless the scene is dark
    (point sources spread into blur disks), then bright values map near white."""
    bright = float(np.percentile(image.pixels.max(axis=-1), 99.9))
    return 1.0 if bright >= 0.5 else float(min(64.0, 0.7 / max(bright, 1e-6)))
