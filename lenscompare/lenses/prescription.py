"""Read and validate lens prescriptions (pbrt's lens file format).

One surface per line, from the scene side to the film side, columns separated
by white space, ``#`` starts a comment::

    radius_mm  thickness_mm  n_d  aperture_diameter_mm  [abbe_v_d | glass]

- ``radius_mm`` > 0: centre of curvature toward the film; ``0``: the aperture
  stop (a plane in air); ``inf``: a planar refracting surface.
- ``thickness_mm``: axial distance to the next surface; the last row's value is
  ignored (focusing sets the film).
- ``n_d``: index of the medium after the surface; ``0`` or ``1`` is air.
- 5th column (optional): the Abbe number V_d of that medium (``0`` for air),
  or a catalogue glass name (``N-BK7``, ``S-LAH66``) whose n_d must agree with
  the ``n_d`` column within :data:`N_D_TOLERANCE`; see :mod:`.glass`.  Without
  it the medium does not disperse.

Everything is checked here, at the edge; the :class:`Prescription` handed on is
known to be physically sensible (see :func:`parse_prescription` for the list).
"""

from __future__ import annotations

import dataclasses
import hashlib
import math
import os
import re
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

from ..errors import InputError
from ..limits import read_input_bytes
from .glass import D_NM, AbbeGlass, CatalogueGlass, find_catalogue_glass, near_glass_names

__all__ = [
    "Surface",
    "Prescription",
    "shipped_lens_names",
    "load_prescription",
    "parse_prescription",
    "sag_mm",
    "N_D_TOLERANCE",
]

N_D_TOLERANCE = 1e-4
"""Largest difference between a file's n_d and its named glass's catalogue n_d."""

_COLUMNS = ("radius_mm", "thickness_mm", "n_d", "aperture_diameter_mm", "abbe_v_d")
_NUMBER = re.compile(
    r"[+-]?(?:(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?|inf(?:inity)?)\Z", re.IGNORECASE
)
_NAN = re.compile(r"[+-]?nan\Z", re.IGNORECASE)
# A glass name: a letter first (so a mistyped number is not taken for one).
_GLASS_NAME = re.compile(r"[A-Za-z][A-Za-z0-9_.+/-]{0,39}\Z")


@dataclass(frozen=True)
class Surface:
    """One surface of a lens system.

    Attributes
    ----------
    radius_mm : float
        Radius of curvature in mm, positive when the centre lies toward the
        film; ``inf`` for a plane (planar refracting surfaces and the stop).
    thickness_mm : float
        Axial distance to the next surface, mm (0 for the last surface).
    n_after : float
        Refractive index (n_d) of the medium after the surface; 1.0 for air.
    semi_aperture_mm : float
        Clear semi-aperture (radius of the opening), mm.
    abbe_v_d : float or None
        Abbe number of the medium after the surface when the 5th column gives
        one; None for air, a glass name or no 5th column.
    is_stop : bool
        True for the aperture stop (a plane with no refraction).
    line : int
        Line of the lens file this surface came from, for messages.
    glass : AbbeGlass or CatalogueGlass or None
        Dispersion of the medium after the surface; None: it does not disperse.
    """

    radius_mm: float
    thickness_mm: float
    n_after: float
    semi_aperture_mm: float
    abbe_v_d: float | None
    is_stop: bool
    line: int
    glass: AbbeGlass | CatalogueGlass | None = None

    @property
    def curvature_per_mm(self) -> float:
        """Curvature 1/radius in 1/mm; 0 for a plane."""
        return 0.0 if math.isinf(self.radius_mm) else 1.0 / self.radius_mm


@dataclass(frozen=True)
class Prescription:
    """A validated lens system: surfaces from the scene side to the film side.

    Attributes
    ----------
    name : str
        Shipped name (``"dgauss.50mm"``) or the file name without ``.dat``.
    source : str
        The file the prescription was read from (for messages).
    surfaces : tuple of Surface
        The surfaces in order; the medium in front of the first is air.
    sha256 : str
        Hex SHA-256 of the file bytes, for provenance (with the glass names
        and Abbe numbers, the file names the dispersion too).
    wavelength_nm : float or None
        None: indices are the file's n_d (every first-order value of
        DESIGN.md).  A number: indices at that wavelength (see
        :meth:`at_wavelength`).
    """

    name: str
    source: str
    surfaces: tuple[Surface, ...]
    sha256: str
    wavelength_nm: float | None = None

    @property
    def disperses(self) -> bool:
        """True when some medium has a glass (an Abbe number or a catalogue name)."""
        return any(surface.glass is not None for surface in self.surfaces)

    def at_wavelength(self, wavelength_nm: float) -> Prescription:
        """The same lens with every index at ``wavelength_nm`` (nm).

        Media without a glass keep their n_d.  Every paraxial and real-ray
        function then works at that wavelength unchanged.  A catalogue glass
        gives the catalogue's index, which may differ from the file's n_d by
        up to :data:`N_D_TOLERANCE` at the d line.

        Raises
        ------
        ValueError
            When ``wavelength_nm`` is not a positive finite number.
        """
        if not (math.isfinite(wavelength_nm) and wavelength_nm > 0):
            raise ValueError(f"wavelength must be a positive number of nm, got {wavelength_nm}")
        surfaces = tuple(surface if surface.glass is None else
                         dataclasses.replace(surface, n_after=surface.glass.index_at(wavelength_nm))
                         for surface in self.surfaces)
        return dataclasses.replace(self, surfaces=surfaces, wavelength_nm=float(wavelength_nm))

    @property
    def vertex_z_mm(self) -> tuple[float, ...]:
        """Axial position of each vertex, mm from the first vertex toward the film."""
        z, positions = 0.0, []
        for surface in self.surfaces:
            positions.append(z)
            z += surface.thickness_mm
        return tuple(positions)

    @property
    def total_track_mm(self) -> float:
        """Distance from the first to the last vertex, mm."""
        return self.vertex_z_mm[-1]

    @property
    def stop_index(self) -> int | None:
        """Index of the surface marked as aperture stop (radius 0), or None."""
        for index, surface in enumerate(self.surfaces):
            if surface.is_stop:
                return index
        return None

    def n_before(self, index: int) -> float:
        """Refractive index of the medium in front of surface ``index``."""
        return 1.0 if index == 0 else self.surfaces[index - 1].n_after

    def with_semi_aperture(self, index: int, semi_aperture_mm: float) -> Prescription:
        """Return a copy in which surface ``index`` has another semi-aperture (mm).

        Used to stop the lens down; see
        :func:`lenscompare.lenses.paraxial.stopped_down`.
        """
        if not (semi_aperture_mm > 0 and math.isfinite(semi_aperture_mm)):
            raise ValueError(f"semi-aperture must be positive, got {semi_aperture_mm}")
        surfaces = list(self.surfaces)
        surfaces[index] = dataclasses.replace(surfaces[index], semi_aperture_mm=semi_aperture_mm)
        return dataclasses.replace(self, surfaces=tuple(surfaces))


def sag_mm(curvature_per_mm: float, r_mm):
    """Sag of a spherical surface: axial offset from its vertex at height ``r_mm``.

    Positive toward the film for a positive curvature.  Written in the form
    without cancellation, so a nearly flat surface (radius 1e9 mm) gives 0.
    Works on floats and numpy arrays; ``r_mm`` must not exceed ``|radius|``.
    """
    c = curvature_per_mm
    return c * r_mm * r_mm / (1.0 + (1.0 - (c * r_mm) ** 2) ** 0.5)


def shipped_lens_names() -> tuple[str, ...]:
    """Names of the prescriptions shipped with the package, sorted."""
    data = resources.files(__package__) / "data"
    return tuple(sorted(p.name[: -len(".dat")] for p in data.iterdir() if p.name.endswith(".dat")))


def load_prescription(name_or_path: str | os.PathLike) -> Prescription:
    """Load a shipped prescription by name, or one from a file.

    Parameters
    ----------
    name_or_path : str or os.PathLike
        A shipped name such as ``"dgauss.50mm"`` (see
        :func:`shipped_lens_names`), or the path of a lens file.  A bare name
        (no directory) is looked up among the shipped lenses first.

    Returns
    -------
    Prescription

    Raises
    ------
    InputError
        Unknown lens name, unreadable file, or a file that breaks the format
        (the message names the file and the line).
    """
    text = os.fspath(name_or_path)
    bare = os.sep not in text and (os.altsep is None or os.altsep not in text)
    names = shipped_lens_names()
    if bare and text in names:
        resource = resources.files(__package__) / "data" / f"{text}.dat"
        return parse_prescription(resource.read_bytes(), source=str(resource), name=text)
    path = Path(text)
    if bare and path.suffix != ".dat" and not path.exists():
        raise InputError(text, "unknown lens name; shipped lenses: " + ", ".join(names))
    if not path.exists():
        raise InputError(text, "cannot read lens file: no such file (nor a shipped lens: " + ", ".join(names) + ")")
    # At most MAX_FILE_BYTES, and never a device such as /dev/zero.
    data = read_input_bytes(path, what="lens file")
    name = path.name[: -len(".dat")] if path.name.endswith(".dat") else path.name
    return parse_prescription(data, source=text, name=name)


def parse_prescription(data: bytes, *, source: str, name: str) -> Prescription:
    """Parse and validate the bytes of a lens file.

    Parameters
    ----------
    data : bytes
        The file contents.
    source : str
        File name used in messages.
    name : str
        Name given to the prescription.

    Returns
    -------
    Prescription

    Raises
    ------
    InputError
        With ``key="line N"`` when a row has the wrong number of columns, a
        token that is not a number, NaN anywhere or ``inf`` outside the radius
        column, a negative thickness, an aperture that is not positive, an
        index below 1 (other than 0 for air), a negative Abbe number, a radius
        smaller than the semi-aperture, two neighbouring surfaces that cross
        within their common aperture, a second stop, a stop that is not in air,
        or a last surface that does not leave the light in air; without a line
        when the file is not text or holds no surface.
    """
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        raise InputError(source, "not a text file (expected UTF-8 or ASCII)") from None

    rows = [(number, _parse_row(line, source, number))
            for number, line in enumerate(text.splitlines(), start=1)]
    rows = [(number, values) for number, values in rows if values is not None]
    if not rows:
        raise InputError(source, "no surfaces: expected one line per surface "
                         "'radius_mm thickness_mm n_d aperture_diameter_mm [abbe_v_d]'")

    surfaces = []
    for position, (number, values) in enumerate(rows):
        is_last = position == len(rows) - 1
        surfaces.append(_make_surface(values, source, number, is_last=is_last))
    surfaces = tuple(surfaces)

    _check_stop(surfaces, source)
    _check_neighbours(surfaces, source)
    if surfaces[-1].n_after != 1.0:
        raise InputError(source, f"the last surface must leave the light in air (n 0 or 1), "
                         f"found {surfaces[-1].n_after:g}: the film sits in air",
                         key=f"line {surfaces[-1].line}")
    return Prescription(name=name, source=source, surfaces=surfaces,
                        sha256=hashlib.sha256(data).hexdigest())


def _parse_row(line: str, source: str, number: int) -> list[float] | None:
    """Values of one line (numbers, and a glass name in the 5th column), or
    None for a blank or comment line."""
    tokens = line.split("#", 1)[0].split()
    if not tokens:
        return None
    key = f"line {number}"
    if len(tokens) not in (4, 5):
        raise InputError(source, f"expected 4 or 5 columns (radius_mm thickness_mm n_d "
                         f"aperture_diameter_mm [abbe_v_d | glass]), found {len(tokens)}", key=key)
    values = []
    for column, token in zip(_COLUMNS, tokens):
        if _NAN.match(token):
            raise InputError(source, f"{column} is NaN", key=key)
        if column == "abbe_v_d" and not _NUMBER.match(token):
            if not _GLASS_NAME.match(token):
                raise InputError(source, f"5th column {token!r} is neither an Abbe number nor a "
                                 f"glass name", key=key)
            values.append(token)
            continue
        if not _NUMBER.match(token):
            raise InputError(source, f"{column} {token!r} is not a number", key=key)
        values.append(float(token))
    return values


def _make_surface(values: list[float], source: str, number: int, *, is_last: bool) -> Surface:
    """Check one row's values and turn them into a Surface."""
    key = f"line {number}"
    radius, thickness, n, aperture = values[:4]
    fifth = values[4] if len(values) == 5 else None
    abbe = fifth if isinstance(fifth, float) else None

    # The last thickness is ignored (the film position comes from focusing).
    if is_last:
        thickness = 0.0
    elif not math.isfinite(thickness) or thickness < 0:
        raise InputError(source, f"thickness_mm must be finite and >= 0, got {thickness:g}",
                         key=key)
    if not math.isfinite(n):
        raise InputError(source, f"n_d must be finite, got {n:g}", key=key)
    if n != 0 and n < 1:
        raise InputError(source, f"n_d {n:g} is below 1 (write 0 or 1 for air)", key=key)
    if not math.isfinite(aperture) or aperture <= 0:
        raise InputError(source, f"aperture_diameter_mm must be finite and > 0, got {aperture:g}",
                         key=key)
    if abbe is not None and (not math.isfinite(abbe) or abbe < 0):
        raise InputError(source, f"abbe_v_d must be finite and >= 0, got {abbe:g}", key=key)

    semi_aperture = aperture / 2.0
    is_stop = radius == 0.0
    if not is_stop and math.isfinite(radius) and abs(radius) < semi_aperture:
        raise InputError(source, f"|radius| {abs(radius):g} mm is smaller than the "
                         f"semi-aperture {semi_aperture:g} mm", key=key)
    n_after = 1.0 if n == 0 else n
    if isinstance(fifth, str):
        glass = _catalogue_glass(fifth, n_after, source, key)
    else:
        # Air (n 1) has n_F - n_C = 0 whatever the column says.
        glass = AbbeGlass(n_d=n_after, abbe_v_d=abbe) if abbe and n_after != 1.0 else None
    return Surface(
        radius_mm=math.inf if is_stop else radius,
        thickness_mm=thickness,
        n_after=n_after,
        semi_aperture_mm=semi_aperture,
        abbe_v_d=abbe if abbe else None,
        is_stop=is_stop,
        line=number,
        glass=glass,
    )


def _catalogue_glass(name: str, n_d: float, source: str, key: str) -> CatalogueGlass:
    """The named catalogue glass, checked against the row's n_d."""
    if n_d == 1.0:
        raise InputError(source, f"glass {name!r} on a row whose medium is air (n_d 0 or 1)", key=key)
    glass = find_catalogue_glass(name)
    if glass is None:
        near = near_glass_names(name)
        hint = f"; near names: {', '.join(near)}" if near else ""
        raise InputError(source, f"unknown glass {name!r} (not in the Schott, Ohara, Hoya, CDGM, "
                         f"Hikari or Sumita catalogues){hint}", key=key)
    n_catalogue = glass.index_at(D_NM)
    if not abs(n_d - n_catalogue) <= N_D_TOLERANCE:
        raise InputError(source, f"n_d {n_d:.6f} disagrees with {glass.label}'s catalogue n_d "
                         f"{n_catalogue:.6f} by more than {N_D_TOLERANCE:g}", key=key)
    return glass


def _check_stop(surfaces: tuple[Surface, ...], source: str) -> None:
    """At most one stop, and it must stand in air on both sides (it does not refract)."""
    first = None
    for index, surface in enumerate(surfaces):
        if not surface.is_stop:
            continue
        key = f"line {surface.line}"
        if first is not None:
            raise InputError(source, f"a second aperture stop (radius 0); the first is on "
                             f"line {first.line}", key=key)
        first = surface
        if surface.n_after != 1.0:
            raise InputError(source, f"the aperture stop (radius 0) must be followed by air: "
                             f"n_d 0 or 1, found {surface.n_after:g}", key=key)
        if index > 0 and surfaces[index - 1].n_after != 1.0:
            raise InputError(source, f"the aperture stop sits inside glass (n_d "
                             f"{surfaces[index - 1].n_after:g} from line "
                             f"{surfaces[index - 1].line}); a stop must be in air", key=key)


def _check_neighbours(surfaces: tuple[Surface, ...], source: str) -> None:
    """Neighbouring surfaces must not cross inside their common aperture.

    The axial gap at height r is ``g(r) = t + sag_next(r) - sag_this(r)``.  In
    powers of r^2 every term of ``sag_next - sag_this`` has the sign of
    ``c_next - c_this``, so g is monotonic in r: checking r = 0 (t >= 0, already
    checked) and the rim r = h suffices.  Touching at the rim is allowed.
    """
    for this, after in zip(surfaces, surfaces[1:]):
        h = min(this.semi_aperture_mm, after.semi_aperture_mm)
        sag_this = sag_mm(this.curvature_per_mm, h)
        sag_after = sag_mm(after.curvature_per_mm, h)
        gap = this.thickness_mm + sag_after - sag_this
        # Rounding of the sags only; a real overlap is orders of magnitude larger.
        tolerance = 1e-9 * (1.0 + abs(sag_this) + abs(sag_after) + this.thickness_mm)
        if gap < -tolerance:
            raise InputError(source, f"this surface and the next one (line {after.line}) "
                             f"cross inside the aperture: axial gap {gap:.4g} mm at "
                             f"{h:g} mm from the axis", key=f"line {this.line}")
