"""Forward kinematics and assembly modes agree with the inverse kinematics on the working mode:
a pose whose legs the IK reports as outside the working mode (the mirror image through the base
plane, which has the same leg lengths) is never a working-mode solution, for the families that
have one (ups6: platform joints above their base joints; luzi3: each upper link on its nominal
branch)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECH_DIR

from pkmlab import load_mechanism
from pkmlab.mechanisms import Luzi3

MIRROR = np.array([1, 1, -1, 1, 1, 1])        # level nominal poses: the mirror keeps R


@pytest.fixture(scope="module", params=["ups6", "luzi3"])
def mech(request):
    if request.param == "ups6":
        return load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")
    return Luzi3.from_paper(base_diameter=700.0, phi=math.radians(30), platform_diameter=220.0,
                            upper_link=80.0, stroke=(600.0, 950.0))


def test_the_mirror_pose_is_not_a_working_mode(mech):
    X = np.asarray(mech.nominal_pose, dtype=float)
    assert abs(X[3]) < 1e-9 and abs(X[4]) < 1e-9            # level: the mirror is a pose
    q = mech.inverse(X).q[0]
    Xm = X * MIRROR
    ik = mech.inverse(Xm)
    np.testing.assert_allclose(ik.q[0], q, atol=1e-6)       # same lengths
    assert not ik.valid[0] and ik.reason_text[0] == "leg outside the working mode"
    # Newton from the mirror converges there; FK must not return it as the working mode
    fk = mech.forward(q, guess=Xm)
    assert fk.converged[0]
    np.testing.assert_allclose(fk.pose[0, :3], X[:3], atol=1e-6)
    modes = mech.assembly_modes(q, starts=200, seed=1)
    near = np.linalg.norm(modes.pose[:, :3] - Xm[:3], axis=1) < 1e-3
    assert near.any() and not modes.working_mode[near].any()
    assert modes.working_mode[np.linalg.norm(modes.pose[:, :3] - X[:3], axis=1) < 1e-3].all()
