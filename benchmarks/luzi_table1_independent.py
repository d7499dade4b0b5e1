"""Independent cross-check of the Luzi et al. Table 1 figures (docs/validation.md).

Re-derives the mechanism from the paper's Sect. 3-4 with NumPy/SciPy only (own base layout,
inverse kinematics from eqs. 8-12, forward kinematics by ``scipy.optimize.least_squares``, ψ
measured directly from their definitions, ψ → pose from eqs. 4-7 with θ from a circle
intersection instead of eq. 1), then compares with pkmlab.

Run: .venv/bin/python benchmarks/luzi_table1_independent.py
"""

from __future__ import annotations

import numpy as np
from paper_validation import TABLE
from scipy.optimize import least_squares
from scipy.spatial.transform import Rotation

D = np.radians


def geometry(l: float, db: float = 840.0, dp: float = 280.0, phi_deg: float = 20.0):
    """A_ij (6, 3); C_i (3, 3) at the level reference (platform centroid at the origin, C_i
    facing chain i); chains centred at -90°, 30°, 150° (A11 at -140°, so x ∥ A11→A12)."""
    centres = np.array([-90.0, 30.0, 150.0])
    half = (120.0 - phi_deg) / 2
    ang = D(np.stack([centres - half, centres + half], axis=1).ravel())
    A = np.stack([db / 2 * np.cos(ang), db / 2 * np.sin(ang), np.zeros(6)], axis=1)
    C = np.stack([dp / 2 * np.cos(D(centres)), dp / 2 * np.sin(D(centres)), np.zeros(3)], 1)
    return A, C, l


def ik(geo, p, R):
    """Lengths for centroid ``p`` and rotation ``R`` from the level reference."""
    A, C0, l = geo
    C = p + C0 @ R.T
    k = R[:, 2]
    q = []
    for i in range(3):
        a1, a2 = A[2 * i], A[2 * i + 1]
        r = a2 - a1
        t = np.cross(k, np.cross(r, C[i] - a1))           # eq. (10)
        t /= np.linalg.norm(t)
        t = t if t @ r >= 0 else -t
        q += [np.linalg.norm(C[i] - l / 2 * t - a1), np.linalg.norm(C[i] + l / 2 * t - a2)]
    return np.array(q)


def fk(geo, q, x0=(0, 0, 900, 0, 0, 0)):
    """(p, R, residual) by Levenberg-Marquardt on (p, rotation vector)."""
    def f(x):
        return ik(geo, x[:3], Rotation.from_rotvec(x[3:]).as_matrix()) - q
    s = least_squares(f, np.asarray(x0, float), method="lm", xtol=1e-15, ftol=1e-15, gtol=1e-15)
    return s.x[:3], Rotation.from_rotvec(s.x[3:]).as_matrix(), float(np.max(np.abs(f(s.x))))


def pose_psi(geo, p, R):
    """ψ1..ψ4 from Sect. 3's definitions, angles measured from +x = A11→A12 as in eq. (5)."""
    A, C0, l = geo
    C = p + C0 @ R.T
    k, a1, r = R[:, 2], A[0], A[1] - A[0]
    ex = r / np.linalg.norm(r)
    d = C[0] - a1
    psi2 = np.arctan2(d[2], d[1])                        # dihedral angle of γ1 and the base
    ep = np.array([0.0, np.cos(psi2), np.sin(psi2)])
    u = np.cross(r, d)
    u /= np.linalg.norm(u)
    t = np.cross(k, u)
    t /= np.linalg.norm(t)
    t = t if t @ r >= 0 else -t
    b = C[0] - l / 2 * t - a1                            # A11 → B11
    psi1 = np.arctan2(b @ ep, b @ ex)
    psi3 = np.arctan2(np.cross(u, k) @ t, u @ k)         # signed angle u1 → k about t1
    yp = (C[2] - C[0]) / np.linalg.norm(C[2] - C[0])     # y of S_P
    m = np.cross(k, t)
    psi4 = np.arctan2(np.cross(m, yp) @ k, m @ yp)       # signed angle k×t1 → y_P about k
    return np.array([psi1, psi2, psi3, psi4])


def psi_pose(geo, psi, l11, l12):
    """ψ → (p, R) for both four-bar assemblies: eqs. (4)-(7), θ by circle intersection."""
    A, C0, l = geo
    p1, p2, p3, p4 = psi
    r1 = np.linalg.norm(A[1] - A[0])
    b = l11 * np.array([np.cos(p1), np.sin(p1)])
    dv = np.array([r1, 0.0]) - b
    dd = np.linalg.norm(dv)
    a = (l**2 - l12**2 + dd**2) / (2 * dd)
    h = np.sqrt(max(l**2 - a**2, 0.0))
    mid, perp = b + a * dv / dd, np.array([-dv[1], dv[0]]) / dd
    rx = lambda x: Rotation.from_euler("x", x).as_matrix()   # noqa: E731
    rz = lambda x: Rotation.from_euler("z", x).as_matrix()   # noqa: E731
    F = rz(np.pi / 6)                                        # S_P at the level reference
    out = []
    for X in (mid + h * perp, mid - h * perp):
        th = np.arctan2((X - b)[1], (X - b)[0])
        e = lambda g: np.array([np.cos(g), np.sin(g) * np.cos(p2), np.sin(g) * np.sin(p2)])  # noqa: E731
        C1 = A[0] + l11 * e(p1) + l / 2 * e(th)
        RSP = rx(p2) @ rz(th) @ rx(p3) @ rz(p4)
        out.append((C1 + RSP @ F.T @ (C0.mean(0) - C0[0]), RSP @ F.T))
    return out


def compare_with_pkmlab() -> None:
    from pkmlab.mechanisms import NO_STROKE, Luzi3
    from pkmlab.mechanisms.families.luzi3 import pose_to_psi
    from pkmlab.poses import as_frames, frames_to_poses

    F = Rotation.from_euler("z", 30, degrees=True).as_matrix()
    for l in (100.0, 150.0, 200.0):
        m, g = Luzi3.from_paper(upper_link=l, stroke=(700, 1200)), geometry(l)
        rng = np.random.default_rng(0)
        dq = dpsi = 0.0
        for _ in range(100):
            p = np.array([0, 0, 900.0]) + rng.uniform(-60, 60, 3)
            R = Rotation.from_rotvec(D(rng.uniform(-20, 20, 3))).as_matrix()
            dq = max(dq, np.abs(m.inverse((p[None], (R @ F)[None]), stroke=NO_STROKE).q[0]
                                - ik(g, p, R)).max())
            dpsi = max(dpsi, np.abs(pose_to_psi(m, frames_to_poses(p[None], (R @ F)[None]))[0]
                                    - pose_psi(g, p, R)).max())
        dfk = 0.0
        for q, _ in TABLE:
            pm, Rm = as_frames(m.forward(np.array(q)).pose)
            p, R, _ = fk(g, np.array(q))
            dfk = max(dfk, np.abs(pm[0] - p).max(), np.abs(Rm[0] - R @ F).max())
        print(f"l={l:5.0f}: pkmlab vs independent: IK {dq:.1e} mm, ψ {dpsi:.1e} rad "
              f"(100 random poses); FK of the table rows {dfk:.1e} (mm / rotation entries)")


def main() -> None:
    np.set_printoptions(precision=5, suppress=True)
    for l in (100.0, 150.0, 200.0):
        g = geometry(l)
        for k, (q, psi) in enumerate(TABLE, 1):
            p, R, res = fk(g, np.array(q))
            back = min(np.abs(ik(g, pp, RR) - q).max() for pp, RR in psi_pose(g, psi, q[0], q[1]))
            print(f"l={l:5.0f} row {k}: FK res {res:.1e} mm, centroid {p}, rotation vector from "
                  f"level {np.degrees(Rotation.from_matrix(R).as_rotvec())} deg; ψ - ψ_table "
                  f"{pose_psi(g, p, R) - psi}; table ψ → lengths max|Δq| {back:.3f} mm")
    compare_with_pkmlab()


if __name__ == "__main__":
    main()
