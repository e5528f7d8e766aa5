"""POV-Ray as an independent reference: the same scene, rendered by POV-Ray 3.7.

:func:`scene_to_pov` writes the ``.pov`` text for a scene through the pinhole
or thin-lens camera; :func:`render_povray` runs the ``povray`` binary on it and
returns an :class:`~lenscompare.image.Image` like a native render's.
"""

from .export import POVRAY_MODELS, PovCamera, pov_camera, scene_to_pov, unsupported
from .runner import MAX_POVRAY_SPP, pinhole_antialias_depth, povray_version, render_povray

__all__ = ["POVRAY_MODELS", "PovCamera", "pov_camera", "scene_to_pov", "render_povray", "povray_version",
           "pinhole_antialias_depth", "MAX_POVRAY_SPP", "unsupported"]
