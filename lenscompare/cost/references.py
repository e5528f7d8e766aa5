"""Converged reference renders, cached by a content hash of everything that
determines them (scene, model, samples, seed, lens file, and the tracer itself:
the compiled native module and the Python sources that set up cameras and
renders), so repeated studies render each reference once and a changed tracer
renders them again."""

from __future__ import annotations

import dataclasses
import functools
import hashlib
import json
import os
from pathlib import Path

from .. import _native
from ..image import Image, read_exr, write_exr
from ..render import render
from ..scene import Scene

__all__ = ["default_cache_dir", "reference_key", "converged_reference", "tracer_fingerprint", "fingerprint_files"]


def default_cache_dir() -> Path:
    """``$LENSCOMPARE_CACHE``, else ``$XDG_CACHE_HOME/lenscompare``, else ``~/.cache/lenscompare``."""
    if os.environ.get("LENSCOMPARE_CACHE"):
        return Path(os.environ["LENSCOMPARE_CACHE"])
    base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache")
    return base / "lenscompare"


# Subpackages that only read or present finished images: their sources do not
# enter the fingerprint (anything else in the package, new modules included, does).
_NOT_RENDERING = frozenset({"report", "cost", "figures", "commands", "checks", "povray", "metrics"})


def fingerprint_files(native_module: Path, package_dir: Path) -> str:
    """Hex SHA-256 of the native module's bytes and of every ``.py`` file of
    the package outside :data:`_NOT_RENDERING`, each with its relative path."""
    digest = hashlib.sha256()
    digest.update(b"native\0" + Path(native_module).read_bytes())
    package_dir = Path(package_dir)
    for path in sorted(package_dir.rglob("*.py")):
        relative = path.relative_to(package_dir)
        if relative.parts[0] in _NOT_RENDERING or "__pycache__" in relative.parts:
            continue
        digest.update(b"\0" + relative.as_posix().encode() + b"\0" + path.read_bytes())
    return digest.hexdigest()


@functools.cache
def tracer_fingerprint() -> str:
    """Fingerprint of the tracer in this process (computed once): the compiled
    ``lenscompare._native`` and the Python that builds cameras and renders.
    ``__version__`` is no fingerprint: it stays put across tracer changes."""
    return fingerprint_files(Path(_native.__file__), Path(__file__).resolve().parent.parent)


def reference_key(scene: Scene, model: str, *, spp: int, sampler: str, seed: int) -> str:
    """Hex SHA-256 naming a reference render."""
    content = dataclasses.asdict(scene)
    for volatile in ("source", "base_dir", "description", "name"):
        content.pop(volatile, None)
    lens_hash = scene.camera.lens.sha256 if scene.camera.lens is not None else None
    payload = {"scene": content, "model": model, "spp": spp, "sampler": sampler, "seed": seed,
               "lens_sha256": lens_hash, "tracer": tracer_fingerprint()}
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
