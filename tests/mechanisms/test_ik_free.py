"""Inverse kinematics of poses given in the free coordinates (``kernels/ik_free.py``, issue 24):
the same numbers, bit for bit, as the Euler driver on the poses expanded to six coordinates
(which is what ``inverse`` ran before); non-finite and huge inputs take the same paths."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECH_DIR

import pkmlab
from pkmlab.mechanisms.kernels import ik as _kernels
from pkmlab.mechanisms.kernels.ik_free import fixed_rotation, free_rows

FILES = ["fivebar-scara.yaml", "planar-3rpr.yaml", "clavel-delta3.yaml",
         "klipper-example-ldelta3.yaml", "tripod-3prs.yaml"]


def _same(a, b):
    return (np.array_equal(a.q, b.q, equal_nan=True)
            and np.array_equal(a.leg_status, b.leg_status)
            and np.array_equal(a.reason, b.reason))


@pytest.mark.parametrize("name", FILES)
def test_free_driver_bit_identical_to_expanded_euler(name):
    m = pkmlab.load_mechanism(MECH_DIR / name)
    mob = m.mobility
    rng = np.random.default_rng(3)
    span = np.array([60.0, 60.0, 60.0, *np.radians([20.0] * 3)])[mob.index]
    F = m.nominal_pose[mob.index] + rng.uniform(-1, 1, (3001, mob.width)) * span
    F[5] = np.nan                      # non-finite: INVALID_INPUT on every leg
    F[7, 0] = np.inf
    F[9, -1] = -np.inf
    F[11, :2] = 1e308                  # finite, but x + y + z (or an angle sum) overflows
    if mob.rotations:
        F[13, -1] = 3e5                # beyond TRIG_MAX: libm's sine and cosine, as Euler
    expanded = mob.full(F, m.nominal_pose)
    for stroke in (None, (-np.inf, np.inf)):
        a = m.inverse(F, stroke=stroke)
        b = m.inverse(expanded, stroke=stroke)
        assert _same(a, b)
    assert np.all(a.reason[[5, 7, 9]] == _kernels.INVALID_INPUT)
    assert 0.3 < a.valid.mean()                     # the test exercises real solutions
    # one pose (width,), and batches across block boundaries and lane padding
    one = m.inverse(F[20])
    assert one.q.shape == (1, m.n_actuators) and _same(one, m.inverse(expanded[20]))
    for n in (1, 63, 65, 511, 513, 1025):
        assert _same(m.inverse(F[:n]), m.inverse(expanded[:n]))


def test_fixed_rotation_is_the_euler_drivers():
    """The constant rotation handed to a no-angle mobility's kernel equals the per-pose one
    the Euler driver builds (read back through a kernel that reports r00 ... r22)."""
    for angles in ([0.0, 0.0, 0.0], [0.1, -0.2, 2.5], [1e-9, 3.0, -3.1]):
        r = np.array(fixed_rotation(angles))
        R = np.array(pkmlab.poses.as_frames(np.r_[0.0, 0.0, 0.0, angles])[1][0])
        np.testing.assert_allclose(r.reshape(3, 3), R, rtol=0, atol=4e-16)
    big = fixed_rotation([3e5, 0.0, 0.0])
    assert big[8] == math.cos(3e5) and big[7] == math.sin(3e5)


def test_free_rows_only_for_free_coordinates():
    m = pkmlab.load_mechanism(MECH_DIR / "fivebar-scara.yaml")
    assert free_rows(m.mobility, np.zeros(2)).shape == (1, 2)
    assert free_rows(m.mobility, np.zeros((4, 2))).shape == (4, 2)
    assert free_rows(m.mobility, np.zeros((4, 6))) is None
    assert free_rows(m.mobility, np.zeros((4, 2, 2))) is None
    six = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")
    assert free_rows(six.mobility, np.zeros((4, 6))) is None


def test_fivebar_kernel_against_acos_formula():
    """The five-bar's kernel (no division: atan2 of the scaled elbow direction) against the
    textbook θ = atan2(AP) + σ·acos((l1² + D² − l2²)/(2·l1·D)) in NumPy, in the window's frame
    (c − π, c + π]: 1e-12 rad where the elbow is not within 1e-6 of straight (acos is
    ill-conditioned there), and the same reach everywhere."""
    m = pkmlab.load_mechanism(MECH_DIR / "fivebar-scara.yaml")
    rng = np.random.default_rng(11)
    P = rng.uniform(-m.scale, m.scale, (200_000, 2))
    for mode in m.working_modes():
        mm = m.with_working_mode(mode)
        ik = mm.inverse(P, stroke=(-np.inf, np.inf))
        d = P[:, None, :] - mm.base_points[:, :2]
        D = np.hypot(d[..., 0], d[..., 1])
        c = (mm.proximal**2 + D**2 - mm.distal**2) / (2 * mm.proximal * D)
        reach = np.abs(c) <= 1
        assert np.array_equal(np.isfinite(ik.q), reach)
        with np.errstate(invalid="ignore"):
            th = np.arctan2(d[..., 1], d[..., 0]) + np.array(mm.branch) * np.arccos(c)
        centre = 0.5 * sum(mm.stroke)
        th = centre + np.angle(np.exp(1j * (th - centre)))
        good = np.abs(c) < 1 - 1e-6
        assert np.max(np.abs(ik.q - th)[good]) < 1e-12
