"""Spectral renders (``[render] spectral = true``): the tables the native tracer reads.

Wavelength is one more sample dimension over :data:`MIN_NM`-:data:`MAX_NM`.
Each camera sample carries four wavelengths: a hero and three rotations of it
by a quarter of the sampling distribution (Wilkie et al. 2014, "Hero
Wavelength Spectral Sampling", EGSR; with a uniform density that would be
100 nm apart over the 400 nm range). The density is not uniform: it follows
the film's response (the sum of the channels' |weight|), so the rotations
are by a quarter of the probability, i.e. the four wavelengths sit in the
four quartiles of the film's response (importance sampling, as pbrt-v4's
SampleVisibleWavelengths does with a fitted curve).

- **Colours to spectra.** An RGB colour c (albedo, emission, light intensity,
  background) becomes the spectrum c_r B_r(λ) + c_g B_g(λ) + c_b B_b(λ) with
  the three basis spectra of Mallett and Yuksel 2019 ("Spectral Primary
  Decomposition for Rendering with sRGB Reflectance", EGSR), as colour-science
  ships them (``colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019``). The
  map is linear, the basis sums to 1 at every wavelength (white is the
  equal-energy spectrum), and colours within [0, 1] give reflectances within
  [0, 1].
- **Film.** Radiance L(λ) reaches the pixel as
  ∫ L(λ) M x̄ȳz̄(λ) D65(λ) dλ, the CIE 1931 2° colour-matching functions
  (colour-science) weighted by CIE D65 and taken to linear sRGB by
  colour-science's XYZ → sRGB matrix M: the film is white-balanced so that the
  equal-energy spectrum — the Mallett–Yuksel spectrum of RGB white — reads
  (1, 1, 1), which is how the basis round-trips sRGB (it was fitted under D65).
  Each channel's weight is scaled so that its integral over 380–780 nm is
  exactly 1 (the CMFs' tails beyond the range, < 0.1 %, would otherwise tint
  white).
- **Monochromatic emitters** (``wavelength_nm``) emit a band
  :data:`LINE_WIDTH_NM` wide centred on the line, with the luminance (CIE Y)
  of their RGB colour. Half of every sample's wavelength probability goes to
  these bands (split evenly between the lines), so a line is sampled as often
  as the whole continuum; the estimator divides by the mixture's density, so
  both parts stay unbiased.

Tables are sampled every nanometre, 380–780 nm, and read by linear
interpolation in native/src/spectral.h.
"""

from __future__ import annotations

import functools

import numpy as np

__all__ = ["MIN_NM", "MAX_NM", "STEP_NM", "LINE_WIDTH_NM", "LINE_PROBABILITY", "wavelengths_nm",
           "basis_table", "film_table", "wavelength_distribution", "line_radiance"]

MIN_NM = 380.0
MAX_NM = 780.0
STEP_NM = 1.0
LINE_WIDTH_NM = 1.0
"""Width of a monochromatic emitter's band, nm (a 1 nm line filter)."""
LINE_PROBABILITY = 0.5
"""Share of the wavelength samples given to the scene's lines, when it has any."""


def wavelengths_nm() -> np.ndarray:
    """The tables' wavelengths, 380, 381, ..., 780 nm."""
    return np.arange(MIN_NM, MAX_NM + 0.5 * STEP_NM, STEP_NM)


@functools.lru_cache(maxsize=1)
def basis_table() -> np.ndarray:
    """Mallett–Yuksel 2019 basis spectra (r, g, b) at :func:`wavelengths_nm`, shape (401, 3)."""
    import colour  # slow to import: spectral renders only

    basis = colour.recovery.MSDS_BASIS_FUNCTIONS_sRGB_MALLETT2019.copy()
    table = basis.align(colour.SpectralShape(MIN_NM, MAX_NM, STEP_NM)).values
    return np.ascontiguousarray(table, dtype=np.float64)


@functools.lru_cache(maxsize=1)
def film_table() -> np.ndarray:
    """Linear-sRGB response per nm of radiance at :func:`wavelengths_nm`, shape (401, 3).

    Each column integrates (trapezoid rule, which is what linear interpolation
    of the table integrates) to exactly 1.
    """
    import colour  # slow to import: spectral renders only

    shape = colour.SpectralShape(MIN_NM, MAX_NM, STEP_NM)
    cmfs = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape).values
    d65 = colour.SDS_ILLUMINANTS["D65"].copy().align(shape).values
    xyz_to_rgb = colour.RGB_COLOURSPACES["sRGB"].matrix_XYZ_to_RGB
    rgb = (cmfs * d65[:, None]) @ np.asarray(xyz_to_rgb).T
    integral = np.trapezoid(rgb, dx=STEP_NM, axis=0)
    return np.ascontiguousarray(rgb / integral, dtype=np.float64)


def _luminance_per_nm(wavelength_nm: float) -> float:
    """The film's luminance (CIE Y of linear sRGB) per unit spectral radiance at wavelength_nm."""
    rgb = [np.interp(wavelength_nm, wavelengths_nm(), film_table()[:, c]) for c in range(3)]
    return float(np.asarray(rgb) @ _srgb_luminance_weights())


@functools.lru_cache(maxsize=1)
def _srgb_luminance_weights() -> np.ndarray:
    """Row Y of colour-science's linear sRGB -> XYZ matrix."""
    import colour  # slow to import: spectral renders only

    return np.asarray(colour.RGB_COLOURSPACES["sRGB"].matrix_RGB_to_XYZ)[1]


def line_radiance(color, wavelength_nm: float) -> float:
    """Spectral radiance (per nm) in a line's band: the luminance of its RGB colour, spread over the band."""
    luminance = float(np.asarray(color, dtype=float) @ _srgb_luminance_weights())
    return luminance / (_luminance_per_nm(wavelength_nm) * LINE_WIDTH_NM)


def wavelength_distribution(lines_nm) -> tuple[np.ndarray, np.ndarray]:
    """Piecewise-constant density of the wavelength samples: ``(edges_nm, probabilities)``.

    Over 380-780 nm the density follows the film's response, the sum of the
    three channels' |weight| per 1 nm bin (importance sampling: the
    wavelengths the film barely sees are drawn rarely); with lines,
    :data:`LINE_PROBABILITY` of it is spread evenly over their bands. Segment
    i is [edges_nm[i], edges_nm[i + 1]) and holds probabilities[i].
    """
    lines = sorted(set(float(v) for v in lines_nm))
    grid = wavelengths_nm()
    response = np.abs(film_table()).sum(axis=1)
    edges = set(grid.tolist())
    for line in lines:
        edges.update(np.clip([line - 0.5 * LINE_WIDTH_NM, line + 0.5 * LINE_WIDTH_NM], MIN_NM, MAX_NM).tolist())
    edges = np.array(sorted(edges))
    mids = 0.5 * (edges[:-1] + edges[1:])
    # The continuum's density: the response averaged over each 1 nm bin, normalised.
    continuum = 0.5 * (np.interp(np.floor(mids), grid, response) + np.interp(np.floor(mids) + 1.0, grid, response))
    continuum /= (continuum * np.diff(edges)).sum()
    density = continuum * ((1.0 - LINE_PROBABILITY) if lines else 1.0)
    for line in lines:
        lo, hi = max(line - 0.5 * LINE_WIDTH_NM, MIN_NM), min(line + 0.5 * LINE_WIDTH_NM, MAX_NM)
        inside = (mids > lo) & (mids < hi)
        density[inside] += LINE_PROBABILITY / len(lines) / (hi - lo)
    probabilities = density * np.diff(edges)
    return edges, probabilities / probabilities.sum()
