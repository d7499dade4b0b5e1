"""CLI of the dexterity and trajectory evaluators, and the per-voxel metric maps."""

from __future__ import annotations

import json

import numpy as np
import pytest
import trimesh
from conftest import MECH_DIR
from typer.testing import CliRunner

from pkmlab import OrientationSet, load_mechanism, workspace
from pkmlab.cli import app
from pkmlab.dexterity.maps import metric_map

HOPKINS = MECH_DIR / "hopkins-williams-6psu.yaml"


def test_dexterity_cli_reports_independently_checkable_figures(tmp_path):
    out = tmp_path / "dx"
    r = CliRunner().invoke(app, ["dexterity", str(HOPKINS), "--box", "10,10,10", "--samples", "3",
                                 "--resolution", "5", "--characteristic-length", "60",
                                 "--gci-samples", "500", "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    d = json.loads(r.stdout)
    mech = load_mechanism(HOPKINS)
    J = mech.jacobian(mech.nominal_pose)[0]
    J[:, 3:] /= 60.0
    assert d["nominal"]["kappa"] == pytest.approx(np.linalg.cond(J), rel=1e-10)
    assert d["nominal"]["characteristic_length"]["status"] == "given"
    assert d["characteristic_length"]["length_mm"] == 60.0
    a = d["aggregates"]
    assert a["kappa"]["min"] <= d["nominal"]["kappa"] <= a["kappa"]["max"]
    # the worst case is over the same grid: its κ is the grid's largest, its force the map's
    w = a["worst_case"]
    assert w["status"] == "ok" and not w["singular"]
    assert w["worst_kappa"] == pytest.approx(a["kappa"]["max"], rel=1e-12)
    assert w["min_force_N"] == pytest.approx(a["force_all_directions_N"]["min"], rel=1e-9)
    assert w["characteristic_length"]["length_mm"] == 60.0
    assert abs(a["gci_monte_carlo"] - a["gci_grid"]) < 0.05
    assert 0 < a["well_conditioned_volume_cm3"] <= a["workspace_volume_cm3"] + 1e-9
    names = {p.name for p in out.iterdir()}
    assert names == {"dexterity.json", "kappa_slices.png", "workspace_kappa.ply",
                     "workspace_kappa.glb"}
    mesh = trimesh.load(out / "workspace_kappa.ply")
    colours = np.asarray(mesh.visual.vertex_colors)
    assert colours.shape == (len(mesh.vertices), 4) and len(np.unique(colours, axis=0)) > 5


@pytest.mark.parametrize("args, field", [(["--metric", "beauty"], "--metric"),
                                         (["--characteristic-length", "-3"],
                                          "--characteristic-length"),
                                         (["--force-limit", "0"], "--force-limit")])
def test_dexterity_cli_bad_input(tmp_path, args, field):
    r = CliRunner().invoke(app, ["dexterity", str(HOPKINS), *args, "--out", str(tmp_path / "o")])
    assert r.exit_code == 2 and field in r.stderr
    assert not (tmp_path / "o").exists()


def test_metric_maps_are_worst_cases_over_the_set():
    mech = load_mechanism(HOPKINS)
    res = workspace(mech, "dexterous", OrientationSet.box(np.radians([10] * 3), samples=3), 5.0)
    km = metric_map(mech, res, "kappa", L=60.0)
    fm = metric_map(mech, res, "force", L=60.0, f_max=150.0)
    # the worst over the set is at least as bad as the value at the nominal orientation
    X = np.column_stack([km.positions, np.zeros((len(km.positions), 3))])
    J = mech.jacobian(X)
    J[..., 3:] /= 60.0
    assert np.all(km.values >= np.linalg.cond(J) - 1e-9)
    from pkmlab.dexterity import max_force_all_directions

    assert np.all(fm.values <= max_force_all_directions(mech.jacobian(X), 150.0) + 1e-9)
    assert np.isnan(km.grid[~res.occupancy]).all() and np.isfinite(km.grid[res.occupancy]).all()


def test_maps_computed_only_where_drawn_give_the_same_picture_and_mesh_colours():
    """Issue 14 (cheap exports): the export evaluates κ only on the slice layers and the
    surface voxels; the drawn values and the mesh vertex values equal the full map's."""
    from pkmlab.dexterity.maps import drawn_voxels, vertex_values
    from pkmlab.workspaces.output.slicing import slice_layout

    mech = load_mechanism(HOPKINS)
    res = workspace(mech, "dexterous", OrientationSet.box(np.radians([10] * 3), samples=3), 4.0)
    levels = slice_layout(res, "auto", None, None, None, 12).levels
    where = drawn_voxels(res, levels)
    full = metric_map(mech, res, "kappa", L=60.0)
    part = metric_map(mech, res, "kappa", L=60.0, where=where)
    assert 0 < where.sum() < res.occupancy.sum() and not (where & ~res.occupancy).any()
    k = np.rint((np.asarray(levels) - res.zs[0]) / res.resolution).astype(int)
    np.testing.assert_array_equal(part.grid[:, :, k], full.grid[:, :, k])
    mesh = res.mesh()
    np.testing.assert_array_equal(vertex_values(mesh, part), vertex_values(mesh, full))


def test_trajectory_cli_reports_the_first_violation(tmp_path):
    mech = load_mechanism(HOPKINS)
    t = np.linspace(0, 2, 41)
    X = np.tile(mech.nominal_pose, (41, 1))
    X[:, 2] += np.linspace(0, 80, 41)                 # rises 80 mm: past the 50.8 mm headroom
    first = int(np.argmax(X[:, 2] - mech.nominal_pose[2] > 50.8))
    rows = ["t,x,y,z,theta_x,theta_y,theta_z"] + [
        ",".join(f"{v:.9g}" for v in [ti, *x[:3], *np.degrees(x[3:])]) for ti, x in zip(t, X)]
    csv = tmp_path / "ramp.csv"
    csv.write_text("\n".join(rows) + "\n")
    out = tmp_path / "tr"
    r = CliRunner().invoke(app, ["trajectory", str(HOPKINS), "--csv", str(csv), "--out", str(out),
                                 "--json"])
    assert r.exit_code == 1, r.output          # a failed sample: reported, exit status 1
    d = json.loads(r.stdout)
    assert d["fits"] is False
    assert d["violations"]["stroke"]["index"] == first
    assert {p.name for p in out.iterdir()} == {"trajectory.json", "trajectory.csv",
                                               "actuators.png"}
    bad = tmp_path / "bad.csv"
    bad.write_text("t,x,y\n0,1,2\n")
    r = CliRunner().invoke(app, ["trajectory", str(HOPKINS), "--csv", str(bad), "--out",
                                 str(tmp_path / "none")])
    assert r.exit_code == 2 and not (tmp_path / "none").exists()
    r = CliRunner().invoke(app, ["trajectory", str(HOPKINS)])
    assert r.exit_code == 2 and "--paper-motion" in r.stderr


def test_column_shared_maps_equal_the_per_voxel_computation():
    """Issue 14 (cheap exports): for a 6-PSU, J does not depend on z, so the maps evaluate J
    once per (x, y) column; every voxel's worst κ, LCI and force over the set equal a per-voxel
    computation (J at the voxel itself, numpy's cond, the IK's validity) on the drawn subset."""
    from pkmlab.dexterity import max_force_all_directions
    from pkmlab.dexterity.maps import drawn_voxels

    mech = load_mechanism(HOPKINS)
    res = workspace(mech, "dexterous", OrientationSet.box(np.radians([10] * 3), samples=3), 6.0)
    where = drawn_voxels(res, [res.zs[len(res.zs) // 2]])
    maps = {m: metric_map(mech, res, m, L=60.0, f_max=150.0, where=where)
            for m in ("kappa", "lci", "force")}
    pos = maps["kappa"].positions
    Rs = res.orientations.rotations()
    P, RR = np.tile(pos, (len(Rs), 1)), np.repeat(Rs, len(pos), axis=0)
    J = mech.jacobian((P, RR))
    valid = mech.inverse((P, RR)).valid
    Jh = J.copy()
    Jh[..., 3:] /= 60.0
    kap = np.where(valid, np.linalg.cond(Jh), np.inf).reshape(len(Rs), -1)
    force = np.where(valid, max_force_all_directions(J, 150.0, 60.0), 0.0).reshape(len(Rs), -1)
    assert len(np.unique(maps["kappa"].index[:, :2], axis=0)) < len(pos)   # columns shared
    np.testing.assert_allclose(maps["kappa"].values, kap.max(axis=0), rtol=1e-9)
    np.testing.assert_allclose(maps["lci"].values, (1.0 / kap).min(axis=0), rtol=1e-9)
    np.testing.assert_allclose(maps["force"].values, force.min(axis=0), rtol=1e-9)
