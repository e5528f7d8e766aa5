"""A second barrier around POV-Ray: its writes confined to its working folder.

The exporter's escaping is the first barrier (no string from a scene file
reaches the SDL outside a ``//`` comment, through ``repr``). Should it ever
fail, POV-Ray's own I/O restrictions do not hold on Debian: the system-wide
``/etc/povray/3.7/povray.conf`` grants ``read+write* = /tmp`` (all of /tmp,
recursively), and a user ``povray.conf`` can only add paths, not remove that
one. So the runner starts POV-Ray under two operating-system limits:

- **Landlock** (Linux 5.13 and later, unprivileged): before ``exec``, the child
  process restricts itself so that creating, writing, truncating, renaming or
  removing files is allowed only beneath its private working folder. Reading
  is left to POV-Ray's own rules (its include folders, ``/etc/povray``, its
  working folder and ``/tmp``). Where the kernel has no Landlock (or a
  seccomp profile forbids it), this barrier is absent:
  :func:`landlock_abi` says which.
- **RLIMIT_FSIZE**: no file POV-Ray writes can grow beyond a limit set from
  the image it is asked for, so even its working folder cannot be filled.

``tests/test_povray_sandbox.py`` runs an SDL file that writes outside its
folder: POV-Ray alone writes it; under the sandbox it cannot.
"""

from __future__ import annotations

import ctypes
import os
import platform
import resource

__all__ = ["landlock_abi", "confined_writes"]

# Linux system call numbers (the same on every architecture with the generic table).
_SYS_LANDLOCK_CREATE_RULESET = 444
_SYS_LANDLOCK_ADD_RULE = 445
_SYS_LANDLOCK_RESTRICT_SELF = 446
_LANDLOCK_CREATE_RULESET_VERSION = 1
_LANDLOCK_RULE_PATH_BENEATH = 1
_PR_SET_NO_NEW_PRIVS = 38

# File-system access rights (linux/landlock.h): every way of changing the tree.
_WRITE_FILE = 1 << 1
_REMOVE_DIR, _REMOVE_FILE = 1 << 4, 1 << 5
_MAKE_CHAR, _MAKE_DIR, _MAKE_REG, _MAKE_SOCK, _MAKE_FIFO, _MAKE_BLOCK, _MAKE_SYM = (1 << n for n in range(6, 13))
_REFER = 1 << 13     # ABI 2: renames and links across folders
_TRUNCATE = 1 << 14  # ABI 3


class _RulesetAttr(ctypes.Structure):
    _fields_ = [("handled_access_fs", ctypes.c_uint64)]


class _PathBeneathAttr(ctypes.Structure):
    _pack_ = 1
    _fields_ = [("allowed_access", ctypes.c_uint64), ("parent_fd", ctypes.c_int32)]


def _libc():
    libc = ctypes.CDLL(None, use_errno=True)
    libc.syscall.restype = ctypes.c_long
    return libc


def landlock_abi() -> int:
    """The kernel's Landlock ABI version; 0 when unavailable (not Linux, an
    old kernel, or disabled)."""
    if platform.system() != "Linux":
        return 0
    try:
        version = _libc().syscall(_SYS_LANDLOCK_CREATE_RULESET, None, ctypes.c_size_t(0),
                                  ctypes.c_uint32(_LANDLOCK_CREATE_RULESET_VERSION))
    except (OSError, AttributeError):
        return 0
    return max(0, int(version))


def _write_rights(abi: int) -> int:
    rights = (_WRITE_FILE | _REMOVE_DIR | _REMOVE_FILE | _MAKE_CHAR | _MAKE_DIR | _MAKE_REG | _MAKE_SOCK
              | _MAKE_FIFO | _MAKE_BLOCK | _MAKE_SYM)
    if abi >= 2:
        rights |= _REFER
    if abi >= 3:
        rights |= _TRUNCATE
    return rights


def confined_writes(folder: str | os.PathLike, *, max_file_bytes: int):
    """``(preexec_fn, pass_fds, landlock)`` for :func:`subprocess.run`: the
    child may write only beneath ``folder`` (when Landlock is available) and
    no file larger than ``max_file_bytes``.

    The ruleset is built here, in the parent; the child only makes two system
    calls and sets one limit before ``exec``. Close the ruleset descriptor
    (the second item's only element) after the run.
    """
    abi = landlock_abi()
    ruleset_fd = -1
    libc = _libc()
    if abi:
        rights = _write_rights(abi)
        attr = _RulesetAttr(rights)
        ruleset_fd = libc.syscall(_SYS_LANDLOCK_CREATE_RULESET, ctypes.byref(attr),
                                  ctypes.c_size_t(ctypes.sizeof(attr)), ctypes.c_uint32(0))
        if ruleset_fd >= 0:
            folder_fd = os.open(folder, os.O_PATH | os.O_DIRECTORY | os.O_CLOEXEC)
            try:
                rule = _PathBeneathAttr(rights, folder_fd)
                added = libc.syscall(_SYS_LANDLOCK_ADD_RULE, ctypes.c_int(ruleset_fd),
                                     ctypes.c_int(_LANDLOCK_RULE_PATH_BENEATH), ctypes.byref(rule), ctypes.c_uint32(0))
            finally:
                os.close(folder_fd)
            if added != 0:
                os.close(ruleset_fd)
                ruleset_fd = -1
    prctl, syscall = libc.prctl, libc.syscall  # looked up now, not in the child

    def preexec() -> None:
        # In the child, between fork and exec: no allocation, nothing that can block.
        resource.setrlimit(resource.RLIMIT_FSIZE, (max_file_bytes, max_file_bytes))
        if ruleset_fd >= 0:
            if prctl(_PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0) != 0 or syscall(_SYS_LANDLOCK_RESTRICT_SELF, ruleset_fd, 0) != 0:
                os._exit(126)  # never run POV-Ray half confined

    return preexec, ((ruleset_fd,) if ruleset_fd >= 0 else ()), ruleset_fd >= 0
