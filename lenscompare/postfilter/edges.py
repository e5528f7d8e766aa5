"""Where the postfilter is wrong, and whether the planner may use it.

A single pinhole image holds one surface per pixel. At an occlusion edge a
real lens sees round the nearer object (part of its aperture looks past
it), so the farther surface hidden in the pinhole image shows through the
nearer one's blurred rim; the postfilter has nothing to show there, and
its error grows with the difference in blur across the edge.

Edge band (for measurement): occlusion-edge pixels are those whose depth
differs from a 4-neighbour's by more than ``DEPTH_JUMP`` (relative) and
whose blur diameter differs by more than ``EDGE_JUMP_PX``; the band is every
pixel within ``band_px`` of one.

Predicate (for the planner): the *predicted edge error* is the largest
difference in blur diameter (eq. 5, px of the scene's film) across any
occlusion edge of a cheap low-resolution depth buffer (and between each
sphere and the depth behind it, for spheres too small to be hit). The postfilter's
artefacts reach about half that difference from the edge, so the planner may
choose it only when the defocus is needed and the predicted edge error is
within its own px tolerance: an artefact then no wider than an effect the
planner already leaves out.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..cameras import CameraModel, camera_for
from ..scene import Scene, Sphere
from .blur import signed_coc_px
from .depth import depth_buffer_m

__all__ = ["DEPTH_JUMP", "EDGE_JUMP_PX", "BAND_PX", "EdgeError", "occlusion_edges", "edge_band",
           "postfilter_edge_error", "edge_band_error", "postfilter_suffices", "PREDICTOR_PIXELS"]

DEPTH_JUMP = 0.05       # relative depth step between neighbours that counts as a discontinuity
EDGE_JUMP_PX = 1.0      # and the blur difference across it (px) that makes it matter
BAND_PX = 4             # the edge band's half width, px
PREDICTOR_PIXELS = 20_000  # the predictor's depth buffer: about this many pixels


def _neighbour_jumps(depth_m: np.ndarray, coc_px: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Per pixel, the largest relative depth step and the largest blur
    difference (px) to a 4-neighbour across a depth discontinuity."""
    depth = np.asarray(depth_m, dtype=float)
    coc = np.asarray(coc_px, dtype=float)
    worst_jump = np.zeros(depth.shape)
    worst_coc = np.zeros(depth.shape)
    for axis in (0, 1):
        a = [slice(None)] * 2
        b = [slice(None)] * 2
        a[axis], b[axis] = slice(1, None), slice(None, -1)
        za, zb = depth[tuple(a)], depth[tuple(b)]
        with np.errstate(invalid="ignore", divide="ignore"):
            # inf against finite: a discontinuity; inf against inf: none
            jump = np.where(np.isinf(za) & np.isinf(zb), 0.0,
                            np.abs(za - zb) / np.minimum(za, zb))
        jump = np.nan_to_num(jump, nan=0.0, posinf=math.inf)
        dc = np.where(jump > DEPTH_JUMP, np.abs(coc[tuple(a)] - coc[tuple(b)]), 0.0)
        for side in (a, b):
            worst_jump[tuple(side)] = np.maximum(worst_jump[tuple(side)], jump)
            worst_coc[tuple(side)] = np.maximum(worst_coc[tuple(side)], dc)
    return worst_jump, worst_coc


def occlusion_edges(depth_m: np.ndarray, coc_px: np.ndarray, *, jump_px: float = EDGE_JUMP_PX) -> np.ndarray:
    """Pixels on an occlusion edge whose blur differs by more than ``jump_px``
    across it (bool, the depth buffer's shape)."""
    _, coc_jump = _neighbour_jumps(depth_m, coc_px)
    return coc_jump > jump_px


def edge_band(depth_m: np.ndarray, coc_px: np.ndarray, *, band_px: float = BAND_PX,
              jump_px: float = EDGE_JUMP_PX) -> np.ndarray:
    """Pixels within ``band_px`` of an occlusion edge (:func:`occlusion_edges`)."""
    edges = occlusion_edges(depth_m, coc_px, jump_px=jump_px)
    if not edges.any():
        return edges
    return ndimage.distance_transform_edt(~edges) <= band_px


@dataclass(frozen=True)
class EdgeError:
    """The postfilter's predicted error at occlusion edges, for the planner.

    Attributes
    ----------
    max_coc_jump_px : float
        Largest blur-diameter difference across an occlusion edge, px of the
        scene's film (0: no occlusion edge).
    edge_fraction : float
        Share of the (low-resolution) frame on such edges (jump > 1 px).
    resolution : (int, int)
        The depth buffer the prediction was made from.
    """

    max_coc_jump_px: float
    edge_fraction: float
    resolution: tuple[int, int]

    def within(self, tolerance_px: float) -> bool:
        """Whether the postfilter's edge artefacts stay within ``tolerance_px``."""
        return self.max_coc_jump_px <= tolerance_px

    def to_json(self) -> dict:
        return {"max_coc_jump_px": self.max_coc_jump_px, "edge_fraction": self.edge_fraction,
                "resolution": list(self.resolution)}


def postfilter_edge_error(scene: Scene, *, camera: CameraModel | None = None, pixels: int = PREDICTOR_PIXELS,
                          threads: int | None = None) -> EdgeError:
    """Predict the postfilter's error at occlusion edges from a depth buffer
    of about ``pixels`` pixels (one ray each: milliseconds).

    Parameters
    ----------
    scene : Scene
        The scene, at its own resolution and camera.
    camera : CameraModel, optional
        The thin lens imitated (default ``camera_for(scene, "thin")``).
    pixels : int
        Size of the depth buffer traced; blur differences are measured in the
        scene's own pixels whatever it is.

    Returns
    -------
    EdgeError
        :meth:`EdgeError.within` is the planner's predicate.
    """
    camera = camera or camera_for(scene, "thin")
    w, h = scene.camera.resolution
    scale = max(1, int(math.sqrt(w * h / max(int(pixels), 1))))
    small = scene.with_camera(resolution=(max(1, w // scale), max(1, h // scale)))
    if small.camera.width_px * h != small.camera.height_px * w:  # keep square pixels
        small = scene
    depth = depth_buffer_m(small, camera_for(small, "pinhole"), threads=threads)
    coc = signed_coc_px(depth, camera)  # in the scene's own pixels
    _, coc_jump = _neighbour_jumps(depth, coc)
    worst = float(coc_jump.max()) if coc_jump.size else 0.0
    # Spheres smaller than a pixel may fall between the pixel centres: each
    # sphere's blur against the depth behind its centre's pixel, too.
    spheres = [o for o in scene.objects if isinstance(o, Sphere)]
    if spheres:
        xyz = camera.frame.camera_from_world([o.center for o in spheres])
        ahead = xyz[:, 2] > 0
        px = camera.project_px(xyz[ahead]) * (small.camera.width_px / w)
        inside = (px[:, 0] >= 0) & (px[:, 0] < small.camera.width_px) & (px[:, 1] >= 0) & (px[:, 1] < small.camera.height_px)
        if inside.any():
            z = xyz[ahead][inside, 2]
            behind = depth[px[inside, 1].astype(int), px[inside, 0].astype(int)].astype(float)
            with np.errstate(invalid="ignore", divide="ignore"):
                apart = np.isinf(behind) | (np.abs(behind - z) > DEPTH_JUMP * np.minimum(behind, z))
            jumps = np.abs(signed_coc_px(z, camera) - signed_coc_px(behind, camera))
            worst = max(worst, float(np.max(np.where(apart, jumps, 0.0))))
    return EdgeError(max_coc_jump_px=worst,
                     edge_fraction=float((coc_jump > EDGE_JUMP_PX).mean()) if coc_jump.size else 0.0,
                     resolution=small.camera.resolution)


def edge_band_error(image_true: np.ndarray, image_test: np.ndarray, band: np.ndarray) -> dict:
    """Relative RMSE of ``image_test`` against ``image_true`` in the edge band
    and elsewhere: the RMSE over a region's pixels and channels divided by
    ``image_true``'s mean there (:func:`lenscompare.metrics.relative_rmse`'s
    definition, per region).

    Returns
    -------
    dict
        ``band_relative_rmse``, ``elsewhere_relative_rmse`` (None for an
        empty region) and ``band_fraction`` (share of the frame in the band).
    """
    true, test = np.asarray(image_true, dtype=float), np.asarray(image_test, dtype=float)
    band = np.asarray(band, dtype=bool)

    def relative(mask: np.ndarray) -> float | None:
        if not mask.any():
            return None
        t, s = true[mask], test[mask]
        mean = t.mean()
        return float(np.sqrt(np.mean((s - t) ** 2)) / mean) if mean > 0 else None

    return {"band_relative_rmse": relative(band), "elsewhere_relative_rmse": relative(~band),
            "band_fraction": float(band.mean())}


def postfilter_suffices(scene: Scene, *, defocus_needed: bool, tolerance_px: float,
                        camera: CameraModel | None = None, threads: int | None = None) -> tuple[bool, EdgeError | None]:
    """The planner's predicate: the postfilter may stand in for the thin lens
    only when defocus is needed (else the pinhole is cheaper still) and its
    predicted edge error (:func:`postfilter_edge_error`) is within
    ``tolerance_px``. ``camera``: the thin lens the defocus was sized with. Returns the verdict and the prediction (None when
    defocus is not needed: nothing is traced)."""
    if not defocus_needed:
        return False, None
    error = postfilter_edge_error(scene, camera=camera, threads=threads)
    return error.within(tolerance_px), error
