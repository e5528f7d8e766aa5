"""What a spectral render hands the native tracer beyond an RGB one.

The scene gets the colour tables of :mod:`lenscompare.spectral` and its
monochromatic emitters; the camera, when ``camera.lens`` disperses (a glass
in its 5th column), gets its dispersion:

- thin and thick lens: the lens's paraxial focal length f(λ)
  (:meth:`Prescription.at_wavelength`) with the film where the d line focuses
  it, i.e. the plane of focus 1/d(λ) = 1/f(λ) − 1/d'. Only the plane of
  focus moves: the principal planes stay at their d-line places, so these
  models show longitudinal colour but no lateral colour (a thin lens has none).
- lens system: every surface's indices at each nm, traced exactly;
- composite: its colour parts, when its effects name them (lateral colour as
  the distortion map per wavelength, longitudinal colour as the thin lens's).

The d-line values are shifted to equal the file's n_d ones, so that the d line
renders as the RGB render does (a catalogue glass's own index may differ from
the file's n_d by up to 1e-4).
"""

from __future__ import annotations

import numpy as np

from . import _native
from .lenses import paraxial_data
from .scene import EmissiveMaterial, Scene
from .spectral import LINE_WIDTH_NM, basis_table, film_table, line_radiance, wavelength_distribution, wavelengths_nm

__all__ = ["make_spectral"]

# Focal lengths are computed this far apart and interpolated between (smooth in λ).
_FOCAL_STEP_NM = 5.0


def make_spectral(native_scene, native_camera, scene: Scene, camera, *,
                  traced_wavelengths: int | None = None, sample_wavelengths: bool = False,
                  lens_bands: bool = True, band_roulette: bool = True) -> dict:
    """Turn ``native_scene`` spectral and give ``native_camera`` its lens's dispersion.

    ``traced_wavelengths``: see :func:`traced_wavelengths_for` (None: its default
    for the model). ``lens_bands``: a dispersive lens system's rays carry bands
    of the spectrum where the model passes its check (:func:`_lens_band_check`).
    ``band_roulette``: where rays carry bands, Russian roulette on the split
    samples' rays a pixel away (native/src/spectral_bands.h, BandRoulette).
    ``sample_wavelengths``: draw hero wavelengths even when
    the camera does not disperse; by default such a render integrates the
    film's response over the wavelengths exactly instead (every ray then
    carries the whole spectrum, and with direct light only each path's
    spectrum is a fixed bilinear function of the file's RGB colours:
    native/src/spectral.h), which is the sampled estimate's expectation
    without its colour noise. Returns what the image's metadata records about it.
    """
    traced = traced_wavelengths_for(camera.model) if traced_wavelengths is None else traced_wavelengths
    if traced not in (1, 2, 4):
        raise ValueError(f"traced_wavelengths must be 1, 2 or 4, not {traced!r}")
    line_nm, radiance = [], []
    for name in scene.materials:
        m = scene.materials[name]
        line = m.wavelength_nm if isinstance(m, EmissiveMaterial) and m.wavelength_nm is not None else None
        line_nm.append(line or 0.0)
        radiance.append(line_radiance(m.color, line) if line else 0.0)
    edges_nm, probabilities = wavelength_distribution([v for v in line_nm if v > 0])
    f64 = lambda a: np.ascontiguousarray(a, dtype=np.float64)  # noqa: E731
    native_scene.set_spectral(basis_table(), film_table(), f64(edges_nm), f64(probabilities), f64(line_nm),
                              f64(radiance), LINE_WIDTH_NM, traced, sample_wavelengths)
    disperses = _set_dispersion(native_camera, scene, camera)
    # A dispersive thin or thick lens integrates each ray's band of wavelengths
    # (native/src/render_tile_bands.h; a moving camera's band rays shift with
    # their sample's time) unless asked to draw them; so does a dispersive lens
    # system whose band model passes its check (below).
    band_check = None
    if disperses and camera.model == "lens" and lens_bands and not sample_wavelengths:
        band_check = _lens_band_check(native_camera)
    bands = (disperses and not sample_wavelengths and camera.model in ("thin", "thick", "lens")
             and native_camera.carries_bands())
    sampled = (disperses or sample_wavelengths) and not bands
    if bands:
        native_camera.band_roulette = band_roulette
    wavelengths = ("hero wavelengths (Wilkie et al. 2014)" if sampled
                   else "integrated exactly over each ray's band of wavelengths" if bands
                   else "integrated exactly (the camera does not disperse)")
    info = {"wavelengths_nm": [float(wavelengths_nm()[0]), float(wavelengths_nm()[-1])],
            "method": f"{wavelengths}, Mallett-Yuksel 2019 spectra, CIE 1931 2deg film",
            "wavelengths_sampled": sampled,
            "camera_disperses": disperses,
            "secondaries": ("none: a ray per stretch of the spectrum landing in one pixel" if bands
                            else _secondaries(traced, camera.model) if disperses
                            else "shared ray" if sampled else "none: integrated")}
    if bands:
        info["band_roulette_gain"] = float(_native.BAND_ROULETTE_GAIN) if band_roulette else None
    if band_check is not None:
        info["lens_bands"] = band_check
    return info


# The lens system's band rays (native/src/cameras/lens_system_bands.cpp) are
# a model: each ray's film point and rim clearance linear in the glasses'
# dispersion between d and 380 nm, sampled from the pupil region around the
# d pupil. Checked per camera against rays traced back at 400-780 nm
# (check_band_model, 8192 rays, about 5 ms); past these the render draws hero
# wavelengths instead. Measured (flat field through dgauss_abbe.dat):
# passing one way only 0.007 % at f/2.1, 0.10 % at f/64, 22 % at f/1000;
# film points p99 0.021 px wide open (showcase 360 x 240: dgauss_abbe 0.042,
# cooke_triplet.abbe 0.041, with catalogue glass, whose partial dispersions
# differ, sasian_triplet 0.40, telescope_triplet 0.83, edmund_49847 0.87,
# which draw hero wavelengths); passing only away from d 0.34 % at
# f/2.1, 1.7 % at f/16, 3.6 % at f/64 (where the flat field's blue read
# 0.7 % low against red: such rays crossing outside the sampled region are
# never drawn), 22 % at f/1000.
BAND_ONE_WAY_TOLERANCE = 0.01
BAND_FILM_TOLERANCE_PX = 0.1
BAND_ELSEWHERE_TOLERANCE = 0.02


def _lens_band_check(native_camera) -> dict:
    """Turn the camera's band rays on if its model holds (see above); what was measured."""
    native_camera.set_band_rays(True)
    if not native_camera.carries_bands():
        return {"used": False, "reason": "the lens's dispersion does not fit the band model"}
    passing, one_way, film_p99_px, rays, elsewhere = native_camera.check_band_model()
    figures = {"one_way": one_way / max(passing, 1), "film_p99_px": film_p99_px,
               "passing_only_away_from_d": elsewhere / max(rays, 1)}
    failed = [name for name, limit in (("one_way", BAND_ONE_WAY_TOLERANCE), ("film_p99_px", BAND_FILM_TOLERANCE_PX),
                                       ("passing_only_away_from_d", BAND_ELSEWHERE_TOLERANCE))
              if not figures[name] <= limit]
    if failed:
        native_camera.set_band_rays(False)
    return {"used": not failed, **figures, **({"reason": f"over tolerance: {', '.join(failed)}"} if failed else {})}


def traced_wavelengths_for(model: str) -> int:
    """How many of a sample's four hero wavelengths a dispersive ``model`` traces, a ray each.

    The lens system gives each traced wavelength a scene ray of its own, so
    four per sample cost four rays for about RGB's noise; two (the hero and
    the wavelength half the distribution away) reach 1 % relative RMSE on
    showcase through dgauss_abbe sooner (3.9x RGB's time against 4.6x;
    one: 8.6x, its colour noise too high; bench/bench_spectral.py). The thin
    and thick lens, when their wavelengths are drawn (``sample_wavelengths``;
    otherwise they integrate each ray's band, moving or not), trace all
    four: a secondary rides on the hero's ray wherever that ray is its own,
    so most samples cost one ray anyway. The composite keeps four (not
    measured with fewer).
    """
    return 2 if model == "lens" else 4


def _secondaries(traced: int, model: str) -> str:
    """What the render did with the secondary wavelengths (render_tile_spectral.h)."""
    if traced == 1:
        return "terminated"
    if traced == 2:
        return "hero and antipode traced, others terminated"
    # The thin and thick lens know when a wavelength's own ray is the hero's.
    return "on the hero's ray where it is theirs, else traced" if model in ("thin", "thick") else "traced"


def _set_dispersion(native_camera, scene: Scene, camera) -> bool:
    lens = scene.camera.lens
    if lens is None or not lens.disperses or camera.model not in ("thin", "thick", "lens", "composite"):
        return False
    if camera.model == "composite":
        return _set_composite_dispersion(native_camera, lens, camera)
    if camera.model == "lens":
        native_camera.set_dispersion(*lens_indices(camera.prescription))
    else:
        native_camera.set_dispersion(inverse_focus_per_m(lens, film_distance_mm=camera.film_distance_mm,
                                                         focal_length_mm=camera.focal_length_mm))
    return True


def _set_composite_dispersion(native_camera, lens, camera) -> bool:
    """The composite's colour parts: lateral colour as the distortion map per
    wavelength, longitudinal colour as the thin lens's (its lens at the
    entrance pupil, focused at the camera's focus distance, taking the
    prescription's change of power with wavelength). False when it has neither."""
    if "lateral_color" in camera.effects:
        native_camera.set_lateral_color(*camera.lateral_color_arrays(with_distortion="distortion" in camera.effects))
    if "longitudinal_color" in camera.effects:
        native_camera.set_dispersion(composite_inverse_focus_per_m(lens, focus_distance_m=camera.focus_distance_m))
    return "lateral_color" in camera.effects or "longitudinal_color" in camera.effects


def composite_inverse_focus_per_m(lens, *, focus_distance_m: float) -> np.ndarray:
    """1 / (plane of focus) at every nm, 1/m, for the composite's thin lens
    focused at ``focus_distance_m`` in d light: 1/d(λ) = 1/d + P(λ) − P_d,
    P the prescription's paraxial power (the film stays where d focuses)."""
    focal_length_mm = paraxial_data(lens).effective_focal_length_mm
    film_distance_mm = 1.0 / (1.0 / focal_length_mm - 1.0 / (1e3 * focus_distance_m))
    return inverse_focus_per_m(lens, film_distance_mm=film_distance_mm, focal_length_mm=focal_length_mm)


def inverse_focus_per_m(lens, *, film_distance_mm: float, focal_length_mm: float) -> np.ndarray:
    """1 / (plane of focus) at every nm of :func:`wavelengths_nm`, 1/m, film fixed at ``film_distance_mm``."""
    coarse_nm = np.arange(wavelengths_nm()[0], wavelengths_nm()[-1] + 0.5 * _FOCAL_STEP_NM, _FOCAL_STEP_NM)
    power = np.array([1.0 / paraxial_data(lens.at_wavelength(nm)).effective_focal_length_mm for nm in coarse_nm])
    d_power = 1.0 / paraxial_data(lens.at_wavelength(587.56)).effective_focal_length_mm
    power_per_mm = np.interp(wavelengths_nm(), coarse_nm, power) - d_power + 1.0 / focal_length_mm
    return np.ascontiguousarray(1e3 * (power_per_mm - 1.0 / film_distance_mm))


def lens_indices(prescription) -> tuple[np.ndarray, np.ndarray]:
    """Each surface's (scene side, film side) index at every nm, shape (401, surfaces) each."""
    surfaces = prescription.surfaces
    after = np.empty((len(wavelengths_nm()), len(surfaces)))
    for i, surface in enumerate(surfaces):
        if surface.glass is None:
            after[:, i] = surface.n_after
        else:
            at = np.array([surface.glass.index_at(float(nm)) for nm in wavelengths_nm()])
            after[:, i] = at - surface.glass.index_at(587.56) + surface.n_after
    before = np.concatenate([np.ones((len(after), 1)), after[:, :-1]], axis=1)
    return np.ascontiguousarray(before), np.ascontiguousarray(after)
