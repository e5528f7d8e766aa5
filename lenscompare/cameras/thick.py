"""Thick lens (paper section 2.3): principal planes H and H' with a gap.

======================  =====  ====  =========================================
Parameter               Type   Unit  Meaning
======================  =====  ====  =========================================
lens                    str    -     derive f and the gap H -> H' from it, or:
focal_length_mm         float  mm    focal length f
principal_plane_gap_mm  float  mm    signed distance from H to H'
f_number                float  -     N; aperture diameter f / N at H
focus_distance          float  m     plane of sharp focus, from H
film_mm                 pair   mm    film width and height
======================  =====  ====  =========================================

``camera.position`` is H. With focus measured from H, the rays in front of
the lens are the thin lens's (see native/src/cameras/thick_lens.h); the gap
places the film d' behind H', so the lens is ``gap`` longer than a thin one.
"""

from __future__ import annotations

from .. import _native
from . import thin
from .common import require, scene_prescription

__all__ = ["build", "principal_plane_gap_mm"]


def principal_plane_gap_mm(scene) -> float:
    """H -> H' in mm, from ``camera.lens`` when given, else the scene key."""
    if scene.camera.lens is not None:
        from ..lenses import paraxial_data

        data = paraxial_data(scene_prescription(scene, "thick"))
        return data.rear_principal_plane_mm - data.front_principal_plane_mm
    return require(scene, scene.camera.principal_plane_gap_mm, "principal_plane_gap_mm", "thick")


def build(scene):
    gap_mm = principal_plane_gap_mm(scene)
    at_h, info = thin.build(scene, model="thick")
    camera = _native.ThickLensCamera(at_h)
    return camera, {**info, "principal_plane_gap_mm": gap_mm}
