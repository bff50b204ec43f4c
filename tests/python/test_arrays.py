"""Packed arrays (docs/formats.md, "Packed arrays") read from Python: the files lamina's C++ wrote
decode to the bit patterns they were written from (tests/core/packed_array_test.cpp makes the same
patterns), and a study's packed tables hold exactly what the model computes.

Run by ctest (`python`): PYTHONPATH=BUILD/python LAMINA_CLI=BUILD/lamina python3 -m pytest.
"""

import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import lamina

ROOT = Path(__file__).resolve().parents[2]
DATA = ROOT / "tests" / "core" / "data"
CLI = os.environ.get("LAMINA_CLI", str(ROOT / "build" / "lamina"))
SHAPE = (2, 3, 5, 3)


def half_pattern(count):
    k = np.arange(count, dtype=np.uint64)
    bits = ((k * 40503) % 65536).astype(np.uint16)
    inf_nan = ((bits >> 10) & 31) == 31
    bits[inf_nan] &= np.uint16(~0x4000 & 0xFFFF)
    bits[5] = 0x7E00
    return bits


def float_pattern(count):
    k = np.arange(count, dtype=np.uint64)
    return ((k * 2654435761) % (1 << 32)).astype(np.uint32)


def test_committed_files_decode_to_their_patterns():
    h = lamina.read_array(DATA / "pattern-f16.lza")
    assert h.dtype == np.float16 and h.shape == SHAPE
    assert np.array_equal(h.view(np.uint16).ravel(), half_pattern(90))
    f = lamina.read_array(DATA / "pattern-f32.lza")
    assert f.dtype == np.float32 and f.shape == SHAPE
    assert np.array_equal(f.view(np.uint32).ravel(), float_pattern(90))


def test_damaged_file_is_refused(tmp_path):
    data = (DATA / "pattern-f16.lza").read_bytes()
    bad = tmp_path / "bad.lza"
    bad.write_bytes(data[:-4])
    with pytest.raises(Exception):
        lamina.read_array(bad)
    bad.write_bytes(b"\x93NUMPY" + data)
    with pytest.raises(ValueError, match="not a lamina packed array"):
        lamina.read_array(bad)


def test_study_tables_hold_the_models_binned_values(tmp_path):
    plastic = ROOT / "examples" / "plastic.json"
    out = tmp_path / "s"
    for tables in ("full", "half"):
        subprocess.run([CLI, "compare", str(plastic), "--particles", "20000", "--theta-i", "0,45",
                        "--grid", "18x12", "--models", "ww-prime", "--tables", tables,
                        "--no-figures", "--out", str(out / tables)], check=True,
                       capture_output=True)
    binned = np.asarray(lamina.Model("ww-prime", plastic).binned([0, 45], grid=(18, 12)).f)
    full = lamina.load_study(out / "full", pandas=False).tables("plastic")
    half = lamina.load_study(out / "half", pandas=False).tables("plastic")
    assert full["ww-prime"].dtype == np.float32 and half["ww-prime"].dtype == np.float16
    assert np.array_equal(full["ww-prime"], binned.astype(np.float32))
    assert np.array_equal(half["ww-prime"], binned.astype(np.float32).astype(np.float16))
    # The reference: float16 is the float32 table rounded.
    assert np.array_equal(half["reference"], full["reference"].astype(np.float16))
