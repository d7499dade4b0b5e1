"""The generic six-leg crank kernel (``sixleg_ik._crank_one``) against an independent NumPy
evaluation of the closed form (libm ``arctan2``, ``euler_to_matrix``), on non-paper designs:
random crank machines (``testing.random_sixleg``, servo axes in any direction) and the servo
hexapod with three tilted axes (issue 28, session 5).

Any fast path of the crank legs must keep this test: statuses and NaN placement identical on
every leg, and ``|Δq| <= 5e-14·(1 + 1/sqrt(h²/ρ²))`` rad, on reachable and unreachable poses
alike, including poses beyond the Euler driver's fast sine range (``TRIG_MAX``) and beyond
every leg's reach. ``h²/ρ² = 1 − (G/ρ)²`` measures how far a leg is from tangency: the angle's
condition number grows as ``1/sqrt(h²/ρ²)``, and the kernel and the NumPy form, which round
differently, were seen to differ by at most ``1.3e-14/sqrt(h²/ρ²)`` rad (5.9e-13 rad on a leg
with ``h²/ρ² = 1.6e-6``) on these designs and poses.

Kept out of the suite (it compiles the generic crank kernel for three more designs, about a
minute of CPU on an empty cache, and the suite already checks the per-kind kernels against an
independent NumPy evaluation in tests/mechanisms/test_sixleg_ik.py). Run it with pytest:

    .venv/bin/python -m pytest -q benchmarks/validate_sixleg_crank_reference.py
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest

sys.path[:0] = [str(Path(__file__).resolve().parents[1] / "tests"),
                str(Path(__file__).resolve().parents[1] / "tests" / "mechanisms")]
from test_sixleg import _tilted_cranks  # noqa: E402
from test_sixleg_ik import _reference  # noqa: E402

from pkmlab import testing  # noqa: E402
from pkmlab.mechanisms.families import sixleg_ik  # noqa: E402
from pkmlab.mechanisms.kernels import ik as K  # noqa: E402
from pkmlab.poses import euler_to_matrix  # noqa: E402


def _designs():
    rng = np.random.default_rng(2028)
    return {"random-negative": testing.random_sixleg(rng, ["crank"] * 6, "negative"),
            "random-positive": testing.random_sixleg(rng, ["crank"] * 6, "positive"),
            "tilted": _tilted_cranks()}


def _poses(m, seed):
    """Very near and near the nominal pose, wide, far beyond reach, and angles > TRIG_MAX."""
    rng = np.random.default_rng(seed)
    n = 8000
    amp = np.repeat([[2.0, np.radians(1)], [10.0, np.radians(4)],
                     [0.3 * m.scale, np.radians(40)], [3.0 * m.scale, np.pi]], n // 4, axis=0)
    X = m.nominal_pose + rng.uniform(-1, 1, (n, 6)) * np.repeat(amp, 3, axis=1)
    big = m.nominal_pose + np.zeros((40, 6))
    big[:, 3:] += rng.uniform(-1, 1, (40, 3)) * np.array([[2e5], [1e6], [3e5]]).T
    return np.concatenate([X, big])


def _tangency(m, X):
    """``h²/ρ²`` of every leg (NumPy): 1 far from the reach limits, 0 at them."""
    R = euler_to_matrix(X[:, 3:])
    d = X[:, None, :3] + np.einsum("nij,kj->nki", R, m.tool_points) - m.base_points
    a = m.crank_length
    E = 2 * a * np.einsum("nki,ki->nk", d, m.zero_directions)
    F = 2 * a * np.einsum("nki,ki->nk", d, m.v_directions)
    G = np.sum(d**2, axis=2) + a * a - m.link_length**2
    with np.errstate(all="ignore"):
        return np.clip((E * E + F * F - G * G) / (E * E + F * F), 1e-30, None)


@pytest.mark.parametrize("name", ["random-negative", "random-positive", "tilted"])
def test_generic_crank_kernel_matches_numpy_on_non_paper_designs(name):
    m = _designs()[name]
    assert m._ik_kernel() is sixleg_ik._crank_one
    X = _poses(m, seed=len(name))
    res = m.inverse(X)
    q, st = _reference(m, X)
    valid = res.valid
    unreachable = np.any(res.leg_status == K.NO_SOLUTION, axis=1)
    # both sides are exercised: solved poses, poses out of the servo window, unreachable ones
    assert np.mean(valid) > 0.05 and np.mean(unreachable) > 0.4
    assert np.any((res.leg_status == K.BELOW_STROKE) | (res.leg_status == K.ABOVE_STROKE))
    assert np.all(valid[-40:] == (np.max(st[-40:], axis=1) == K.OK))
    np.testing.assert_array_equal(res.leg_status, st)
    np.testing.assert_array_equal(np.isnan(res.q), np.isnan(q))
    ok = np.isfinite(q)
    tol = 5e-14 * (1.0 + 1.0 / np.sqrt(_tangency(m, X)[ok]))
    worst = np.max(np.abs(res.q[ok] - q[ok]) / tol)
    assert worst <= 1.0, f"crank angle differs from NumPy by {worst:.3g}x the tolerance"


def test_the_reference_sees_a_wrong_branch():
    """The comparison can fail: the same design with the legs' branches flipped gives angles
    that differ from the reference of the original by far more than the tolerance."""
    m = _designs()["random-negative"]
    X = _poses(m, seed=3)
    q, _ = _reference(m, X)
    flipped = type(m)(m.base_points, m.platform_points, ["crank"] * 6, m.axes,
                      m.zero_directions, m.crank_length, m.link_length, m.stroke, -m.branch)
    qf = flipped.inverse(X).q
    both = np.isfinite(q) & np.isfinite(qf)
    assert np.mean(both) > 0.05
    assert np.max(np.abs(qf[both] - q[both])) > 1e-3
