"""Triangle meshes from OBJ and PLY files (``type = "mesh"`` objects).

The files are read by trimesh (polygons are triangulated, nothing else is
changed: ``process=False``). trimesh's own errors do not say where a file is
wrong, so when it fails, or hands back something unusable (no triangles, a
non-finite coordinate, an index out of range), the text of the file is
scanned line by line for the first line that breaks the format, and the error
names the file and that line: ``bunny.obj: line 12: ...``. Binary PLY bodies
have no lines; their errors name the header line or say the body does not
match the header.
"""

from __future__ import annotations

import math
import os
import re
from pathlib import Path

import numpy as np

from .errors import InputError

__all__ = ["MESH_SUFFIXES", "read_mesh"]

MESH_SUFFIXES = (".obj", ".ply")


def read_mesh(path: str | os.PathLike) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) float64 and triangles (m, 3) int32 of an OBJ or PLY file.

    Raises
    ------
    InputError
        Unreadable file, unknown suffix, or a malformed file: the message names
        the file and, where the format has lines, the first bad one.
    """
    path = Path(path)
    suffix = path.suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise InputError(path, f"expected an OBJ or PLY mesh file ({', '.join(MESH_SUFFIXES)}), got {suffix!r}")
    try:
        data = path.read_bytes()
    except OSError as error:
        raise InputError(path, f"cannot read mesh file ({error.strerror or error})") from None
    import trimesh  # ~1 s to import: only scenes with meshes pay for it

    try:
        mesh = trimesh.load(trimesh.util.wrap_as_stream(data), file_type=suffix[1:], force="mesh", process=False)
        vertices = np.asarray(mesh.vertices, dtype=np.float64)
        faces = np.asarray(mesh.faces, dtype=np.int64)
        problem = None
    except Exception as error:  # trimesh raises many kinds (ValueError, IndexError, KeyError...) for bad files
        vertices, faces, problem = None, None, f"{type(error).__name__}: {error}"
    if problem is None:
        if faces.ndim != 2 or len(faces) == 0:
            problem = "no triangles"
        elif not np.isfinite(vertices).all():
            problem = "a vertex coordinate is not a finite number"
        elif faces.min() < 0 or faces.max() >= len(vertices):
            problem = "a face refers to a vertex that does not exist"
    # trimesh skips some broken lines silently (a face of two vertices): when fewer
    # vertices or faces came back than the file declares, it is checked line by line too.
    failed = problem is not None
    line, detail = _locate(data, suffix, failed=failed) if failed or _dropped(data, suffix, vertices, faces) \
        else (None, None)
    if problem is not None or detail is not None:
        raise InputError(path, detail or f"not a valid {suffix[1:].upper()} mesh ({problem})", key=line)
    return vertices, faces.astype(np.int32)


def _dropped(data: bytes, suffix: str, vertices: np.ndarray, faces: np.ndarray) -> bool:
    """Whether trimesh returned fewer vertices or faces than the file declares (a cheap count)."""
    if suffix == ".obj":
        n_vertices = len(re.findall(rb"^[ \t]*v[ \t]", data, flags=re.MULTILINE))
        n_faces = len(re.findall(rb"^[ \t]*f[ \t]", data, flags=re.MULTILINE))
    else:
        header = data[:max(data.find(b"end_header"), 0)]
        counts = dict(re.findall(rb"^element[ \t]+(\w+)[ \t]+(\d+)", header, flags=re.MULTILINE))
        n_vertices, n_faces = int(counts.get(b"vertex", 0)), int(counts.get(b"face", 0))
    return len(vertices) < n_vertices or len(faces) < n_faces


def _locate(data: bytes, suffix: str, *, failed: bool) -> tuple[str | None, str | None]:
    """("line N", what is wrong there) for the first line that breaks the format; (None, problem)
    for a problem with no line; (None, None) when the text follows the format."""
    try:
        text = data.decode("utf-8")
    except UnicodeDecodeError:
        if suffix == ".obj":
            return None, "not a text file (OBJ is text)"
        text = None
    if suffix == ".obj":
        return _locate_obj(text)
    return _locate_ply(data, failed=failed)


def _number(token: str) -> float | None:
    try:
        value = float(token)
    except ValueError:
        return None
    return value if math.isfinite(value) else None


def _locate_obj(text: str) -> tuple[str | None, str | None]:
    lines = text.splitlines()
    n_vertices = sum(1 for line in lines if line.split()[:1] == ["v"])
    seen = 0
    for number, line in enumerate(lines, start=1):
        tokens = line.split("#", 1)[0].split()
        if not tokens:
            continue
        if tokens[0] == "v":
            seen += 1
            if len(tokens) < 4 or any(_number(t) is None for t in tokens[1:4]):
                return f"line {number}", f"expected 'v x y z' with three finite numbers, got {line.strip()!r}"
        elif tokens[0] == "f":
            if len(tokens) < 4:
                return f"line {number}", f"a face needs at least three vertices, got {line.strip()!r}"
            for ref in tokens[1:]:
                head = ref.split("/")[0]
                try:
                    index = int(head)
                except ValueError:
                    return f"line {number}", f"expected vertex numbers, got {ref!r} in {line.strip()!r}"
                if index == 0 or not (-seen <= index <= n_vertices):
                    return f"line {number}", (f"vertex {index} does not exist ({n_vertices} vertices in the file, "
                                              "numbered from 1)")
    if n_vertices == 0:
        return None, "no vertices ('v' lines)"
    if not any(line.split()[:1] == ["f"] for line in lines):
        return None, "no faces ('f' lines)"
    return None, None


def _locate_ply(data: bytes, *, failed: bool) -> tuple[str | None, str | None]:
    end = data.find(b"end_header")
    if not data.startswith(b"ply"):
        return "line 1", "a PLY file starts with 'ply'"
    if end < 0:
        return None, "no 'end_header' line"
    header = data[:end].decode("ascii", errors="replace").splitlines()
    elements, fmt = [], None
    for number, line in enumerate(header, start=1):
        tokens = line.split()
        if not tokens or tokens[0] in ("ply", "comment", "obj_info", "property"):
            continue
        if tokens[0] == "format":
            fmt = tokens[1] if len(tokens) > 1 else None
            if fmt not in ("ascii", "binary_little_endian", "binary_big_endian"):
                return f"line {number}", f"unknown PLY format {line.strip()!r}"
        elif tokens[0] == "element":
            if len(tokens) != 3 or not tokens[2].isdigit():
                return f"line {number}", f"expected 'element NAME COUNT', got {line.strip()!r}"
            elements.append((tokens[1], int(tokens[2])))
        else:
            return f"line {number}", f"unknown PLY header line {line.strip()!r}"
    counts = dict(elements)
    if counts.get("vertex", 0) == 0 or counts.get("face", 0) == 0:
        return None, "the header declares no vertices or no faces"
    if fmt != "ascii":  # no lines to point at
        return (None, "the binary body does not match the header (truncated or corrupt)") if failed else (None, None)
    body = data[end:].decode("ascii", errors="replace").splitlines()
    first = len(header) + 2  # the line after end_header
    number = first
    for name, count in elements:
        for _ in range(count):
            if number - first >= len(body) - 1:
                return f"line {number}", f"the file ends inside element {name!r} ({count} declared)"
            tokens = body[number - first + 1].split()
            values = [_number(t) for t in tokens]
            if any(v is None for v in values):
                return f"line {number}", f"expected numbers, got {body[number - first + 1].strip()!r}"
            if name == "vertex" and len(values) < 3:
                return f"line {number}", "a vertex needs x, y and z"
            if name == "face":
                n = int(values[0]) if values else 0
                indices = values[1:1 + n]
                if n < 3 or len(indices) < n or any(not (0 <= i < counts["vertex"]) for i in indices):
                    return f"line {number}", (f"expected 'N i1 ... iN' with N >= 3 vertex indices below "
                                              f"{counts['vertex']}, got {body[number - first + 1].strip()!r}")
            number += 1
    return None, None
