"""The CLI commands run, speak mm/deg, and their --json parses."""

from __future__ import annotations

import json
import math
import os
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from conftest import MECH_DIR
from typer.testing import CliRunner

import pkmlab
from pkmlab.cli import app

runner = CliRunner()
HOPKINS = str(MECH_DIR / "hopkins-williams-6psu.yaml")


@pytest.mark.parametrize("path", sorted(MECH_DIR.glob("*.yaml")), ids=lambda p: p.stem)
def test_inspect_json(path):
    r = runner.invoke(app, ["inspect", str(path), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    m = pkmlab.load_mechanism(path)
    assert d["nominal_pose"]["z"] == pytest.approx(m.nominal_pose[2])
    assert d["nominal_pose"]["theta_z"] == pytest.approx(math.degrees(m.nominal_pose[5]))
    assert list(d["nominal_actuators"]) == list(m.actuator_names)
    assert d["nominal_valid"] is True
    # a translational Jacobian (delta3, ldelta3) needs no characteristic length
    status = "angeles" if m.mobility.rotations else "not-applicable"
    assert d["kappa"] > 1 and d["characteristic_length"]["status"] == status


def test_inspect_text():
    r = runner.invoke(app, ["inspect", HOPKINS])
    assert r.exit_code == 0
    assert "κ = " in r.stdout and "homogenised with L = " in r.stdout and "nominal pose" in r.stdout


def test_ik_json_in_mm_and_degrees():
    m = pkmlab.load_mechanism(HOPKINS)
    r = runner.invoke(app, ["ik", HOPKINS, "--pose", "5,-3,300,10,-5,20", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    expect = m.inverse(np.array([5, -3, 300, *np.radians([10, -5, 20])])).q[0]
    assert [d["actuators"][f"q{i}"] for i in range(1, 7)] == pytest.approx(expect)
    assert d["valid"] is True and d["reason"] == "ok"
    # κ of the Jacobian homogenised with the stated L (it was the unscaled condition number)
    L = d["characteristic_length"]["length_mm"]
    assert d["characteristic_length"]["status"] == "angeles"
    J = m.jacobian(np.array([5, -3, 300, *np.radians([10, -5, 20])]))[0]
    J[:, 3:] /= L
    assert d["kappa"] == pytest.approx(np.linalg.cond(J), rel=1e-10)


def test_ik_unreachable_is_data_not_error():
    """An unreachable pose is reported as data, and the exit status says it failed (1; a bad
    input is 2)."""
    r = runner.invoke(app, ["ik", HOPKINS, "--pose", "0,0,900,0,0,0", "--json"])
    assert r.exit_code == 1
    d = json.loads(r.stdout)
    assert d["valid"] is False and d["reason"] == "stroke above maximum"
    r = runner.invoke(app, ["ik", HOPKINS, "--pose", "0,0,900,0,0,0"])
    assert "stroke above maximum" in r.stdout


def test_fk_json_round_trip_and_all_modes():
    m = pkmlab.load_mechanism(HOPKINS)
    X = np.array([10, 5, 290, *np.radians([3, 4, -6])])
    q = m.inverse(X).q[0]
    r = runner.invoke(app, ["fk", HOPKINS, "--actuators", ",".join(f"{v:.12f}" for v in q),
                            "--all", "--starts", "300", "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    assert d["converged"] is True
    got = [d["pose"][k] for k in ("x", "y", "z")]
    assert got == pytest.approx(X[:3], abs=1e-6)
    assert d["pose"]["theta_z"] == pytest.approx(-6.0, abs=1e-6)
    modes = d["assembly_modes"]
    assert modes and modes[0]["working_mode"] is True
    assert modes[0]["pose"]["z"] == pytest.approx(290.0, abs=1e-6)


@pytest.mark.parametrize("args, fragment", [
    (["ik", HOPKINS, "--pose", "1,2,3"], "--pose: must be 6 comma-separated values"),
    (["ik", HOPKINS, "--pose", "0,0,300,0,0,1 furlong"], "--pose[5]: must be"),
    (["fk", HOPKINS, "--actuators", "1,2"], "--actuators: must be 6 comma-separated values"),
    (["inspect", "no-such-file.yaml"], "path: must be an existing mechanism YAML file"),
])
def test_bad_input_exits_2_with_named_field(args, fragment):
    r = runner.invoke(app, args)
    assert r.exit_code == 2
    assert fragment in r.stderr.replace("\n", "")


def test_bad_mechanism_file_exits_2(tmp_path):
    f = tmp_path / "m.yaml"
    f.write_text((MECH_DIR / "hopkins-williams-6psu.yaml").read_text()
                 .replace("link_length: 225 mm", "link_length: -225 mm"))
    r = runner.invoke(app, ["inspect", str(f)])
    assert r.exit_code == 2
    assert "link_length (m.yaml, line 19, column 1): must be a length > 0 mm" in r.stderr


# ---- bad input: one line on stderr naming the field (and where in the file), exit 2 ----------

BAD_DIR = Path(__file__).resolve().parents[1] / "data" / "bad"
HW = (MECH_DIR / "hopkins-williams-6psu.yaml").read_text()


def expectation(path: Path) -> list[str]:
    """``# expect: <command> | <field path> | <position>`` on the file's first line."""
    first = path.read_bytes().split(b"\n", 1)[0].decode("latin-1")
    assert first.startswith("# expect: "), path
    return [part.strip() for part in first.removeprefix("# expect: ").split("|")]


def one_clean_error(r, *fragments: str) -> str:
    assert r.exit_code == 2, (r.exit_code, r.output, r.exception)
    assert isinstance(r.exception, SystemExit), r.exception
    lines = r.stderr.splitlines()
    assert len(lines) == 1, r.stderr
    line = lines[0]
    assert line.startswith("error: ") and ": must be " in line and "; got " in line, line
    for text in fragments:
        assert text in line, (text, line)
    for leak in ("Traceback", "Input should", "function-", "[key]", "Value error"):
        assert leak not in r.output, line
    return line


@pytest.mark.parametrize("path", sorted(BAD_DIR.glob("*.yaml")), ids=lambda p: p.stem)
def test_bad_input_corpus(path):
    command, field, where = expectation(path)
    r = runner.invoke(app, [command, str(path)])
    line = one_clean_error(r, field, f"{where})")
    assert line.index(field) < line.index(where) < line.index(": must be ")


def test_bracketed_text_is_printed_as_written(tmp_path):
    line = one_clean_error(runner.invoke(app, ["inspect", str(BAD_DIR / "stroke-reversed.yaml")]))
    assert "must be [min, max] with min < max; got ['4 in', '0 mm']" in line
    one_clean_error(runner.invoke(app, ["ik", HOPKINS, "--pose", "[/],0,300,0,0,0"]),
                    "--pose[0]: must be", "got '[/]'")
    folder = tmp_path / "["
    folder.mkdir()
    (folder / "x]").write_text(HW.replace("name: hopkins-williams-6psu", "name: '[/bold]'"))
    r = runner.invoke(app, ["inspect", str(folder / "x]")])
    assert r.exit_code == 0, r.output
    assert "[/bold]" in r.stdout


def timed(args: list[str]):
    t = time.perf_counter()
    r = runner.invoke(app, args)
    return r, time.perf_counter() - t


def test_billion_laughs_is_refused_at_once(tmp_path):
    bomb = ['a: &a ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    bomb += [f"{c}: &{c} [" + ", ".join([f"*{p}"] * 9) + "]" for p, c in zip("abcdefgh",
                                                                              "bcdefghi")]
    f = tmp_path / "laughs.yaml"
    f.write_text("\n".join(bomb) + "\n" + HW.replace("stroke: [0 mm, 4 in]", "stroke: *i"))
    r, seconds = timed(["inspect", str(f)])
    one_clean_error(r, "laughs.yaml (line 5, column 8): must be at most 10,000 values expanded "
                       "from aliases")
    assert seconds < 2


def test_50_mb_file_is_refused_at_once(tmp_path):
    f = tmp_path / "big.yaml"
    row = "  - [1.0, 2.0, 3.0]\n"
    with f.open("w") as out:
        out.write(HW + "base_points:\n")
        for _ in range(50):
            out.write(row * (2**20 // len(row)))
    assert f.stat().st_size > 50e6
    r, seconds = timed(["inspect", str(f)])
    one_clean_error(r, "big.yaml: must be at most 1,048,576 bytes")
    assert seconds < 2


def test_50000_brackets_are_refused_at_once(tmp_path):
    f = tmp_path / "deep.yaml"
    f.write_text("name: " + "[" * 50_000 + "]" * 50_000 + "\n")
    r, seconds = timed(["inspect", str(f)])
    one_clean_error(r, "deep.yaml (line 1, column 106): must be nested at most 100 levels")
    assert seconds < 2


def test_utf16_without_a_byte_order_mark(tmp_path):
    f = tmp_path / "utf16.yaml"
    f.write_bytes(HW.encode("utf-16-le"))
    one_clean_error(runner.invoke(app, ["inspect", str(f)]), "utf16.yaml (line 1, column 2): "
                    "must be UTF-8 text (or UTF-16 with a byte-order mark)")


def test_one_line_in_a_real_process_on_a_narrow_terminal():
    env = {**os.environ, "PYTHONPATH": str(Path(__file__).parents[2] / "src"), "COLUMNS": "60"}
    p = subprocess.run([sys.executable, "-m", "pkmlab.cli", "validate",
                        str(BAD_DIR / "unknown-key-typo.yaml")], capture_output=True, text=True,
                       env=env, timeout=120)
    assert p.returncode == 2
    assert p.stderr.count("\n") == 1 and "Traceback" not in p.stderr, p.stderr
    assert p.stderr.startswith("error: evaluate.workspace.resolutoin (unknown-key-typo.yaml, "
                               "line 10, column 5): must be a known key (did you mean "
                               "'resolution'?")
