"""Validation against the two seed papers (figures and errata: docs/validation.md)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import MECH_DIR
from scipy.optimize import minimize_scalar

import pkmlab
from pkmlab.mechanisms import Luzi3
from pkmlab.mechanisms.families.luzi3 import four_bar_theta, pose_to_psi, psi_to_pose, reduced_dpa
from pkmlab.poses import as_frames, euler_to_matrix, log_so3

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from paper_validation import (  # noqa: E402
    LEVEL,
    PRINTED_L,
    PSI_ROUNDING,
    TABLE,
    axis_deviation_deg,
    hopkins_f,
    hopkins_jnr_printed,
    ik_lengths,
    luzi,
    luzi_fk,
    minimax,
    psi_of_lengths,
    psi_rounding_gap,
    relative_motion,
    rot,
    rounding_bound,
)

HOPKINS = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")


def test_hopkins_default_geometry_has_equal_legs_near_radial_alignment():
    q = HOPKINS.inverse(HOPKINS.nominal_pose).q[0]
    assert np.ptp(q) < 1e-9 and q[0] == pytest.approx(50.8)      # mid-stroke, all equal
    beta = HOPKINS.describe()["base_pair_angle_deg"]
    assert abs(beta - 90.0) < 0.5                                  # base pair ≈ on +Y_B


def corrected_jnr(X, B, P, L):
    """Eq. (11) with the errata applied, in the order of X = (x, y, z, θx, θy, θz)."""
    J = hopkins_jnr_printed(X, B, P, L)
    x, y, z, tx, ty, tz = X
    r = euler_to_matrix(X[3:])
    Px, Py = P[0], P[1]
    col5 = 2 * ((-Px * math.cos(tz) * math.sin(ty) + Py * math.cos(tz) * r[2, 1]) * (x - B[0])
                + (-Px * math.sin(tz) * math.sin(ty) + Py * math.sin(tz) * r[2, 1]) * (y - B[1])
                - (Px * math.cos(ty) + Py * math.sin(ty) * math.sin(tx)) * (z - L))
    col6 = 2 * Py * (r[0, 2] * (x - B[0]) + r[1, 2] * (y - B[1]) + r[2, 2] * (z - L))
    return np.array([J[0], J[1], J[2], col6, col5, J[3]])


def test_hopkins_eq9_and_eq11_errata():
    """Our IK satisfies the corrected eq. (9), not the printed one; corrected eq. (11) = FD."""
    X = HOPKINS.nominal_pose + np.array([12.0, -7.0, 5.0, *np.radians([8.0, -6.0, 11.0])])
    q = HOPKINS.inverse(X).q[0]
    Xp = X.copy()
    Xp[:3] -= euler_to_matrix(X[3:]) @ HOPKINS.tool_offset         # {P}, not {H}
    h = 1e-5
    for i in range(6):
        B, P, L = HOPKINS.base_points[i], HOPKINS.platform_points[i], q[i]
        assert abs(hopkins_f(Xp, B, P, L, 225.0, printed=False)) < 1e-6        # mm²
        assert abs(hopkins_f(Xp, B, P, L, 225.0, printed=True)) > 1.0
        fd = np.array([(hopkins_f(Xp + e, B, P, L, 225.0, False)
                        - hopkins_f(Xp - e, B, P, L, 225.0, False)) / (2 * h)
                       for e in np.eye(6) * h])
        assert np.allclose(corrected_jnr(Xp, B, P, L), fd, rtol=1e-6, atol=1e-4)
    printed = hopkins_jnr_printed(Xp, B, P, L)
    assert not np.allclose(printed, fd, rtol=1e-3)      # the printed matrix is wrong


# ---- Luzi et al. Table 1 (docs/validation.md) ---------------------------------------------
# The printed lengths are, at the printed l = 100 mm, simple motions from a level home pose; the
# printed ψ are the FK ψ of the same lengths with l = 200 mm (rows 1-2) and 150 mm (row 3).
# Lengths are printed to 0.1 mm (rounding ±0.05 mm), ψ1-ψ3 to 1e-5 rad (±5e-6 rad).
Z_AXIS, Y_AXIS = np.array([0.0, 0.0, 1.0]), np.array([0.0, 1.0, 0.0])


def test_luzi_table1_lengths_are_simple_motions_at_printed_l_100():
    mech = luzi(PRINTED_L)
    (p1, R1, r1), (p2, R2, r2), (p3, R3, r3) = (luzi_fk(mech, q) for q, _ in TABLE)
    assert max(r1, r2, r3) < 1e-9
    # Tolerances: linearised worst-case pose change for ±0.05 mm on every length.
    b1, b2, b3 = (rounding_bound(mech, p, R) for p, R in ((p1, R1), (p2, R2), (p3, R3)))
    # Row 1: level, centred, S_P at ψ4 = π/6; z = 910.044 mm, i.e. 910 within ±0.053 mm.
    assert np.abs(R1 - LEVEL).max() < 1e-12 and np.abs(p1[:2]).max() < 1e-9
    assert abs(p1[2] - 910.0) < b1[2]
    # Row 2: a rotation about the vertical through the centroid, 30.043° (30 within ±0.076°),
    # and a drop of 100.125 mm: 0.02 mm more than the ±0.106 mm the rounding allows, because
    # the printed l_i2 = 847.8 should read 847.9 (next test); with 847.9 it is -100.043 mm.
    ang, axis, dp = relative_motion(p1, R1, p2, R2)
    assert axis_deviation_deg(axis, Z_AXIS) < 1e-6 and axis[2] > 0
    assert np.abs(dp[:2]).max() < 1e-9
    assert abs(ang - 30.0) < math.degrees(b2[5])
    assert abs(dp[2] + 100.0) < 0.15 and abs(dp[2] + 100.0) > b1[2] + b2[2]
    q2 = np.array(TABLE[1][0])
    q2[1::2] = 847.9
    p2b, R2b, _ = luzi_fk(mech, q2)
    ang, _, dp = relative_motion(p1, R1, p2b, R2b)
    assert abs(ang - 30.0) < math.degrees(b2[5]) and abs(dp[2] + 100.0) < b1[2] + b2[2]
    # Row 3: a rotation by 20.162° about -y; the axis is 0.110° off y (rounding allows 0.25°),
    # no slide along it (0.022 mm), and the centroid keeps y (-0.121 mm, rounding ±0.31 mm).
    ang, axis, dp = relative_motion(p1, R1, p3, R3)
    dev_bound = math.degrees(math.hypot(b3[3], b3[5]) / math.radians(ang))
    assert axis_deviation_deg(axis, Y_AXIS) < dev_bound and axis[1] < 0
    assert abs(float(dp @ axis)) < b1[1] + b3[1]
    assert abs(dp[1]) < b1[1] + b3[1]
    assert abs(ang - 20.16) < 0.05


def test_luzi_table1_round_motions_reproduce_printed_lengths_at_l_100():
    """IK at l = 100 mm of the round motions gives the printed lengths to their rounding."""
    mech = luzi(PRINTED_L)
    q1, q2, q3 = (np.array(q) for q, _ in TABLE)
    home = ik_lengths(mech, [0.0, 0.0, 910.0], np.eye(3))
    assert np.max(np.abs(home - q1)) < 0.05                              # 958.5585
    # Row 2 with exactly 30° about z: some z reproduces the printed lengths (0.028 mm, z = 809.935)
    fit = minimize_scalar(lambda z: np.max(np.abs(ik_lengths(mech, [0, 0, z], rot("z", 30)) - q2)),
                          bounds=(800.0, 820.0), method="bounded", options={"xatol": 1e-6})
    assert fit.fun < 0.05
    # but 910 → 810 mm exactly gives l_i2 = 847.8905 where 847.8 is printed (a rounding slip)
    down = ik_lengths(mech, [0.0, 0.0, 810.0], rot("z", 30))
    assert np.max(np.abs(down[0::2] - q2[0::2])) < 0.05
    assert np.allclose(np.round(down[1::2], 1), 847.9) and np.all(q2[1::2] == 847.8)
    # Row 3: a pure rotation about y (Chebyshev fit printed by benchmarks/paper_validation.py)
    tilt = ik_lengths(mech, [64.9402, 0.0, 920.2675], rot("y", -20.1517))
    assert np.max(np.abs(tilt - q3)) < 0.05                              # 0.033 mm
    # A round -20° is not within the rounding: the best centroid leaves 0.24 mm.
    _, err = minimax(lambda x: ik_lengths(mech, x, rot("y", -20.0)) - q3, [65.0, 0.0, 920.0])
    assert err > 0.1


@pytest.mark.parametrize("l, row2_yaw, row3_axis_off",
                         [(150.0, 33.46, 5.58), (200.0, 37.85, 23.73)])
def test_luzi_table1_lengths_are_not_these_motions_at_l_150_or_200(l, row2_yaw, row3_axis_off):
    """The same lengths with l = 150 or 200 mm give no round yaw and no rotation about y."""
    mech = luzi(l)
    (p1, R1, _), (p2, R2, _), (p3, R3, _) = (luzi_fk(mech, q) for q, _ in TABLE)
    ang, _, _ = relative_motion(p1, R1, p2, R2)
    assert abs(ang - row2_yaw) < 0.01 and abs(ang - 30.0) > 3.0
    _, axis, _ = relative_motion(p1, R1, p3, R3)
    assert abs(axis_deviation_deg(axis, Y_AXIS) - row3_axis_off) < 0.01


@pytest.mark.parametrize("row, l_fit, l_other", [(0, 200.0, 150.0), (1, 200.0, 150.0),
                                                 (2, 150.0, 200.0)])
def test_luzi_table1_psi_are_the_fk_psi_with_another_upper_link(row, l_fit, l_other):
    """The printed ψ are the FK ψ of lengths within the printed ones' rounding for l_fit only."""
    q, psi = TABLE[row]
    assert psi_rounding_gap(luzi(l_fit), q, psi) < PSI_ROUNDING          # ≤ 4e-7 rad
    assert psi_rounding_gap(luzi(PRINTED_L), q, psi) > 0.03              # 0.054 / 0.134 / 0.039
    assert psi_rounding_gap(luzi(l_other), q, psi) > 0.02                # 0.027 / 0.074 / 0.33
    # At l = 100 mm the printed ψ2 and ψ4 (fixed by the pose alone: the plane of chain 1 and
    # the platform yaw) already disagree, so no sign, offset or unit change of ψ1/ψ3 helps.
    d = psi_of_lengths(luzi(PRINTED_L), q) - psi
    assert np.max(np.abs(d[[1, 3]])) > 2e-3


def test_luzi_table1_rows_1_2_psi_are_those_of_the_round_poses_through_l_200():
    """Unrounded IK lengths (l = 100) of z = 910 mm level and z = 810 mm yawed 30°, solved with
    l = 200 mm, give the printed ψ to their last digit; the printed (rounded) lengths do not."""
    m100, m200 = luzi(PRINTED_L), luzi(200.0)
    for row, (p, R) in enumerate((([0.0, 0.0, 910.0], np.eye(3)),
                                  ([0.0, 0.0, 810.0], rot("z", 30)))):
        psi = psi_of_lengths(m200, ik_lengths(m100, p, R))
        assert np.max(np.abs(psi - TABLE[row][1])) < 2 * PSI_ROUNDING     # 3.2e-6 / 4.5e-6
    rounded = psi_of_lengths(m200, TABLE[1][0])
    assert abs(rounded[3] - TABLE[1][1][3]) > 5e-4                        # 1.0e-3 rad


def test_luzi_psi_round_trip_and_four_bar_equation():
    mech = Luzi3.from_paper(upper_link=200.0)
    rng = np.random.default_rng(5)
    X = mech.nominal_pose + np.concatenate([rng.uniform(-60, 60, (200, 3)),
                                            np.radians(rng.uniform(-20, 20, (200, 3)))], 1)
    q = mech.inverse(X).q
    psi = pose_to_psi(mech, X)
    back = psi_to_pose(mech, psi, q[:, 0], q[:, 1])
    assert np.max(np.abs(back[:, :3] - X[:, :3])) < 1e-8
    R1, R2 = euler_to_matrix(back[:, 3:]), euler_to_matrix(X[:, 3:])
    assert np.max(np.linalg.norm(log_so3(np.einsum("nji,njk->nik", R1, R2)), axis=1)) < 1e-10
    # psi_to_pose rebuilds the pose with θ from eq. (1), so the round trip above validates
    # eq. (1) and its "−√" branch; the other branch must give a different (wrong) pose.
    theta = four_bar_theta(mech, psi[:, 0], q[:, 0], q[:, 1])
    assert np.all(np.isfinite(theta))
    other = psi_to_pose(mech, psi, q[:, 0], q[:, 1], branch=1)
    assert np.min(np.max(np.abs(other[:, :3] - X[:, :3]), axis=1)) > 1.0


def test_reduced_dpa_equals_full_closure_modes():
    """The reduced ψ system (with t_i oriented) and the multi-start on the full closure agree."""
    mech = Luzi3.from_paper(upper_link=200.0, stroke=(700.0, 1200.0))
    q = np.array(TABLE[2][0])
    red = reduced_dpa(mech, q)
    modes = mech.assembly_modes(q, starts=2000)
    phys = red.pose[red.physical]
    assert len(phys) == len(modes.pose) >= 2
    pa, Ra = as_frames(phys)
    pb, Rb = as_frames(modes.pose)
    for i in range(len(pa)):
        d = np.abs(pb - pa[i]).max(1) + np.linalg.norm(
            log_so3(np.einsum("ji,njk->nik", Ra[i], Rb)), axis=1)
        assert d.min() < 1e-6
    assert np.all(red.residual[red.physical] < 1e-9)
    assert np.any(~red.physical)                    # the reduced system has spurious roots
