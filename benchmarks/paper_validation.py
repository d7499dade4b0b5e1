"""Figures for docs/validation.md: Hopkins & Williams errata and geometry, Luzi et al. Table 1.

Run: .venv/bin/python benchmarks/paper_validation.py
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

import pkmlab
from pkmlab.mechanisms import NO_STROKE, Luzi3
from pkmlab.mechanisms.layout import equal_leg_base_angle, paired_layout
from pkmlab.mechanisms.luzi3 import four_bar_theta, pose_to_psi, psi_to_pose, reduced_dpa
from pkmlab.poses import euler_to_matrix

ROOT = Path(__file__).resolve().parents[1]
D = math.radians

# ---------------------------------------------------------------------------------------------
# Hopkins & Williams: eq. (9) and (11) as printed, against the loop-closure they come from.


def hopkins_f(X, B, P, L, A, printed: bool):
    """Eq. (9) for one leg; ``printed`` keeps the paper's typos (x - B_iy, r_p1)."""
    x, y, z = X[:3]
    r = euler_to_matrix(X[3:])
    rp2 = P[0] ** 2 + P[1] ** 2
    term_y = (x if printed else y) - B[1]
    return (x * x + y * y + z * z + rp2 + B[0] ** 2 + B[1] ** 2 + L * L
            + 2 * (P[0] * r[0, 0] + P[1] * r[0, 1]) * (x - B[0])
            + 2 * (P[0] * r[1, 0] + P[1] * r[1, 1]) * term_y
            + 2 * (P[0] * r[2, 0] + P[1] * r[2, 1]) * (z - L)
            - 2 * (x * B[0] + y * B[1] + z * L) - A * A)


def hopkins_jnr_printed(X, B, P, L):
    """Eq. (11) exactly as printed (columns 1..6)."""
    x, y, z, tx, ty, tz = X
    r = euler_to_matrix(X[3:])
    sx, cy, sy, cz, sz = (math.sin(tx), math.cos(ty), math.sin(ty),
                              math.cos(tz), math.sin(tz))
    Px, Py = P[0], P[1]
    return np.array([
        2 * (x + Px * r[0, 0] + Py * r[0, 1] - B[0]),
        2 * (y + Px * r[1, 0] + Py * r[1, 1] - B[1]),
        2 * (z + Px * r[2, 0] + Py * r[2, 1] - L),
        2 * (-(Px * r[1, 0] + Py * r[1, 1]) * (x - B[0]) + (Px * r[0, 0] + Py * r[0, 1])
             * (y - B[1])),
        2 * ((-Px * cz * sy + Py * cz * r[2, 1]) * (x - B[0])
             + (-Px * sz * sy + Py * sz * r[2, 1]) * (y - B[1])
             - (Px * cy + Py * sz * sx) * (z - L)),
        2 * (Px * r[0, 2] * (x - B[0]) + Py * r[1, 2] * (y - B[1]) + Py * r[2, 2] * (z - L)),
    ])


def hopkins_report() -> None:
    mech = pkmlab.load_mechanism(ROOT / "studies/mechanisms/hopkins-williams-6psu.yaml")
    print("== Hopkins & Williams 6-PSU ==")
    print(f"solved base pair angle beta = {mech.describe()['base_pair_angle_deg']:.4f} deg")
    nom = mech.nominal_pose
    q = mech.inverse(nom).q[0]
    print(f"nominal tool pose z_H = {nom[2]:.4f} mm, actuators {np.round(q, 6)} "
          f"(spread {np.ptp(q):.2e} mm)")
    # Interpretations of the pairing, with beta solved and with beta = 90 deg exactly.
    radii = ((100.0, 165.0), (50.0, 80.0))
    for pairing in ("same", "crossed"):
        beta = equal_leg_base_angle(*radii, D(33.7), pairing=pairing)
        B, P = paired_layout(*radii, D(90.0), D(33.7), pairing=pairing)
        d = np.linalg.norm((B - P)[:, :2], axis=1)
        dz = np.sqrt(225**2 - d**2)
        print(f"pairing={pairing:8s} equal-leg beta = {math.degrees(beta):8.3f} deg; at beta=90: "
              f"horizontal spans {d[0]:.2f}/{d[1]:.2f} mm, actuator mismatch "
              f"{abs(dz[0] - dz[1]):.3f} mm")
    # Eq. (9)/(11) against an exact solution (pose of {P}, not {H}).
    rng = np.random.default_rng(0)
    Xh = nom + np.array([12.0, -7.0, 5.0, D(8), D(-6), D(11)])
    qh = mech.inverse(Xh).q[0]
    Xp = Xh.copy()
    Xp[:3] -= euler_to_matrix(Xh[3:]) @ mech.tool_offset
    worst_printed = worst_fixed = 0.0
    for i in range(6):
        B, P, L = mech.base_points[i], mech.platform_points[i], qh[i]
        worst_printed = max(worst_printed, abs(hopkins_f(Xp, B, P, L, 225.0, True)))
        worst_fixed = max(worst_fixed, abs(hopkins_f(Xp, B, P, L, 225.0, False)))
    print(f"eq. (9) at an exact IK solution: printed |f| max = {worst_printed:.3f} mm^2, "
          f"corrected |f| max = {worst_fixed:.2e} mm^2")
    # Eq. (11): printed columns vs central differences of the corrected f.
    h = 1e-6
    errs = np.zeros((6, 6))
    for _ in range(20):
        X = Xp + np.concatenate([rng.uniform(-20, 20, 3), np.radians(rng.uniform(-15, 15, 3))])
        for i in range(6):
            B, P, L = mech.base_points[i], mech.platform_points[i], qh[i]
            Jp = hopkins_jnr_printed(X, B, P, L)
            for j in range(6):
                e = np.zeros(6)
                e[j] = h
                fd = (hopkins_f(X + e, B, P, L, 225, False)
                      - hopkins_f(X - e, B, P, L, 225, False)) / (2 * h)
                for c in range(6):
                    errs[c, j] = max(errs[c, j], abs(Jp[c] - fd) / max(abs(fd), 1.0))
    names = ["x", "y", "z", "θx", "θy", "θz"]
    for c in range(6):
        best = int(np.argmin(errs[c]))
        print(f"  printed column {c + 1}: closest to d f/d {names[best]} "
              f"(max rel. error {errs[c, best]:.2e})")
    # Corrected J_NR: columns 4 and 6 swapped, P_ix -> P_iy in col 6, s_z s_x -> s_y s_x in col 5
    # (exercised in tests/test_papers.py).


# ---------------------------------------------------------------------------------------------
# Luzi et al. Table 1

TABLE = [
    ([958.6] * 6, [1.33736, 1.43097, -1.43097, 0.523599]),
    ([891.6, 847.8, 891.6, 847.8, 891.6, 847.8], [1.21866, 1.37925, -1.37925, 1.183130]),
    ([973.3, 969.8, 1004.2, 1002.9, 939.5, 941.6], [1.17517, 1.43822, -1.47862, 0.438011]),
]


def luzi_row(l: float, q, psi_table):
    """FK (analytic Newton, from the level pose) → ψ; reduced DPA → closest physical ψ;
    table ψ → lengths."""
    mech = Luzi3.from_paper(upper_link=l, stroke=(700.0, 1200.0))
    q = np.array(q)
    fk = mech.forward(q)
    psi_fk = pose_to_psi(mech, fk.pose)[0] if fk.converged[0] else np.full(4, np.nan)
    red = reduced_dpa(mech, q)
    phys = red.psi[red.physical]
    dmin = np.min(np.max(np.abs(phys - psi_table), axis=1)) if len(phys) else np.nan
    pose_t = psi_to_pose(mech, psi_table, q[0], q[1])
    q_back = mech.inverse(pkmlab.poses.as_frames(pose_t), stroke=NO_STROKE).q[0]
    return dict(fk_ok=bool(fk.converged[0]), fk_res=float(fk.residual[0]), psi_fk=psi_fk,
                dpsi_fk=float(np.max(np.abs(psi_fk - psi_table))), n_roots=len(red.psi),
                n_phys=int(red.physical.sum()), dpsi_dpa=float(dmin),
                dq=float(np.max(np.abs(q_back - q))), pose=fk.pose[0])


def luzi_report() -> None:
    print("\n== Luzi, Sancisi, Parenti Castelli, Table 1 ==")
    for k, (q, psi) in enumerate(TABLE, 1):
        for l in (100.0, 150.0, 200.0):
            r = luzi_row(l, q, np.array(psi))
            p = r["pose"]
            print(f"row {k} l={l:5.0f}: FK {'ok' if r['fk_ok'] else 'FAILED'} "
                  f"(res {r['fk_res']:.1e} mm) pose x,y,z=({p[0]:.2f},{p[1]:.2f},{p[2]:.2f}) mm "
                  f"θ=({math.degrees(p[3]):.2f},{math.degrees(p[4]):.2f},"
                  f"{math.degrees(p[5]):.2f}) deg; max|Δψ| FK {r['dpsi_fk']:.2e}, reduced DPA "
                  f"{r['dpsi_dpa']:.2e} rad ({r['n_phys']}/{r['n_roots']} roots physical); "
                  f"table ψ → lengths max|Δq| {r['dq']:.3f} mm")
    mech = Luzi3.from_paper(upper_link=200.0)
    th = four_bar_theta(mech, 1.33736, 958.6, 958.6)
    print(f"eq. (1) θ for row 1 (l=200): {th:.2e} rad (symmetric trapezoid → 0)")


if __name__ == "__main__":
    hopkins_report()
    luzi_report()
