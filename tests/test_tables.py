"""The one CSV reader (pkmlab.tables, pkmlab.motion.csvfile): encodings, sizes and messages
that never show a file's contents (issue 27, items 7 and 9)."""

import math

import numpy as np
import pytest

from pkmlab import ParameterError
from pkmlab.motion import load_motion_csv
from pkmlab.tables import read_table

HEADER = "t,x,y,z,theta_x,theta_y,theta_z"
ROWS = "".join(f"{0.01 * k:.2f},{k},0,300,0,0,{k}\n" for k in range(10))


def _motion(tmp_path, data: bytes, **kw):
    p = tmp_path / "m.csv"
    p.write_bytes(data)
    return load_motion_csv(p, field="file", **kw)


def test_utf8_bom_and_utf16_read_as_utf8(tmp_path):
    text = HEADER + "\n" + ROWS
    plain = _motion(tmp_path, text.encode())
    for data in ("\ufeff" + text).encode("utf-8"), text.encode("utf-16"):
        m = _motion(tmp_path, data)
        np.testing.assert_array_equal(m.poses, plain.poses)
        np.testing.assert_array_equal(m.t, plain.t)
    assert plain.poses[3, 5] == pytest.approx(math.radians(3))


def test_latin1_is_refused_with_the_offset_not_a_crash(tmp_path):
    data = ("# caf\u00e9\n" + HEADER + "\n" + ROWS).encode("latin-1")
    with pytest.raises(ParameterError, match="not UTF-8 at byte offset 5"):
        _motion(tmp_path, data)


def test_a_huge_field_is_a_clear_error(tmp_path):
    data = (HEADER + "\n" + ROWS + '"' + "9" * 200_000 + '",0,0,0,0,0,0\n').encode()
    with pytest.raises(ParameterError, match="well-formed CSV rows") as exc:
        _motion(tmp_path, data)
    assert "9999" not in str(exc.value)


@pytest.mark.parametrize("secret", ["TOKEN=s3cr3tvalue:/bin\x00HOME=/home/s3cr3tvalue",
                                    "s3cr3tvalue:x:0:0:s3cr3tvalue:/home:/bin/bash"])
def test_errors_never_show_the_files_contents(tmp_path, secret):
    p = tmp_path / "secret.csv"
    p.write_text(secret + "\n1,2\n")
    with pytest.raises(ParameterError) as exc:
        load_motion_csv(p, field="file")
    assert "s3cr3t" not in str(exc.value)
    cell = secret.replace(",", ";").replace("\x00", ";")
    p.write_text(HEADER + "\n" + "0,0,0,0,0,0,0\n1,0,0,0," + cell + ",0,0\n")
    with pytest.raises(ParameterError) as exc:
        load_motion_csv(p, field="file")
    assert "s3cr3t" not in str(exc.value) and "not shown" in str(exc.value)


def test_proc_environ_is_not_echoed(tmp_path):
    with pytest.raises(ParameterError) as exc:
        load_motion_csv("/proc/self/environ", field="file")
    assert "=" not in str(exc.value).split("got", 1)[1]


def test_enormous_time_steps_are_refused(tmp_path):
    rows = "".join(f"{k * 1e305:g},0,0,300,0,0,0\n" for k in range(10))
    with pytest.raises(ParameterError, match=r"times within ±1e\+07 s"):
        _motion(tmp_path, (HEADER + "\n" + rows).encode())


def test_acceleration_columns_without_velocities_are_refused(tmp_path):
    ddot = ",".join(f"{c}_ddot" for c in HEADER.split(",")[1:])
    rows = "".join(f"{0.01 * k:.2f},0,0,300,0,0,0," + ",".join(["1"] * 6) + "\n"
                   for k in range(10))
    with pytest.raises(ParameterError, match="acceleration columns only"):
        _motion(tmp_path, (HEADER + "," + ddot + "\n" + rows).encode())


def test_size_and_row_limits(tmp_path, monkeypatch):
    import pkmlab.tables as tables

    monkeypatch.setattr(tables, "CSV_MAX_ROWS", 5)
    p = tmp_path / "m.csv"
    p.write_text(HEADER + "\n" + ROWS)
    with pytest.raises(ParameterError, match="at most 5 data rows"):
        read_table(p, "file")
    monkeypatch.setattr(tables, "CSV_MAX_BYTES", 2**20)
    p.write_bytes(b"#" * (2**20 + 1))
    with pytest.raises(ParameterError, match="at most 1 MiB"):
        read_table(p, "file")
