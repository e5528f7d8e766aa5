"""The reference scenes shipped inside the package (``*.toml`` beside this file).

The source tree's top-level ``reference_scenes/`` is a symbolic link to this
folder, so the same files serve a checkout and an installed wheel.  They are
read through :mod:`importlib.resources`; the package holds a compiled
extension, so it is always installed as plain files and the folder is a real
directory (scenes may refer to files beside them).

A shipped scene also has a short name, its file name without ``.toml``
(``showcase``): :func:`find_scene` turns a short name into the shipped file
when no file of that name exists.
"""

from __future__ import annotations

import os
from importlib import resources
from pathlib import Path

__all__ = ["scenes_dir", "shipped_scene_names", "shipped_scene", "find_scene"]


def scenes_dir() -> Path:
    """The folder that holds the shipped scene files."""
    root = resources.files(__name__)
    # A package on disk (always so here, see above) gives a Path.
    return root if isinstance(root, Path) else Path(__file__).resolve().parent


def shipped_scene_names() -> tuple[str, ...]:
    """Short names of the shipped scenes, sorted (``("blur_disks", ...)``)."""
    return tuple(sorted(p.stem for p in scenes_dir().glob("*.toml")))


def shipped_scene(name: str) -> Path | None:
    """The file of the shipped scene called ``name`` (no ``.toml``), or None."""
    return scenes_dir() / f"{name}.toml" if name in shipped_scene_names() else None


def find_scene(value: str | os.PathLike, base_dir: str | os.PathLike | None = None) -> Path:
    """The scene file that ``value`` means.

    A path (relative ones against ``base_dir``, default the working folder) when
    that file exists; otherwise, when ``value`` is a bare short name (no folder,
    no ``.toml``) of a shipped scene, that scene's file; otherwise the path as
    given, so that reading it reports the missing file.
    """
    text = os.fspath(value)
    path = Path(text)
    if not path.is_absolute() and base_dir is not None:
        path = Path(base_dir) / path
    if path.exists():
        return path
    shipped = shipped_scene(text) if Path(text).name == text and not text.endswith(".toml") else None
    return shipped or path
