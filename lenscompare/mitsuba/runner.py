"""Render a scene with Mitsuba 3, from the very files ``lenscompare export --to mitsuba`` writes.

The scene is exported (:func:`lenscompare.mitsuba.export.scene_to_mitsuba`),
written to a fresh temporary folder (XML and PLY meshes) and loaded from there
with ``mitsuba.load_file``, so what this renders is what a user gets from the
exported XML. Variant ``scalar_rgb`` by default; ``llvm_ad_rgb`` runs too where
Dr.Jit finds an LLVM library (``DRJIT_LIBLLVM_PATH``, e.g. Debian's
``libLLVM-19.so``).
"""

from __future__ import annotations

import os
import tempfile
import time
from pathlib import Path

import numpy as np

from .. import __version__
from ..atomic import atomic_output
from ..errors import ExternalError, InputError
from ..image import Image
from ..scene import Scene
from .export import MitsubaScene, scene_to_mitsuba, write_ply

__all__ = ["MITSUBA_VARIANTS", "render_mitsuba", "write_mitsuba", "mitsuba_version", "load_mitsuba"]

MITSUBA_VARIANTS = ("scalar_rgb", "llvm_ad_rgb")


def load_mitsuba(variant: str = "scalar_rgb"):
    """The ``mitsuba`` module set to ``variant``.

    Raises
    ------
    InputError
        A variant other than those in :data:`MITSUBA_VARIANTS`.
    ExternalError
        Mitsuba is not installed, or the variant cannot run on this machine
        (for ``llvm_ad_rgb``: no LLVM library found).
    """
    if variant not in MITSUBA_VARIANTS:
        raise InputError("--variant", f"expected one of {', '.join(MITSUBA_VARIANTS)}, got {variant!r}")
    try:
        import mitsuba  # heavy (Dr.Jit, ~0.3 s): only the Mitsuba commands pay for it
    except ImportError as error:
        raise ExternalError(f"Mitsuba 3 is not installed ({error}); pip install mitsuba (make install does)") \
            from None
    try:
        mitsuba.set_variant(variant)
    except (ImportError, AttributeError, RuntimeError) as error:
        hint = " (set DRJIT_LIBLLVM_PATH to an LLVM library, e.g. Debian's libLLVM-19.so)" if "llvm" in variant \
            else ""
        raise ExternalError(f"Mitsuba cannot run variant {variant!r}: {error}{hint}") from None
    return mitsuba


def mitsuba_version() -> str:
    """Mitsuba's version (e.g. "3.9.1"), or raise ExternalError when it is missing."""
    return load_mitsuba().__version__


def write_mitsuba(exported: MitsubaScene, path: str | os.PathLike) -> list[Path]:
    """Write the XML to ``path`` and its PLY meshes beside it (the names it uses); return every file written.

    The meshes go first and the XML last, each atomically, so a failure leaves
    no XML that names a missing mesh.
    """
    path = Path(path)
    written = []
    for name, triangles in exported.meshes.items():
        target = path.parent / name
        target.parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(target, option="-o") as tmp:
            write_ply(tmp, triangles)
        written.append(target)
    with atomic_output(path, option="-o") as tmp:
        Path(tmp).write_text(exported.xml, encoding="utf-8")
    written.append(path)
    return written


def render_mitsuba(scene: Scene, *, model: str | None = None, spp: int | None = None, seed: int | None = None,
                   variant: str = "scalar_rgb", sampler: str = "independent") -> Image:
    """Render ``scene`` with Mitsuba 3 through the pinhole or the thin lens.

    Parameters
    ----------
    scene : Scene
        A loaded scene.
    model : {'pinhole', 'thin'}, optional
        Camera model; default the scene's.
    spp, seed : int, optional
        Samples per pixel and sampler seed (default the scene's ``[render]``).
    variant : {'scalar_rgb', 'llvm_ad_rgb'}
        Mitsuba variant.
    sampler : str
        Mitsuba's sampler plugin (:data:`~lenscompare.mitsuba.export.MITSUBA_SAMPLERS`;
        ``stratified``, the native ``jittered``, needs a square ``spp``).

    Returns
    -------
    Image
        Linear radiance, float32, row 0 at the top, carrying the camera value
        (``camera_for(scene, model)``). Metadata: scene, model, spp, seed,
        seconds (the render), wall_seconds (export, load and render),
        samples_per_second, resolution, camera, renderer ("Mitsuba 3.x.y
        variant"), variant.

    Raises
    ------
    InputError
        A model Mitsuba has no sensor for, a falloff or a checker it cannot
        draw (see the export), a bad option.
    ExternalError
        Mitsuba is missing, cannot run the variant, or fails to load or
        render the scene.
    """
    start = time.perf_counter()
    exported = scene_to_mitsuba(scene, model=model, spp=spp, seed=seed, sampler=sampler)
    mi = load_mitsuba(variant)
    camera = exported.camera
    width, height = camera.film.resolution
    spp = scene.render.spp if spp is None else int(spp)
    with tempfile.TemporaryDirectory(prefix="lenscompare-mitsuba-") as folder:
        xml_path = Path(folder) / "scene.xml"
        write_mitsuba(exported, xml_path)
        try:
            loaded = mi.load_file(str(xml_path))
            render_start = time.perf_counter()
            pixels = np.array(mi.render(loaded), dtype=np.float32)
            seconds = time.perf_counter() - render_start
        except Exception as error:  # Mitsuba raises plain RuntimeErrors for everything
            raise ExternalError(f"Mitsuba failed to render {scene.source}: {error}") from None
    if pixels.shape != (height, width, 3):
        raise ExternalError(f"Mitsuba returned an image of shape {pixels.shape}, expected {(height, width, 3)}")
    metadata = {
        "scene": scene.name,
        "model": exported.model,
        "spp": spp,
        "seed": scene.render.seed if seed is None else int(seed),
        "seconds": seconds,
        "wall_seconds": time.perf_counter() - start,
        "samples_per_second": width * height * spp / seconds if seconds > 0 else float("inf"),
        "resolution": [width, height],
        "camera": camera.to_json(),
        "renderer": f"Mitsuba {mi.__version__} {variant}",
        "variant": variant,
        "lenscompare_version": __version__,
    }
    return Image(pixels, metadata, camera=camera)
