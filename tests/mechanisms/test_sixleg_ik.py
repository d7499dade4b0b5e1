"""Per-leg-kind IK kernels of the generic six-leg family (issue 28, item 5b).

Each instance runs the kernel of its leg kinds (``sixleg_ik.ik_function``); the results are
checked against an independent NumPy evaluation of
the module's closed forms (libm sin/cos and another summation order: 1e-9 mm on nearly tangent
legs, statuses identical) and against the dedicated families whose per-leg kernels they call
(``ups6``, ``rss6``: bit-identical; ``psu6``, whose formula rounds differently, to 1e-9 mm:
near-tangent links amplify its rounding to 1.7e-12 mm). The comparison with the family's
all-kinds kernel ``SixLeg._ik_one`` (the kernel every instance ran before: q to 1e-12, statuses
identical) is ``benchmarks/validate_sixleg_kinds.py``: that kernel is compiled by nothing else,
about a minute of CPU on an empty cache.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from test_sixleg import _hexaglide, _mixed_linear

import pkmlab
from pkmlab.mechanisms import SixLeg
from pkmlab.mechanisms.families import sixleg_ik
from pkmlab.mechanisms.kernels import ik as K
from pkmlab.poses import euler_to_matrix

ROOT = Path(__file__).resolve().parents[2] / "studies" / "mechanisms"
FILES = {"psu6": "hopkins-williams-6psu", "ups6": "gough-stewart-6ups",
         "rss6": "instructables-servo-6rss"}


def _dedicated(family):
    return pkmlab.load_mechanism(ROOT / f"{FILES[family]}.yaml")


def _cases():
    return {"ups6": SixLeg.from_mechanism(_dedicated("ups6")),
            "psu6": SixLeg.from_mechanism(_dedicated("psu6")),
            "rss6": SixLeg.from_mechanism(_dedicated("rss6")),
            "hexaglide": _hexaglide(25.0), "mixed": _mixed_linear()}


EXPECTED = {"ups6": "_prismatic_one", "psu6": "_slider_one", "rss6": "_crank_one",
            "hexaglide": "_slider_one", "mixed": "_linear_one"}


def _status(q, lo, hi):
    return np.where(q < lo, K.BELOW_STROKE, np.where(q > hi, K.ABOVE_STROKE, K.OK))


def _reference(m, X):
    """The closed forms of :mod:`pkmlab.mechanisms.families.sixleg`, in NumPy: ``(q, status)``."""
    R = euler_to_matrix(X[:, 3:])
    d = X[:, None, :3] + np.einsum("nij,kj->nki", R, m.tool_points) - m.base_points
    lo, hi = m.stroke
    q = np.empty(d.shape[:2])
    st = np.empty(d.shape[:2], dtype=np.int8)
    for i, kind in enumerate(m.leg_kinds):
        di = d[:, i]
        if kind == "prismatic":
            v = np.sqrt(np.sum(di**2, axis=1))
            s = np.where(di[:, 2] * m._sides[i] <= 0, K.OTHER_MODE, _status(v, lo, hi))
            s = np.where(v < 1e-12, K.DEGENERATE, s)
        elif kind == "slider":
            e, b = m.axes[i], m.branch[i]
            t = di @ e
            n = di - t[:, None] * e
            h2 = m.link_length[i] ** 2 - np.sum(n**2, axis=1)
            h = np.sqrt(np.clip(h2, 0, None))
            v = np.where(h2 >= 0, t + b * h, np.nan)
            az = n[:, 2] - b * h * e[2]
            s = np.where(h2 < 0, K.NO_SOLUTION, np.where(az * m._slider_sides[i] < 0,
                                                         K.OTHER_MODE, _status(v, lo, hi)))
        else:
            a, b = m.crank_length[i], m.branch[i]
            E = 2 * a * di @ m.zero_directions[i]
            F = 2 * a * di @ m.v_directions[i]
            G = np.sum(di**2, axis=1) + a * a - m.link_length[i] ** 2
            h2 = E * E + F * F - G * G
            h = np.sqrt(np.clip(h2, 0, None))
            v = np.arctan2(F * G + b * E * h, E * G - b * F * h)
            bad = E * E + F * F <= 1e-24 * a**4
            v = np.where((h2 >= 0) & ~bad, v, np.nan)
            s = np.where(bad, K.DEGENERATE, np.where(h2 < 0, K.NO_SOLUTION, _status(v, lo, hi)))
        q[:, i], st[:, i] = v, s
    return q, st


def _poses(m, n=4000, seed=0):
    """Half near the nominal pose (±40 mm, ±15°), half wide (±scale/4, ±30°)."""
    rng = np.random.default_rng(seed)
    amp = np.repeat([[40.0, np.radians(15)], [0.25 * m.scale, np.radians(30)]], n // 2, axis=0)
    return m.nominal_pose + rng.uniform(-1, 1, (n, 6)) * np.repeat(amp, 3, axis=1)


@pytest.mark.parametrize("case", sorted(EXPECTED))
def test_each_instance_runs_the_kernel_of_its_leg_kinds(case):
    m = _cases()[case]
    one = m._ik_kernel()
    assert one is getattr(sixleg_ik, EXPECTED[case]) and one is not SixLeg._ik_one


@pytest.mark.parametrize("case", sorted(EXPECTED))
def test_kind_kernels_match_the_closed_forms_in_numpy(case):
    m = _cases()[case]
    X = _poses(m)
    res = m.inverse(X)
    q, st = _reference(m, X)
    assert np.mean(res.valid) > 0.02 and np.mean(~res.valid) > 0.02   # both sides tested
    np.testing.assert_array_equal(res.leg_status, st)
    np.testing.assert_array_equal(np.isnan(res.q), np.isnan(q))
    np.testing.assert_allclose(res.q, q, rtol=0, atol=1e-9)


@pytest.mark.parametrize("family", sorted(FILES))
def test_kind_kernels_match_the_dedicated_families(family):
    fast = _dedicated(family)
    gen = SixLeg.from_mechanism(fast)
    X = _poses(fast, seed=1)
    a, b = fast.inverse(X), gen.inverse(X)
    np.testing.assert_array_equal(a.leg_status, b.leg_status)
    np.testing.assert_array_equal(a.reason, b.reason)
    if family == "psu6":    # (l² - a_x²) - a_y² there, l² - |d⊥|² here: 1.7e-12 mm seen
        np.testing.assert_allclose(b.q, a.q, rtol=0, atol=1e-9)
    else:                   # the same per-leg kernel: bit for bit
        np.testing.assert_array_equal(b.q, a.q)


@pytest.mark.parametrize("case", ["rss6", "rss6-dedicated"])
def test_crank_legs_beyond_reach_and_invalid_poses(case):
    """Poses far beyond every leg's reach (up to 1e308 mm, where E, F, G overflow) are
    NO_SOLUTION with NaN on every leg, non-finite ones INVALID_INPUT, and the nominal pose
    solves: the one-division atan2 (``rss6._atan2``) changes none of this."""
    m = _cases()["rss6"] if case == "rss6" else _dedicated("rss6")
    far = np.array([[1e4, 0, 0], [0, 0, -1e6], [1e150, 0, 0], [0, 1e300, 0],
                    [1e308, -1e308, 1e308]])
    X = np.concatenate([far, np.zeros((len(far), 3))], axis=1) + [0, 0, 0, *m.nominal_pose[3:]]
    bad = m.nominal_pose + np.array([[np.inf, 0, 0, 0, 0, 0], [0, 0, 0, 0, np.nan, 0]])
    res = m.inverse(np.concatenate([X, bad, m.nominal_pose[None]]))
    assert np.all(res.leg_status[:len(far)] == K.NO_SOLUTION)
    assert np.all(np.isnan(res.q[:len(far)]))
    assert np.all(res.reason[len(far):-1] == K.INVALID_INPUT)
    assert res.reason[-1] == K.OK and np.all(np.isfinite(res.q[-1]))
