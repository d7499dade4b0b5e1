"""Validation against the two seed papers (figures and errata: docs/validation.md)."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import MECH_DIR

import pkmlab
from pkmlab.mechanisms import Luzi3
from pkmlab.mechanisms.luzi3 import four_bar_theta, pose_to_psi, psi_to_pose, reduced_dpa
from pkmlab.poses import as_frames, euler_to_matrix, log_so3

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "benchmarks"))
from paper_validation import TABLE, hopkins_f, hopkins_jnr_printed  # noqa: E402

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


# Rows of Table 1 and the upper-link length each one is consistent with.
CONSISTENT = [(0, 200.0), (1, 200.0), (2, 150.0)]


@pytest.mark.parametrize("row, l", CONSISTENT)
def test_luzi_table1_rows_reproduced_with_their_upper_link(row, l):
    q, psi_table = np.array(TABLE[row][0]), np.array(TABLE[row][1])
    mech = Luzi3.from_paper(upper_link=l, stroke=(700.0, 1200.0))
    fk = mech.forward(q)
    assert fk.converged[0] and fk.residual[0] < 1e-9
    psi = pose_to_psi(mech, fk.pose)[0]
    # Table lengths are rounded to 0.1 mm, which moves ψ by up to ~1e-3 rad.
    assert np.max(np.abs(psi - psi_table)) < 2e-3
    # The paper's ψ, turned back into a pose, reproduces the table's lengths.
    back = mech.inverse(psi_to_pose(mech, psi_table, q[0], q[1])).q[0]
    assert np.max(np.abs(back - q)) < 0.2


@pytest.mark.parametrize("row", [0, 1, 2])
def test_luzi_table1_not_consistent_with_printed_l_100(row):
    q, psi_table = np.array(TABLE[row][0]), np.array(TABLE[row][1])
    mech = Luzi3.from_paper(upper_link=100.0, stroke=(700.0, 1200.0))
    psi = pose_to_psi(mech, mech.forward(q).pose)[0]
    assert np.max(np.abs(psi - psi_table)) > 0.03


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
