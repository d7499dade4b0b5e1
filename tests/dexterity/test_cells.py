"""The branch and bound over cells of the worst case (issue 28 item 2).

* :func:`pkmlab.dexterity._fused.fused_sweep_at` (the per-pose kernel on a list of poses)
  gives :func:`~pkmlab.dexterity._fused.fused_sweep`'s values bit for bit;
* the box Jacobians enclose the Jacobian at random poses in their box;
* the cell bounds are certified: at every sample of a certified cell, and at random poses in
  its box, the exact κ is at most ``K``, the all-direction force at least ``F`` and ``det J``
  has the cell's sign;
* ``worst_case`` with the cells and with every sample evaluated gives the same result, every
  field but the count of exact κ evaluations, on designs of several families.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECH_DIR
from conftest import same_result as _same

import pkmlab
from pkmlab import dexterity as dx
from pkmlab.dexterity import _cells, worst
from pkmlab.dexterity._fused import fused_sweep, fused_sweep_at
from pkmlab.dexterity.aggregate import _units, _voxels
from pkmlab.dexterity.force import max_force_all_directions
from pkmlab.dexterity.metrics import condition_number
from pkmlab.workspaces import OrientationSet, workspace

PSU = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
UPS = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")


@pytest.mark.parametrize("mech", [PSU, UPS], ids=["psu6", "ups6"])
def test_sweep_at_equals_fused_sweep(mech):
    """Random poses (one NaN position, one far out of reach) × rotations, a random subset:
    bit-identical kup, force, det; the others untouched."""
    rng = np.random.default_rng(3)
    U, K = 61, 7
    P = mech.nominal_pose[:3] + rng.uniform(-80, 80, (U, 3))
    P[5] = np.nan
    P[9] = mech.nominal_pose[:3] + 1e4
    R = pkmlab.poses.euler_to_matrix(np.radians(rng.uniform(-30, 30, (K, 3)))).reshape(-1, 3, 3)
    feas = np.ones((U, K), dtype=bool)
    L, fmax = 90.0, np.linspace(100.0, 200.0, 6)
    want = fused_sweep(mech, P, R, feas, L, fmax)
    at = np.flatnonzero(rng.random(U * K) < 0.7)
    got = [np.full((K, U), 7.0) for _ in range(3)]
    fused_sweep_at(mech, P, R, at, L, fmax, *got)
    for g, w in zip(got, want):
        flat = g.ravel()
        np.testing.assert_array_equal(flat[at], w.T.ravel()[at])     # bit for bit, NaN too
        rest = np.ones(U * K, dtype=bool)
        rest[at] = False
        assert np.all(flat[rest] == 7.0)
    assert np.isnan(got[1].ravel()[at]).any()


@pytest.mark.parametrize("mech", [PSU, UPS], ids=["psu6", "ups6"])
def test_box_jacobian_encloses(mech):
    rng = np.random.default_rng(5)
    box = type(mech)._jac_box.py_func if hasattr(type(mech)._jac_box, "py_func") else \
        type(mech)._jac_box
    g = np.asarray(mech.jacobian_kernel()[1])
    for _ in range(20):
        c = mech.nominal_pose[:3] + rng.uniform(-30, 30, 3)
        half = rng.uniform(0.5, 8.0, 3)
        R = pkmlab.poses.euler_to_matrix(np.radians(rng.uniform(-15, 15, 3))).reshape(3, 3)
        Jlo, Jhi = np.empty((6, 6)), np.empty((6, 6))
        assert box(c - half, c + half, R, R, g, Jlo, Jhi)
        p = c + half * rng.uniform(-1, 1, (200, 3))
        J = mech.jacobian((p, np.repeat(R[None], 200, axis=0)))
        assert np.all(J >= Jlo) and np.all(J <= Jhi)


def _plan(mech, res):
    idx, pos = _voxels(res)
    unit_pos, _, _ = _units(mech, idx, pos)
    Rs = res.orientations.rotations()
    feas = worst._unit_feasibility(mech, pos, Rs, _units(mech, idx, pos)[1], len(unit_pos))
    L, fmax = dx.resolve_length(mech).length, np.full(6, 150.0)
    plan = _cells.CellPlan(mech, unit_pos, Rs, feas, L, fmax, res.resolution,
                           lambda u, m: math.nan)
    return plan, unit_pos, Rs, feas, L, fmax


@pytest.mark.parametrize("mech,h,deg,tight", [(PSU, 5.0, 15.0, 5.0), (UPS, 20.0, 10.0, 20.0)],
                         ids=["psu6", "ups6"])
def test_cell_bounds_are_certified(mech, h, deg, tight):
    """Every feasible sample of a certified cell, and random poses in its box: exact κ <= K,
    force >= F, sign(det J) = the cell's sign. The 6-UPS's cells are 60 mm boxes here (its
    median K / κ was 7.8), the 6-PSU's 15 mm."""
    res = workspace(mech, "dexterous", OrientationSet.box(np.radians([deg] * 3), samples=3), h)
    plan, unit_pos, Rs, feas, L, fmax = _plan(mech, res)
    cert = np.argwhere(plan.certified)
    assert len(cert) > 0.5 * np.sum(plan.K > -np.inf)          # most cells are certified
    rng = np.random.default_rng(1)
    ratios = []
    for t, m in cert[rng.permutation(len(cert))[:60]]:
        units = plan.order[np.flatnonzero(plan.cell[plan.order] == t)]
        units = units[feas[units, m]]
        lo, hi = unit_pos[units].min(axis=0), unit_pos[units].max(axis=0)
        p = np.concatenate([unit_pos[units], lo + (hi - lo) * rng.random((20, 3))])
        J = mech.jacobian((p, np.repeat(Rs[[m]], len(p), axis=0)))
        k = condition_number(J, L)
        f = max_force_all_directions(J, fmax, L, mech.mobility)
        assert np.all(k <= plan.K[t, m]), (k.max(), plan.K[t, m])
        assert np.all(f >= plan.F[t, m]), (f.min(), plan.F[t, m])
        assert np.all(np.sign(np.linalg.det(J)) == plan.S[t, m])
        ratios.append(plan.K[t, m] / k.max())
    assert np.median(ratios) < tight                           # a bound, not a vacuous one


@pytest.mark.parametrize("case", ["psu6", "psu6-wide", "ups6", "ups6-singular"])
def test_worst_case_with_cells_is_identical(case):
    """worst_case with the cells and with every sample evaluated: every field identical but
    ``exact`` (the count of exact κ evaluations) and the wall time."""
    if case == "psu6":
        mech, res = PSU, workspace(PSU, "dexterous",
                                   OrientationSet.box(np.radians([15] * 3), samples=3), 5.0)
    elif case == "psu6-wide":                           # a wide reachable set: near singular
        mech, res = PSU, workspace(PSU, "reachable",
                                   OrientationSet.box(np.radians([25] * 3), samples=3), 8.0)
    elif case == "ups6":
        mech, res = UPS, workspace(UPS, "dexterous",
                                   OrientationSet.box(np.radians([10] * 3), samples=3), 20.0)
    else:                                              # turned by up to 90° about z (Fichter)
        mech, res = UPS, workspace(UPS, "reachable",
                                   OrientationSet.box(np.radians([5, 5, 90]), samples=3), 40.0)
    out = {}
    try:
        for flag in (False, True):
            worst.CELLS = flag
            out[flag] = dx.worst_case(mech, res, None, 150.0).as_dict()
    finally:
        worst.CELLS = True
    for d in out.values():
        d.pop("seconds")
        d.pop("exact_kappa_evaluations")
        d["method"] = d["method"].split("; exact κ at")[0]
    assert out[True]["status"] == "ok"
    assert _same(out[False], out[True]), (out[False], out[True])
    if case == "ups6-singular":
        assert out[True]["singular"]
