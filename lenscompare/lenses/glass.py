"""Glass: the refractive index of a lens medium at a wavelength.

The 5th column of a lens file (DESIGN.md, "Glass and dispersion") is either

- an Abbe number V_d: n(λ) = A + B / λ², the two-term Cauchy formula fitted
  through n_d at :data:`D_NM` with n_F − n_C = (n_d − 1) / V_d
  (:data:`F_NM`, :data:`C_NM`) — :class:`AbbeGlass`;
- or a glass name from a manufacturer's catalogue (Schott, Ohara, Hoya, CDGM,
  then Hikari and Sumita), whose own dispersion formula (Sellmeier for most)
  the ``opticalglass`` package evaluates — :class:`CatalogueGlass`.

Both are small frozen values, so a prescription holding them stays hashable.
Catalogue data: the catalogues shipped inside ``opticalglass`` (M. Hayford,
BSD-3), which are the manufacturers' published spreadsheets.
"""

from __future__ import annotations

import difflib
import functools
from dataclasses import dataclass

__all__ = [
    "D_NM", "F_NM", "C_NM", "CATALOGUES", "AbbeGlass", "CatalogueGlass", "find_catalogue_glass",
    "near_glass_names", "cauchy_coefficients",
]

D_NM = 587.56
"""Helium d line (587.5618 nm) as the contract rounds it, nm."""
F_NM = 486.13
"""Hydrogen F line, nm."""
C_NM = 656.27
"""Hydrogen C line, nm."""

CATALOGUES = ("Schott", "Ohara", "Hoya", "CDGM", "Hikari", "Sumita")
"""Catalogues searched for a glass name, in this order (the first match wins)."""


def cauchy_coefficients(n_d: float, abbe_v_d: float) -> tuple[float, float]:
    """``(A, B_nm2)`` of n(λ) = A + B / λ² through n_d with n_F − n_C = (n_d − 1) / V_d.

    Examples
    --------
    >>> a, b = cauchy_coefficients(1.5168, 64.17)
    >>> round(a + b / D_NM**2, 12), round((b / F_NM**2 - b / C_NM**2) * 64.17, 12)
    (1.5168, 0.5168)
    """
    b_nm2 = (n_d - 1.0) / abbe_v_d / (1.0 / F_NM**2 - 1.0 / C_NM**2)
    return n_d - b_nm2 / D_NM**2, b_nm2


@dataclass(frozen=True)
class AbbeGlass:
    """A medium given by n_d and its Abbe number (the contract's Cauchy fit).

    Attributes
    ----------
    n_d : float
        Index at :data:`D_NM`.
    abbe_v_d : float
        Abbe number, > 0.
    """

    n_d: float
    abbe_v_d: float

    @property
    def label(self) -> str:
        """How ``lens info`` shows it: ``V_d 64.17``."""
        return f"V_d {self.abbe_v_d:g}"

    def index_at(self, wavelength_nm: float) -> float:
        """Refractive index at ``wavelength_nm``."""
        a, b_nm2 = cauchy_coefficients(self.n_d, self.abbe_v_d)
        return a + b_nm2 / (wavelength_nm * wavelength_nm)


@dataclass(frozen=True)
class CatalogueGlass:
    """A manufacturer's glass, its index from the catalogue's formula.

    Attributes
    ----------
    name : str
        The manufacturer's name, e.g. ``"N-BK7"``.
    catalogue : str
        One of :data:`CATALOGUES`.
    """

    name: str
    catalogue: str

    @property
    def label(self) -> str:
        """How ``lens info`` shows it: ``N-BK7 (Schott)``."""
        return f"{self.name} ({self.catalogue})"

    def index_at(self, wavelength_nm: float) -> float:
        """Refractive index at ``wavelength_nm`` (the catalogue's own formula)."""
        return float(_glass(self.name, self.catalogue).rindex(wavelength_nm))


@functools.lru_cache(maxsize=None)
def _glass(name: str, catalogue: str):
    import opticalglass.glassfactory as glassfactory  # 1.4 s to import: only lenses with glass names pay

    return glassfactory.create_glass(name, catalogue)


@functools.lru_cache(maxsize=1024)
def find_catalogue_glass(name: str) -> CatalogueGlass | None:
    """The catalogue glass called ``name`` (first of :data:`CATALOGUES` that has it), or None.

    Names are matched as ``opticalglass`` decodes them (``N-BK7`` and
    ``NBK7`` are one glass); the result carries the catalogue's spelling.
    """
    from opticalglass import glasserror  # slow to import, as in _glass

    for catalogue in CATALOGUES:
        try:
            glass = _glass(name, catalogue)
        except (glasserror.GlassError, KeyError, ValueError, IndexError):
            continue
        return CatalogueGlass(name=glass.name(), catalogue=catalogue)
    return None


def near_glass_names(name: str, *, count: int = 3) -> list[str]:
    """Up to ``count`` catalogue glass names that look like ``name`` (for messages)."""
    return difflib.get_close_matches(name.upper(), _all_names(), n=count, cutoff=0.6)


@functools.lru_cache(maxsize=1)
def _all_names() -> list[str]:
    import opticalglass.glassfactory as glassfactory  # slow to import, as in _glass
    from opticalglass import glasserror  # slow to import, as in _glass

    names = []
    for catalogue in CATALOGUES:
        try:
            lookup = glassfactory.get_glass_catalog(catalogue).glass_lookup
        except glasserror.GlassError:
            continue
        names.extend(glass_name for glass_name, _ in lookup.values())
    return sorted(set(names))
