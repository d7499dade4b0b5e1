"""Issue 22 item 3: ``task_contained`` (method ``exact``) is proved over the *continuous*
orientation set, not over its sample.

The counterexamples are found with scipy's L-BFGS-B over the continuous Euler box, on
pkmlab's per-pose inverse kinematics (the leg values and the stroke): independent of how
pkmlab samples or bounds orientations.
"""

from __future__ import annotations

import numpy as np
import pytest
from conftest import MECH_DIR
from scipy.optimize import minimize

from pkmlab import load_mechanism
from pkmlab.poses import euler_to_matrix
from pkmlab.requirements import task as task_mod
from pkmlab.requirements.task import TaskRegion, task_contained, task_margins
from pkmlab.workspaces import OrientationSet
from pkmlab.workspaces.optima.binding import column_ends

HALF = np.radians(15.0)


def _hopkins():
    return load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")


def _leg_margin(mech, p, e):
    """Smallest stroke margin (mm) over the legs at position p and Euler offset e (negative:
    a leg outside its window, by that much)."""
    ik = mech.inverse((np.asarray(p, float)[None], euler_to_matrix(np.asarray(e))[None]),
                      stroke=(-np.inf, np.inf))
    lo, hi = mech.stroke
    return float(np.min(np.minimum(ik.q[0] - lo, hi - ik.q[0])))


def _worst_orientation(mech, p, half, starts=12, seed=0):
    """L-BFGS-B over the continuous box ±half from random starts and the corners:
    (smallest leg margin found, its Euler offset)."""
    rng = np.random.default_rng(seed)
    corners = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)]) * half
    x0s = np.concatenate([rng.uniform(-half, half, (starts, 3)), corners])
    best = (np.inf, None)
    for x0 in x0s:
        r = minimize(lambda e: _leg_margin(mech, p, e), x0, method="L-BFGS-B",
                     bounds=[(-half, half)] * 3)
        if r.fun < best[0]:
            best = (float(r.fun), r.x)
    return best


def _bottom_task(mech, n, above=0.03):
    """A 2 mm vertical task on the column (10, 0) mm whose bottom is ``above`` mm over the
    column's lower end at the n³ sample of the ±15° box."""
    ax = np.linspace(-HALF, HALF, n)
    E = np.stack([g.ravel() for g in np.meshgrid(ax, ax, ax, indexing="ij")], axis=1)
    a, _, _ = column_ends(mech, mech.column_params(), 10.0, 0.0, np.zeros(3), E)
    z0 = float(a.max()) + above
    return TaskRegion("box", frame="base", centre=(10.0, 0.0, z0 + 1.0), size=(0, 0, 2)), z0


@pytest.mark.parametrize("n", [7, 3])
def test_hopkins_bottom_task_is_not_called_contained(n):
    mech = _hopkins()
    oset = OrientationSet.box([HALF] * 3, samples=n)
    task, z0 = _bottom_task(mech, n)
    # the orientation sample alone admits the task (what the check reported before the fix:
    # contained, margins +0.031 mm / +0.049° at 7 samples in the issue)
    R = oset.centred((0.0, 0.0, 0.0)).rotations()
    assert not task_mod._exact_fail(mech, R, task).any()
    # an orientation inside the box puts a leg outside its stroke at the task's bottom point
    worst, e = _worst_orientation(mech, (10.0, 0.0, z0), HALF)
    assert np.all(np.abs(e) <= HALF + 1e-12)
    assert worst < -0.04, worst           # 7 samples: -0.049 mm; 3 samples: -0.79 mm
    chk = task_contained(mech, task, oset)
    assert not chk.contained and chk.status == "not contained" and chk.method == "exact"
    m = task_margins(mech, task, oset)
    # the margin is negative and a lower bound: -(erosion) <= the violation found
    assert m["margin_mm"] < 0 and m["margin_mm"] <= worst + 1e-9
    assert m["margin_mm"] + m["margin_bracket_mm"] >= worst - 0.02
    assert m["orientation_margin_deg"] < 0


def test_contained_is_never_refuted_by_a_continuous_search():
    """Where the check says contained, L-BFGS-B over the continuous box finds no orientation
    that puts a leg outside its stroke at the task's corners or at random task points."""
    mech = _hopkins()
    oset = OrientationSet.box([HALF] * 3, samples=3)
    rng = np.random.default_rng(3)
    seen = 0
    for above in (0.05, 0.9, 2.0):
        task, z0 = _bottom_task(mech, 3, above)
        if not task_contained(mech, task, oset).contained:
            continue
        seen += 1
        pts = [(10.0, 0.0, z0), (10.0, 0.0, z0 + 2.0)] + \
            [(10.0, 0.0, z) for z in rng.uniform(z0, z0 + 2.0, 2)]
        for p in pts:
            worst, _ = _worst_orientation(mech, p, HALF, starts=4, seed=int(rng.integers(99)))
            assert worst >= -1e-9, (above, p, worst)
    assert seen >= 1
    # a box task around the nominal pose (±5° box), its 8 corners
    box = TaskRegion("box", size=(20, 20, 10))
    five = np.radians(5.0)
    chk = task_contained(mech, box, OrientationSet.box([five] * 3, samples=3))
    assert chk.contained and chk.cells > 0
    p0 = np.asarray(mech.nominal_pose[:3])
    for c in np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)]):
        worst, _ = _worst_orientation(mech, p0 + c * (10, 10, 5), five, starts=2)
        assert worst >= -1e-9


def test_budget_exhausted_is_undecided_not_contained(monkeypatch):
    mech = _hopkins()
    oset = OrientationSet.box([HALF] * 3, samples=3)
    task, _ = _bottom_task(mech, 3, 0.9)
    assert task_contained(mech, task, oset).contained
    monkeypatch.setattr(task_mod, "CELL_BUDGET", 10)
    chk = task_contained(mech, task, oset)
    assert chk.status == "undecided" and not chk.contained and chk.undecided > 0
    assert "not proved" in chk.note
    m = task_margins(mech, task, oset)
    assert "undecided" in m["notes"]["task_margin"]
