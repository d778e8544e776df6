"""Map images beyond 8-bit greyscale: 16-bit PGMs and alpha channels, as nav2's map_io reads them.

A 16-bit image's channel maximum is 65535 (it was the image's own brightest pixel, which turned
unknown grey into free space on a map without white pixels), and in trinary mode an alpha
channel is averaged in with the three colour channels (it was ignored, so transparent white
pixels became free).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays
from robot_data import nav2_cell, write_map

from tlmpc.importers.occupancy import read_map

#: map_saver's thresholds (nav2's defaults).
OCCUPIED, FREE = 0.65, 0.196


def _write_pgm16(path: Path, pixels: np.ndarray, maxval: int = 65535) -> None:
    rows, cols = pixels.shape
    header = f"P5\n{cols} {rows}\n{maxval}\n".encode()
    path.write_bytes(header + pixels.astype(">u2").tobytes())


def _yaml(path: Path, image: str, mode: str = "trinary") -> Path:
    path.write_text(
        f"image: {image}\nresolution: 0.1\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
        f"occupied_thresh: {OCCUPIED}\nfree_thresh: {FREE}\nmode: {mode}\n"
    )
    return path


def _nav2_trinary_with_alpha(grey: np.ndarray, alpha: np.ndarray) -> np.ndarray:
    """nav2 map_io, trinary, an image with a matte: the mean of red, green, blue and the
    alpha (MaxRGB - opacity), over the channel maximum."""
    shade = (3.0 * grey.astype(np.float64) + alpha.astype(np.float64)) / 4.0 / 255.0
    occ = 1.0 - shade
    return np.where(occ > OCCUPIED, 100, np.where(occ < FREE, 0, -1))


@settings(max_examples=25)
@given(pixels=arrays(np.uint8, (3, 4)))
def test_a_16_bit_pgm_reads_as_its_8_bit_picture(
    tmp_path_factory: pytest.TempPathFactory, pixels: np.ndarray
) -> None:
    tmp = tmp_path_factory.mktemp("depth")
    # the 8-bit picture and the same picture at 16 bits (v * 257 maps 0..255 onto 0..65535)
    eight = read_map(write_map(tmp, "eight", pixels, occupied=OCCUPIED, free=FREE))
    _write_pgm16(tmp / "sixteen.pgm", pixels.astype(np.uint32) * 257)
    sixteen = read_map(_yaml(tmp / "sixteen.yaml", "sixteen.pgm"))
    want = np.array(
        [
            [nav2_cell(v / 255.0, mode="trinary", negate=False, occupied=OCCUPIED, free=FREE)]
            for v in pixels.ravel().tolist()
        ]
    ).reshape(pixels.shape)[::-1]
    assert np.array_equal(eight.values, want)
    assert np.array_equal(sixteen.values, want)


def test_unknown_grey_is_not_free_on_a_16_bit_map_without_white(tmp_path: Path) -> None:
    # map_saver's unknown grey 205 and free 254, at 16 bits: unknown stays unknown
    pixels = np.array([[205 * 257, 254 * 257, 0]], dtype=np.uint32)
    _write_pgm16(tmp_path / "m.pgm", pixels)
    assert read_map(_yaml(tmp_path / "m.yaml", "m.pgm")).values.tolist() == [[-1, 0, 100]]
    # no white pixel at all: the brightest is unknown, and no cell is free
    _write_pgm16(tmp_path / "dark.pgm", np.array([[205 * 257, 0, 205 * 257]], dtype=np.uint32))
    dark = read_map(_yaml(tmp_path / "dark.yaml", "dark.pgm"))
    assert dark.values.tolist() == [[-1, 100, -1]]
    # a maxval below 65535: the file's own range, 500 of 1000 is mid grey (unknown)
    _write_pgm16(tmp_path / "k.pgm", np.array([[500, 1000, 0]], dtype=np.uint32), maxval=1000)
    assert read_map(_yaml(tmp_path / "k.yaml", "k.pgm")).values.tolist() == [[-1, 0, 100]]


@settings(max_examples=25)
@given(grey=arrays(np.uint8, (3, 4)), alpha=arrays(np.uint8, (3, 4)), rgba=st.booleans())
def test_trinary_averages_the_alpha_in(
    tmp_path_factory: pytest.TempPathFactory, grey: np.ndarray, alpha: np.ndarray, rgba: bool
) -> None:
    tmp = tmp_path_factory.mktemp("alpha")
    image = np.dstack([grey, grey, grey, alpha] if rgba else [grey, alpha])
    got = read_map(write_map(tmp, "m", image, suffix="png", occupied=OCCUPIED, free=FREE))
    assert np.array_equal(got.values, _nav2_trinary_with_alpha(grey, alpha)[::-1])


def test_a_transparent_white_pixel_is_not_free(tmp_path: Path) -> None:
    image = np.zeros((1, 3, 4), dtype=np.uint8)
    image[..., :3] = 254
    image[0, :, 3] = [255, 0, 128]  # opaque, transparent, half
    got = read_map(write_map(tmp_path, "m", image, suffix="png", occupied=OCCUPIED, free=FREE))
    # shades (3 * 254 + a) / 1020: 0.996 free, 0.747 unknown, 0.873 free under 0.196
    assert got.values.tolist() == [[0, -1, 0]]
    scaled = read_map(
        write_map(tmp_path, "s", image, suffix="png", mode="scale", occupied=OCCUPIED, free=FREE)
    )
    assert scaled.values.tolist() == [[0, -1, -1]]  # scale: every pixel not opaque is unknown
