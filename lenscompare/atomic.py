"""Atomic output: write to a temporary file beside the target, then rename.

A failed or interrupted run leaves no partial file and never replaces a good
one. This module is also the one place output paths are checked:

- :func:`check_output_file` / :func:`prepare_output_dir` ask the file system,
  before any work, whether the output can be created (a read-only folder is
  an exit-2 error up front, not a traceback after a long render);
- :func:`safe_file_name` turns a string from an input file (a scene's
  ``name``) into a file name that cannot leave its folder, and
  ``atomic_output(..., within=DIR)`` refuses any target outside ``DIR``;
- temporary files are named ``.NAME.lctmp<pid>-<host>-<random>.tmp<suffix>``:
  SIGINT/SIGTERM remove them (:mod:`lenscompare.interrupts`), and one left by
  a killed process (SIGKILL, power loss) is removed by the next write into
  that folder once its process is gone.
"""

from __future__ import annotations

import contextlib
import hashlib
import os
import re
import secrets
import socket
import time
from pathlib import Path

from . import interrupts
from .errors import ExternalError, InputError

__all__ = ["atomic_output", "check_output_file", "prepare_output_dir", "safe_file_name", "unique_file_names",
           "sweep_stale_temporaries", "is_temporary_name"]

_HOST = hashlib.sha1(socket.gethostname().encode()).hexdigest()[:6]
_TEMPORARY = re.compile(r"\A\..*\.lctmp(?P<pid>\d+)-(?P<host>[0-9a-f]{6})-[0-9a-f]+\.tmp(\.[^.]*)?\Z", re.DOTALL)
# Before the pid was in the name (mkstemp's eight characters); removed when an hour old.
_OLD_TEMPORARY = re.compile(r"\A\..+\.[a-z0-9_]{8}\.tmp(\.[A-Za-z0-9]+)?\Z", re.DOTALL)
_OLD_AGE_S = 3600.0
_NAME_IN_TEMPORARY = 100  # characters of the target's name kept in its temporary's name
_SAFE = re.compile(r"[^A-Za-z0-9._-]")


def safe_file_name(text: str, *, fallback: str = "scene", max_chars: int = 100) -> str:
    """A file name made from ``text`` that stays in its folder.

    Keeps ASCII letters, digits, ``.``, ``_`` and ``-``; every other character
    (``/``, ``\\``, NUL, spaces, control and non-ASCII characters) becomes
    ``_``; leading dots and dashes go (no hidden files, no ``..``, nothing
    read as an option); at most ``max_chars`` characters; ``fallback`` when
    nothing is left.

    Examples
    --------
    >>> safe_file_name("../../etc/passwd"), safe_file_name("/abs/x"), safe_file_name("..")
    ('_.._etc_passwd', '_abs_x', 'scene')
    >>> safe_file_name("showcase"), safe_file_name("My scene: f/2")
    ('showcase', 'My_scene__f_2')
    """
    name = _SAFE.sub("_", str(text)).lstrip(".-")[:max_chars].rstrip(".")
    return name if name.strip("_") else fallback


def unique_file_names(names, **options) -> dict[str, str]:
    """:func:`safe_file_name` of each name, with ``-2``, ``-3``... where two
    names would share one (``"a b"`` and ``"a_b"``)."""
    result, taken = {}, set()
    for name in names:
        stem = base = safe_file_name(name, **options)
        count = 1
        while stem.lower() in taken:  # case-insensitive file systems too
            count += 1
            stem = f"{base}-{count}"
        taken.add(stem.lower())
        result[name] = stem
    return result


def is_temporary_name(name: str) -> bool:
    """True for the name of one of our temporary files (either naming)."""
    return bool(_TEMPORARY.match(name) or _OLD_TEMPORARY.match(name))


def _alive(pid: int) -> bool:
    if pid == os.getpid():
        return True
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    except OSError:  # e.g. another user's process: it exists
        return True
    return True


def sweep_stale_temporaries(folder: str | os.PathLike) -> list[Path]:
    """Remove our temporary files in ``folder`` whose process is gone (and
    old-style ones an hour old); return what was removed. Never raises."""
    removed = []
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return removed
    now = time.time()
    for entry in entries:
        match = _TEMPORARY.match(entry.name)
        try:
            if match:
                stale = match["host"] == _HOST and not _alive(int(match["pid"]))
            elif _OLD_TEMPORARY.match(entry.name):
                stale = now - entry.stat(follow_symlinks=False).st_mtime > _OLD_AGE_S
            else:
                continue
            if stale and entry.is_file(follow_symlinks=False):
                os.unlink(entry.path)
                removed.append(Path(entry.path))
        except OSError:
            continue
    return removed


def _temporary_path(target: Path, folder: Path) -> Path:
    name = target.name[:_NAME_IN_TEMPORARY]
    return folder / f".{name}.lctmp{os.getpid()}-{_HOST}-{secrets.token_hex(4)}.tmp{target.suffix[:16]}"


def _create_temporary(target: Path, folder: Path) -> Path:
    """Create an empty temporary file beside ``target`` (mode as a new file's)."""
    for _ in range(100):
        tmp = _temporary_path(target, folder)
        try:
            fd = os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666)  # the umask applies
        except FileExistsError:
            continue
        os.close(fd)
        return tmp
    raise FileExistsError(f"no free temporary name beside {target}")  # pragma: no cover


def _folder_of(target: Path) -> Path:
    return target.parent if str(target.parent) else Path(".")


def check_output_file(path: str | os.PathLike, *, option: str = "-o") -> Path:
    """Check, before any work, that ``path`` can be written (its folder exists
    and takes a new file); return it as a Path.

    Creates and removes one temporary file in the folder: only writing tells
    (permissions, read-only mounts, quotas). Also sweeps stale temporaries.

    Raises
    ------
    InputError
        Naming ``option`` and why the file cannot be written.
    """
    target = Path(path)
    folder = _folder_of(target)
    if not folder.exists():
        raise InputError(option, f"folder {str(folder)!r} for {str(target)!r} does not exist")
    if not folder.is_dir():
        raise InputError(option, f"{str(folder)!r} is not a folder, so {str(target)!r} cannot be written")
    if target.is_dir():
        raise InputError(option, f"{str(target)!r} is a folder, expected a file name")
    sweep_stale_temporaries(folder)
    with interrupts.deferred():
        try:
            os.unlink(_create_temporary(target, folder))
        except OSError as error:
            raise InputError(option, f"cannot write {str(target)!r}: {error.strerror or error}") from None
    return target


def prepare_output_dir(path: str | os.PathLike, *, option: str = "-o") -> Path:
    """Create the output folder ``path`` (and its parents) and check that it
    takes new files; return it. Call after the inputs are validated, before
    the work.

    Raises
    ------
    InputError
        Naming ``option``: ``path`` is a file, or cannot be created or written.
    """
    out = Path(path)
    if out.exists() and not out.is_dir():
        raise InputError(option, f"{str(out)!r} exists and is not a folder")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as error:
        raise InputError(option, f"cannot create folder {str(out)!r}: {error.strerror or error}") from None
    check_output_file(out / "probe", option=option)
    return out


def _inside(target: Path, folder: Path) -> bool:
    resolved, root = target.resolve(), folder.resolve()
    return resolved == root or root in resolved.parents


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike, *, option: str = "-o", within: str | os.PathLike | None = None,
                  final: bool = False):
    """Yield a temporary path; on success rename it onto ``path``.

    Parameters
    ----------
    path : str or os.PathLike
        Final file. Its folder must exist (an InputError naming ``option``
        otherwise).
    option : str, optional
        The command-line option the path came from, for messages.
    within : path, optional
        The output folder; a ``path`` that resolves outside it is refused
        (a second barrier behind :func:`safe_file_name`).
    final : bool, optional
        This is the command's last output: once it is renamed into place, a
        SIGINT/SIGTERM no longer fails the command (:mod:`lenscompare.interrupts`).

    Raises
    ------
    InputError
        The folder does not exist, the target is a folder or lies outside
        ``within``.
    ExternalError
        The operating system refused the write (disk full, permissions).
    """
    target = Path(path)
    folder = _folder_of(target)
    if within is not None and not _inside(target, Path(within)):
        raise InputError(option, f"{str(target)!r} lies outside the output folder {str(within)!r}")
    if not folder.is_dir():
        raise InputError(option, f"folder {str(folder)!r} for {str(target)!r} does not exist")
    if target.is_dir():
        raise InputError(option, f"{str(target)!r} is a folder, expected a file name")
    sweep_stale_temporaries(folder)
    with interrupts.deferred():  # no signal between creating the file and owning its removal
        try:
            tmp = _create_temporary(target, folder)
        except OSError as error:
            raise ExternalError(f"cannot write {str(target)!r}: {error.strerror or error}") from None
    try:
        try:
            yield tmp
        except OSError as error:
            raise ExternalError(f"cannot write {str(target)!r}: {error.strerror or error}") from None
        with interrupts.deferred():  # the rename is the commit: a signal waits until it is done
            try:
                os.replace(tmp, target)
            except OSError as error:
                raise ExternalError(f"cannot write {str(target)!r}: {error.strerror or error}") from None
            if final:
                interrupts.mark_finished(target)
    except BaseException:
        with interrupts.deferred(), contextlib.suppress(OSError):
            os.unlink(tmp)
        raise
