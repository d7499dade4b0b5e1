"""The crank leg's column set without a resolvent cubic or an atan2 (``legs/crank.py``, issue 24
third session): the biquadratic roots of D against NumPy's quartic roots, the window test by
cross products against the IK's atan2 test, and the whole leg set against IK sampling on
columns of a delta3 leg (whose quartic is biquadratic) and a tilted one (Ferrari's path)."""

from __future__ import annotations

import math

import numpy as np
from conftest import MECH_DIR
from numba import njit

import pkmlab
from pkmlab.mechanisms.families import _delta
from pkmlab.mechanisms.legs import crank


@njit(cache=True)
def _roots(e0, e1, f0, f1, g0, L):
    T = np.empty(crank.PIECES)
    A = e1 * e1 + f1 * f1
    n = crank._d_roots(e0, e1, f0, f1, g0, A, L, -np.inf, np.inf, T)
    return T[:n].copy()


@njit(cache=True)
def _both(t, e0, e1, f0, f1, g0, b, amin, amax):
    fast = crank._ok(t, e0, e1, f0, f1, g0, b, 0.0, math.cos(amin), math.sin(amin),
                     math.cos(amax), math.sin(amax), amax - amin > math.pi)
    E, F, G = e0 + e1 * t, f0 + f1 * t, t * t + g0
    h2 = E * E + F * F - G * G
    if h2 < 0:
        return fast, False, 0.0
    h = math.sqrt(h2)
    al = math.atan2(F * G + b * E * h, E * G - b * F * h)
    return fast, amin <= al <= amax, min(abs(al - amin), abs(al - amax))


def test_biquadratic_roots_against_numpy():
    """No linear term (e0·e1 + f0·f1 = 0: e1 = 0, f0 = 0): the real roots of D = E² + F² − G²
    equal numpy.roots of the quartic −t⁴ + (A − 2g0)t² + (e0² − g0²) to 1e-9 relative, and
    as many (double roots excluded)."""
    rng = np.random.default_rng(4)
    checked = 0
    for _ in range(2000):
        a, s = rng.uniform(50, 400, 2)
        e0 = 2 * a * rng.uniform(-900, 900)
        f1 = -2 * a
        g0 = rng.uniform(-900, 900) ** 2 + a * a - s * s
        got = np.sort(_roots(e0, 0.0, 0.0, f1, g0, a + s))
        c = np.roots([-1.0, 0.0, f1 * f1 - 2 * g0, 0.0, e0 * e0 - g0 * g0])
        want = np.sort(c[np.abs(c.imag) < 1e-7 * (a + s)].real)
        if len(want) and np.min(np.abs(np.diff(want)), initial=np.inf) < 1e-3:
            continue                                   # near-double roots: ill-conditioned
        assert len(got) == len(want)
        np.testing.assert_allclose(got, want, rtol=1e-9, atol=1e-9 * (a + s))
        checked += len(want) > 0
    assert checked > 500


def test_window_by_cross_products_equals_atan2():
    """Windows narrower and wider than π, and the full circle: the same verdict as atan2 for
    every angle more than 1e-9 rad from an edge."""
    rng = np.random.default_rng(5)
    windows = [(-math.radians(40), math.radians(90)), (-math.radians(150), math.radians(170)),
               (math.radians(10), math.radians(20)), (-math.pi, math.pi)]
    n = 0
    for amin, amax in windows:
        for _ in range(4000):
            e0, e1, f0, f1 = rng.uniform(-600, 600, 4)
            g0 = rng.uniform(-2e5, 2e5)
            t = rng.uniform(-500, 500)
            b = rng.choice([-1.0, 1.0])
            fast, slow, dist = _both(t, e0, e1, f0, f1, g0, b, amin, amax)
            if dist > 1e-9:
                assert fast == slow
                n += 1
    assert n > 4000


def _leg_set_vs_samples(u, v, a, s, window, rng):
    cw = (math.cos(window[0]), math.sin(window[0]), math.cos(window[1]), math.sin(window[1]))
    lo, hi = np.empty(crank.PIECES), np.empty(crank.PIECES)
    for _ in range(300):
        dx, dy = rng.uniform(-600, 600, 2)
        cnt = crank.crank_leg_set(dx, dy, 0.0, *u, *v, a, s, -1.0, *window, *cw, -np.inf,
                                  np.inf, lo, hi)
        z = np.linspace(-900, 900, 3601)
        E = 2 * a * (dx * u[0] + dy * u[1] + z * u[2])
        F = 2 * a * (dx * v[0] + dy * v[1] + z * v[2])
        G = dx * dx + dy * dy + z * z + a * a - s * s
        with np.errstate(invalid="ignore"):
            h = np.sqrt(E * E + F * F - G * G)
            al = np.arctan2(F * G - E * h, E * G + F * h)
        ok = (h >= 0) & (al >= window[0]) & (al <= window[1])
        inside = np.zeros_like(ok)
        for k in range(cnt):
            inside |= (z >= lo[k] - 1e-9) & (z <= hi[k] + 1e-9)
        near = np.zeros_like(ok)
        for k in range(cnt):
            near |= (np.abs(z - lo[k]) < 1e-6) | (np.abs(z - hi[k]) < 1e-6)
        assert np.all(inside[ok]) and np.all(ok[inside & ~near])


def test_leg_sets_against_ik_samples():
    """Every sampled feasible z on 300 random columns is inside the set, and every sample
    inside it (more than 1e-6 mm from an end) is feasible: a delta3-style leg (u horizontal,
    v = −z: the biquadratic path) and a tilted one (Ferrari)."""
    rng = np.random.default_rng(6)
    _leg_set_vs_samples((0.0, 1.0, 0.0), (0.0, 0.0, -1.0), 350.0, 800.0,
                        (-math.radians(40), math.radians(90)), rng)
    u = np.array([0.3, 0.9, 0.2])
    u /= np.linalg.norm(u)
    n = np.cross(u, [0.0, 0.0, 1.0])
    n /= np.linalg.norm(n)
    _leg_set_vs_samples(tuple(u), tuple(np.cross(n, u)), 120.0, 300.0,
                        (-math.radians(150), math.radians(170)), rng)


def test_delta_columns_two_slot_pass_falls_back(monkeypatch):
    """The rotary delta's columns are computed with COLUMN_SLOTS slots first and again with
    all K when a column needs more: forcing the fallback (one slot, where many columns hold
    two pieces) gives the same sets as the 8-slot pass, and no overflow."""
    m = pkmlab.load_mechanism(MECH_DIR / "clavel-delta3.yaml")
    xs, ys = np.arange(-450.0, 451.0, 30.0), np.arange(-520.0, 521.0, 30.0)
    R = np.eye(3)[None]
    lo2, hi2, over2 = m.column_intervals(xs, ys, R, "all")
    monkeypatch.setattr(_delta, "COLUMN_SLOTS", 1)
    lo1, hi1, over1 = m.column_intervals(xs, ys, R, "all")
    monkeypatch.setattr(_delta, "COLUMN_SLOTS", 8)
    lo8, hi8, over8 = m.column_intervals(xs, ys, R, "all")
    assert over1 == over2 == over8 == 0
    assert lo2.shape[-1] == 2 and lo1.shape[-1] == 8
    assert np.any(np.sum(lo8 <= hi8, axis=-1) == 2)          # two-piece columns exist
    for lo, hi in ((lo1, hi1), (lo2, hi2)):
        k = lo.shape[-1]
        assert np.array_equal(lo, lo8[..., :k]) and np.array_equal(hi, hi8[..., :k])
        assert not np.any(lo8[..., k:] <= hi8[..., k:])
