"""Camera models on the Python side: validate a scene's camera for one model
and build the matching native camera. One file per model.

``native_camera(scene, model)`` is the only entry point the renderer uses.
"""

from __future__ import annotations

from ..errors import InputError
from . import lens, pinhole, thick, thin

__all__ = ["native_camera", "NATIVE_MODELS"]

_BUILDERS = {"pinhole": pinhole.build, "thin": thin.build, "thick": thick.build, "lens": lens.build}
NATIVE_MODELS = tuple(_BUILDERS)


def native_camera(scene, model: str):
    """Native camera for ``scene`` seen through ``model``.

    Returns
    -------
    camera : lenscompare._native camera object
    description : dict
        The derived quantities (film distance, aperture, ...) for metadata.
    """
    try:
        build = _BUILDERS[model]
    except KeyError:
        raise InputError("--model", f"the {model!r} model is not available yet "
                         f"(available: {', '.join(NATIVE_MODELS)})") from None
    return build(scene)
