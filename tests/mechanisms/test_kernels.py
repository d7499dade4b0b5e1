"""The blocked inverse-kinematics drivers of ``pkmlab.mechanisms.kernels.ik``."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import random_valid_poses
from numba import njit

from pkmlab.mechanisms.kernels import ik as _kernels
from pkmlab.poses import as_frames


@njit
def _sincos_many(x, s, c):
    for i in range(x.shape[0]):
        s[i], c[i] = _kernels._sincos(x[i])


@njit
def _libm_many(x, s, c):
    for i in range(x.shape[0]):
        s[i], c[i] = math.sin(x[i]), math.cos(x[i])


@pytest.mark.parametrize("span", [1e-300, 1e-8, 0.8, 4.0, 100.0, _kernels.TRIG_MAX])
def test_sincos_within_one_ulp_of_one_of_libm(span):
    rng = np.random.default_rng(0)
    x = rng.uniform(-span, span, 200_000)
    x[:4] = [0.0, -0.0, span, -span]
    x[4:200] = np.round(x[4:200] / (np.pi / 2)) * (np.pi / 2)     # near multiples of π/2
    s, c, s0, c0 = (np.empty_like(x) for _ in range(4))
    _sincos_many(x, s, c)
    _libm_many(x, s0, c0)
    assert np.max(np.abs(s - s0)) <= 2.3e-16
    assert np.max(np.abs(c - c0)) <= 2.3e-16


def _split_runs(mech, X, sizes):
    """Inverse kinematics of X in consecutive batches of the given sizes, concatenated."""
    parts, k = [], 0
    for n in sizes:
        parts.append(mech.inverse(X[k:k + n]))
        k += n
    return (np.concatenate([p.q for p in parts]), np.concatenate([p.leg_status for p in parts]),
            np.concatenate([p.reason for p in parts]))


def test_result_does_not_depend_on_batching_or_block_position(mech):
    B = _kernels.BLOCK
    n = 2 * B + 37
    X = random_valid_poses(mech, 50, seed=7)[np.arange(n) % 50]
    X[::5, 2] += np.linspace(-200.0, 200.0, len(X[::5]))            # some invalid ones too
    full = mech.inverse(X)
    for sizes in ([1] * 40 + [n - 40], [B - 1, 3, n - B - 2], [n]):
        q, st, reason = _split_runs(mech, X, sizes)
        np.testing.assert_array_equal(q, full.q)
        np.testing.assert_array_equal(st, full.leg_status)
        np.testing.assert_array_equal(reason, full.reason)


@pytest.mark.parametrize("path", ["euler", "frames"])
def test_non_finite_poses_are_invalid_and_leave_neighbours_alone(mech, path):
    X = np.repeat(mech.nominal_pose[None], 3 * _kernels.BLOCK, axis=0)
    bad = np.arange(5, len(X), 97)
    for m, k in enumerate(bad):
        X[k, m % 6] = (np.nan, np.inf, -np.inf)[m % 3]
    if path == "euler":
        ik = mech.inverse(X)
        nominal = mech.inverse(mech.nominal_pose)
    else:
        p, R = as_frames(np.where(np.isfinite(X), X, 0.0))
        p[bad[::2], bad[::2] % 3] = np.nan
        R[bad[1::2], 1, 2] = np.inf
        ik = mech.inverse((p, R))
        nominal = mech.inverse(as_frames(mech.nominal_pose))
    invalid = np.zeros(len(X), dtype=bool)
    invalid[bad] = True
    assert np.all(ik.reason[invalid] == _kernels.INVALID_INPUT)
    assert np.all(ik.leg_status[invalid] == _kernels.INVALID_INPUT)
    assert np.all(np.isnan(ik.q[invalid]))
    np.testing.assert_array_equal(ik.q[~invalid], np.repeat(nominal.q, (~invalid).sum(), 0))
    assert np.all(ik.valid[~invalid])


def test_euler_path_matches_frames_path(mech):
    rng = np.random.default_rng(3)
    X = mech.nominal_pose + np.concatenate(
        [rng.uniform(-40, 40, (5000, 3)), rng.uniform(-3.2, 3.2, (5000, 3))], axis=1)
    X[:10, 3:] = rng.uniform(-1e7, 1e7, (10, 3))        # beyond TRIG_MAX: libm path
    euler = mech.inverse(X)
    frames = mech.inverse(as_frames(X))
    # 1-ulp differences of _sincos vs libm (used by as_frames) grow only near a leg losing its
    # real root.
    np.testing.assert_allclose(euler.q, frames.q, rtol=0, atol=1e-10)
    # The large-angle poses take the same libm rotation as ``as_frames``: bit-identical.
    np.testing.assert_array_equal(euler.q[:10], frames.q[:10])
    assert np.mean(euler.leg_status == frames.leg_status) > 0.9999
