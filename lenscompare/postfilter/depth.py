"""The depth buffer of a scene's pinhole camera, traced by Embree."""

from __future__ import annotations

import os

import numpy as np

from .. import _native
from ..cameras import PinholeCamera
from ..native_scene import build_native_scene
from ..scene import Scene

__all__ = ["depth_buffer_m"]


def depth_buffer_m(scene: Scene, camera: PinholeCamera, *, threads: int | None = None,
                   native_scene: "_native.Scene | None" = None) -> np.ndarray:
    """Depth along the view axis (m) of the first surface behind each pixel.

    Parameters
    ----------
    scene : Scene
        The scene (its Embree scene is built unless ``native_scene`` is given).
    camera : PinholeCamera
        Its pinhole (:func:`lenscompare.cameras.camera_for` with ``"pinhole"``),
        at any resolution.
    threads : int, optional
        Worker threads (default all cores); the buffer does not depend on it.

    Returns
    -------
    ndarray, float32, (H, W)
        Depth from ``camera.frame.origin`` along the view axis, m, of the
        nearest surface the pixel sees; ``inf`` where it sees nothing.

    Notes
    -----
    One ray through each pixel centre; where the depth jumps (by more than
    5 %) to one of the 8 neighbours, a silhouette, the nearest hit of an 8 x 8
    grid of rays over the pixel. Not a mean over the film samples of the
    colour pass: a mean would invent, at every silhouette, a depth between
    the two surfaces that neither has (and a blur that belongs to neither).
    Not the centre alone either: a pixel half covered by a bright object
    holds half its light, which must spread with that object's blur (a
    point source's rim pixels would otherwise spread with the background's
    and widen its disk by tens of percent). The rest of such a pixel's colour
    then spreads with the nearer blur: part of the edge error :mod:`.edges`
    measures. An object smaller than a pixel that no pixel centre hits keeps
    the depth behind it (a limitation: its light spreads with that blur).
    """
    depth = np.empty((camera.film.height_px, camera.film.width_px), dtype=np.float32)
    threads = min(int(threads or 0), os.cpu_count() or 1)
    _native.render_depth(native_scene or build_native_scene(scene), camera.native(), threads, depth)
    return depth
