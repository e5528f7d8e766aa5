"""Native renders: a scene, a camera model, settings in; an :class:`Image` out.

The image is rendered in bands of rows so that a progress bar can advance;
every pixel owns its random stream, so bands, tiles and thread counts do not
change a single bit of the result.
"""

from __future__ import annotations

import os
import platform
import time

import numpy as np

from . import __version__, _native
from .cameras import native_camera
from .errors import InputError
from .image import Image
from .native_scene import build_native_scene
from .progress import progress_bar
from .scene import MODELS, SAMPLERS, Scene

__all__ = ["render", "SAMPLER_CODES"]

SAMPLER_CODES = {"random": _native.SAMPLER_RANDOM, "jittered": _native.SAMPLER_JITTERED,
                 "regular": _native.SAMPLER_REGULAR, "poisson": _native.SAMPLER_POISSON,
                 "sobol": _native.SAMPLER_SOBOL}

# Rows per native call: enough samples (~2 M) that the worker threads all join
# in, few enough that the progress bar moves.
_BAND_SAMPLES = 2_000_000


def render(scene: Scene, *, model: str | None = None, spp: int | None = None, sampler: str | None = None,
           seed: int | None = None, threads: int | None = None, progress: bool | None = None) -> Image:
    """Render ``scene`` with the native tracer.

    Parameters
    ----------
    scene : Scene
        A loaded scene (:func:`lenscompare.scene.load_scene`).
    model : {'pinhole', 'thin', 'thick', 'lens', 'auto'}, optional
        Camera model; default the scene's ``camera.model``. ``'auto'`` asks
        :func:`lenscompare.plan.plan_scene` for the cheapest model within the
        default tolerances and records the plan in the metadata.
    spp, sampler, seed : optional
        Override the scene's ``[render]`` settings.
    threads : int, optional
        Worker threads; default all cores. The image does not depend on it.
    progress : bool, optional
        Force the progress bar on or off (default: on for a terminal only).

    Returns
    -------
    Image
        Linear radiance, with metadata: model, spp, sampler, seed, seconds,
        samples_per_second, threads, and the camera's derived quantities.
    """
    model = model or scene.camera.model
    plan = None
    if model == "auto":
        # Simulate only what the scene calls for (default tolerances; no timing renders).
        from .plan import plan_scene

        plan = plan_scene(scene, measure_costs=False)
        model = plan.model
    if model not in MODELS:
        raise InputError("--model", f"expected one of {', '.join(MODELS)}, got {model!r}")
    scene = scene.with_render(spp=spp, sampler=sampler, seed=seed)
    settings = scene.render
    if settings.spp < 1:
        raise InputError("--spp", f"expected a positive integer, got {settings.spp}")
    if settings.sampler not in SAMPLERS:
        raise InputError("--sampler", f"expected one of {', '.join(SAMPLERS)}, got {settings.sampler!r}")
    if settings.seed < 0:
        raise InputError("--seed", f"expected an integer >= 0, got {settings.seed}")
    threads = 0 if threads is None else int(threads)
    if threads < 0:
        raise InputError("--threads", f"expected a positive integer, got {threads}")

    camera, camera_info = native_camera(scene, model)
    native_scene = build_native_scene(scene)
    height, width = scene.camera.height_px, scene.camera.width_px
    pixels = np.zeros((height, width, 3), dtype=np.float32)

    rays_passed = 0
    start = time.perf_counter()
    band_rows = max(16, -(-_BAND_SAMPLES // (width * settings.spp)))
    with progress_bar(height, description=f"{model} {settings.spp} spp", enabled=progress) as bar:
        for row in range(0, height, band_rows):
            row_end = min(row + band_rows, height)
            _, passed = _native.render_rows(native_scene, camera, settings.spp, SAMPLER_CODES[settings.sampler],
                                            settings.seed, threads, row, row_end, pixels)
            rays_passed += passed
            bar.update(row_end - row)
    seconds = time.perf_counter() - start

    samples = width * height * settings.spp
    metadata = {
        "scene": scene.name,
        "model": model,
        "spp": settings.spp,
        "sampler": settings.sampler,
        "disk_mapping": settings.disk_mapping,
        "seed": settings.seed,
        "threads": threads or os.cpu_count(),
        "seconds": seconds,
        "samples_per_second": samples / seconds if seconds > 0 else float("inf"),
        "ray_pass_fraction": rays_passed / samples,
        "resolution": [width, height],
        "camera": camera_info,
        "renderer": f"lenscompare {__version__} native (Embree 3)",
        "machine": platform.machine(),
    }
    if plan is not None:
        metadata["plan"] = plan.to_json()
    return Image(pixels, metadata)
