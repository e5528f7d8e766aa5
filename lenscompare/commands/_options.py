"""Option types shared by the sub-commands: every number an option takes is
checked against its limit (:mod:`lenscompare.limits`) while the command line
is parsed, so a bad value is exit 2 naming the option before any work."""

from __future__ import annotations

import argparse
import math
from pathlib import Path

from ..atomic import check_output_file
from ..errors import InputError
from ..lenses import resolve_lens
from ..limits import MAX_SEED, MAX_SPP, MAX_THREADS
from ..reference_scenes import find_scene, shipped_scene_names
from ..scene import EFFECT_NAMES, Scene, load_scene

__all__ = ["integer_option", "number_option", "effect_list", "SPP", "SEED", "THREADS", "POSITIVE", "NON_NEGATIVE",
           "with_lens_option", "check_output_suffix", "scene_path", "load_scene_argument", "SCENE_HELP"]


def _shown(text: str) -> str:
    shown = repr(text)
    return shown if len(shown) <= 40 else shown[:37] + "..."


def integer_option(*, minimum: int, maximum: int):
    """An argparse type: a decimal integer in ``[minimum, maximum]``."""

    def parse(text: str) -> int:
        try:
            value = int(text, 10)
        except ValueError:  # also Python's cap on the digits of an integer
            value = None
        if value is None or not minimum <= value <= maximum:
            raise argparse.ArgumentTypeError(f"expected an integer from {minimum:,} to {maximum:,}, got {_shown(text)}")
        return value

    return parse


def number_option(*, positive: bool = True, minimum: float | None = None, maximum: float | None = None):
    """An argparse type: a finite number, positive (or >= 0), optionally in
    ``[minimum, maximum]``."""

    def parse(text: str) -> float:
        try:
            value = float(text)
        except ValueError:
            value = math.nan
        if not (math.isfinite(value) and (value > 0 if positive else value >= 0)):
            raise argparse.ArgumentTypeError(
                f"expected a finite number {'> 0' if positive else '>= 0'}, got {_shown(text)}")
        if (minimum is not None and value < minimum) or (maximum is not None and value > maximum):
            low = "" if minimum is None else f"from {minimum:g} "
            raise argparse.ArgumentTypeError(f"expected a number {low}to {maximum:g}, got {_shown(text)}"
                                             if maximum is not None else
                                             f"expected a number >= {minimum:g}, got {_shown(text)}")
        return value

    return parse


def effect_list(text: str) -> tuple[str, ...]:
    """An argparse type: comma-separated effect names (DESIGN.md's table)."""
    names = tuple(dict.fromkeys(n.strip() for n in text.split(",") if n.strip()))
    unknown = [n for n in names if n not in EFFECT_NAMES]
    if unknown or not names:
        got = _shown(unknown[0]) if unknown else "nothing"
        raise argparse.ArgumentTypeError(f"expected comma-separated names from {', '.join(EFFECT_NAMES)}, got {got}")
    return names


SPP = integer_option(minimum=1, maximum=MAX_SPP)
SEED = integer_option(minimum=0, maximum=MAX_SEED)
THREADS = integer_option(minimum=1, maximum=MAX_THREADS)
POSITIVE = number_option(positive=True)
NON_NEGATIVE = number_option(positive=False)


def with_lens_option(scene, text: str | None):
    """``scene`` through the lens ``--lens`` names (a shipped name, or a path
    relative to the working folder, as a user typing it means it)."""
    if text is None:
        return scene
    return scene.with_camera(lens=resolve_lens(text, source="--lens", key=None))


def check_output_suffix(path: str, suffix: str, *, option: str = "-o"):
    """The output file of a single-output command: the right suffix, and
    writable (checked now, before the work)."""
    if not str(path).lower().endswith(suffix):
        raise InputError(option, f"expected a {suffix} file name, got {_shown(str(path))}")
    return check_output_file(path, option=option)


SCENE_HELP = "a scene file, or the short name of a shipped scene (showcase, blur_disks, ...) when no such file exists"
"""The help of every command-line argument that names a scene (:func:`scene_path`)."""


def scene_path(given: str) -> Path:
    """The scene file a command-line argument means: a path, or the short name
    of a shipped scene (``showcase``) when no file of that name exists
    (:func:`lenscompare.reference_scenes.find_scene`).

    Raises
    ------
    InputError
        A bare name that is neither a file nor a shipped scene, listing the shipped ones.
    """
    path = find_scene(given)
    if not path.exists() and Path(given).name == given and not given.endswith(".toml"):
        raise InputError(given, "no such scene file, nor a shipped scene of that name (shipped: "
                                + ", ".join(shipped_scene_names()) + ")")
    return path


def load_scene_argument(given: str) -> Scene:
    """The scene a command-line argument names (:func:`scene_path`), loaded."""
    return load_scene(scene_path(given))

