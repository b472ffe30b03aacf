"""Label artwork: PNG, JPEG, TIFF and EXR decode to straight linear RGBA (sRGB decoded for
integer images, EXR linear and un-premultiplied), once per content and read-only; hostile
images (huge, corrupt, 1 x 1, NaN/Inf, empty, truncated) are refused with one clear line and
never make a C library write to stderr."""
from __future__ import annotations

import struct
import zlib

import numpy as np
import pytest

from engine import limits
from engine.appearance import images
from engine.appearance.images import ArtworkError, decode_image, probe_image, read_image_file
from tests.label_helpers import write_image


def srgb(v):
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


@pytest.mark.parametrize("name, dtype, scale", [("a.png", np.uint8, 255), ("a16.png", np.uint16, 65535),
                                                ("a.tif", np.uint8, 255), ("a16.tif", np.uint16, 65535)])
def test_integer_images_are_srgb_decoded_with_straight_alpha(tmp_path, name, dtype, scale):
    px = np.zeros((3, 5, 4), dtype)
    px[..., 0], px[..., 1], px[..., 2], px[..., 3] = scale, scale // 2, 0, scale // 4
    img = decode_image(write_image(tmp_path / name, px), name)
    assert img.shape == (3, 5, 4) and img.dtype == np.float32
    g = (scale // 2) / scale
    assert img[1, 2] == pytest.approx([1.0, float(srgb(g)), 0.0, (scale // 4) / scale], abs=1e-6)
    assert not img.flags.writeable


def test_jpeg_is_srgb_decoded_and_opaque(tmp_path):
    px = np.full((16, 16, 3), 128, np.uint8)
    img = decode_image(write_image(tmp_path / "a.jpg", px), "a.jpg")
    assert img[8, 8, :3] == pytest.approx([float(srgb(128 / 255))] * 3, abs=0.01)
    assert np.all(img[..., 3] == 1.0)


def test_exr_is_linear_and_its_premultiplied_colour_is_divided_out(tmp_path):
    px = np.zeros((4, 4, 4), np.float32)
    px[..., :3], px[..., 3] = 0.2, 0.5  # EXR colour is premultiplied: straight 0.4
    px[0, 0] = (3.0, -1.0, 0.1, 1.0)   # out-of-range albedo is clipped to [0, 1]
    img = decode_image(write_image(tmp_path / "a.exr", px, unassociated=False), "a.exr")
    assert img[2, 2] == pytest.approx([0.4, 0.4, 0.4, 0.5])
    assert img[0, 0] == pytest.approx([1.0, 0.0, 0.1, 1.0])


def test_grey_and_grey_alpha_images_become_rgba(tmp_path):
    grey = np.full((2, 3, 1), 255, np.uint8)
    assert decode_image(write_image(tmp_path / "g.png", grey), "g")[0, 0] == pytest.approx([1, 1, 1, 1])
    ga = np.zeros((2, 3, 2), np.uint8)
    ga[..., 1] = 255
    assert decode_image(write_image(tmp_path / "ga.png", ga), "ga")[0, 0] == pytest.approx([0, 0, 0, 1])


def test_an_image_is_decoded_once_per_content(tmp_path, monkeypatch):
    data = write_image(tmp_path / "c.png", np.random.default_rng(2).integers(0, 255, (8, 8, 3), dtype=np.uint8))
    first = decode_image(data, "c.png")
    before = images.DECODED.decodes
    monkeypatch.setattr(images, "_decode_path", lambda *a: pytest.fail("decoded again"))
    again = decode_image(bytes(bytearray(data)), "same bytes, another name")
    assert again is first and images.DECODED.decodes == before


def png_chunk(kind: bytes, body: bytes) -> bytes:
    return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))


def png_claiming(width: int, height: int) -> bytes:
    """A PNG whose header claims ``width`` x ``height`` but holds almost nothing."""
    return (b"\x89PNG\r\n\x1a\n" + png_chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + png_chunk(b"IDAT", zlib.compress(b"\0" * 16)) + png_chunk(b"IEND", b""))


def hostile(tmp_path):
    good_png = write_image(tmp_path / "g.png", np.random.default_rng(3).integers(0, 255, (64, 64, 3), dtype=np.uint8))
    good_jpg = write_image(tmp_path / "g.jpg", np.random.default_rng(3).integers(0, 255, (64, 64, 3), dtype=np.uint8))
    good_exr = write_image(tmp_path / "g.exr", np.random.default_rng(3).random((64, 64, 3), dtype=np.float32))
    nan = np.ones((4, 4, 3), np.float32)
    nan[1, 1, 1] = np.nan
    inf = np.ones((4, 4, 3), np.float32)
    inf[2, 2, 0] = np.inf
    crc = bytearray(good_png)
    crc[len(crc) // 2] ^= 0xFF  # inside the image data: its chunk checksum no longer holds
    return {
        "huge": (png_claiming(100_000, 100_000), "100000 x 100000 pixels, more than artwork may have"),
        "too wide": (png_claiming(limits.MAX_ARTWORK_SIDE + 1, 2), "more than artwork may have"),
        "one pixel": (write_image(tmp_path / "one.png", np.zeros((1, 1, 3), np.uint8)), "is 1 x 1 pixels"),
        "zero size": (png_claiming(0, 0), "is 0 x 0 pixels"),
        "empty": (b"", "is empty"),
        "not an image": (b"GIF89a" + b"\0" * 64, "is not a PNG, JPEG, TIFF or EXR image"),
        "corrupt png": (good_png[:8] + b"garbage!" * 8, "damaged"),
        "png checksum": (bytes(crc), "fails its checksum"),
        "truncated png": (good_png[: len(good_png) // 2], "is truncated"),
        "truncated jpeg": (good_jpg[: len(good_jpg) // 2], "cannot be decoded"),
        "corrupt jpeg": (good_jpg[:4] + b"\0" * 200, "not a readable image"),
        "truncated exr": (good_exr[: len(good_exr) // 2], "cannot be decoded"),
        "nan exr": (write_image(tmp_path / "nan.exr", nan), "holds NaN or infinite values"),
        "inf exr": (write_image(tmp_path / "inf.exr", inf), "holds NaN or infinite values"),
    }


def test_hostile_images_are_refused_with_one_clear_line(tmp_path, capfd):
    for case, (data, message) in hostile(tmp_path).items():
        with pytest.raises(ArtworkError) as info:
            decode_image(data, f"{case}.img")
        text = str(info.value)
        assert message in text and text.startswith(f"{case}.img"), (case, text)
        assert "\n" not in text and len(text) < 300 and "/tmp" not in text, (case, text)
    out = capfd.readouterr()
    assert out.err == "" and out.out == "", "a C library wrote to the terminal"


def test_the_size_is_refused_from_the_header_before_any_decoding(tmp_path, monkeypatch):
    monkeypatch.setattr(images, "_decode_path", lambda *a: pytest.fail("decoded a refused image"))
    with pytest.raises(ArtworkError, match="more than artwork may have"):
        decode_image(png_claiming(8192, 8192), "big.png")
    with pytest.raises(ArtworkError, match="more than artwork may have"):
        probe_image(png_claiming(5000, 4000), "big.png")
    assert probe_image(png_claiming(4096, 4096), "ok.png").width == 4096  # at the limit: fine


def test_image_files_are_read_no_further_than_the_limit(tmp_path, monkeypatch):
    monkeypatch.setattr(limits, "MAX_ARTWORK_BYTES", 1000)
    path = tmp_path / "big.png"
    path.write_bytes(png_claiming(4, 4) + b"\0" * 2000)
    with pytest.raises(ArtworkError, match="big.png' is 2068 bytes, larger than 1000"):
        read_image_file(path)
