"""lamina's packed arrays (docs/formats.md, "Packed arrays"): configs/<id>/tables.lza and
reference_se.lza of a study, read with numpy alone.

This file needs nothing but numpy and the standard library (no compiled lamina): `lamina figures`
runs it inside the figure script, and `lamina.read_array` is this module's read_array.
"""

import json
import zlib

import numpy as np

_MAGIC = b"lamina-array 1\n"
_DTYPES = {"float16": (np.float16, np.uint16), "float32": (np.float32, np.uint32)}


def unpack_array(data, where="packed array"):
    """The numpy array (float16 or float32, C order) held by the bytes of a packed-array file."""
    if not data.startswith(_MAGIC):
        raise ValueError(f"{where}: not a lamina packed array (no 'lamina-array 1' line)")
    eol = data.index(b"\n", len(_MAGIC))
    header = json.loads(data[len(_MAGIC):eol])
    if header.get("dtype") not in _DTYPES:
        raise ValueError(f"{where}: dtype {header.get('dtype')!r}, expected float16 or float32")
    float_type, uint_type = _DTYPES[header["dtype"]]
    shape = [int(d) for d in header["shape"]]
    width = np.dtype(uint_type).itemsize
    # Byte planes (low byte first) back into unsigned integers.
    planes = np.frombuffer(zlib.decompress(data[eol + 1:]), np.uint8)
    count = int(np.prod(shape))
    if planes.size != count * width:
        raise ValueError(f"{where}: {planes.size} bytes unpacked, the shape {shape} needs "
                         f"{count * width}")
    planes = planes.reshape(width, count)
    bits = np.zeros(count, uint_type)
    for b in range(width):
        bits |= planes[b].astype(uint_type) << uint_type(8 * b)
    # [outer, channels, n] of differences along n → running sums (modulo 2^bits) → [outer, n, c].
    n, channels = shape[-2], shape[-1]
    bits = np.cumsum(bits.reshape(-1, channels, n), axis=-1, dtype=uint_type)
    return np.ascontiguousarray(np.swapaxes(bits, -1, -2)).view(float_type).reshape(shape)


def read_array(path):
    """Reads a packed-array file (.lza) into a numpy array; a .npy path is read by numpy.load."""
    path = str(path)
    if path.endswith(".npy"):
        return np.load(path)
    with open(path, "rb") as f:
        return unpack_array(f.read(), path)
