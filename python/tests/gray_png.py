"""A reader of the development scenes' PNGs: non-interlaced grayscale, 8 or 16 bits a sample.

zlib and struct suffice for these, so the tests need no imaging package.
"""

import struct
import zlib

import numpy as np

SIGNATURE = b"\x89PNG\r\n\x1a\n"
GRAYSCALE = 0  # IHDR colour type of one-channel images
DTYPES = {8: np.dtype("u1"), 16: np.dtype(">u2")}  # PNG stores 16-bit samples big-endian


def read_gray_png(path):
    """The samples of a grayscale PNG: an (H, W) array of uint8 or uint16."""
    with open(path, "rb") as file:
        data = file.read()
    if not data.startswith(SIGNATURE):
        raise ValueError(f"{path} is not a PNG")
    chunks = list(_chunks(data, len(SIGNATURE)))
    width, height, bits, colour, _, _, interlace = struct.unpack(">IIBBBBB", chunks[0][1])
    if colour != GRAYSCALE or bits not in DTYPES or interlace:
        raise ValueError(f"{path}: only non-interlaced 8- or 16-bit grayscale is read")
    compressed = b"".join(body for kind, body in chunks if kind == b"IDAT")
    stride, step = width * bits // 8, bits // 8
    rows = _unfilter(zlib.decompress(compressed), height, stride, step)
    samples = np.frombuffer(rows, dtype=DTYPES[bits]).reshape(height, width)
    return samples.astype(DTYPES[bits].newbyteorder("="))


def _chunks(data, offset):
    """(type, body) of each chunk, from `offset` to IEND."""
    while offset < len(data):
        (length,) = struct.unpack(">I", data[offset : offset + 4])
        kind = data[offset + 4 : offset + 8]
        yield kind, data[offset + 8 : offset + 8 + length]
        offset += 12 + length  # length, type, body, CRC


def _unfilter(raw, height, stride, step):
    """The image bytes of `raw`, rows of a filter-type byte and `stride` filtered bytes; `step`
    is the bytes per pixel, the distance to the byte on the left."""
    image, above = bytearray(), bytearray(stride)
    for y in range(height):
        start = y * (stride + 1)
        kind, row = raw[start], bytearray(raw[start + 1 : start + 1 + stride])
        for i in range(stride):
            left = row[i - step] if i >= step else 0
            corner = above[i - step] if i >= step else 0
            row[i] = (row[i] + _predict(kind, left, above[i], corner)) & 0xFF
        image += row
        above = row
    return bytes(image)


def _predict(kind, left, above, corner):
    """The PNG filter `kind`'s prediction of a byte from its neighbours."""
    if kind == 0:
        return 0
    if kind == 1:
        return left
    if kind == 2:
        return above
    if kind == 3:
        return (left + above) // 2
    if kind == 4:
        return _paeth(left, above, corner)
    raise ValueError(f"unknown PNG filter type {kind}")


def _paeth(left, above, corner):
    estimate = left + above - corner
    distances = [abs(estimate - left), abs(estimate - above), abs(estimate - corner)]
    return (left, above, corner)[distances.index(min(distances))]
