"""lamina's packed arrays (docs/formats.md, "Packed arrays"): configs/<id>/tables.lza and
reference_se.lza of a study, read with numpy alone.

This file needs nothing but numpy and the standard library (no compiled lamina): `lamina figures`
runs it inside the figure script, and `lamina.read_array` is this module's read_array.
"""

import json
import os
import stat
import zlib

import numpy as np

_MAGIC = b"lamina-array 1\n"
_DTYPES = {"float16": (np.float16, np.uint16), "float32": (np.float32, np.uint32)}


class ArrayError(ValueError):
    """A file that is not a readable packed array: `where` names it, `problem` says why."""

    def __init__(self, where, problem):
        super().__init__(f"{where}: {problem}")
        self.where, self.problem = where, problem


def unpack_array(data, where="packed array"):
    """The numpy array (float16 or float32, C order) held by the bytes of a packed-array file.

    ArrayError (a ValueError) naming `where` for bytes that are not one: damaged or truncated.
    """
    try:
        return _unpack(data, where)
    except ArrayError:
        raise
    except (ValueError, KeyError, IndexError, TypeError, AttributeError, OverflowError,
            zlib.error) as e:
        raise ArrayError(where, f"not a readable lamina packed array ({type(e).__name__}: {e}): "
                                "damaged or truncated?") from None


def _unpack(data, where):
    if not data.startswith(_MAGIC):
        raise ArrayError(where, "not a lamina packed array (no 'lamina-array 1' line)")
    eol = data.index(b"\n", len(_MAGIC))
    header = json.loads(data[len(_MAGIC):eol])
    if not isinstance(header, dict) or header.get("dtype") not in _DTYPES:
        dtype = header.get("dtype") if isinstance(header, dict) else None
        raise ArrayError(where, f"dtype {dtype!r}, expected float16 or float32")
    float_type, uint_type = _DTYPES[header["dtype"]]
    shape = header.get("shape")
    if (not isinstance(shape, list) or len(shape) < 2
            or not all(isinstance(d, int) and not isinstance(d, bool) and d >= 0 for d in shape)):
        raise ArrayError(where, f"shape {shape!r}: expected a list of at least two sizes")
    width = np.dtype(uint_type).itemsize
    count = int(np.prod(shape, dtype=np.int64)) if shape else 0
    # Byte planes (low byte first) back into unsigned integers; no more bytes inflated than the
    # shape needs (a damaged header must not make a small file expand without bound).
    inflate = zlib.decompressobj()
    planes = inflate.decompress(data[eol + 1:], count * width + 1)
    if len(planes) != count * width or not inflate.eof:
        raise ArrayError(where, f"the data does not hold the {count * width} bytes the shape "
                                f"{shape} needs: damaged or truncated?")
    planes = np.frombuffer(planes, np.uint8).reshape(width, count)
    bits = np.zeros(count, uint_type)
    for b in range(width):
        bits |= planes[b].astype(uint_type) << uint_type(8 * b)
    # [outer, channels, n] of differences along n → running sums (modulo 2^bits) → [outer, n, c].
    n, channels = shape[-2], shape[-1]
    bits = np.cumsum(bits.reshape(-1, channels, n), axis=-1, dtype=uint_type)
    return np.ascontiguousarray(np.swapaxes(bits, -1, -2)).view(float_type).reshape(shape)


# The largest file lamina reads as a table (as the C++ readers: core/atomic_file.h).
MAX_FILE_BYTES = 2 << 30


def read_bytes_bounded(path, limit=MAX_FILE_BYTES):
    """The bytes of a regular file of at most `limit` bytes; anything else (a device, a pipe, a
    directory, a larger file) is an ArrayError naming it, read no further than its size says."""
    path = str(path)
    info = os.stat(path)  # follows a symbolic link, as open does
    if not stat.S_ISREG(info.st_mode):
        raise ArrayError(path, "not a regular file (a device, a pipe or a folder?)")
    if info.st_size > limit:
        raise ArrayError(path, f"{info.st_size} bytes; allowed: at most {limit}")
    with open(path, "rb") as f:
        return f.read(info.st_size + 1)  # its size, as checked (read(limit) would reserve limit)


def read_array(path):
    """Reads a packed-array file (.lza) into a numpy array; a .npy path is read by numpy.load."""
    path = str(path)
    data = read_bytes_bounded(path)
    if path.endswith(".npy"):
        import io
        return np.load(io.BytesIO(data))
    return unpack_array(data, path)
