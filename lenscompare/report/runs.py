"""The renders a report needs: every applicable model natively, POV-Ray for
the pinhole and the thin lens, each written as EXR plus a PNG preview."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..errors import ExternalError
from ..image import Image, write_exr, write_png_preview
from ..lenses import paraxial_data
from ..render import render
from ..scene import MODELS, Scene

__all__ = ["RenderRun", "ReportSettings", "prepare_scene", "render_scene"]

POVRAY_MODELS = ("pinhole", "thin")


@dataclass(frozen=True)
class ReportSettings:
    """How much work the report does (``quick`` for CI)."""

    lens: str = "dgauss.50mm"
    quick: bool = False
    threads: int | None = None
    povray: bool = True

    def resolution(self, scene: Scene) -> tuple[int, int]:
        w, h = scene.camera.resolution
        return (w // 2, h // 2) if self.quick and w % 2 == 0 and h % 2 == 0 else (w, h)

    def spp(self, scene: Scene) -> int:
        return max(4, scene.render.spp // 4) if self.quick else scene.render.spp


@dataclass
class RenderRun:
    scene: str
    model: str
    renderer: str  # "native" or "povray"
    image: Image
    exr: str
    png: str

    @property
    def label(self) -> str:
        return f"{self.model} (POV-Ray)" if self.renderer == "povray" else self.model

    @property
    def seconds(self) -> float:
        return float(self.image.metadata.get("seconds", math.nan))

    def summary(self) -> dict:
        m = self.image.metadata
        return {"scene": self.scene, "model": self.model, "renderer": self.renderer, "spp": m.get("spp"),
                "seconds": m.get("seconds"), "samples_per_second": m.get("samples_per_second"),
                "exr": self.exr, "png": self.png, "camera": m.get("camera", {})}


def prepare_scene(scene: Scene, settings: ReportSettings) -> tuple[Scene, list[str]]:
    """The scene as the report renders it: through the report's lens (unless the
    scene names one), at an f-number the real lens can reach, at the report's
    resolution. Returns the scene and notes on what was changed."""
    notes = []
    camera = scene.camera
    changes = {"resolution": settings.resolution(scene)}
    lens = camera.lens or settings.lens
    if camera.lens is None:
        changes["lens"] = lens
        notes.append(f"all models share the lens {lens} (thin and thick use its focal length)")
    prepared = scene.with_camera(**changes)
    from ..cameras.common import scene_prescription

    own_f_number = paraxial_data(scene_prescription(prepared, "lens")).f_number
    if camera.f_number is None or camera.f_number < own_f_number:
        f_number = math.ceil(own_f_number * 1000) / 1000
        notes.append(f"f-number set to f/{f_number:g}, the widest {lens} allows"
                     + (f" (the scene asks for f/{camera.f_number:g})" if camera.f_number else ""))
        prepared = prepared.with_camera(f_number=f_number)
    return dataclasses.replace(prepared, render=dataclasses.replace(prepared.render, spp=settings.spp(scene))), notes


def render_scene(scene: Scene, out_dir: Path, settings: ReportSettings, *, progress=None) -> tuple[list[RenderRun], list[str]]:
    """Render ``scene`` with every model (and POV-Ray); write EXR and PNG files."""
    runs, notes = [], []
    images = {}
    for model in MODELS:
        images[model] = render(scene, model=model, threads=settings.threads, progress=False)
        if progress:
            progress.update(1)
    exposure = preview_exposure(images["thin"])
    for model, image in images.items():
        runs.append(_save(scene, model, "native", image, out_dir, exposure))
    if settings.povray:
        from ..povray import render_povray

        for model in POVRAY_MODELS:
            try:
                image = render_povray(scene, model=model, threads=settings.threads)
            except ExternalError as error:
                notes.append(f"POV-Ray {model} render of {scene.name} failed: {error}")
                continue
            finally:
                if progress:
                    progress.update(1)
            # Same camera as the native render of that model (for the measurements).
            image.metadata["povray_camera"] = image.metadata.get("camera")
            image.metadata["camera"] = images[model].metadata.get("camera", {})
            runs.append(_save(scene, model, "povray", image, out_dir, exposure))
    return runs, notes


def preview_exposure(image: Image) -> float:
    """One exposure per scene for the PNG previews: 1 unless the scene is dark
    (point sources spread into blur disks), then bright values map near white."""
    bright = float(np.percentile(image.pixels.max(axis=-1), 99.9))
    return 1.0 if bright >= 0.5 else float(min(64.0, 0.7 / max(bright, 1e-6)))


def _save(scene: Scene, model: str, renderer: str, image: Image, out_dir: Path, exposure: float) -> RenderRun:
    stem = f"{scene.name}.{model}" + (".povray" if renderer == "povray" else "")
    exr, png = out_dir / "renders" / f"{stem}.exr", out_dir / "renders" / f"{stem}.png"
    write_exr(exr, image)
    # All models of a scene share one exposure, so the previews compare.
    write_png_preview(png, image, exposure=exposure)
    return RenderRun(scene.name, model, renderer, image, str(exr.relative_to(out_dir)), str(png.relative_to(out_dir)))
