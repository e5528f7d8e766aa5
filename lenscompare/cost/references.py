"""Converged reference renders, cached by a content hash of everything that
determines them (scene, model, samples, seed, lens file, renderer version), so
repeated studies render each reference once."""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from pathlib import Path

from .. import __version__
from ..image import Image, read_exr, write_exr
from ..render import render
from ..scene import Scene

__all__ = ["default_cache_dir", "reference_key", "converged_reference"]


def default_cache_dir() -> Path:
    """``$LENSCOMPARE_CACHE``, else ``$XDG_CACHE_HOME/lenscompare``, else ``~/.cache/lenscompare``."""
    if os.environ.get("LENSCOMPARE_CACHE"):
        return Path(os.environ["LENSCOMPARE_CACHE"])
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "lenscompare"


def reference_key(scene: Scene, model: str, *, spp: int, sampler: str, seed: int) -> str:
    """Hex SHA-256 naming a reference render."""
    content = dataclasses.asdict(scene)
    for volatile in ("source", "base_dir", "description", "name"):
        content.pop(volatile, None)
    lens_hash = scene.camera.lens.sha256 if scene.camera.lens is not None else None
    payload = {"scene": content, "model": model, "spp": spp, "sampler": sampler, "seed": seed,
               "lens_sha256": lens_hash, "lenscompare": __version__}
    return hashlib.sha256(json.dumps(payload, sort_keys=True, default=str).encode()).hexdigest()


def converged_reference(scene: Scene, model: str, *, spp: int, sampler: str = "jittered", seed: int = 1_000_003,
                        cache_dir: Path | None = None, threads: int | None = None) -> tuple[Image, bool]:
    """The reference image and whether it came from the cache.

    The seed differs from the study's renders so that reference noise is
    independent of the noise being measured.
    """
    cache_dir = Path(cache_dir or default_cache_dir())
    path = cache_dir / "references" / f"{reference_key(scene, model, spp=spp, sampler=sampler, seed=seed)}.exr"
    if path.is_file():
        try:
            return read_exr(path), True
        except Exception:  # a damaged cache entry is rendered again
            pass
    image = render(scene, model=model, spp=spp, sampler=sampler, seed=seed, threads=threads, progress=False)
    path.parent.mkdir(parents=True, exist_ok=True)
    write_exr(path, image)
    return image, False
