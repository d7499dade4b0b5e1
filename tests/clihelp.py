"""Helpers shared by test modules: the console entry point run in process, the one-line error
check, a small study file, edited mechanism files and a test mesh format. (The folder ``tests``
is on ``sys.path``, see ``pythonpath`` in pyproject.toml.)"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import yaml
from conftest import MECH_DIR

from pkmlab.cli import run_cli

HW = MECH_DIR / "hopkins-williams-6psu.yaml"
GS = MECH_DIR / "gough-stewart-6ups.yaml"
LUZI = MECH_DIR / "luzi-3chain.yaml"


def cli(capsys, *args, env: dict | None = None, monkeypatch=None) -> tuple[int, str, str]:
    """Run the console entry point in process: (exit code, stdout, stderr)."""
    if env and monkeypatch is not None:
        for k, v in env.items():
            monkeypatch.setenv(k, v)
    old = sys.argv
    sys.argv = ["pkmlab", *map(str, args)]
    try:
        run_cli()
        code = 0
    except SystemExit as exc:
        code = exc.code
    finally:
        sys.argv = old
    o, e = capsys.readouterr()
    return code, o, e


def error_lines(err: str) -> list[str]:
    """stderr without pkmlab's progress log lines (``pkmlab: …``), which are not errors."""
    return [ln for ln in err.strip().splitlines() if not ln.startswith("pkmlab: ")]


def one_line(code, err, *fragments):
    assert code == 2, (code, err)
    lines = error_lines(err)
    assert len(lines) == 1 and lines[0].startswith("error: "), err
    assert "Traceback" not in err
    for f in fragments:
        assert f in lines[0], (f, lines[0])
    return lines[0]


def small_study(tmp_path: Path, **over) -> Path:
    data = {
        "study": "tiny",
        "mechanism": {"file": str(HW)},
        "design": {"link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "constant", "samples": 1, "resolution": "8 mm"}},
        "objectives": [{"maximize": "constant_volume"}],
        "optimizer": {"method": "sobol", "samples": 4},
        "seed": 1,
        "output": str(tmp_path / "out"),
    }
    data.update(over)
    p = tmp_path / "study.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


def mech_file(tmp_path: Path, src: Path, **replace) -> Path:
    text = src.read_text()
    for key, value in replace.items():
        lines = [f"{key}: {value}" if ln.startswith(f"{key}:") else ln
                 for ln in text.splitlines()]
        text = "\n".join(lines) + "\n"
    p = tmp_path / f"{src.stem}-edited.yaml"
    p.write_text(text)
    return p


def off_bytes(mesh) -> bytes:
    """Object File Format (text): 'OFF', counts, vertices (mm), faces."""
    v, f = np.asarray(mesh.vertices), np.asarray(mesh.faces)
    lines = ["OFF", f"{len(v)} {len(f)} 0"]
    lines += [f"{a:.6f} {b:.6f} {c:.6f}" for a, b, c in v]
    lines += [f"3 {a} {b} {c}" for a, b, c in f]
    return ("\n".join(lines) + "\n").encode()
