"""Camera models on the Python side: one frozen value per model, built once
from a scene, and the native camera each value builds. One file per model.

``camera_for(scene, model)`` is the one entry point: the renderer, the POV-Ray
exporter, the planner and the measurements all read the value it returns.
"""

from __future__ import annotations

from ..errors import InputError
from .base import CameraModel, check_camera_numbers
from .composite import (COLOR_PARTS, COMPOSITE_EFFECTS, POST_FILTER_EFFECTS, CompositeCamera, check_composite_effects,
                        check_spectral_parts)
from .frame import CameraFrame, Film
from .lens import LensSystemCamera
from .pinhole import PinholeCamera
from .thick import ThickLensCamera
from .thin import ThinLensCamera

__all__ = ["camera_for", "CameraModel", "CameraFrame", "Film", "PinholeCamera", "ThinLensCamera",
           "ThickLensCamera", "LensSystemCamera", "CompositeCamera", "COMPOSITE_EFFECTS", "COLOR_PARTS",
           "POST_FILTER_EFFECTS", "check_composite_effects", "check_spectral_parts", "CAMERA_TYPES"]

CAMERA_TYPES = {cls.model: cls for cls in (PinholeCamera, ThinLensCamera, ThickLensCamera, LensSystemCamera,
                                            CompositeCamera)}


def camera_for(scene, model: str | None = None, *, effects=None) -> CameraModel:
    """The camera value of ``scene`` seen through ``model`` (default: the scene's);
    ``postfilter`` gives the thin lens it imitates.

    ``effects`` (model ``composite`` only): the effects to simulate, as
    ``--effects`` gave them (default: the scene's ``[render] effects``).

    Raises
    ------
    InputError
        Unknown model, or the scene lacks a key the model needs, or the lens
        cannot do what the scene asks (focus, f-number).
    """
    model = model or scene.camera.model
    if model == "postfilter":  # the image-based depth of field (lenscompare.postfilter) imitates the thin lens
        model = "thin"
    try:
        kind = CAMERA_TYPES[model]
    except KeyError:
        raise InputError("--model", f"expected one of {', '.join(CAMERA_TYPES)}, got {model!r}") from None
    # Nothing non-finite may reach the native tracer (or POV-Ray).
    camera = kind.from_scene(scene, effects=effects) if kind is CompositeCamera else kind.from_scene(scene)
    return check_camera_numbers(camera, scene)
