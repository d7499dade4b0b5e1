"""Regular workspace: the largest inscribed axis-aligned box and vertical cylinder.

Both are valid for the continuous workspace, not just its voxels:

1. A start is grown on the voxel grid (a box of occupied voxels around the deepest point).
2. Sequential convex programming (cvxpy, Clarabel) enlarges it, maximising the log-volume.
   The shape carries a lattice of points, affine in its parameters (5×5×5 for the box; the
   axis and two rings of 16 on 5 levels for the cylinder). Each iteration evaluates every
   actuator value at every lattice point for every orientation of the set, keeps for each
   (orientation, leg) the lattice points with the smallest and largest value, linearises
   them with the translational Jacobian ``∂q/∂p = J[:, :3]`` and solves for a new shape in a
   trust region; a step is accepted (with backtracking) only where the true stroke holds at
   every lattice point.
3. Verification is what makes the shape valid: its vertices, edge and face centres and a
   seeded uniform random sample of the solid are checked against every constraint of the
   request (stroke, joint cones, interference, κ) for every orientation of the set (for a
   reachable workspace, at least one). Any failure shrinks the shape about its centre by 2 %
   and the check repeats.

Every shape carries a ``status`` and a ``reason``: ``"ok"`` (verified; the enlargement
converged, or was not asked for), ``"not converged"`` (verified, but the enlargement stopped on
a solver or kinematics problem or its iteration cap: it may not be the largest), ``"failed"``
(no scaled copy of the shape passed verification: its size is 0 and it is not a result) or
``"empty"`` (the workspace is empty).
"""

from __future__ import annotations

import logging
import math
import warnings
from dataclasses import dataclass

import numpy as np
from scipy import ndimage

from ..mechanisms import NO_STROKE
from .constraints import check

log = logging.getLogger(__name__)

__all__ = ["InscribedBox", "InscribedCylinder", "inscribed_box", "inscribed_cylinder",
           "STATUSES"]

_POLY = 16

#: algorithm constant: the trust region (and a step) below which the search stops (mm, rad)
_RHO_MIN = 1e-3


STATUSES = ("ok", "not converged", "failed", "empty")


def _fin(v):
    return float(v) if math.isfinite(v) else None


@dataclass(frozen=True)
class InscribedBox:
    """Axis-aligned box ``[lower, upper]`` (mm) verified inside the workspace.

    ``status`` and ``reason``: see the module docstring; only ``"ok"`` and ``"not converged"``
    shapes are results (``ok``).
    """

    lower: np.ndarray
    upper: np.ndarray
    verified_samples: int
    iterations: int
    shrink: float = 1.0
    status: str = "ok"
    reason: str = ""

    @property
    def ok(self) -> bool:
        """A verified shape of positive size (status ``"ok"`` or ``"not converged"``)."""
        return self.status in ("ok", "not converged")

    @property
    def size(self) -> np.ndarray:
        return self.upper - self.lower

    @property
    def centre(self) -> np.ndarray:
        return 0.5 * (self.upper + self.lower)

    @property
    def volume(self) -> float:
        return float(np.prod(self.size))

    def sample(self, n: int, seed: int = 0) -> np.ndarray:
        rng = np.random.default_rng(seed)
        return self.lower + rng.random((n, 3)) * self.size

    def as_dict(self) -> dict:
        return {"status": self.status, "reason": self.reason,
                "centre_mm": [_fin(v) for v in self.centre],
                "size_mm": [_fin(v) for v in self.size],
                "volume_cm3": _fin(self.volume / 1e3), "verified_samples": self.verified_samples,
                "scp_iterations": self.iterations, "verification_shrink": self.shrink}


@dataclass(frozen=True)
class InscribedCylinder:
    """Vertical cylinder (mm) verified inside the workspace (``status``, ``reason``: see the
    module docstring)."""

    centre_xy: np.ndarray
    radius: float
    z_range: tuple[float, float]
    verified_samples: int
    iterations: int
    shrink: float = 1.0
    status: str = "ok"
    reason: str = ""

    @property
    def ok(self) -> bool:
        """A verified shape of positive size (status ``"ok"`` or ``"not converged"``)."""
        return self.status in ("ok", "not converged")

    @property
    def height(self) -> float:
        return self.z_range[1] - self.z_range[0]

    @property
    def volume(self) -> float:
        return math.pi * self.radius**2 * self.height

    def sample(self, n: int, seed: int = 0) -> np.ndarray:
        rng = np.random.default_rng(seed)
        r = self.radius * np.sqrt(rng.random(n))
        t = 2 * np.pi * rng.random(n)
        z = self.z_range[0] + self.height * rng.random(n)
        return np.stack([self.centre_xy[0] + r * np.cos(t), self.centre_xy[1] + r * np.sin(t),
                         z], axis=1)

    def as_dict(self) -> dict:
        return {"status": self.status, "reason": self.reason,
                "centre_xy_mm": [_fin(v) for v in self.centre_xy], "radius_mm": _fin(self.radius),
                "z_range_mm": [_fin(v) for v in self.z_range], "height_mm": _fin(self.height),
                "volume_cm3": _fin(self.volume / 1e3), "verified_samples": self.verified_samples,
                "scp_iterations": self.iterations, "verification_shrink": self.shrink}


# ---- feasibility of point sets ------------------------------------------------------------------


def points_feasible(result, points: np.ndarray) -> np.ndarray:
    """``(N,)`` True where a point satisfies the request for all (or any) orientations."""
    mech = result.mechanism
    R = result.orientations.rotations()
    lo, hi = mech.stroke
    want_all = result.kind != "reachable"
    ok = np.full(len(points), want_all)
    for Rm in R:
        todo = np.nonzero(ok if want_all else ~ok)[0]
        if len(todo) == 0:
            break
        Rb = np.ascontiguousarray(np.broadcast_to(Rm, (len(todo), 3, 3)))
        good = mech.inverse((points[todo], Rb), stroke=(lo, hi)).valid
        if result.constraints.extra:
            sel = np.nonzero(good)[0]
            good[sel] = check(mech, points[todo[sel]], Rb[sel], result.constraints)
        ok[todo] = good
    return ok


_SHRINKS = 60


def _verify(result, shape_points, seed: int, n_random: int):
    """Shrink factor loop → ``(scale, samples checked, reason)`` with every sample feasible;
    ``(0.0, 0, reason)`` when even the smallest copy (0.98^60 ≈ 30 %) fails."""
    scale = 1.0
    for _ in range(_SHRINKS):
        pts = shape_points(scale, n_random, seed)
        ok = points_feasible(result, pts)
        if ok.all():
            return scale, len(pts), ""
        scale *= 0.98
    reason = (f"verification failed at every scale down to {scale / 0.98:.0%} of the shape: "
              f"{int(np.sum(~ok))} of {len(ok)} points still violate the request there")
    return 0.0, 0, reason


def _status(optimised: bool, scp, verified_reason: str, what: str) -> tuple[str, str]:
    """Status and reason of a shape from its SCP outcome and its verification."""
    if verified_reason:
        return "failed", f"no {what} fits: {verified_reason}"
    if scp is None:
        return "ok", ("the voxel start, verified (the enlargement runs only for constant and "
                      "dexterous workspaces)" if optimised else
                      "the voxel start, verified (optimise=False)")
    x, it, accepted, converged, problem = scp
    if converged:
        return "ok", f"enlarged by {accepted} SCP steps in {it} iterations, converged, verified"
    return "not converged", (f"the SCP enlargement stopped after {it} iterations ({accepted} "
                             f"steps accepted): {problem}; verified, but maybe not the largest")


# ---- starting shapes on the voxel grid ----------------------------------------------------------


def _voxel_box(result):
    """Greedy largest box of occupied voxels grown from the deepest voxel → index bounds."""
    occ = result.occupancy
    dist = ndimage.distance_transform_edt(np.pad(occ, 1))[1:-1, 1:-1, 1:-1]
    start = np.unravel_index(np.argmax(dist), occ.shape)
    lo = np.array(start)
    hi = np.array(start) + 1                 # half-open index box
    cs = np.pad(occ.astype(np.int64), ((1, 0), (1, 0), (1, 0))).cumsum(0).cumsum(1).cumsum(2)

    def full(a, b):
        s = (cs[b[0], b[1], b[2]] - cs[a[0], b[1], b[2]] - cs[b[0], a[1], b[2]]
             - cs[b[0], b[1], a[2]] + cs[a[0], a[1], b[2]] + cs[a[0], b[1], a[2]]
             + cs[b[0], a[1], a[2]] - cs[a[0], a[1], a[2]])
        return s == np.prod(b - a)

    grew = True
    while grew:
        grew = False
        # grow the shortest edges first, so the box stays balanced
        for ax in np.argsort(hi - lo):
            for side in (0, 1):
                a, b = lo.copy(), hi.copy()
                if side == 0 and a[ax] > 0:
                    a[ax] -= 1
                elif side == 1 and b[ax] < occ.shape[ax]:
                    b[ax] += 1
                else:
                    continue
                if full(a, b):
                    lo, hi = a, b
                    grew = True
    return lo, hi


# ---- sequential convex programming -------------------------------------------------------------


def _linearise(mech, pts, R):
    """Actuator values ``(P, M, n)`` and gradients ``(P, M, n, 3)`` at points × orientations
    (``n`` actuators; the first three Jacobian columns are x, y, z for every mobility with x,
    y and z free, spatial or translational)."""
    P, M, n = len(pts), len(R), mech.n_actuators
    p = np.repeat(pts, M, axis=0)
    Rr = np.ascontiguousarray(np.tile(R, (P, 1, 1)))
    q = mech.inverse((p, Rr), stroke=NO_STROKE).q.reshape(P, M, n)
    G = mech.jacobian((p, Rr))[..., :3].reshape(P, M, n, 3)
    return q, G


def _scp(result, x0, points_of, jac_of, objective, lower_bounds, iters=30):
    """Enlarge a shape parametrised by ``x`` (points affine in x) by SCP with line search.

    Every iteration evaluates the actuator values at the shape's lattice points for every
    orientation, keeps for each (orientation, leg) the lattice points with the smallest and
    the largest value, linearises those two with the translational Jacobian and solves the
    convex program for the step ``x' = x + ρ·d`` with ``|d| <= 1`` (the trust region ρ in mm;
    solving for ``d`` keeps the program well scaled); a step is accepted (backtracking on its
    length) only when the true stroke holds at every lattice point. A sub-problem the solver
    cannot solve halves the trust region, as a rejected step does.

    Returns:
        ``(x, iterations, accepted, converged, problem)``: the shape, the iterations run, the
        steps accepted, whether the last step was below 1e-3 mm, and the last solver or
        kinematics problem met ("" if none).
    """
    import cvxpy as cp

    mech = result.mechanism
    R = result.orientations.rotations()
    qlo, qhi = mech.stroke
    x = np.asarray(x0, dtype=float)
    A = jac_of()                                               # (n, 3, nx)
    rho = 0.5 * float(np.max(np.abs(x0[len(x0) // 2:]))) + result.resolution

    def stroke_ok(xc):
        # every status counts (a working-mode side as well as the stroke), not just q's range
        pts = points_of(xc)
        p = np.repeat(pts, len(R), axis=0)
        Rr = np.ascontiguousarray(np.tile(R, (len(pts), 1, 1)))
        return bool(np.all(mech.inverse((p, Rr), stroke=(qlo, qhi)).valid))

    it = accepted = 0
    problem = ""
    converged = False
    for it in range(1, iters + 1):  # noqa: B007
        V = points_of(x)                                       # (n, 3)
        q, G = _linearise(mech, V, R)                          # (n, M, k), (n, M, k, 3)
        if not (np.all(np.isfinite(q)) and np.all(np.isfinite(G))):
            problem = "the inverse kinematics or Jacobian is undefined at a lattice point"
            break
        M = len(R)
        mi, li = np.meshgrid(np.arange(M), np.arange(q.shape[2]), indexing="ij")
        rows, slack = [], []
        for pick, is_low in ((np.argmin(q, axis=0), True), (np.argmax(q, axis=0), False)):
            g = G[pick, mi, li]                                 # (M, k, 3)
            r = np.einsum("mic,micx->mix", g, A[pick]).reshape(-1, len(x))
            qv = q[pick, mi, li].reshape(-1)
            rows.append(r * rho)
            slack.append((qv - qlo) if is_low else (qhi - qv))  # >= 0: x is feasible
        d = cp.Variable(len(x))
        cons = [rows[0] @ d >= -slack[0], rows[1] @ d <= slack[1], cp.abs(d) <= 1.0]
        cons += [x[k] + rho * d[k] >= lb for k, lb in lower_bounds.items()]
        prob = cp.Problem(cp.Maximize(objective(x + rho * d)), cons)
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", UserWarning)   # "may be inaccurate": checked
                prob.solve(solver=cp.CLARABEL)
            status = prob.status
        except cp.SolverError as exc:
            status = f"solver error ({exc})"
        log.debug("SCP iteration %d: %s, trust region %.3g", it, status, rho)
        if d.value is None or status not in ("optimal", "optimal_inaccurate"):
            problem = f"convex sub-problem not solved: {status}"
            rho *= 0.5
            if rho < _RHO_MIN:
                break
            continue
        step = rho * np.asarray(d.value)
        for _ in range(8):                                     # backtracking line search
            if stroke_ok(x + step):
                break
            step *= 0.5
        else:
            problem = "no step along the sub-problem's solution keeps the stroke"
            rho *= 0.5
            if rho < _RHO_MIN:
                break
            continue
        x = x + step
        accepted += 1
        if float(np.max(np.abs(step))) < _RHO_MIN:
            converged = True
            break
    else:
        problem = f"iteration cap ({iters}) reached" + (f", last: {problem}" if problem else "")
    if not converged and not problem:
        problem = "trust region shrank below 1e-3 mm"
    return x, it, accepted, converged, problem


_LAT = np.array([[i, j, k] for i in np.linspace(-0.5, 0.5, 5) for j in np.linspace(-0.5, 0.5, 5)
                 for k in np.linspace(-0.5, 0.5, 5)])


def _box_points(x):
    return x[:3] + _LAT * x[3:]


def _box_jac():
    A = np.zeros((len(_LAT), 3, 6))
    A[:, :, :3] = np.eye(3)
    for v, c in enumerate(_LAT):
        A[v, :, 3:] = np.diag(c)
    return A


def inscribed_box(result, *, samples: int = 20000, seed: int = 0,
                  optimise: bool = True) -> InscribedBox:
    """Largest axis-aligned box (by volume) inside ``result``'s workspace, verified.

    Args:
        samples: uniform random points checked inside the final box (plus its 26 vertices,
            edge and face centres).
        seed: seed of the verification sample.
        optimise: run the SCP enlargement (otherwise the voxel start, verified).

    Returns:
        :class:`InscribedBox` with its ``status`` and ``reason`` (module docstring): an empty
        workspace or a box that verification shrinks away is reported, not raised.
    """
    import cvxpy as cp

    if result.empty:
        nan = np.full(3, np.nan)
        return InscribedBox(nan, nan, 0, 0, 0.0, "empty", "the workspace is empty: no box fits")
    h = result.resolution
    i0, i1 = _voxel_box(result)
    lower = np.array([result.xs[i0[0]], result.ys[i0[1]], result.zs[i0[2]]])
    upper = np.array([result.xs[i1[0] - 1], result.ys[i1[1] - 1], result.zs[i1[2] - 1]])
    size = np.maximum(upper - lower, 1e-3 * h)
    x = np.concatenate([0.5 * (lower + upper), size])
    scp = None
    if optimise and result.kind != "reachable":
        scp = _scp(result, x, _box_points, _box_jac, lambda v: cp.sum(cp.log(v[3:])),
                   {3: 1e-3, 4: 1e-3, 5: 1e-3})
        x = scp[0]
    it = 0 if scp is None else scp[1]
    c, s = x[:3], x[3:]
    grid = np.array([[i, j, k] for i in (-0.5, 0, 0.5) for j in (-0.5, 0, 0.5)
                     for k in (-0.5, 0, 0.5)])

    def pts(scale, n, sd):
        rng = np.random.default_rng(sd)
        return np.vstack([c + grid * s * scale, c + (rng.random((n, 3)) - 0.5) * s * scale])

    scale, checked, failed = _verify(result, pts, seed, samples)
    status, reason = _status(optimise, scp, failed, "box")
    if status == "failed":
        log.warning("inscribed box: %s", reason)
    s = s * scale
    return InscribedBox(c - s / 2, c + s / 2, checked, it, scale, status, reason)


def inscribed_cylinder(result, *, samples: int = 20000, seed: int = 0,
                       optimise: bool = True) -> InscribedCylinder:
    """Largest vertical cylinder (by volume) inside ``result``'s workspace, verified.

    Arguments as :func:`inscribed_box`; returns :class:`InscribedCylinder` with its
    ``status`` and ``reason``.
    """
    import cvxpy as cp

    if result.empty:
        return InscribedCylinder(np.full(2, np.nan), 0.0, (math.nan, math.nan), 0, 0, 0.0,
                                 "empty", "the workspace is empty: no cylinder fits")
    box = inscribed_box(result, samples=2000, seed=seed, optimise=False)
    c = box.centre
    r0 = 0.5 * min(box.size[0], box.size[1])
    x = np.array([c[0], c[1], r0, box.lower[2], box.upper[2]])
    ang = 2 * np.pi * np.arange(_POLY) / _POLY
    # lattice: rings at 0, 1/2 and 1 of the radius (16 points each) on 5 levels
    rings = np.vstack([[[0.0, 0.0]]] + [f * np.stack([np.cos(ang), np.sin(ang)], axis=1)
                                        for f in (0.5, 1.0)])
    levels = np.linspace(0.0, 1.0, 5)
    lat = np.array([[u, v, w] for w in levels for u, v in rings])

    def lattice(v):
        return np.column_stack([v[0] + v[2] * lat[:, 0], v[1] + v[2] * lat[:, 1],
                                v[3] + (v[4] - v[3]) * lat[:, 2]])

    def jac():
        A = np.zeros((len(lat), 3, 5))
        A[:, 0, 0] = 1.0
        A[:, 1, 1] = 1.0
        A[:, 0, 2] = lat[:, 0]
        A[:, 1, 2] = lat[:, 1]
        A[:, 2, 3] = 1.0 - lat[:, 2]
        A[:, 2, 4] = lat[:, 2]
        return A

    scp = None
    if optimise and result.kind != "reachable":
        scp = _scp(result, x, lattice, jac, lambda v: 2 * cp.log(v[2]) + cp.log(v[4] - v[3]),
                   {2: 1e-3})
        x = scp[0]
    it = 0 if scp is None else scp[1]
    cx, cy, r, z0, z1 = x
    zc, hz = 0.5 * (z0 + z1), 0.5 * (z1 - z0)

    def pts(scale, n, sd):
        rng = np.random.default_rng(sd)
        rim = np.stack([np.cos(ang), np.sin(ang)], axis=1) * r * scale
        edge = [np.column_stack([cx + rim[:, 0], cy + rim[:, 1], np.full(_POLY, z)])
                for z in (zc - hz * scale, zc, zc + hz * scale)]
        rr = r * scale * np.sqrt(rng.random(n))
        t = 2 * np.pi * rng.random(n)
        z = zc + hz * scale * (2 * rng.random(n) - 1)
        body = np.column_stack([cx + rr * np.cos(t), cy + rr * np.sin(t), z])
        axis = np.column_stack([np.full(3, cx), np.full(3, cy), [zc - hz * scale, zc,
                                                                 zc + hz * scale]])
        return np.vstack(edge + [body, axis])

    scale, checked, failed = _verify(result, pts, seed, samples)
    status, reason = _status(optimise, scp, failed, "cylinder")
    if status == "failed":
        log.warning("inscribed cylinder: %s", reason)
    return InscribedCylinder(np.array([cx, cy]), float(r * scale),
                             (float(zc - hz * scale), float(zc + hz * scale)), checked, it,
                             scale, status, reason)
