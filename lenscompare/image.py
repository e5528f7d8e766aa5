"""Images: linear float RGB with metadata, OpenEXR files and sRGB PNG previews.

Pixels are linear (radiance, or normalised irradiance for the lens system),
float32, shape (height, width, 3), row 0 at the top of the picture.
"""

from __future__ import annotations

import json
import os
from dataclasses import dataclass, field
from typing import Any

import numpy as np
import OpenEXR

from .atomic import atomic_output
from .cameras import CameraModel
from .errors import InputError
from .limits import MAX_PIXELS

__all__ = ["Image", "write_exr", "read_exr", "write_png_preview", "srgb_encode"]

_METADATA_KEY = "lenscompare"


@dataclass(frozen=True)
class Image:
    """A linear RGB image and what produced it.

    Attributes
    ----------
    pixels : ndarray, float32, shape (H, W, 3)
        Linear RGB; row 0 is the top of the picture.
    metadata : dict
        JSON-serialisable provenance (model, spp, seed, timing, ...); written
        into the EXR header. ``metadata["camera"]`` is ``camera.to_json()``.
    camera : CameraModel, optional
        The camera the image was rendered through (native and POV-Ray renders
        carry it; an image read from a file does not).
    variance : ndarray, float32, shape (H, W), optional
        Per-pixel variance of the mean, summed over R, G and B, where the
        renderer measured it (native renders).
    """

    pixels: np.ndarray
    metadata: dict[str, Any] = field(default_factory=dict)
    camera: CameraModel | None = None
    variance: np.ndarray | None = None

    @property
    def height_px(self) -> int:
        return self.pixels.shape[0]

    @property
    def width_px(self) -> int:
        return self.pixels.shape[1]


def write_exr(path: str | os.PathLike, image: Image, *, option: str = "-o", within: str | os.PathLike | None = None,
              final: bool = False) -> None:
    """Write a linear float32 OpenEXR file (channels R, G, B), atomically.

    The metadata goes into a string header attribute ``lenscompare`` as JSON.
    ``within`` and ``final`` as for :func:`lenscompare.atomic.atomic_output`.
    """
    pixels = np.ascontiguousarray(image.pixels, dtype=np.float32)
    header = {
        "compression": OpenEXR.ZIP_COMPRESSION,
        "type": OpenEXR.scanlineimage,
        _METADATA_KEY: json.dumps(image.metadata, sort_keys=True),
    }
    channels = {name: np.ascontiguousarray(pixels[:, :, i]) for i, name in enumerate("RGB")}
    with atomic_output(path, option=option, within=within, final=final) as tmp:
        with OpenEXR.File(header, channels) as exr:
            exr.write(str(tmp))


def read_exr(path: str | os.PathLike) -> Image:
    """Read an OpenEXR file with R, G, B channels (half or float) as float32.

    Raises
    ------
    InputError
        The file cannot be read or has no R, G, B channels.
    """
    source = os.fspath(path)
    # Checked here: the library would print its own message too.
    if os.path.isdir(source):
        raise InputError(source, "is a folder, expected an OpenEXR image")
    if not os.path.exists(source):
        raise InputError(source, "no such file")
    if not os.path.isfile(source):
        raise InputError(source, "is not a regular file (a device or a pipe), expected an OpenEXR image")
    try:
        with OpenEXR.File(source, header_only=True) as exr:
            low, high = exr.header()["dataWindow"]
        width_px, height_px = int(high[0]) - int(low[0]) + 1, int(high[1]) - int(low[1]) + 1
    except Exception as error:  # the binding raises plain RuntimeError/OSError
        raise InputError(source, f"cannot read as OpenEXR ({error})") from None
    if width_px * height_px > MAX_PIXELS:  # before the pixels are allocated
        raise InputError(source, f"image of {width_px}x{height_px} pixels, more than the limit {MAX_PIXELS:,}")
    try:
        with OpenEXR.File(source, separate_channels=True) as exr:
            header = dict(exr.header())  # the binding empties it on close
            channels = {name: channel.pixels for name, channel in exr.channels().items()}
    except Exception as error:  # the binding raises plain RuntimeError/OSError
        raise InputError(source, f"cannot read as OpenEXR ({error})") from None
    missing = [c for c in "RGB" if c not in channels]
    if missing:
        raise InputError(source, f"has no {', '.join(missing)} channel(s) (found: {', '.join(sorted(channels))})")
    pixels = np.stack([np.asarray(channels[c], dtype=np.float32) for c in "RGB"], axis=-1)
    metadata: dict[str, Any] = {}
    raw = header.get(_METADATA_KEY)
    if isinstance(raw, (str, bytes)):
        try:
            metadata = json.loads(raw)
        except json.JSONDecodeError:
            metadata = {}
    return Image(pixels, metadata)


def srgb_encode(linear: np.ndarray, *, exposure: float = 1.0) -> np.ndarray:
    """Linear RGB -> 8-bit sRGB (IEC 61966-2-1 curve via colour-science), clipped."""
    import colour  # here, not at the top: colour-science takes about a second to import

    scaled = np.clip(np.nan_to_num(np.asarray(linear, dtype=float) * exposure), 0.0, 1.0)
    encoded = colour.cctf_encoding(scaled, function="sRGB")
    return np.round(encoded * 255.0).astype(np.uint8)


def write_png_preview(path: str | os.PathLike, image: Image, *, exposure: float = 1.0,
                      within: str | os.PathLike | None = None, final: bool = False) -> None:
    """Write an sRGB-encoded 8-bit PNG preview, atomically (``within`` and
    ``final`` as for :func:`lenscompare.atomic.atomic_output`)."""
    import imageio.v3 as iio  # here: only previews need it, and it is slow to import

    data = srgb_encode(image.pixels, exposure=exposure)
    with atomic_output(path, within=within, final=final) as tmp:
        iio.imwrite(tmp, data, extension=".png")
