"""Where a scene's ``camera.lens`` points: resolved once, when the scene is loaded.

A lens is named three ways, tried in this order:

1. a shipped name (``dgauss.50mm``, see :func:`shipped_lens_names`);
2. a path relative to the scene file's folder (``lens = "my.dat"`` beside it);
3. the path as given (absolute, or relative to the working directory).

Everything after loading holds the :class:`Prescription` itself, never the
string, so no later step can read a different file than the render did.
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError
from .prescription import Prescription, load_prescription, shipped_lens_names

__all__ = ["resolve_lens"]


def resolve_lens(name_or_path: str | os.PathLike, *, base_dir: str | os.PathLike | None = None,
                 source: str = "<scene>", key: str | None = "camera.lens") -> Prescription:
    """Load the prescription a scene names.

    Parameters
    ----------
    name_or_path : str or os.PathLike
        Shipped name or lens-file path.
    base_dir : path, optional
        Folder of the scene file; relative paths are tried there first.
    source, key : str
        The scene file and key, for the message when nothing is found.

    Raises
    ------
    InputError
        No shipped lens of that name and no readable file at either place, or
        the file breaks the lens format (the message names the file and line).
    """
    text = os.fspath(name_or_path)
    if text in shipped_lens_names():
        return load_prescription(text)
    path = Path(text)
    if base_dir is not None and not path.is_absolute() and (Path(base_dir) / path).is_file():
        return load_prescription(Path(base_dir) / path)
    if path.is_file():
        return load_prescription(path)
    where = f" (looked in {base_dir} and the working directory)" if base_dir is not None else ""
    raise InputError(source, f"no shipped lens and no lens file named {text!r}{where}; shipped lenses: "
                     + ", ".join(shipped_lens_names()), key=key)
