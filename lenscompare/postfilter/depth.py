"""The depth buffer of a scene's pinhole camera, traced by Embree."""

from __future__ import annotations

import os

import numpy as np

from .. import _native
from ..cameras import PinholeCamera
from ..native_scene import build_native_scene
from ..scene import Scene, Sphere

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
    measures. Spheres under 2 px across, which may fall between the pixel
    centres, have the grid traced over the pixels round their image whatever
    the centres found (other objects that small keep the depth behind them).
    """
    depth = np.empty((camera.film.height_px, camera.film.width_px), dtype=np.float32)
    threads = min(int(threads or 0), os.cpu_count() or 1)
    _native.render_depth(native_scene or build_native_scene(scene), camera.native(), threads, depth,
                         _small_sphere_pixels(scene, camera))
    return depth


def _small_sphere_pixels(scene: Scene, camera: PinholeCamera) -> np.ndarray | None:
    """Pixels within 1 px of the image of a sphere under 2 px across (uint8 mask), or None."""
    spheres = [o for o in scene.objects if isinstance(o, Sphere)]
    if not spheres:
        return None
    xyz = camera.frame.camera_from_world([o.center for o in spheres])
    radius_px = np.array([o.radius for o in spheres]) * camera.image_scale_mm / np.maximum(xyz[:, 2], 1e-12) \
        / camera.pixel_pitch_mm
    small = (xyz[:, 2] > 0) & (radius_px < 1.0)
    if not small.any():
        return None
    h, w = camera.film.height_px, camera.film.width_px
    mask = np.zeros((h, w), dtype=np.uint8)
    for (x, y), r in zip(camera.project_px(xyz[small]), radius_px[small]):
        x0, x1 = int(np.floor(x - r - 1)), int(np.floor(x + r + 1))
        y0, y1 = int(np.floor(y - r - 1)), int(np.floor(y + r + 1))
        if x1 < 0 or y1 < 0 or x0 >= w or y0 >= h:
            continue
        mask[max(y0, 0):min(y1, h - 1) + 1, max(x0, 0):min(x1, w - 1) + 1] = 1
    return mask
