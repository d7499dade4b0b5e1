"""Issue 25 (optional check): Pinocchio's MJCF reader reads the MJCF export as one tree with
its loop constraints, and agrees with MuJoCo and pkmlab.

Skips without Pinocchio (``pip install pin``: not in the locked environment, about 450 MB).
For every registered family: the same numbers of coordinates and of loop constraints as
MuJoCo; at the file's ``home`` configuration the tool frame is at pkmlab's nominal pose and
every constraint's two frames coincide; at a pose MuJoCo settled to (``drive``), MuJoCo's
joint values in Pinocchio put the tool at pkmlab's pose and close every loop.
"""

from __future__ import annotations

import numpy as np
import pytest
from export_samples import FAMILIES, sample

pin = pytest.importorskip("pinocchio", reason="the Pinocchio check needs pinocchio "
                          "(pip install pin)")
mujoco = pytest.importorskip("mujoco", reason="needs the simulator (mujoco-core)")

from pkmlab.export import roundtrip as rt  # noqa: E402
from pkmlab.export.mjcf import mjcf_text  # noqa: E402
from pkmlab.poses import log_so3  # noqa: E402
from pkmlab.testing import random_valid_poses  # noqa: E402


def _pin_model(mech, tmp_path):
    path = tmp_path / "m.mjcf.xml"
    path.write_text(mjcf_text(mech))
    model, constraints, _, _ = pin.buildModelsFromMJCF(str(path))
    return model, constraints


def _errors(mech, model, constraints, q, pose):
    data = model.createData()
    pin.framesForwardKinematics(model, data, q)
    p, R = mech._frames(pose)
    tool = data.oMf[model.getFrameId("tool")]
    pos = np.linalg.norm(tool.translation * 1e3 - p[0])
    rot = np.linalg.norm(log_so3(tool.rotation.T @ R[0]))
    gap = max(np.linalg.norm((data.oMi[c.joint1_id] * c.joint1_placement).translation
                             - (data.oMi[c.joint2_id] * c.joint2_placement).translation)
              for c in constraints) * 1e3
    return pos, rot, gap


def _q_from_mujoco(model, mjm, d):
    """MuJoCo's joint values in Pinocchio's order (balls: w, x, y, z → x, y, z, w)."""
    q = pin.neutral(model)
    for j in range(1, model.njoints):
        name = model.names[j]
        jm = mjm.joint(name)
        a, n = model.joints[j].idx_q, model.joints[j].nq
        v = d.qpos[jm.qposadr[0]:jm.qposadr[0] + n]
        q[a:a + n] = np.r_[v[1:], v[:1]] if n == 4 else v
    return q


@pytest.mark.parametrize("family", FAMILIES)
def test_pinocchio_reads_the_mjcf_with_its_loops(family, tmp_path):
    mech = sample(family)
    model, constraints = _pin_model(mech, tmp_path)
    mjm, d = rt.load(mech)
    assert (model.nq, model.nv, len(constraints)) == (mjm.nq, mjm.nv, mjm.neq)
    home = model.referenceConfigurations["home"]
    pos, rot, gap = _errors(mech, model, constraints, home, mech.nominal_pose)
    assert pos <= 1e-9 and rot <= 1e-12 and gap <= 1e-9
    X = random_valid_poses(mech, 1, seed=31)[0]
    rt.drive(mech, mjm, d, X)
    pos, rot, gap = _errors(mech, model, constraints, _q_from_mujoco(model, mjm, d), X)
    assert pos <= 1e-6 and rot <= 1e-6 and gap <= 1e-6
