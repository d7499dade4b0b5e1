"""The first-order cell bounds of the worst case (issue 28, session 5): the 6-PSU's
``_jac_lin`` and :func:`pkmlab.dexterity._cells._lin_bounds_kernel`.

* the first-order form encloses the per-pose Jacobian: ``|J(p) - J(pc) - Σ Δ_k A_k| <= W``
  at random positions of random boxes, and its remainder is second order (not vacuous: the
  sampled remainder reaches a stated fraction of ``W``; ``W = 0`` is violated);
* the cell bounds are certified (exact κ <= K, force >= F, sign of ``det J``) at every
  feasible sample of 80 random certified cells and 20 random poses in each box, and the same
  check finds violations when ``K`` is lowered 15 % or ``F`` raised 10 %, or the sign flipped;
* ``worst_case`` with them (cells of 3 and 6 columns) equals the pass over every sample.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import MECH_DIR
from conftest import same_result as _same
from test_cells import _plan, _violations

import pkmlab
from pkmlab import dexterity as dx
from pkmlab.dexterity import _cells, worst
from pkmlab.workspaces import OrientationSet, workspace

PSU = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
LIN = type(PSU)._jac_lin
LIN = getattr(LIN, "py_func", LIN)


def _remainders(rng, n_boxes=30, half=(0.5, 10.0)):
    g = np.asarray(PSU.jacobian_kernel()[1])
    out = []
    for _ in range(n_boxes):
        c = PSU.nominal_pose[:3] + rng.uniform(-30, 30, 3)
        h = rng.uniform(*half, 3)
        lo, hi = c - h, c + h
        pc = 0.5 * (lo + hi)
        R = pkmlab.poses.euler_to_matrix(np.radians(rng.uniform(-15, 15, 3))).reshape(3, 3)
        A, W = np.empty((3, 6, 6)), np.empty((6, 6))
        assert LIN(lo, hi, pc, R, g, A, W)
        p = np.concatenate([lo + (hi - lo) * rng.random((300, 3)),
                            lo + (hi - lo) * rng.integers(0, 2, (16, 3))])     # + corners
        J = PSU.jacobian((p, np.repeat(R[None], len(p), axis=0)))
        J0 = PSU.jacobian((pc[None], R[None]))[0]
        rem = np.abs(J - J0 - np.einsum("nk,kij->nij", p - pc, A))
        out.append((rem, W, A))
    return out


def test_linear_form_encloses_the_jacobian():
    rng = np.random.default_rng(11)
    worst_ratio = 0.0
    for rem, W, A in _remainders(rng):
        assert np.all(rem <= W)
        assert np.all(A[2] == 0.0)                        # J does not depend on z
        worst_ratio = max(worst_ratio, float(np.max(rem / W)))
        assert np.any(rem > 0.0 * W + 1e-12)              # W = 0 (first order only) fails
    # the remainder is not vacuous: the sampled remainder reaches a good part of W
    assert worst_ratio > 0.4, worst_ratio                   # measured 0.497


def test_linear_remainder_is_second_order():
    """Halving the box quarters the remainder bound (to within rounding): W is O(h²)."""
    g = np.asarray(PSU.jacobian_kernel()[1])
    c = PSU.nominal_pose[:3] + np.array([12.0, -7.0, 0.0])
    R = pkmlab.poses.euler_to_matrix(np.radians([5.0, -8.0, 3.0])).reshape(3, 3)
    ws = []
    for h in (8.0, 4.0):
        A, W = np.empty((3, 6, 6)), np.empty((6, 6))
        assert LIN(c - h, c + h, c.copy(), R, g, A, W)
        ws.append(np.max(W))
    assert 3.0 < ws[0] / ws[1] < 5.0, ws


@pytest.mark.parametrize("tile", [3, 6])
def test_linear_cell_bounds_are_certified(monkeypatch, tile):
    monkeypatch.setattr(_cells, "LINEAR_TILE", tile)
    res = workspace(PSU, "dexterous", OrientationSet.box(np.radians([15] * 3), samples=3), 5.0)
    plan, unit_pos, Rs, feas, L, fmax = _plan(PSU, res)
    assert np.sum(plan.certified) > 0.9 * np.sum(plan.K > -np.inf)
    args = (PSU, plan, unit_pos, Rs, feas, L, fmax)
    bad, ratios = _violations(*args, plan.K, plan.F, plan.S, n_cells=80)
    assert bad == 0
    # K / max κ of the cell: 1.12-1.25 (median) on 3-column cells, 1.75 on 6-column ones; K
    # keeps the per-pose bound's Gram-trace factor (up to 1.18 on the 6-PSU), so lowering K
    # by 15 % (not 10 %) must give violations; F is tight to 5 %
    assert np.median(ratios) < (1.4 if tile == 3 else 2.0), np.median(ratios)
    for K, F, S in ((plan.K * 0.85, plan.F, plan.S), (plan.K, plan.F * 1.1, plan.S),
                    (plan.K, plan.F, -plan.S)):
        assert _violations(*args, K, F, S, n_cells=80)[0] > 0


@pytest.mark.parametrize("tile", [3, 6])
@pytest.mark.parametrize("kind,deg,h", [("dexterous", 15, 5.0), ("reachable", 25, 8.0)])
def test_worst_case_with_linear_cells_is_identical(monkeypatch, tile, kind, deg, h):
    monkeypatch.setattr(_cells, "LINEAR_TILE", tile)
    res = workspace(PSU, kind, OrientationSet.box(np.radians([deg] * 3), samples=3), h)
    out = {}
    for flag in (False, True):
        monkeypatch.setattr(worst, "CELLS", flag)
        out[flag] = dx.worst_case(PSU, res, None, 150.0).as_dict()
    for d in out.values():
        d.pop("seconds")
        d.pop("exact_kappa_evaluations")
        d["method"] = d["method"].split("; exact κ at")[0]
    assert out[True]["status"] == "ok"
    assert _same(out[False], out[True]), (out[False], out[True])
