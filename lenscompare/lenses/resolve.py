"""Where a scene's ``camera.lens`` points: resolved once, when the scene is loaded.

A lens is named three ways, tried in this order:

1. a shipped name (``dgauss.50mm``, see :func:`shipped_lens_names`);
2. a path relative to the scene file's folder (``lens = "my.dat"`` beside it);
3. the path as given (absolute, or relative to the working directory).

Everything after loading holds the :class:`Prescription` itself, never the
string, so no later step can read a different file than the render did.

A scene's lens must form a real image of a distant object (positive focal
length, rear focal point behind the last vertex) with a focal length inside
:data:`~lenscompare.limits.MIN_FOCAL_LENGTH_MM` ...
:data:`~lenscompare.limits.MAX_FOCAL_LENGTH_MM`: a diverging or nearly
powerless lens is refused here, naming the scene's key, the lens and why,
before any model derives a negative or enormous focal length from it.
(``lens info`` reads any valid prescription, diverging ones too.)
"""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import InputError
from ..limits import MAX_FOCAL_LENGTH_MM, MIN_FOCAL_LENGTH_MM
from .paraxial import paraxial_data
from .prescription import Prescription, load_prescription, shipped_lens_names

__all__ = ["resolve_lens", "check_forms_real_image"]


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
        return check_forms_real_image(load_prescription(text), source=source, key=key)
    path = Path(text)
    if base_dir is not None and not path.is_absolute() and (Path(base_dir) / path).is_file():
        return check_forms_real_image(load_prescription(Path(base_dir) / path), source=source, key=key)
    if path.is_file():
        return check_forms_real_image(load_prescription(path), source=source, key=key)
    where = f" (looked in {base_dir} and the working directory)" if base_dir is not None else ""
    raise InputError(source, f"no shipped lens and no lens file named {text!r}{where}; shipped lenses: "
                     + ", ".join(shipped_lens_names()), key=key)


def check_forms_real_image(prescription: Prescription, *, source: str, key: str | None) -> Prescription:
    """``prescription``, after checking that a scene can use it (see the module notes).

    Raises
    ------
    InputError
        Naming ``source`` and ``key``, the lens and why it cannot image a scene.
    """
    lens = f"lens {prescription.name} ({prescription.source})"
    try:
        data = paraxial_data(prescription)
    except InputError as error:  # afocal
        raise InputError(source, f"{lens}: {error.problem}", key=key) from None
    efl = data.effective_focal_length_mm
    if not efl > 0:
        raise InputError(source, f"{lens} has a negative focal length ({efl:.4g} mm): it diverges light and forms "
                         "no real image on film", key=key)
    if not data.back_focal_length_mm > 0:
        raise InputError(source, f"{lens} has its rear focal point {-data.back_focal_length_mm:.4g} mm inside the "
                         "lens: no film position can be in focus", key=key)
    if not MIN_FOCAL_LENGTH_MM <= efl <= MAX_FOCAL_LENGTH_MM:
        raise InputError(source, f"{lens} has a focal length of {efl:.4g} mm, outside the limits "
                         f"{MIN_FOCAL_LENGTH_MM:g} ... {MAX_FOCAL_LENGTH_MM:g} mm (nearly no optical power)"
                         if efl > MAX_FOCAL_LENGTH_MM else
                         f"{lens} has a focal length of {efl:.4g} mm, outside the limits "
                         f"{MIN_FOCAL_LENGTH_MM:g} ... {MAX_FOCAL_LENGTH_MM:g} mm", key=key)
    return prescription
