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


def _violations(mech, plan, unit_pos, Rs, feas, L, fmax, K, F, S, n_cells=60, seed=1):
    """Sampled check of cell bounds ``K, F, S`` (T, M) on ``n_cells`` random certified cells:
    every feasible sample and 20 random poses in the cell's box. Returns ``(violations,
    ratios K / max κ)``; a violation is a pose with κ > K, force < F or sign(det J) != S."""
    cert = np.argwhere(plan.certified)
    rng = np.random.default_rng(seed)
    bad, ratios = 0, []
    for t, m in cert[rng.permutation(len(cert))[:n_cells]]:
        units = plan.order[np.flatnonzero(plan.cell[plan.order] == t)]
        units = units[feas[units, m]]
        lo, hi = unit_pos[units].min(axis=0), unit_pos[units].max(axis=0)
        p = np.concatenate([unit_pos[units], lo + (hi - lo) * rng.random((20, 3))])
        J = mech.jacobian((p, np.repeat(Rs[[m]], len(p), axis=0)))
        k = condition_number(J, L)
        f = max_force_all_directions(J, fmax, L, mech.mobility)
        bad += int(np.sum(k > K[t, m]) + np.sum(f < F[t, m])
                   + np.sum(np.sign(np.linalg.det(J)) != S[t, m]))
        ratios.append(K[t, m] / k.max())
    return bad, ratios


@pytest.mark.parametrize("mech,h,deg,tight", [(PSU, 5.0, 15.0, 5.0), (UPS, 20.0, 10.0, 20.0)],
                         ids=["psu6", "ups6"])
def test_cell_bounds_are_certified(mech, h, deg, tight):
    """Every feasible sample of a certified cell, and random poses in its box: exact κ <= K,
    force >= F, sign(det J) = the cell's sign. The 6-UPS's cells are 60 mm boxes here (its
    median K / κ was 7.8), the 6-PSU's 15 mm. The same check finds deliberately broken
    bounds (K lowered 20 %, F raised 20 %, the sign flipped)."""
    res = workspace(mech, "dexterous", OrientationSet.box(np.radians([deg] * 3), samples=3), h)
    plan, unit_pos, Rs, feas, L, fmax = _plan(mech, res)
    assert np.sum(plan.certified) > 0.5 * np.sum(plan.K > -np.inf)   # most are certified
    args = (mech, plan, unit_pos, Rs, feas, L, fmax)
    bad, ratios = _violations(*args, plan.K, plan.F, plan.S)
    assert bad == 0
    assert np.median(ratios) < tight                           # a bound, not a vacuous one
    for K, F, S in ((plan.K * 0.8, plan.F, plan.S), (plan.K, plan.F * 1.2, plan.S),
                    (plan.K, plan.F, -plan.S)):
        assert _violations(*args, K, F, S)[0] > 0


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


@pytest.mark.parametrize("mech", [PSU, UPS], ids=["psu6", "ups6"])
def test_chunk_evaluates_pruned_and_force_only_samples_as_stated(mech):
    """:meth:`CellPlan.chunk` against :func:`fused_sweep` over every sample, with the
    incumbents set to the middle of the cell bounds: a sample is evaluated in full (kup,
    force, det bit for bit) unless its cell is certified with K below the κ lower bound — then
    force and det bit for bit and kup = -inf — and, if also F is above the force incumbent,
    pruned (-inf, inf, the sign of det J); infeasible samples: -inf, inf, 0. Each of the three
    kinds occurs."""
    h, deg = (5.0, 15.0) if mech is PSU else (20.0, 10.0)
    res = workspace(mech, "dexterous", OrientationSet.box(np.radians([deg] * 3), samples=3), h)
    plan, unit_pos, Rs, feas, L, fmax = _plan(mech, res)
    M = len(Rs)
    cert = plan.certified
    plan.k_low = float(np.median(plan.K[cert]))
    plan.f_inc = float(np.median(plan.F[cert]))
    kc = (cert & (plan.K < plan.k_low))[plan.cell]              # (U, M)
    fc = (cert & (plan.F > plan.f_inc))[plan.cell]
    kup, force, det = plan.chunk(0, M)                          # (it updates the incumbents)
    want = fused_sweep(mech, unit_pos, Rs, feas, L, fmax)
    full, fonly, pruned = feas & ~kc, feas & kc & ~fc, feas & kc & fc
    for got, ref in zip((kup, force, det), want):
        np.testing.assert_array_equal(got[full], ref[full])
    np.testing.assert_array_equal(force[fonly], want[1][fonly])
    np.testing.assert_array_equal(det[fonly], want[2][fonly])
    assert np.all(kup[fonly] == -np.inf)
    assert np.all(kup[pruned] == -np.inf) and np.all(force[pruned] == np.inf)
    np.testing.assert_array_equal(det[pruned], np.sign(want[2][pruned]))
    assert np.all(kup[~feas] == -np.inf) and np.all(force[~feas] == np.inf)
    assert np.all(det[~feas] == 0.0)
    assert full.sum() and fonly.sum() and pruned.sum()
    assert plan.evaluated == int(full.sum() + fonly.sum())


def test_broken_cell_bounds_change_the_worst_case(monkeypatch):
    """The identity check has teeth: cells whose bounds claim too much (K = 0, F = inf, every
    cell certified with det J > 0) make ``worst_case`` differ from the pass over every
    sample."""
    res = workspace(PSU, "dexterous", OrientationSet.box(np.radians([15] * 3), samples=3), 5.0)
    want = dx.worst_case(PSU, res, None, 150.0).as_dict()
    init = _cells.CellPlan.__init__

    def broken(self, *a, **kw):
        init(self, *a, **kw)
        self.K[:], self.F[:], self.S[:] = 0.0, np.inf, 1
        self.certified[:] = True
        self.k_low, self.f_inc = 1.0, 0.0

    monkeypatch.setattr(_cells.CellPlan, "__init__", broken)
    got = dx.worst_case(PSU, res, None, 150.0).as_dict()
    assert got["worst_kappa"] != want["worst_kappa"]
    assert got["min_force_N"] != want["min_force_N"]
