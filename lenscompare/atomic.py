"""Atomic output: write to a temporary file beside the target, then rename.

A failed run leaves no partial file and never replaces a good one.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path

from .errors import InputError

__all__ = ["atomic_output"]


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, *, option: str = "-o"):
    """Yield a temporary path; on success rename it onto ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        Final file. Its folder must exist (an InputError naming ``option``
        otherwise).
    option : str, optional
        The command-line option the path came from, for messages.
    """
    target = Path(path)
    folder = target.parent if str(target.parent) else Path(".")
    if not folder.is_dir():
        raise InputError(option, f"folder {str(folder)!r} for {str(target)!r} does not exist")
    if target.is_dir():
        raise InputError(option, f"{str(target)!r} is a folder, expected a file name")
    # Same folder, so the final rename is atomic; keep the suffix for writers
    # that look at it.
    fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=f".tmp{target.suffix}", dir=folder)
    os.close(fd)
    # mkstemp makes the file private (0600); give it the usual mode for new files.
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)
    try:
        yield Path(tmp)
        os.replace(tmp, target)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise
