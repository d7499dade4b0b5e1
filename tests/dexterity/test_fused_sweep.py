"""The fused Jacobian + bounds kernel of the worst case (issue 28 item 1) gives the unfused
path's values bit for bit: per pose against ``mech.jacobian`` + ``sweep_bounds``, and whole
``worst_case`` results (every field) with ``worst.FUSED`` on and off, for the 6-PSU and the
6-UPS (a singular workspace among them)."""

from __future__ import annotations

import numpy as np
import pytest
from conftest import MECH_DIR
from conftest import same_result as _same

import pkmlab
from pkmlab import dexterity as dx
from pkmlab.dexterity import worst
from pkmlab.dexterity._fused import fused_available, fused_sweep
from pkmlab.dexterity._linalg import sweep_bounds
from pkmlab.workspaces import OrientationSet, workspace

PSU = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
UPS = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")


@pytest.mark.parametrize("mech", [PSU, UPS], ids=["psu6", "ups6"])
def test_fused_sweep_equals_jacobian_then_sweep_bounds(mech):
    """Random positions around the nominal pose (one NaN: a NaN Jacobian) × random
    rotations, a random feasibility mask: identical kup, force and det (NaN where NaN)."""
    rng = np.random.default_rng(11)
    P = mech.nominal_pose[:3] + rng.uniform(-120, 120, (37, 3))
    P[5] = np.nan                                       # a non-finite Jacobian
    R = pkmlab.poses.euler_to_matrix(np.radians(rng.uniform(-40, 40, (9, 3)))).reshape(-1, 3, 3)
    feas = rng.random((37, 9)) < 0.8
    L, fmax = 90.0, np.linspace(100.0, 200.0, 6)
    assert fused_available(mech)
    kup, force, det = fused_sweep(mech, P, R, feas, L, fmax)
    J = mech.jacobian((np.tile(P, (9, 1)), np.repeat(R, 37, axis=0)))
    ref = [np.empty(len(J)) for _ in range(3)]
    sweep_bounds(np.ascontiguousarray(J), L, fmax, *ref)
    ref = [a.reshape(9, 37).T for a in ref]
    for got, want, off in zip((kup, force, det), ref, (-np.inf, np.inf, 0.0)):
        want = np.where(feas, want, off)
        np.testing.assert_array_equal(got, want)          # bit for bit, NaN where NaN
    assert np.isnan(force[feas]).any() and np.isfinite(force[feas]).any()


@pytest.mark.parametrize("case", ["psu6", "ups6", "ups6-singular"])
def test_worst_case_fused_and_unfused_are_identical(case):
    mech = PSU if case == "psu6" else UPS
    if case == "psu6":
        res = workspace(PSU, "dexterous", OrientationSet.box(np.radians([15] * 3), samples=3),
                        5.0)
    elif case == "ups6":
        res = workspace(UPS, "dexterous", OrientationSet.box(np.radians([10] * 3), samples=3),
                        20.0)
    else:                                              # turned by up to 90° about z (Fichter)
        res = workspace(UPS, "reachable", OrientationSet.box(np.radians([5, 5, 90]), samples=3),
                        40.0)
    out = {}
    try:
        for flag in (False, True):
            worst.FUSED = flag
            out[flag] = dx.worst_case(mech, res, None, 150.0).as_dict()
    finally:
        worst.FUSED = True
    for d in out.values():
        d.pop("seconds")
    assert out[True]["status"] == "ok"
    assert _same(out[False], out[True]), (out[False], out[True])
    if case == "ups6-singular":
        assert out[True]["singular"]
