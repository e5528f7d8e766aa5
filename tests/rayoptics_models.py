"""Independent optical models for the tests: lens files rebuilt in rayoptics.

The rows are read here with plain string splitting, not with lenscompare's
parser, and the indices at a wavelength come from the contract's Cauchy
formula written out again here (Abbe numbers) or from rayoptics' own glass
handling (catalogue names), so a test that compares with these models can
fail when lenscompare is wrong.
"""

from __future__ import annotations

import math
from pathlib import Path

F_NM, C_NM, D_NM = 486.13, 656.27, 587.56


def lens_rows(path: Path) -> list[list[str]]:
    """The surface rows of a lens file as lists of tokens."""
    rows = []
    for line in Path(path).read_text().splitlines():
        tokens = line.split("#", 1)[0].split()
        if tokens:
            rows.append(tokens)
    return rows


def cauchy_index(n_d: float, abbe_v_d: float, wavelength_nm: float) -> float:
    """n(λ) = A + B/λ² through n_d at 587.56 nm with n_F − n_C = (n_d − 1)/V_d (DESIGN.md)."""
    b = (n_d - 1.0) / abbe_v_d / (1.0 / F_NM**2 - 1.0 / C_NM**2)
    return n_d - b / D_NM**2 + b / wavelength_nm**2


def rayoptics_model(path: Path, *, wavelength_nm: float):
    """A rayoptics OpticalModel of the lens file, object at infinity.

    Abbe-number media become constant indices at ``wavelength_nm``; glass
    names become rayoptics' catalogue glasses (evaluated by rayoptics at the
    wavelength it is asked for).
    """
    from opticalglass import glassfactory
    from opticalglass.opticalmedium import ConstantIndex
    # Not rayoptics.environment: it imports the Qt GUI (seconds).
    from rayoptics.optical.opticalmodel import OpticalModel
    from rayoptics.raytr.opticalspec import FieldSpec, PupilSpec, WvlSpec

    opm = OpticalModel()
    sm, osp = opm["seq_model"], opm["optical_spec"]
    osp["pupil"] = PupilSpec(osp, key=["object", "epd"], value=1.0)
    osp["fov"] = FieldSpec(osp, key=["object", "angle"], flds=[0.0])
    osp["wvls"] = WvlSpec([(wavelength_nm, 1.0)], ref_wl=0)
    opm.radius_mode = True
    sm.gaps[0].thi = 1e10
    for tokens in lens_rows(path):
        radius, thickness, n_d = float(tokens[0]), float(tokens[1]), float(tokens[2])
        radius = 0.0 if math.isinf(radius) else radius  # rayoptics: radius 0 is a plane
        n_d = 1.0 if n_d == 0 else n_d
        fifth = tokens[4] if len(tokens) == 5 else "0"
        sm.add_surface([radius, thickness])
        try:
            abbe = float(fifth)
        except ValueError:  # a glass name: the glass object rayoptics itself uses
            medium = glassfactory.create_glass(fifth, ["Schott", "Ohara", "Hoya", "CDGM"])
        else:
            n = cauchy_index(n_d, abbe, wavelength_nm) if abbe and n_d != 1.0 else n_d
            medium = ConstantIndex(n, f"n:{n}")
        sm.gaps[sm.cur_surface].medium = medium
        sm.ifcs[sm.cur_surface].set_max_aperture(float(tokens[3]) / 2)
        if float(tokens[0]) == 0.0:
            sm.set_stop()
    opm.update_model()
    return opm


def back_focal_length_mm(path: Path, *, wavelength_nm: float) -> float:
    """rayoptics' paraxial back focal length of the lens at one wavelength."""
    from rayoptics.parax.firstorder import compute_first_order

    opm = rayoptics_model(path, wavelength_nm=wavelength_nm)
    _, _, fod = compute_first_order(opm, opm["seq_model"].stop_surface, wavelength_nm)
    return fod.bfl
