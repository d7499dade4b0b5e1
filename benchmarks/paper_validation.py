"""Figures for docs/validation.md: Hopkins & Williams errata and geometry, Luzi et al. Table 1
(printed lengths → poses at l = 100 mm; printed ψ → the upper link they were computed with).

Run: .venv/bin/python benchmarks/paper_validation.py
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
from scipy.optimize import least_squares, linprog, minimize, minimize_scalar

import pkmlab
from pkmlab.mechanisms import NO_STROKE, Luzi3
from pkmlab.mechanisms.families.luzi3 import four_bar_theta, pose_to_psi, reduced_dpa
from pkmlab.mechanisms.legs.layout import equal_leg_base_angle, paired_layout
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
#
# What the evidence shows (docs/validation.md): the printed actuator lengths are, at the printed
# upper link l = 100 mm, simple motions from a level home pose; the printed ψ are not the ψ of
# those poses but the direct position analysis of the same lengths with l = 200 mm (rows 1-2)
# and l = 150 mm (row 3).

TABLE = [
    ([958.6] * 6, [1.33736, 1.43097, -1.43097, 0.523599]),
    ([891.6, 847.8, 891.6, 847.8, 891.6, 847.8], [1.21866, 1.37925, -1.37925, 1.183130]),
    ([973.3, 969.8, 1004.2, 1002.9, 939.5, 941.6], [1.17517, 1.43822, -1.47862, 0.438011]),
]
PRINTED_L = 100.0
LENGTH_ROUNDING = 0.05          # mm: the table prints lengths to 0.1 mm
PSI_ROUNDING = 5e-6             # rad: ψ1-ψ3 printed to 1e-5 (ψ4 to 1e-6)
#: The S_P orientation at the level, symmetric pose (ψ4 = π/6, y_P along C1 → C3).
LEVEL = euler_to_matrix(np.array([0.0, 0.0, math.pi / 6]))


def luzi(l: float) -> Luzi3:
    """The paper's geometry with upper link ``l`` (mm) and a stroke wide enough for Table 1."""
    return Luzi3.from_paper(upper_link=l, stroke=(700.0, 1200.0))


def luzi_fk(mech: Luzi3, q):
    """Forward kinematics from the nominal (level) pose: centroid ``p``, S_P orientation ``R``,
    largest closure residual (mm)."""
    fk = mech.forward(np.asarray(q, dtype=float))
    if not fk.converged[0]:
        raise RuntimeError(f"FK did not converge for {q}")
    p, R = pkmlab.poses.as_frames(fk.pose)
    return p[0], R[0], float(fk.residual[0])


def relative_motion(p0, R0, p, R):
    """Rigid motion taking pose (p0, R0) to (p, R), rotation applied in the base frame:
    angle (deg), unit axis, centroid displacement (mm)."""
    Rr = R @ R0.T
    w = pkmlab.poses.log_so3(Rr[None])[0]
    ang = float(np.linalg.norm(w))
    return math.degrees(ang), (w / ang if ang > 0 else np.array([0.0, 0.0, 1.0])), p - p0


def axis_deviation_deg(axis, ref) -> float:
    """Angle (deg) between a rotation axis and a reference line (either sense)."""
    return math.degrees(math.acos(min(1.0, abs(float(np.dot(axis, ref))))))


def rounding_bound(mech: Luzi3, p, R, dq: float = LENGTH_ROUNDING):
    """Linearised worst case of the pose change (mm, mm, mm, rad, rad, rad: centroid and
    rotation vector) when every actuator length moves by at most ``dq``."""
    J = mech.jacobian((p[None], R[None]))[0]
    return dq * np.abs(np.linalg.inv(J)).sum(axis=1)


def minimax(resid, x0):
    """Chebyshev fit: ``min_x max_i |resid(x)_i|`` (SLSQP on ``(x, t)``); returns x and the
    minimum."""
    x0 = np.asarray(x0, dtype=float)
    cons = [{"type": "ineq", "fun": lambda z: z[-1] - resid(z[:-1])},
            {"type": "ineq", "fun": lambda z: z[-1] + resid(z[:-1])}]
    z = np.r_[x0, np.max(np.abs(resid(x0)))]
    for _ in range(3):
        z = minimize(lambda z: z[-1], z, constraints=cons, method="SLSQP",
                     options={"maxiter": 1000, "ftol": 1e-15}).x
        z[-1] = np.max(np.abs(resid(z[:-1])))
    return z[:-1], float(z[-1])


def ik_lengths(mech: Luzi3, p, R_rel):
    """Actuator lengths of the platform with centroid ``p`` rotated by ``R_rel`` (base frame)
    from the level, symmetric orientation."""
    return mech.inverse((np.asarray(p, float)[None], (R_rel @ LEVEL)[None]), stroke=NO_STROKE).q[0]


def rot(axis: str, deg: float) -> np.ndarray:
    a = [0.0, 0.0, 0.0]
    a["xyz".index(axis)] = math.radians(deg)
    return euler_to_matrix(np.array(a))


def psi_of_lengths(mech: Luzi3, q) -> np.ndarray:
    """ψ1..ψ4 of the FK pose of ``q`` (mode reached from the level pose)."""
    p, R, _ = luzi_fk(mech, q)
    return pose_to_psi(mech, pkmlab.poses.frames_to_poses(p[None], R[None]))[0]


def psi_rounding_gap(mech: Luzi3, q, psi_table, dq: float = LENGTH_ROUNDING,
                     h: float = 1e-3) -> float:
    """``min over |δq_i| ≤ dq of max_j |ψ_j(q + δq) - ψ_table_j|`` (rad): the linear programme
    on the central-difference sensitivity dψ/dq (step ``h`` mm), then re-evaluated with the full
    FK at the optimum. Zero (to round-off) means the printed ψ are the FK ψ of some lengths that
    round to the printed ones."""
    q, psi_table = np.asarray(q, float), np.asarray(psi_table, float)
    p0 = psi_of_lengths(mech, q)
    J = np.array([(psi_of_lengths(mech, q + h * e) - psi_of_lengths(mech, q - h * e)) / (2 * h)
                  for e in np.eye(6)]).T
    A = np.r_[np.c_[J, -np.ones(4)], np.c_[-J, -np.ones(4)]]
    b = np.r_[psi_table - p0, p0 - psi_table]
    res = linprog(np.r_[np.zeros(6), 1.0], A_ub=A, b_ub=b,
                  bounds=[(-dq, dq)] * 6 + [(0, None)])
    return float(np.max(np.abs(psi_of_lengths(mech, q + res.x[:6]) - psi_table)))


def upper_link_interval(row: int, inside: float, lo: float, hi: float,
                        tol: float = PSI_ROUNDING) -> tuple[float, float]:
    """Range of l (mm, bisection to 1e-3) around ``inside`` where the row's printed ψ are the FK
    ψ of lengths within the rounding of the printed ones (:func:`psi_rounding_gap` ≤ tol)."""
    q, psi = TABLE[row]

    def edge(a, b):
        while abs(b - a) > 1e-3:
            m = 0.5 * (a + b)
            a, b = (m, b) if psi_rounding_gap(luzi(m), q, psi) <= tol else (a, m)
        return a
    return edge(inside, lo), edge(inside, hi)


def luzi_lengths_report() -> None:
    print("\n-- printed lengths at the printed l = 100 mm: FK (Newton from the level pose) --")
    mech = luzi(PRINTED_L)
    poses = [luzi_fk(mech, q) for q, _ in TABLE]
    p0, R0, _ = poses[0]
    for k, (p, R, res) in enumerate(poses, 1):
        b = rounding_bound(mech, p, R)
        ang, axis, dp = relative_motion(p0, R0, p, R)
        print(f"row {k}: residual {res:.1e} mm; centroid ({p[0]:.3f}, {p[1]:.3f}, {p[2]:.3f}) mm;"
              f" from row 1: rotation {ang:.3f} deg about ({axis[0]:+.4f}, {axis[1]:+.4f}, "
              f"{axis[2]:+.4f}), centroid moved ({dp[0]:+.3f}, {dp[1]:+.3f}, {dp[2]:+.3f}) mm; "
              f"rounding bound ±({b[0]:.3f}, {b[1]:.3f}, {b[2]:.3f}) mm, "
              f"±({math.degrees(b[3]):.3f}, {math.degrees(b[4]):.3f}, "
              f"{math.degrees(b[5]):.3f}) deg")
    ang, axis, dp = relative_motion(p0, R0, *poses[2][:2])
    Rr = poses[2][1] @ R0.T
    a = np.linalg.solve((np.eye(3) - Rr)[np.ix_([0, 2], [0, 2])], (poses[2][0] - Rr @ p0)[[0, 2]])
    print(f"row 3 axis {axis_deviation_deg(axis, [0, 1, 0]):.3f} deg from y, slide along it "
          f"{float(np.dot(dp, axis)):+.3f} mm, through (x, z) = ({a[0]:.2f}, {a[1]:.2f}) mm")
    q2 = np.array(TABLE[1][0])
    q2[1::2] = 847.9
    ang, axis, dp = relative_motion(p0, R0, *luzi_fk(mech, q2)[:2])
    print(f"row 2 with l_i2 = 847.9 instead of 847.8: rotation {ang:.3f} deg about z, "
          f"dz {dp[2]:+.3f} mm")

    for l in (150.0, 200.0):
        m = luzi(l)
        (a1, B1, _), (a2, B2, _), (a3, B3, _) = (luzi_fk(m, q) for q, _ in TABLE)
        ang2, _, dp2 = relative_motion(a1, B1, a2, B2)
        ang3, axis3, _ = relative_motion(a1, B1, a3, B3)
        print(f"same lengths at l={l:.0f}: row 2 {ang2:.2f} deg about z, dz {dp2[2]:+.2f} mm; "
              f"row 3 {ang3:.2f} deg about an axis {axis_deviation_deg(axis3, [0, 1, 0]):.2f} "
              f"deg off y")
    print("round motions vs printed lengths (Chebyshev fit, max |q_IK - q_printed| in mm):")
    q = [np.array(r[0]) for r in TABLE]
    for l in (PRINTED_L, 150.0, 200.0):
        m = luzi(l)
        z1, e1 = minimax(lambda x, m=m: ik_lengths(m, [0, 0, x[0]], np.eye(3)) - q[0],
                         [910.0])
        z2, e2 = minimax(lambda x, m=m: ik_lengths(m, [0, 0, x[0]], rot("z", 30)) - q[1],
                         [810.0])
        x3, e3 = minimax(lambda x, m=m: ik_lengths(m, [x[0], 0, x[1]], rot("y", x[2])) - q[2],
                         [65.0, 920.0, -20.15])
        print(f"  l={l:5.0f}: row 1 level, z={z1[0]:.3f}: {e1:.3f}; row 2 yaw 30 deg exactly, "
              f"z={z2[0]:.3f}: {e2:.3f}; row 3 pure rotation about y by {x3[2]:.4f} deg, "
              f"centroid ({x3[0]:.4f}, 0, {x3[1]:.4f}): {e3:.3f}")
    e = np.max(np.abs(np.r_[ik_lengths(mech, [0, 0, 910.0], np.eye(3)) - q[0],
                            ik_lengths(mech, [0, 0, 810.0], rot("z", 30)) - q[1]]))
    print(f"  l=100: z = 910 level and z = 810 yawed 30 deg (no free parameter): {e:.3f}; "
          f"unrounded lengths {ik_lengths(mech, [0, 0, 910.0], np.eye(3))[0]:.4f}, "
          f"{np.round(ik_lengths(mech, [0, 0, 810.0], rot('z', 30))[:2], 4)}")
    _, e = minimax(lambda x: ik_lengths(mech, x[:3], rot("y", -20.0)) - q[2], [65.0, 0, 920.0])
    print(f"  l=100: row 3 as a rotation of exactly -20 deg about y, centroid free: {e:.3f}")
    for k in range(3):
        n = [int(reduced_dpa(mech, q[k], grid=g).physical.sum()) for g in (9, 13)]
        print(f"  l=100 row {k + 1}: physical roots of the reduced DPA with a 9^4 / 13^4 start "
              f"grid {n[0]} / {n[1]}; assembly_modes {len(mech.assembly_modes(q[k]).pose)}")


def luzi_psi_report() -> None:
    print("\n-- printed ψ --")
    for k, (q, psi) in enumerate(TABLE, 1):
        for l in (PRINTED_L, 150.0, 200.0):
            m = luzi(l)
            d = psi_of_lengths(m, q) - psi
            print(f"row {k} l={l:5.0f}: ψ(FK of printed lengths) - ψ_table = "
                  f"{np.array2string(d, precision=5, suppress_small=True)}; min over the "
                  f"length rounding of max|Δψ| = {psi_rounding_gap(m, q, psi):.2e} rad")
    for k, c, lo, hi in ((0, 200.0, 180.0, 220.0), (1, 200.0, 190.0, 210.0),
                         (2, 150.0, 140.0, 160.0)):
        best = minimize_scalar(lambda l, k=k: np.max(np.abs(psi_of_lengths(luzi(l), TABLE[k][0])
                                                            - TABLE[k][1])),
                               bounds=(c - 2, c + 2), method="bounded",
                               options={"xatol": 1e-4})
        a, b = upper_link_interval(k, c, lo, hi)
        print(f"row {k + 1}: best-fit l {best.x:.3f} mm (max|Δψ| {best.fun:.2e} rad); "
              f"consistent to {PSI_ROUNDING:.0e} rad for l in [{a:.3f}, {b:.3f}] mm")
    mech, m200 = luzi(PRINTED_L), luzi(200.0)
    round_poses = [([0, 0, 910.0], np.eye(3)), ([0, 0, 810.0], rot("z", 30))]
    for k, (p, R) in enumerate(round_poses):
        q_un = ik_lengths(mech, p, R)
        d = psi_of_lengths(m200, q_un) - TABLE[k][1]
        print(f"row {k + 1}: round pose {p}, IK at l=100 unrounded -> FK at l=200 -> ψ - ψ_table"
              f" = {np.array2string(d, precision=7, suppress_small=True)}")

    def fit(v):
        d1 = psi_of_lengths(m200, ik_lengths(mech, [0, 0, v[0]], np.eye(3))) - TABLE[0][1]
        d2 = psi_of_lengths(m200, ik_lengths(mech, [0, 0, v[1]], rot("z", v[2]))) - TABLE[1][1]
        return np.r_[d1[:2], d2[[0, 1, 3]]]
    s = least_squares(fit, [910.0, 810.0, 30.0], x_scale=[1.0, 1.0, 0.01], xtol=1e-15,
                      ftol=1e-15)
    sens = PSI_ROUNDING * np.abs(np.linalg.pinv(s.jac)).sum(axis=1)
    print(f"fit of (home z, row-2 z, row-2 yaw) at l=100 to the 5 independent printed ψ of rows "
          f"1-2 through FK at l=200: {s.x[0]:.3f} ± {sens[0]:.3f} mm, {s.x[1]:.3f} ± "
          f"{sens[1]:.3f} mm, {s.x[2]:.5f} ± {sens[2]:.5f} deg (± per {PSI_ROUNDING:.0e} rad), "
          f"max residual {np.max(np.abs(s.fun)):.1e} rad")
    th = four_bar_theta(m200, 1.33736, 958.6, 958.6)
    print(f"eq. (1) θ for row 1 (l=200): {th:.2e} rad (symmetric trapezoid → 0)")


def luzi_report() -> None:
    print("\n== Luzi, Sancisi, Parenti Castelli, Table 1 ==")
    luzi_lengths_report()
    luzi_psi_report()


if __name__ == "__main__":
    hopkins_report()
    luzi_report()
