"""A fuzz over the one CSV reader and the motion CSV loader (issue 27, item 7): 400 random
files — valid tables mutated byte by byte, random bytes, other encodings, long fields, odd
numbers — each either reads or is refused with a ParameterError that names the field; no
other exception, no non-finite number read, and no error shows a secret planted in a
data line."""

from __future__ import annotations

import numpy as np
import pytest

from pkmlab.errors import ParameterError
from pkmlab.motion.csvfile import load_motion_csv
from pkmlab.tables import read_table

SECRET = "SECRETTOKEN42"
HEADER = "t,x,y,z,theta_x,theta_y,theta_z"


def _valid(rng, n) -> bytes:
    t = np.arange(n) * 0.01
    rows = [HEADER] + [",".join([f"{ti:.4f}"] + [f"{v:.5g}" for v in rng.normal(0, 3, 6)])
                       for ti in t]
    return ("\n".join(rows) + "\n").encode()


def _case(rng) -> bytes:
    kind = rng.integers(7)
    data = bytearray(_valid(rng, int(rng.integers(1, 60))))
    if kind == 0:                                    # byte flips
        for _ in range(int(rng.integers(1, 8))):
            data[int(rng.integers(len(data)))] = int(rng.integers(256))
    elif kind == 1:                                  # random bytes
        data = bytearray(rng.integers(0, 256, int(rng.integers(0, 400))).astype(np.uint8))
    elif kind == 2:                                  # other encodings
        enc = ["utf-16", "utf-16-le", "latin-1", "utf-8-sig", "utf-32"][int(rng.integers(5))]
        data = bytearray(data.decode().replace("x", "x\u00e9" if enc == "latin-1" else "x")
                         .encode(enc, errors="replace"))
    elif kind == 3:                                  # odd numbers
        bad = ["nan", "inf", "-inf", "1e309", "1e-320", "0x10", "1_0", "", " ", "١", "1e305"]
        lines = data.decode().splitlines()
        k = int(rng.integers(1, len(lines))) if len(lines) > 1 else 0
        cells = lines[k].split(",")
        cells[int(rng.integers(len(cells)))] = bad[int(rng.integers(len(bad)))]
        lines[k] = ",".join(cells)
        data = bytearray(("\n".join(lines) + "\n").encode())
    elif kind == 4:                                  # a long field
        data = bytearray(data.replace(b"\n", b"," + b"9" * int(rng.integers(1000, 200000))
                                      + b"\n", 1))
    elif kind == 5:                                  # quotes, separators, line ends
        seps = [b";", b"\t", b'"', b"\r", b"\r\n", b"\x00"]
        for _ in range(int(rng.integers(1, 5))):
            pos = int(rng.integers(len(data)))
            data[pos:pos] = seps[int(rng.integers(len(seps)))]
    else:                                            # header mutations
        data = bytearray(data.replace(b"theta_x", [b"theta_x", b"x", b"", b"t"][
            int(rng.integers(4))], 1))
    if rng.random() < 0.5:        # a secret in a data line (header names are shown when
        start = data.find(b"\n") + 1                 # they are plain tokens: a typo helps)
        pos = int(rng.integers(start, len(data) + 1))
        data[pos:pos] = SECRET.encode()
    return bytes(data)


@pytest.mark.parametrize("block", range(4))
def test_csv_fuzz(tmp_path, block):
    rng = np.random.default_rng(1000 + block)
    outcomes = {"read": 0, "refused": 0}
    for i in range(100):
        p = tmp_path / f"case{i}.csv"
        p.write_bytes(_case(rng))
        for reader in (lambda p=p: read_table(p, "file"),
                       lambda p=p: load_motion_csv(p, "m", 0.05, 3, field="motions[0].file")):
            try:
                out = reader()
            except ParameterError as exc:
                outcomes["refused"] += 1
                assert SECRET not in str(exc), str(exc)
                assert exc.field.startswith(("file", "motions[0]")), exc.field
                assert len(str(exc)) < 2000
                continue
            outcomes["read"] += 1
            arrays = [out.values] if hasattr(out, "values") else [out.t, out.poses,
                                                                   out.twist, out.accel]
            assert all(np.all(np.isfinite(a)) for a in arrays)
    assert outcomes["refused"] > 50 and outcomes["read"] >= 1, outcomes
