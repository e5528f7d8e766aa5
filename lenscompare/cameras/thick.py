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

from dataclasses import dataclass

from .. import _native
from ..lenses import paraxial_data
from .base import require
from .thin import ThinLensCamera

__all__ = ["ThickLensCamera", "principal_plane_gap_mm"]


def principal_plane_gap_mm(scene) -> float:
    """H -> H' in mm, from ``camera.lens`` when given, else the scene key."""
    if scene.camera.lens is not None:
        data = paraxial_data(scene.camera.lens)
        return data.rear_principal_plane_mm - data.front_principal_plane_mm
    return require(scene, scene.camera.principal_plane_gap_mm, "principal_plane_gap_mm", "thick")


@dataclass(frozen=True, kw_only=True)
class ThickLensCamera(ThinLensCamera):
    """The thin lens at H, with the film moved ``principal_plane_gap_mm`` back."""

    model = "thick"
    principal_plane_gap_mm: float = 0.0

    @classmethod
    def from_scene(cls, scene, **_):
        return super().from_scene(scene, model="thick", principal_plane_gap_mm=principal_plane_gap_mm(scene))

    def native(self, *, disk_mapping: str = "concentric") -> "_native.ThickLensCamera":
        # The gap moves the film and the lens body, not a single ray in front of the lens.
        return _native.ThickLensCamera(super().native(disk_mapping=disk_mapping))

    def to_json(self) -> dict:
        return {**super().to_json(), "principal_plane_gap_mm": self.principal_plane_gap_mm}
