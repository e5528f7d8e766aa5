"""The two kinds of failure the command line distinguishes.

Every error a user can cause is an :class:`InputError` (exit status 2); a tool
outside the project that is missing or fails is an :class:`ExternalError` (exit
status 1).  Both carry one human sentence that names the source of the problem,
so the command line can print it without a traceback.
"""

from __future__ import annotations

import os

__all__ = ["LensCompareError", "InputError", "ExternalError"]


class LensCompareError(Exception):
    """Base class: an error with a one-line message and an exit status."""

    exit_status = 1


class InputError(LensCompareError):
    """Bad input: an unreadable or invalid scene, lens, image or option.

    Parameters
    ----------
    source : str or os.PathLike
        The file (or option) the problem is in, e.g. ``"scene.toml"`` or
        ``"--spp"``.
    problem : str
        What is wrong and what was expected.
    key : str, optional
        Dotted key or line inside the source, e.g. ``"camera.f_number"`` or
        ``"line 7"``.
    """

    exit_status = 2

    def __init__(self, source: str | os.PathLike, problem: str, *, key: str | None = None):
        self.source = os.fspath(source)
        self.key = key
        self.problem = problem
        where = f"{self.source}: {key}" if key else self.source
        super().__init__(f"{where}: {problem}")

    def __reduce__(self):
        # Pickled whole, so an error raised in a Dask task arrives as it was.
        return _input_error, (type(self), self.source, self.problem, self.key)


def _input_error(cls, source, problem, key):
    return cls(source, problem, key=key)


class ExternalError(LensCompareError):
    """An outside tool (POV-Ray, a browser) is missing or failed."""

    exit_status = 1
