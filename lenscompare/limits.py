"""What lenscompare accepts, and how much it reads: every limit in one place.

Each limit keeps a number finite or an allocation possible; the README's
"Limits" table gives the reason for each.  Values past a limit are refused at
the edge (scene, lens and check files, command-line options) with exit 2,
before anything is allocated or rendered.
"""

from __future__ import annotations

import os
from pathlib import Path

from .errors import InputError

__all__ = [
    "MAX_SPP", "MAX_SEED", "MAX_SIDE_PX", "MAX_PIXELS", "MAX_SAMPLES", "MAX_THREADS", "MAX_COLOR",
    "MAX_LENGTH_M", "MAX_SPEED_M_PER_S", "MAX_SHUTTER_S", "MIN_CHECKER_M", "MIN_F_NUMBER", "MAX_F_NUMBER", "MIN_FOCAL_LENGTH_MM", "MAX_FOCAL_LENGTH_MM",
    "MIN_FILM_MM", "MAX_FILM_MM", "MAX_LIGHTS", "MAX_NAME_CHARS", "MAX_FILE_BYTES", "MAX_TOML_DEPTH",
    "RENDER_BYTES_PER_PIXEL", "ADAPTIVE_BYTES_PER_PIXEL", "read_input_bytes", "available_memory_bytes",
    "check_render_budget", "format_bytes",
]

MAX_SPP = 2**20
"""Samples per pixel: the native per-pixel sample counter's cap (also for adaptive passes)."""
MAX_SEED = 2**64 - 1
"""Seeds are the native tracer's unsigned 64-bit integers."""
MAX_SIDE_PX = 65_536
"""Image width and height, px."""
MAX_PIXELS = 2**27
"""Pixels of one image (134 M, e.g. 14,000 x 9,600): about 2 GB of float32 image and variance."""
MAX_SAMPLES = 2**40
"""Samples of one render (1.1e12: about a day on two cores at 12 M samples/s)."""
MAX_THREADS = 4096
"""``--threads``; more than the machine's cores are not started (see render)."""
MAX_COLOR = 1e6
"""Every colour component (radiance, albedo, intensity): products of two stay far inside float32."""
MAX_LENGTH_M = 1e9
"""Every scene coordinate and size, m: Embree computes in float32."""
MAX_SPEED_M_PER_S = 299_792_458.0
"""Every velocity component (camera and objects), m/s: nothing outruns light. Each
moving thing must also stay within MAX_LENGTH_M over the shutter (scene.py)."""
MAX_SHUTTER_S = 86_400.0
"""``render.shutter`` times, s: a day, longer than any long exposure."""
MIN_CHECKER_M = 1e-6
"""Checker cube size, m: p / size stays below 2^63 for every point within MAX_LENGTH_M."""
MIN_F_NUMBER = 0.5
"""The fastest lens in air (N = 1 / (2 NA), NA <= 1)."""
MAX_F_NUMBER = 10_000.0
"""The slowest stop: the lens system's exit-pupil search renders the flat field right up to
f/20000 (its centre read 1.001) and loses light past it (f/50000: 0.978; f/1e5: a fifth of the
pixels black; f/1e9: all black), as the pupil nears the search's resolution. Diffraction blurs
13 mm at f/10000 anyway."""
MIN_FOCAL_LENGTH_MM, MAX_FOCAL_LENGTH_MM = 0.01, 1e6
"""Focal lengths, mm (a scene's focal_length_mm and a lens's EFL)."""
MIN_FILM_MM, MAX_FILM_MM = 0.01, 10_000.0
"""Film width and height, mm."""
MAX_LIGHTS = 10_000
"""Point lights of one scene: keeps the summed lit radiance and its square inside float32."""
MAX_NAME_CHARS = 200
"""Scene names (they become file names)."""
MAX_FILE_BYTES = 16 * 2**20
"""Scene, lens and check-config files are read up to 16 MiB."""
MAX_TOML_DEPTH = 32
"""Nesting of TOML arrays and tables (a scene needs 4)."""

# Peak bytes per pixel of a render and its EXR write: measured 29 (uniform)
# and 135 (adaptive: two passes, counts, float64 blending) by
# bench/bench_memory.py; refused with a margin for the allocator.
RENDER_BYTES_PER_PIXEL = 64
ADAPTIVE_BYTES_PER_PIXEL = 200


def read_input_bytes(path: str | os.PathLike, *, what: str, max_bytes: int = MAX_FILE_BYTES) -> bytes:
    """The bytes of an input file, refused when it is not a regular file or too large.

    Devices such as ``/dev/zero`` never end; folders are not files. Both are
    refused before reading.

    Raises
    ------
    InputError
        Naming the file and what is wrong (missing, a folder, not a regular
        file, larger than ``max_bytes``, unreadable).
    """
    source = os.fspath(path)
    file = Path(source)
    try:
        if file.is_dir():
            raise InputError(source, f"is a folder, expected a {what}")
        if not file.exists():
            raise InputError(source, f"no such {what}")
        if not file.is_file():
            raise InputError(source, f"is not a regular file (a device or a pipe), expected a {what}")
        with open(file, "rb") as stream:
            data = stream.read(max_bytes + 1)
    except OSError as error:
        raise InputError(source, f"cannot read {what}: {error.strerror or error}") from None
    if len(data) > max_bytes:
        raise InputError(source, f"{what} is larger than {format_bytes(max_bytes)} (the limit for input files)")
    return data


def format_bytes(n: float) -> str:
    """``1536`` -> ``"1.5 KiB"``."""
    for unit in ("bytes", "KiB", "MiB", "GiB", "TiB"):
        if abs(n) < 1024 or unit == "TiB":
            return f"{n:.0f} {unit}" if unit == "bytes" else f"{n:.1f} {unit}"
        n /= 1024
    return f"{n:.1f} TiB"  # pragma: no cover


def _read_int(path: str) -> int | None:
    try:
        text = Path(path).read_text().split()[0]
    except (OSError, IndexError):
        return None
    return int(text) if text.isdigit() else None


def available_memory_bytes() -> int | None:
    """Memory this process can still allocate: the kernel's MemAvailable, or
    the cgroup's limit minus its use when that is smaller; None if unknown."""
    candidates = []
    try:
        for line in Path("/proc/meminfo").read_text().splitlines():
            if line.startswith("MemAvailable:"):
                candidates.append(int(line.split()[1]) * 1024)
    except (OSError, ValueError, IndexError):
        pass
    cgroups = (("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current"),  # v2, then v1
               ("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes"))
    for limit, usage in cgroups:
        cap, used = _read_int(limit), _read_int(usage)
        if cap is not None and used is not None and cap < 2**60:
            candidates.append(max(0, cap - used))
    return min(candidates) if candidates else None


def check_render_budget(width_px: int, height_px: int, spp: int, *, adaptive: bool = False,
                        source: str = "<scene>") -> None:
    """Refuse, before allocating, a render past :data:`MAX_PIXELS` pixels or
    :data:`MAX_SAMPLES` samples, or one whose image needs more memory than
    the machine has free.

    Raises
    ------
    InputError
        Naming ``source`` (the scene file) and the key, with the figures.
    """
    pixels = width_px * height_px
    if pixels > MAX_PIXELS:
        raise InputError(source, f"{width_px}x{height_px} = {pixels:,} pixels, more than the limit {MAX_PIXELS:,}",
                         key="camera.resolution")
    samples = pixels * spp
    if samples > MAX_SAMPLES:
        raise InputError(source, f"{width_px}x{height_px} pixels x {spp:,} spp = {samples:.3g} samples, more than "
                         f"the limit {MAX_SAMPLES:.3g} for one render (about a day on two cores); lower --spp "
                         "or the resolution", key="render.spp")
    needed = pixels * (ADAPTIVE_BYTES_PER_PIXEL if adaptive else RENDER_BYTES_PER_PIXEL)
    free = available_memory_bytes()
    if free is not None and needed > free:
        raise InputError(source, f"a {width_px}x{height_px} render needs about {format_bytes(needed)} of memory; "
                         f"this machine has {format_bytes(free)} free", key="camera.resolution")
