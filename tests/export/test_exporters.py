"""The exporter registry: a format registered the way the built-ins are is offered by the CLI,
written for every exported study design and described in the report's file table."""

from __future__ import annotations

import json

import numpy as np
import pytest
from clihelp import cli, small_study
from clihelp import off_bytes as _off
from conftest import MECH_DIR

from pkmlab.export import EXPORTERS, Exporter, exporters, register_exporter
from pkmlab.export.meshes import STL_HEADER


@pytest.fixture
def off_format():
    ex = register_exporter(Exporter("off", "mesh", "Object File Format text in mm", _off,
                                    trimesh=False))
    yield ex
    EXPORTERS.pop("off")


def _read_off(path):
    lines = path.read_text().splitlines()
    nv, nf, _ = map(int, lines[1].split())
    faces = np.array([list(map(int, ln.split()[1:])) for ln in lines[2 + nv:2 + nv + nf]])
    return nv, faces


def test_built_in_mesh_formats_are_registered():
    assert list(exporters("mesh")) == ["stl", "ply", "glb"]
    assert list(exporters("mesh", option="colors")) == ["ply", "glb"]
    with pytest.raises(ValueError, match="already registered"):
        register_exporter(Exporter("stl", "mesh", "another STL", _off))
    with pytest.raises(ValueError, match="lower-case alphanumeric"):
        Exporter("S.T", "mesh", "bad", _off)


def test_a_registered_format_is_offered_by_the_workspace_command(capsys, tmp_path, off_format):
    out = tmp_path / "ws"
    code, _, err = cli(capsys, "workspace", MECH_DIR / "hopkins-williams-6psu.yaml",
                       "--resolution", "8", "--mesh", "stl,off", "--out", out, "--json")
    assert code == 0, err
    nv, faces = _read_off(out / "workspace.off")
    stl = (out / "workspace.stl").read_bytes()
    assert stl.startswith(STL_HEADER)
    assert len(faces) == int(np.frombuffer(stl[80:84], np.uint32)[0])   # the same triangles
    assert faces.min() == 0 and faces.max() == nv - 1
    code, _, err = cli(capsys, "workspace", MECH_DIR / "hopkins-williams-6psu.yaml",
                       "--mesh", "obj", "--out", out)
    assert code == 2 and "--mesh: must be comma-separated formats from ['stl', 'ply', 'glb', " \
        "'off']; got 'obj'" in err, err


def test_a_registered_format_is_written_for_study_designs_and_described(capsys, tmp_path,
                                                                          off_format):
    code, _, err = cli(capsys, "run", small_study(tmp_path))
    assert code == 0, err
    designs = sorted((tmp_path / "out" / "designs").glob("*/design.json"))
    assert designs
    for d in designs:
        info = json.loads(d.read_text())
        assert {"workspace.stl", "workspace.ply", "workspace.glb", "workspace.off"} \
            <= set(info["files"])
        assert (d.parent / "workspace.off").stat().st_size > 0
    page = (tmp_path / "out" / "report.html").read_text()
    assert "workspace hull, Object File Format text in mm" in page
