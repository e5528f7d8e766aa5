"""Zemax OpticStudio prescriptions (.zmx) turned into lenscompare lens files.

rayoptics (M. Hayford, BSD-3) reads the file: surfaces, curvatures, gaps,
media, the stop, surface types.  What a pbrt lens file cannot say is refused,
naming the Zemax surface: mirrors, non-standard surface types (aspheres,
toroids, gradient index, paraxial, gratings), conics, coordinate breaks and
tilts or decentres, a stop on a curved surface or in glass, media that are
neither air, a catalogue glass, a model glass (n_d, V_d) nor a constant index.

Semi-diameters: OpticStudio stores each surface's current semi-diameter in its
``DIAM`` record, whatever its solve (automatic, fixed, pickup); that value is
kept.  The stop is the exception: its size is the height of the paraxial
marginal ray of the file's system aperture (FNUM, ENPD, ...), so the paraxial
f-number is the designer's (OpticStudio sizes the stop by real rays).  A surface without one (no record, or 0) gets the clear aperture that
rayoptics computes the way OpticStudio's automatic solve does: the largest
height of the boundary rays of every field through the entrance pupil.

Glass names are kept (the 5th column) with n_d from the catalogue at the d
line; a model glass keeps its n_d and V_d; a constant index has no 5th column.
"""

from __future__ import annotations

import contextlib
import io
import logging
import math
import os
import re
import warnings

from ..errors import ExternalError, InputError
from ..limits import read_input_bytes
from .glass import find_catalogue_glass, near_glass_names
from .prescription import parse_prescription

__all__ = ["zemax_to_lens_text", "D_LINE_NM"]

D_LINE_NM = 587.5618
"""Helium d line, nm: the wavelength of the ``n_d`` column written."""

_SURFACE = re.compile(r"\s*SURF\s+(\d+)")


def zemax_to_lens_text(path: str | os.PathLike) -> str:
    """The lens file (pbrt format with glass) equivalent to a Zemax file.

    Parameters
    ----------
    path : str or os.PathLike
        A sequential OpticStudio ``.zmx`` file (UTF-8, Latin-1 or UTF-16).

    Returns
    -------
    str
        Lens-file text, checked by :func:`parse_prescription`.

    Raises
    ------
    InputError
        Unreadable or non-sequential file, or a surface the lens-file format
        cannot represent (the message names the Zemax surface number).
    """
    source = os.fspath(path)
    text = _decode(read_input_bytes(path, what="Zemax file"), source)
    if re.search(r"^\s*MODE\s+NSC", text, re.MULTILINE):
        raise InputError(source, "non-sequential (MODE NSC) files cannot be imported")
    records = _surface_records(text)
    if not records:
        raise InputError(source, "no SURF records: not a Zemax OpticStudio lens file")
    # Refused on the file's own records first: rayoptics may fail on what it cannot model.
    last = max(records)
    for index in sorted(records):
        if 0 < index < last:
            _check_representable(None, records[index], source, f"surface {index}")
    stops = [index for index, record in records.items() if "STOP" in record]
    model = _read_with_rayoptics(text, source, stop=stops[0] if stops else None)
    rows = _rows(model, records, source)
    name = _title(text) or os.path.basename(source)
    header = [f"# {name}", f"# Imported from {os.path.basename(source)} by lenscompare lens import "
              f"(read with rayoptics); n_d at {D_LINE_NM} nm from the glass catalogues.",
              "# radius_mm  thickness_mm  n_d  aperture_diameter_mm  glass_or_V_d"]
    lens_text = "\n".join(header + rows) + "\n"
    try:
        parse_prescription(lens_text.encode(), source="converted lens", name="converted")
    except InputError as error:
        # Row k of the lens file is Zemax surface k: name the surface, not the line.
        line = int(error.key.split()[1]) if error.key and error.key.startswith("line ") else None
        key = f"surface {line - len(header)}" if line else None
        problem = re.sub(r"line (\d+)", lambda m: f"surface {int(m.group(1)) - len(header)}", error.problem)
        raise InputError(source, f"not representable as a lens file: {problem}", key=key) from None
    return lens_text


def _decode(data: bytes, source: str) -> str:
    """OpticStudio writes UTF-16 (with a BOM) or 8-bit text."""
    if data[:2] in (b"\xff\xfe", b"\xfe\xff"):
        try:
            return data.decode("utf-16")
        except UnicodeDecodeError:
            raise InputError(source, "not a text file (UTF-16 that does not decode)") from None
    if b"\x00" in data:
        raise InputError(source, "not a text file")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError:
        return data.decode("latin-1")


def _title(text: str) -> str:
    match = re.search(r"^\s*NAME\s+(.*?)\s*$", text, re.MULTILINE)
    return match.group(1) if match else ""


def _surface_records(text: str) -> dict[int, dict[str, list[str]]]:
    """For each ``SURF n``: its records' first tokens, e.g. ``{"DIAM": ["6.3", "1", ...]}``."""
    records: dict[int, dict[str, list[str]]] = {}
    current = None
    for line in text.splitlines():
        match = _SURFACE.match(line)
        if match:
            current = records.setdefault(int(match.group(1)), {})
            continue
        if current is None or not line[:1].isspace():
            current = None if line.strip() and not line[:1].isspace() else current
            continue
        tokens = line.split()
        if tokens:
            current.setdefault(tokens[0], tokens[1:])
    return records


def _read_with_rayoptics(text: str, source: str, *, stop: int | None):
    """rayoptics' OpticalModel of the file, ``stop`` its STOP surface; its chatter silenced."""
    try:
        from rayoptics.zemax import zmxread  # slow to import (Qt), an optional extra: only lens import needs it
    except ImportError:
        raise ExternalError("lens import needs rayoptics, which is not installed: "
                            "pip install 'lenscompare[zemax]' (or rayoptics>=0.9.8)") from None

    quiet = io.StringIO()
    _no_log_file(zmxread)
    try:
        with warnings.catch_warnings(), contextlib.redirect_stdout(quiet):
            warnings.simplefilter("ignore")
            # No file name: rayoptics would otherwise read (and eval) a .smx file
            # beside the input, and write one when a glass is missing.
            model, _ = zmxread.read_lens(None, text)
            sm = model["seq_model"]
            if stop is not None and sm.stop_surface != stop and 0 < stop < len(sm.ifcs) - 1:
                # rayoptics 0.9.8 drops a STOP on surface 1 (read before surface 2 exists).
                sm.set_stop(stop)
                model.update_model()
    except Exception as error:  # any failure inside the reader is a bad file
        raise InputError(source, f"rayoptics cannot read this Zemax file: "
                         f"{type(error).__name__}: {error}") from None
    return model


def _no_log_file(zmxread) -> None:
    """rayoptics' reader logs to ``zmx_read_lens.log`` in the working folder: not from us."""
    for handler in list(zmxread.logger.handlers):
        if isinstance(handler, logging.FileHandler):
            zmxread.logger.removeHandler(handler)
            handler.close()
    zmxread.logger.setLevel(logging.ERROR)


def _rows(model, records: dict, source: str) -> list[str]:
    """One lens-file row per Zemax surface between the object and the image."""
    sm = model["seq_model"]
    surfaces = range(1, len(sm.ifcs) - 1)
    if not surfaces:
        raise InputError(source, "no surfaces between the object and the image")
    computed = None
    rows = []
    for index in surfaces:
        key = f"surface {index}"
        ifc, gap = sm.ifcs[index], sm.gaps[index]
        record = records.get(index, {})
        _check_representable(ifc, record, source, key)
        curvature = float(ifc.profile.cv)
        is_stop = index == sm.stop_surface
        n_before = _medium_index(sm.gaps[index - 1].medium)
        n_d, fifth = _medium(gap.medium, record, source, key)
        if is_stop and (curvature != 0.0 or n_d != 1.0 or n_before != 1.0):
            raise InputError(source, "the stop must be a plane in air to be imported (lenscompare's stop "
                             "is a radius-0 row in air); add a dummy plane surface as stop", key=key)
        # The stop gets the size that gives the file's system aperture (FNUM, ENPD...)
        # paraxially, as OpticStudio defines it; its DIAM is a real-ray height.
        semi = _paraxial_stop_semi_diameter(model, index) if is_stop else _semi_diameter(record)
        if semi is None:
            computed = computed if computed is not None else _computed_semi_diameters(model, source)
            semi = computed[index]
            if not (semi > 0 and math.isfinite(semi)):
                raise InputError(source, "no semi-diameter in the file and none could be computed from "
                                 "the entrance pupil and fields", key=key)
        radius = "0" if is_stop else ("inf" if curvature == 0.0 else f"{1.0 / curvature:.12g}")
        thickness = float(gap.thi) if index < len(sm.ifcs) - 2 else 0.0
        n_column = "0" if is_stop else (f"{n_d:.10f}" if n_d != 1.0 else "1")
        rows.append(f"{radius}  {thickness:.12g}  {n_column}  {2.0 * semi:.12g}" + (f"  {fifth}" if fifth else ""))
    return rows


def _check_representable(ifc, record: dict, source: str, key: str) -> None:
    """Refuse what a lens file cannot hold; ``ifc`` None checks the records alone."""
    if ifc is None:
        ifc = _NO_INTERFACE
    surface_type = getattr(ifc, "z_type", None) or (record.get("TYPE") or ["STANDARD"])[0]
    if surface_type == "COORDBRK":
        raise InputError(source, "a coordinate break (tilt or decentre) cannot be imported", key=key)
    if surface_type != "STANDARD":
        raise InputError(source, f"surface type {surface_type} cannot be imported: only standard spheres "
                         f"and planes (no aspheres, toroids, gradient index, gratings)", key=key)
    if ifc.interact_mode == "reflect" or (record.get("GLAS") or [""])[0] == "MIRROR":
        raise InputError(source, "a mirror cannot be imported: lens files hold refracting surfaces only", key=key)
    conic = float(getattr(ifc.profile, "cc", 0.0) or 0.0) or _record_number(record, "CONI")
    if conic != 0.0:
        raise InputError(source, f"conic constant {conic:g}: only spheres (conic 0) can be imported", key=key)
    if getattr(ifc, "decenter", None) is not None or any(_record_number(record, k) for k in ("DECX", "DECY", "TILX", "TILY")):
        raise InputError(source, "a tilted or decentred surface cannot be imported", key=key)
    if getattr(ifc, "phase_element", None) is not None:
        raise InputError(source, "a diffractive surface cannot be imported", key=key)


class _NoInterface:
    """Stands for rayoptics' interface while only the file's records are checked."""

    z_type = None
    interact_mode = "transmit"
    profile = None
    decenter = None
    phase_element = None


_NO_INTERFACE = _NoInterface()


def _record_number(record: dict, name: str) -> float:
    try:
        return float(record[name][0])
    except (KeyError, IndexError, ValueError):
        return 0.0


def _medium_index(medium) -> float:
    return float(getattr(medium, "n", 1.0)) if type(medium).__name__ != "Air" else 1.0


def _medium(medium, record: dict, source: str, key: str) -> tuple[float, str]:
    """``(n_d, 5th column)`` of the medium after a surface ('' when it does not disperse)."""
    kind = type(medium).__name__
    glass_name = (record.get("GLAS") or [""])[0]
    if kind == "Air":
        return 1.0, ""
    if kind == "ModelGlass":  # ___BLANK n_d V_d, or a 6-digit glass code
        return float(medium.n), f"{float(medium.v):.10g}"
    if kind == "ConstantIndex" and not glass_name.upper().startswith("NOT ") and \
            not str(getattr(medium, "label", "")).startswith("not "):
        n = float(medium.n)
        return (1.0, "") if n == 1.0 else (n, "")
    glass = find_catalogue_glass(glass_name) if glass_name else None
    if glass is None:
        near = near_glass_names(glass_name) if glass_name else []
        hint = f"; near names: {', '.join(near)}" if near else ""
        raise InputError(source, f"glass {glass_name or kind!r} is not in the Schott, Ohara, Hoya, CDGM, "
                         f"Hikari or Sumita catalogues{hint}", key=key)
    return glass.index_at(D_LINE_NM), glass.name


def _paraxial_stop_semi_diameter(model, index: int) -> float | None:
    """Height at the stop of rayoptics' paraxial marginal ray (the system aperture)."""
    try:
        height = abs(float(model["analysis_results"]["parax_data"].ax_ray[index][0]))
    except (KeyError, IndexError, TypeError, AttributeError):
        return None
    return height if height > 0 and math.isfinite(height) else None


def _semi_diameter(record: dict) -> float | None:
    try:
        value = float(record["DIAM"][0])
    except (KeyError, IndexError, ValueError):
        return None
    return value if value > 0 and math.isfinite(value) else None


def _computed_semi_diameters(model, source: str) -> list[float]:
    """Clear semi-apertures from rayoptics' boundary-ray trace (OpticStudio's automatic solve)."""
    sm = model["seq_model"]
    try:
        with warnings.catch_warnings(), contextlib.redirect_stdout(io.StringIO()):
            warnings.simplefilter("ignore")
            sm.set_clear_apertures()
    except Exception as error:  # a trace that fails leaves the surfaces without a size
        raise InputError(source, f"semi-diameters missing and rayoptics could not compute them from the "
                         f"entrance pupil and fields ({type(error).__name__}: {error})") from None
    return [float(ifc.max_aperture) for ifc in sm.ifcs]
