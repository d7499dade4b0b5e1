"""`pkmlab compare`: the same definitions and requests as the other commands."""

from __future__ import annotations

import json
from dataclasses import dataclass

import numpy as np
import pytest
from conftest import MECH_DIR
from typer.testing import CliRunner

import pkmlab
from pkmlab import PSU6
from pkmlab.cli import app
from pkmlab.study.compare import compare_designs, comparison_markdown
from pkmlab.workspaces import OrientationSet, workspace

HOPKINS = MECH_DIR / "hopkins-williams-6psu.yaml"
H = pkmlab.load_mechanism(HOPKINS)


@dataclass(frozen=True, eq=False)
class _SingularBeyond(PSU6):
    """Hopkins geometry whose Jacobian is rank-deficient (two equal columns) for x > x_singular
    (still independent of z, so the 6-PSU's column sharing holds)."""

    x_singular: float = 1e9

    def _jacobian(self, p, R):
        J = super()._jacobian(p, R)
        far = p[:, 0] > self.x_singular
        J[far, :, 5] = J[far, :, 4]
        return J


def test_compare_gci_counts_singular_poses_as_zero():
    mech = _SingularBeyond(H.base_points, H.platform_points, H.link_length, H.stroke,
                           H.tool_offset, x_singular=H.nominal_pose[0] + 10.0)
    row = compare_designs([("singular", mech)], box_deg=5.0, resolution=5.0, samples=3)[0]
    # independent: every voxel × orientation of the same request, LAPACK's condition number
    res = workspace(mech, "dexterous", OrientationSet.box(np.radians([5.0] * 3), samples=3), 5.0)
    pos, Rs = res.voxel_centres(), res.orientations.rotations()
    p, R = np.tile(pos, (len(Rs), 1)), np.repeat(Rs, len(pos), axis=0)
    valid = mech.inverse((p, R)).valid
    L = row["characteristic_length"]["length_mm"]
    Jh = mech.jacobian((p, R))
    Jh[..., 3:] /= L
    cond = np.linalg.cond(Jh)
    lci = np.where(cond < 1e12, 1.0 / cond, 0.0)[valid]
    singular = lci == 0.0
    assert 0.1 < singular.mean() < 0.9
    assert row["gci"] == pytest.approx(lci.mean(), rel=1e-9)
    assert row["gci"] < 0.95 * lci[~singular].mean()       # dropping them would inflate it
    assert row["gci_result"]["singular"] == int(singular.sum())
    assert row["singular"].startswith("yes") and row["force_N"] == 0.0
    assert row["kappa_range"].endswith("inf")
    assert row["worst_case"]["singular"] and row["worst_case"]["singular_samples"] > 0
    assert row["characteristic_length"]["status"] == "angeles"
    md = comparison_markdown([row])
    assert "singular pose (inside or on the boundary)" in md and "±5° simultaneous" in md


def test_compare_inscribed_shapes_are_those_of_the_workspace_command(tmp_path):
    args = ["--box", "10,10,10", "--samples", "3", "--resolution", "5"]
    r = CliRunner().invoke(app, ["workspace", str(HOPKINS), "--kind", "dexterous", *args,
                                 "--inscribed", "--json", "--out", str(tmp_path / "ws")])
    assert r.exit_code == 0, r.output
    ws = json.loads(r.stdout)
    r = CliRunner().invoke(app, ["compare", str(HOPKINS), "--box", "10", "--samples", "3",
                                 "--resolution", "5", "--json", "--out", str(tmp_path / "cmp")])
    assert r.exit_code == 0, r.output
    row = json.loads(r.stdout)["designs"][0]
    assert row["inscribed_cylinder"] == ws["inscribed_cylinder"]
    assert row["inscribed_box"] == ws["inscribed_box"]
    assert row["inscribed_cylinder"]["status"] == "ok"
    assert row["dexterous_volume_cm3"] == pytest.approx(ws["volume_cm3"], rel=1e-12)
    assert row["request"]["dexterous_set"].startswith("±10° simultaneous Euler box, 3 samples")
    assert row["worst_case"]["status"] == "ok" and not row["worst_case"]["singular"]
    assert row["worst_case"]["worst_kappa"] == pytest.approx(
        float(row["kappa_range"].split("…")[1]), rel=1e-2)
