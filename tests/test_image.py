"""EXR and PNG files: round trips, metadata, sRGB encoding, atomic writes."""

import numpy as np
import pytest

from lenscompare.errors import InputError
from lenscompare.image import Image, read_exr, srgb_encode, write_exr, write_png_preview


def test_exr_round_trip_is_exact_float32(tmp_path):
    rng = np.random.default_rng(0)
    pixels = (rng.random((7, 11, 3)) * 100).astype(np.float32)
    pixels[0, 0] = [0.0, 1e-30, 65504.0 * 4]  # values half floats could not hold
    write_exr(tmp_path / "a.exr", Image(pixels, {"model": "thin", "spp": 3}))
    back = read_exr(tmp_path / "a.exr")
    assert back.pixels.dtype == np.float32 and back.pixels.shape == (7, 11, 3)
    assert back.pixels.tobytes() == pixels.tobytes()
    assert back.metadata == {"model": "thin", "spp": 3}


def test_exr_channel_order_is_rgb(tmp_path):
    pixels = np.zeros((2, 2, 3), np.float32)
    pixels[..., 0], pixels[..., 1], pixels[..., 2] = 1.0, 2.0, 3.0
    write_exr(tmp_path / "c.exr", Image(pixels))
    assert read_exr(tmp_path / "c.exr").pixels[0, 0].tolist() == [1.0, 2.0, 3.0]


def test_unreadable_exr_is_an_input_error(tmp_path):
    (tmp_path / "bad.exr").write_bytes(b"not an exr")
    with pytest.raises(InputError, match=r"bad.exr: cannot read as OpenEXR"):
        read_exr(tmp_path / "bad.exr")


def test_failed_write_leaves_no_file_and_keeps_old(tmp_path, monkeypatch):
    target = tmp_path / "keep.exr"
    target.write_bytes(b"old")

    class Boom(Exception):
        pass

    import OpenEXR

    def broken_file(*args, **kwargs):
        raise Boom()

    monkeypatch.setattr(OpenEXR, "File", broken_file)
    with pytest.raises(Boom):
        write_exr(target, Image(np.zeros((2, 2, 3), np.float32)))
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["keep.exr"]


def test_srgb_encoding_known_values():
    # IEC 61966-2-1: linear 0.5 -> 0.7354 -> 188; 0.0031308 is the knee (-> 0.04045 -> 10).
    encoded = srgb_encode(np.array([[[0.0, 0.5, 1.0]], [[0.0031308, 2.0, -1.0]]]))
    assert encoded[0, 0].tolist() == [0, 188, 255]
    assert encoded[1, 0].tolist() == [10, 255, 0]


def test_png_preview_written(tmp_path):
    import imageio.v3 as iio

    write_png_preview(tmp_path / "p.png", Image(np.full((4, 6, 3), 0.5, np.float32)))
    data = iio.imread(tmp_path / "p.png")
    assert data.shape == (4, 6, 3) and data.dtype == np.uint8 and np.all(data == 188)
