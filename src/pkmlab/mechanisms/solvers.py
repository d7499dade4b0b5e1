"""Generic forward-kinematics solvers shared by every family.

Newton's method runs on the family's loop-closure residuals ``f(p, R; q)`` (mm) with their
analytic derivative ``G = ∂f/∂ξ`` with respect to a base-frame twist displacement ξ = (δp, δφ);
a step updates ``p ← p + δp`` and ``R ← exp(δφ)·R``, so no Euler-angle singularity is involved.
Only the twist components the mechanism's mobility frees move (:mod:`.mobility`); a
mechanism with more actuators than free coordinates takes least-squares steps.
Everything is batched over starting points; converged entries drop out of the active set.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..poses import POSE_SIZE, as_frames, frames_to_poses, log_so3
from ..runtime.threads import threads_for
from ..tolerances import TOL
from .kernels import ik as _kernels
from .results import NO_STROKE, AssemblyModes, FKResult, step_frames


def bracketed_root(f, a: float, b: float, xtol: float) -> float:
    """A root of the scalar function ``f`` in ``[a, b]``, where ``f(a)`` and ``f(b)`` differ in
    sign (or one is zero), to within ``xtol``, by bisection: ``ceil(log2(|b - a| / xtol))``
    evaluations, guaranteed. (``scipy.optimize.brentq`` needs fewer evaluations but importing
    scipy.optimize costs about 0.3 s, more than the whole root search in a fresh process.)"""
    fa = f(a)
    if fa == 0:
        return float(a)
    for _ in range(max(1, int(np.ceil(np.log2(max(abs(b - a), xtol) / xtol))) + 1)):
        m = 0.5 * (a + b)
        fm = f(m)
        if fm == 0:
            return float(m)
        if (fm < 0) == (fa < 0):
            a, fa = m, fm
        else:
            b = m
    return float(0.5 * (a + b))


def mid_stroke_pose(mech) -> np.ndarray:
    """The level, centred pose whose mean actuator value is mid-stroke (highest such z):
    a scan of z on the axis, then bisection to ``TOL.nominal_z_mm`` in the first interval
    that changes sign (``Mechanism._mid_stroke_pose``)."""
    lo, hi = mech.stroke
    mid = 0.5 * (lo + hi)
    yaw = mech._level_yaw()
    Rz = np.array([[[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0],
                    [0.0, 0.0, 1.0]]])

    # the root search evaluates one pose ~40 times (to 1e-12 mm): one driver and one set
    # of buffers for all of them: the same kernel, arithmetic and leg check as _run_ik
    g, L = mech._ik_geometry, mech.n_actuators
    frames = _kernels.make_driver(mech._ik_kernel(), len(g), "frames", L)
    P, Rc = np.zeros((1, 3)), _kernels.carray(Rz)
    q, st, reason = np.empty((1, L)), np.empty((1, L), np.int8), np.empty(1, np.int8)
    q_lo, q_hi = (float(v) for v in NO_STROKE)

    def mean_q(z: float) -> float:
        P[0, 2] = z
        frames(P, Rc, g, q_lo, q_hi, q, st, reason)
        if reason[0] == _kernels.LEG_FAULT:
            mech._check_legs(reason)
        return float(np.mean(q[0])) - mid if reason[0] == _kernels.OK else np.nan

    S = mech.scale
    zs = np.linspace(3.0 * S + hi, -S, 801)
    scan = mech._run_ik(np.stack([np.zeros(801), np.zeros(801), zs], axis=1),
                        np.ascontiguousarray(np.broadcast_to(Rz, (801, 3, 3))), *NO_STROKE)
    vals = np.where(scan.valid, scan.q.mean(axis=1) - mid, np.nan)
    a, b = vals[:-1], vals[1:]
    # the first scan interval whose ends are finite and change sign (or touch zero)
    hit = np.flatnonzero(np.isfinite(a) & np.isfinite(b) & (a * b <= 0))
    if len(hit):
        k = int(hit[0])
        with threads_for(1):
            z = bracketed_root(mean_q, zs[k + 1], zs[k], xtol=TOL.nominal_z_mm)
        return np.array([0.0, 0.0, z, 0.0, 0.0, yaw])
    raise ParameterError("stroke", "a window whose mid-point is reachable by a level, "
                         "centred platform (the nominal pose: give 'nominal' or change the "
                         "stroke or the link lengths)", list(mech.stroke))


def _solve(G: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Batched ``G⁻¹ f`` with a pseudo-inverse fallback when a matrix is singular."""
    try:
        return np.linalg.solve(G, f[..., None])[..., 0]
    except np.linalg.LinAlgError:
        return np.einsum("nij,nj->ni", np.linalg.pinv(G, rcond=TOL.newton_rcond), f)


def newton(mech, p, R, q, *, tol: float, max_iter: int, polish: int = 2):
    """Damped Newton from frames ``p (N,3)``, ``R (N,3,3)`` towards actuator values ``q (N,L)``.

    Returns ``(p, R, residual (N,), iterations (N,), finite (N,))``: ``finite`` is False where
    the residual or its derivative became undefined (e.g. a leg with no real solution).
    """
    p, R, q = p.copy(), R.copy(), np.asarray(q, dtype=float)
    n = p.shape[0]
    residual = np.full(n, np.inf)
    iters = np.zeros(n, dtype=int)
    polished = np.zeros(n, dtype=int)
    finite = np.ones(n, dtype=bool)
    active = np.arange(n)
    max_lin, max_ang = 0.25 * mech.scale, 0.5
    cols = None if mech.mobility.is_spatial else mech.mobility.twist_columns
    for _ in range(max_iter + polish + 1):
        if active.size == 0:
            break
        f, G = mech._closure(p[active], R[active], q[active])
        good = np.all(np.isfinite(f), axis=1) & np.all(np.isfinite(G), axis=(1, 2))
        res = np.where(good, np.max(np.abs(np.where(np.isfinite(f), f, 0.0)), axis=1), np.inf)
        residual[active] = res
        finite[active[~good]] = False
        polished[active] += res < tol
        keep = good & (polished[active] <= polish) & (iters[active] < max_iter + polish)
        active, f, G = active[keep], f[keep], G[keep]
        if active.size == 0:
            break
        if cols is None:
            step = -_solve(G, f)
        else:
            step = np.zeros((len(active), POSE_SIZE))
            step[:, cols] = -_solve(G[:, :, cols], f)
        lin = np.linalg.norm(step[:, :3], axis=1)
        ang = np.linalg.norm(step[:, 3:], axis=1)
        scale = np.minimum(1.0, np.minimum(max_lin / np.maximum(lin, 1e-300),
                                           max_ang / np.maximum(ang, 1e-300)))
        step *= scale[:, None]
        p[active], R[active] = step_frames(p[active], R[active], step)
        iters[active] += 1
    return p, R, residual, iters, finite


def _working_mode(mech, p, R, q, tol_mode: float) -> np.ndarray:
    """True where the family's inverse kinematics at (p, R) reproduces q and puts no leg
    outside the family's working mode (a mirror assembly has the same leg lengths)."""
    ik = mech.inverse((p, R), stroke=NO_STROKE)
    with np.errstate(invalid="ignore"):
        err = np.max(np.abs(ik.q - q), axis=1)
    other = np.any(ik.leg_status == _kernels.OTHER_MODE, axis=1)
    return np.isfinite(err) & (err <= tol_mode) & ~other


def forward_newton(mech, q, guess=None, *, tol: float = TOL.fk_residual_mm, max_iter: int = 50,
                   continuation_steps: int = 12, modes: bool = False) -> FKResult:
    """Batched forward kinematics; see :meth:`Mechanism.forward`."""
    q = np.atleast_2d(np.asarray(q, dtype=float))
    L = mech.n_actuators
    if q.ndim != 2 or q.shape[1:] != (L,):
        raise ParameterError("q", f"an array of shape ({L},) or (N, {L}) in "
                             f"{mech.actuator_unit}", q.shape)
    n = q.shape[0]
    p0, R0 = as_frames(mech.nominal_pose if guess is None else guess, field="guess")
    if p0.shape[0] == 1 and n > 1:
        p0, R0 = np.repeat(p0, n, axis=0), np.repeat(R0, n, axis=0)
    tol_mode = max(1e3 * tol, TOL.working_mode_mm)
    p, R, res, it, _ = newton(mech, p0, R0, q, tol=tol, max_iter=max_iter)
    ok = (res < tol) & _working_mode(mech, p, R, q, tol_mode)

    bad = np.flatnonzero(~ok & np.all(np.isfinite(q), axis=1))
    if bad.size:
        # Continuation from the nominal pose keeps the nominal assembly mode.
        pn, Rn = as_frames(mech.nominal_pose)
        qn = mech.inverse((pn, Rn), stroke=NO_STROKE).q[0]
        pc, Rc = np.repeat(pn, bad.size, axis=0), np.repeat(Rn, bad.size, axis=0)
        itc = np.zeros(bad.size, dtype=int)
        for k in range(1, continuation_steps + 1):
            qk = qn + (k / continuation_steps) * (q[bad] - qn)
            last = k == continuation_steps
            pc, Rc, resc, itk, _ = newton(mech, pc, Rc, qk, tol=tol if last else 1e3 * tol,
                                          max_iter=max_iter if last else 15)
            itc += itk
        okc = (resc < tol) & _working_mode(mech, pc, Rc, q[bad], tol_mode)
        take = okc
        idx = bad[take]
        p[idx], R[idx], res[idx] = pc[take], Rc[take], resc[take]
        it[bad] += itc
        ok[idx] = True

    pose = frames_to_poses(p, R)
    pose[~ok] = np.nan
    status = np.where(ok, "ok", np.where(np.isfinite(res), "not converged", "singular"))
    if not modes:
        return FKResult(pose=pose, converged=ok, residual=res, iterations=it,
                        status=status.astype(object))
    pa, Ra = mech._mode_starts
    nxt, dmm, ddeg = other_modes(mech, q, p, R, ok, pa, Ra, tol=tol, tol_mode=tol_mode)
    amb = np.isfinite(dmm)
    status = np.where(amb, "ambiguous", status)
    return FKResult(pose=pose, converged=ok, residual=res, iterations=it,
                    status=status.astype(object), ambiguous=amb, next_mode=nxt,
                    next_mode_mm=dmm, next_mode_deg=ddeg, mode_starts=len(pa))


def other_modes(mech, q, p, R, ok, pa, Ra, *, tol: float, tol_mode: float):
    """For each converged solution ``(p, R)`` of ``q``: the nearest *other* working-mode
    assembly mode reached by Newton from the starts ``(pa (K, 3), Ra (K, 3, 3))`` (poses of the
    working region, :attr:`Mechanism._mode_starts`) → ``(pose (N, 6), distance mm (N,), angle
    deg (N,))``, NaN / inf where none was found. Two solutions closer than
    ``TOL.mode_duplicate_rel`` (× scale in mm, and in rad) are one mode; "nearest" by
    ``|Δp| + scale·angle``, as :meth:`Mechanism.assembly_modes` orders them. A heuristic
    search: a mode no start reaches is missed (a check that can fail, not a proof)."""
    n, k = len(q), len(pa)
    nxt = np.full((n, POSE_SIZE), np.nan)
    dmm, ddeg = np.full(n, np.inf), np.full(n, np.inf)
    idx = np.flatnonzero(ok)
    if idx.size == 0 or k == 0:
        return nxt, dmm, ddeg
    Q = np.repeat(q[idx], k, axis=0)
    ps, Rs, res, _, _ = newton(mech, np.tile(pa, (idx.size, 1)), np.tile(Ra, (idx.size, 1, 1)),
                               Q, tol=tol, max_iter=50)
    good = (res < tol) & _working_mode(mech, ps, Rs, Q, tol_mode)
    dp = np.linalg.norm(ps - np.repeat(p[idx], k, axis=0), axis=1)
    da = np.linalg.norm(log_so3(np.einsum("nji,njk->nik", Rs, np.repeat(R[idx], k, axis=0))),
                        axis=1)
    same = (dp < TOL.mode_duplicate_rel * mech.scale) & (da < TOL.mode_duplicate_rel)
    score = np.where(good & ~same, dp + mech.scale * da, np.inf).reshape(idx.size, k)
    j = np.argmin(score, axis=1)
    found = np.isfinite(score[np.arange(idx.size), j])
    sel = np.arange(idx.size) * k + j
    hit, s = idx[found], sel[found]
    nxt[hit] = frames_to_poses(ps[s], Rs[s])
    dmm[hit], ddeg[hit] = dp[s], np.degrees(da[s])
    return nxt, dmm, ddeg


def multistart_modes(mech, q, *, starts: int, seed: int, tol: float) -> AssemblyModes:
    """Multi-start assembly-mode search; see :meth:`Mechanism.assembly_modes`."""
    q = np.asarray(q, dtype=float).reshape(mech.n_actuators)
    pr, Rr = mech._random_starts(starts, seed)
    pn, Rn = as_frames(mech.nominal_pose)
    p0 = np.concatenate([pn, pr])
    R0 = np.concatenate([Rn, Rr])
    qq = np.repeat(q[None], p0.shape[0], axis=0)
    p, R, res, _, _ = newton(mech, p0, R0, qq, tol=tol, max_iter=100)
    conv = res < tol
    p, R, res = p[conv], R[conv], res[conv]
    # De-duplicate: greedy clustering in (position, rotation) space.
    lin_tol, ang_tol = TOL.mode_duplicate_rel * mech.scale, TOL.mode_duplicate_rel
    keep: list[int] = []
    for i in np.argsort(res):
        if keep:
            k = np.array(keep)
            dp = np.linalg.norm(p[k] - p[i], axis=1)
            da = np.linalg.norm(log_so3(np.einsum("nji,jk->nik", R[k], R[i])), axis=1)
            if np.any((dp < lin_tol) & (da < ang_tol)):
                continue
        keep.append(int(i))
    k = np.array(keep, dtype=int)
    p, R, res = p[k], R[k], res[k]
    dist = mech._pose_distance(p, R) if k.size else np.zeros(0)
    order = np.argsort(dist)
    p, R, res, dist = p[order], R[order], res[order], dist[order]
    working = _working_mode(mech, p, R, qq[: p.shape[0]], max(1e3 * tol, TOL.working_mode_mm)) \
        if k.size else np.zeros(0, dtype=bool)
    return AssemblyModes(pose=frames_to_poses(p, R) if k.size else np.zeros((0, POSE_SIZE)),
                         residual=res, working_mode=working, distance=dist,
                         starts=int(p0.shape[0]))
