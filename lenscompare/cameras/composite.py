"""Composite camera: only the effects a scene calls for, each from a cheap part
(issue 14; DESIGN.md "Effects").

==================  =====  ====  ===========================================
Parameter           Type   Unit  Meaning
==================  =====  ====  ===========================================
effects             list   -     what to simulate, from ``defocus``,
                                 ``distortion``, ``vignetting``, in a
                                 spectral render ``lateral_color`` and
                                 ``longitudinal_color`` (and
                                 ``diffraction``, the post-filter)
lens                str    -     the prescription the parts are traced from
                                 (needed for distortion and vignetting)
f_number            float  -     as for the lens system (stops it down)
focus_distance      float  m     plane of sharp focus, from the entrance pupil
film_mm             pair   mm    film width and height
aperture_blades     int    -     as the thin lens
==================  =====  ====  ===========================================

The parts: a thin lens at the lens system's entrance pupil (radius the
entrance pupil's; radius 0, a pinhole, without ``defocus``) whose film maps
with the lens system's paraxial image scale, so that its frame is the lens
system's; ``distortion`` scales each screen direction to the real chief ray's
(a table traced once, :mod:`lenscompare.lenses.maps`); ``vignetting`` weighs
each ray by the relative illumination at its film radius (a table, not
noise). Without a lens the composite is the thin lens (or pinhole) of the
scene's focal length, and only ``defocus`` is available.

The colour parts exist only in a spectral render (``[render] spectral``),
where each camera ray has a wavelength; they make the native composite a
camera that disperses (its rays depend on the wavelength), set by
:mod:`lenscompare.render_spectral`:

- ``lateral_color``: the distortion map per wavelength
  (:meth:`CompositeCamera.lateral_color_map`), each ray looking along the
  chief ray of its own wavelength. Without ``distortion`` each row is divided
  by the d row, so that d light is undistorted and only the colour fringes
  remain;
- ``longitudinal_color``: the thin lens's plane of focus per wavelength, from
  the prescription's paraxial focal length at each wavelength, as the thin
  lens model (:func:`lenscompare.render_spectral.inverse_focus_per_m`).

An RGB render asked for either is refused (:func:`check_spectral_parts`):
``--effects`` promises exactly those effects, and an RGB render shows no colour.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass

import numpy as np

from .. import _native
from ..errors import InputError
from ..lenses import LateralColorMap, RadialMaps, lateral_color_map, radial_maps
from ..lenses.glass import D_NM
from ..units import m_from_mm
from .base import CameraModel
from .frame import CameraFrame, Film
from .lens import LensSystemCamera
from .pinhole import PinholeCamera
from .thin import DISK_MAPPING_CODES, ThinLensCamera

__all__ = ["CompositeCamera", "COMPOSITE_EFFECTS", "COLOR_PARTS", "POST_FILTER_EFFECTS", "check_composite_effects",
           "check_spectral_parts"]

# The effects a composite's parts simulate in the render itself, in any render.
COMPOSITE_EFFECTS = ("defocus", "distortion", "vignetting")
# Those it simulates in a spectral render only (each ray's wavelength picks its table row or focus).
COLOR_PARTS = ("lateral_color", "longitudinal_color")
# Effects applied to any render's image afterwards (lenscompare.diffraction).
POST_FILTER_EFFECTS = ("diffraction",)
# Those that need the prescription's traced maps.
_MAPPED_EFFECTS = ("distortion", "vignetting", "lateral_color")


def check_composite_effects(effects, *, source: str, key: str | None = None) -> tuple[str, ...]:
    """``effects`` as a tuple in contract order, or an InputError naming
    ``source`` (and ``key``) when a composite cannot simulate one of them."""
    effects = tuple(dict.fromkeys(effects))
    parts = COMPOSITE_EFFECTS + COLOR_PARTS + POST_FILTER_EFFECTS
    missing = [e for e in effects if e not in parts]
    if missing:
        raise InputError(source, f"a composite cannot simulate {', '.join(missing)} (its parts simulate "
                         f"{', '.join(parts)}): render with --model lens", key=key)
    return effects


def check_spectral_parts(effects, *, spectral: bool, source: str, key: str | None = None) -> None:
    """An InputError naming ``source`` (and ``key``) when a colour part is asked of an RGB render.

    ``--effects`` renders exactly the effects named; colour exists only where
    each ray has a wavelength, so an RGB render cannot keep that promise.
    """
    color = [e for e in effects if e in COLOR_PARTS]
    if color and not spectral:
        raise InputError(source, f"{', '.join(color)} needs a spectral render: an RGB render shows no colour "
                         "(set [render] spectral = true, or leave the colour effects out)", key=key)


@dataclass(frozen=True, kw_only=True)
class CompositeCamera(CameraModel):
    """A thin lens (or pinhole) at the entrance pupil plus traced radial maps.

    Attributes (beyond :class:`CameraModel`)
    ----------------------------------------
    effects : tuple of str
        The effects this render simulates (of :data:`COMPOSITE_EFFECTS`,
        :data:`COLOR_PARTS` and :data:`POST_FILTER_EFFECTS`).
    lens_system : LensSystemCamera or None
        The lens system the parts stand in for (None without ``camera.lens``).
    maps : RadialMaps or None
        The traced tables, when distortion or vignetting is simulated.
    paraxial_scale_mm : float
        Film height per unit tangent of the field angle.
    """

    model = "composite"
    effects: tuple[str, ...]
    lens_system: LensSystemCamera | None
    maps: RadialMaps | None
    paraxial_scale_mm: float

    @classmethod
    def from_scene(cls, scene, *, effects=None, effects_key: str | None = "render.effects") -> "CompositeCamera":
        source = scene.source if effects is None else "--effects"
        effects = scene.render.effects if effects is None else effects
        if effects is None:
            raise InputError(scene.source, "a composite render needs a list of effects ([render] effects or "
                             "--effects)", key="render.effects")
        effects = check_composite_effects(effects, source=source, key=effects_key if source != "--effects" else None)
        mapped = [e for e in effects if e in _MAPPED_EFFECTS]
        if scene.camera.lens is None:
            traced = [e for e in effects if e in _MAPPED_EFFECTS + COLOR_PARTS]
            if traced:
                raise InputError(scene.source, f"{', '.join(traced)} in a composite is traced from a lens: "
                                 "give camera.lens", key="camera.lens")
            return cls._without_lens(scene, effects)
        lens = LensSystemCamera.from_scene(scene)
        maps = None
        if mapped:
            maps = radial_maps(lens.prescription, film_z_mm=lens.film_z_mm, paraxial_scale_mm=lens.paraxial_scale_mm,
                               focus_distance_m=lens.focus_distance_m,
                               film_half_diagonal_mm=lens.film.half_diagonal_mm)
            if not maps.covers_film:
                raise InputError(scene.source, f"a composite cannot stand in for {lens.prescription.name} here: "
                                 f"{maps.reason}; render with --model lens", key="camera.lens")
        return cls(**_shared_fields(lens), effects=effects, lens_system=lens, maps=maps,
                   paraxial_scale_mm=lens.paraxial_scale_mm)

    @classmethod
    def _without_lens(cls, scene, effects: tuple[str, ...]) -> "CompositeCamera":
        """The scene's own thin lens (or, without an f-number, pinhole): defocus alone."""
        ideal = ThinLensCamera.from_scene(scene) if scene.camera.f_number is not None else PinholeCamera.from_scene(
            scene)
        if "defocus" in effects and ideal.f_number is None:
            raise InputError(scene.source, "defocus needs an aperture", key="camera.f_number")
        return cls(**_shared_fields(ideal), effects=effects, lens_system=None, maps=None,
                   paraxial_scale_mm=ideal.film_distance_mm)

    @property
    def image_scale_mm(self) -> float:
        return self.paraxial_scale_mm

    @property
    def screen_half_extent(self) -> tuple[float, float]:
        return (self.film.width_mm / 2.0 / self.paraxial_scale_mm, self.film.height_mm / 2.0 / self.paraxial_scale_mm)

    @property
    def working_f_number(self) -> float | None:
        if self.lens_system is not None:
            return self.lens_system.working_f_number
        return super().working_f_number

    @property
    def lens_radius_mm(self) -> float:
        """The entrance pupil's radius when defocus is simulated, else 0 (a pinhole)."""
        return self.aperture_diameter_mm / 2.0 if "defocus" in self.effects else 0.0

    def native(self, *, disk_mapping: str = "concentric") -> "_native.CompositeCamera":
        half_w, half_h = self.screen_half_extent
        lens = _native.ThinLensCamera(
            *self.frame, self.film.width_px, self.film.height_px, half_w, half_h,
            lens_radius_m=m_from_mm(self.lens_radius_mm), focus_distance_m=self.focus_distance_m,
            disk_mapping=DISK_MAPPING_CODES[disk_mapping], aperture_blades=self.aperture_blades,
            aperture_rotation_deg=self.aperture_rotation_deg)
        empty = np.zeros(0, dtype=np.float64)
        maps = self.maps
        scale = np.ascontiguousarray(maps.screen_scale) if maps and "distortion" in self.effects else empty
        light = np.ascontiguousarray(maps.illumination) if maps and "vignetting" in self.effects else empty
        # Outside the image circle the lens passes nothing, whichever part is asked for.
        max_radius = maps.max_radius_mm if maps else math.inf
        return _native.CompositeCamera(lens, self.film.width_mm, self.film.height_mm, scale, light,
                                       maps.radius_step_mm if maps else 1.0, max_radius)

    def lateral_color_map(self) -> LateralColorMap:
        """The lens system's distortion map per wavelength, on this film (memoised).

        Raises
        ------
        InputError
            Without a lens (an ideal lens has no colour).
        """
        lens = self.lens_system
        if lens is None:
            raise InputError("camera.lens", "lateral colour is traced from a lens: give camera.lens")
        return lateral_color_map(lens.prescription, film_z_mm=lens.film_z_mm, paraxial_scale_mm=self.paraxial_scale_mm,
                                 focus_distance_m=lens.focus_distance_m,
                                 film_half_diagonal_mm=lens.film.half_diagonal_mm)

    def lateral_color_arrays(self, *, with_distortion: bool = True) -> tuple[np.ndarray, np.ndarray, float]:
        """``(wavelengths_nm (k,), screen_scale (k, entries), radius_step_mm)``
        as the spectral composite takes them: contiguous float64, the
        screen-direction scale per wavelength (see :class:`LateralColorMap`).
        Without ``with_distortion`` each row is divided by the d row (d light
        then lands where the paraxial image does)."""
        table = self.lateral_color_map()
        scale = table.screen_scale
        if not with_distortion:
            scale = scale / scale[list(table.wavelengths_nm).index(D_NM)]
        return (np.ascontiguousarray(table.wavelengths_nm, dtype=np.float64),
                np.ascontiguousarray(scale, dtype=np.float64), table.radius_step_mm)

    def to_json(self) -> dict:
        info = {**super().to_json(), "effects": list(self.effects), "lens_radius_mm": self.lens_radius_mm}
        if self.lens_system is not None:
            info.update(lens=self.lens_system.prescription.name, lens_sha256=self.lens_system.prescription.sha256)
        if self.maps is not None:
            info.update(map_entries=len(self.maps.field_tangent), map_max_radius_mm=(
                None if math.isinf(self.maps.max_radius_mm) else self.maps.max_radius_mm))
        return info


def _shared_fields(camera: CameraModel) -> dict:
    """The geometry every camera value holds (:class:`CameraModel`'s fields),
    taken from the camera the composite stands in for."""
    return {f.name: getattr(camera, f.name) for f in dataclasses.fields(CameraModel)}
