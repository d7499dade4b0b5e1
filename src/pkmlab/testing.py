"""The mechanism contract suite, as plain functions a family's own tests (or a plugin's) can run.

Every check takes a :class:`~pkmlab.mechanisms.Mechanism` and raises ``AssertionError`` naming
what failed; :func:`run_contract` runs them all and returns the names of the checks that passed.
They use only the public protocol (``inverse``, ``jacobian``, ``forward``, ``assembly_modes``,
``stroke``, ``nominal_pose``, ``actuator_unit``, ``actuator_names``, ``mobility``) and size
themselves from the mechanism's declaration: poses move in its free coordinates only, the
Jacobian is checked on its free twist columns, actuator vectors have ``n_actuators`` values::

    from pkmlab.testing import run_contract
    run_contract(MyFamily(...))

The checks:

* :func:`check_declaration` — the inverse kinematics writes one value per declared actuator
  (the drivers fill the leg buffers with a sentinel first, so a kernel writing fewer or more
  legs raises), the Jacobian is ``(N, actuators, free coordinates)``, and there are at least
  as many actuators as free coordinates;
* :func:`check_round_trip` — IK → FK of poses near nominal recovers the pose to 1e-9;
* :func:`check_jacobian` — the analytic Jacobian against Richardson-extrapolated central
  differences of the inverse kinematics (error O(h⁴), so the tolerance can be tight);
* :func:`check_batching` — a pose's results do not depend on the batch it is part of, and
  transform / Euler inputs agree;
* :func:`check_statuses` — stroke violations are flagged with their reason and finite values,
  non-finite poses are flagged, forward kinematics reports failure as data (NaN and a status);
* :func:`check_assembly_modes` — the nominal pose is the first mode and doubling the starts finds
  nothing new;
* :func:`check_bad_shapes` — malformed pose arrays raise a named error;
* :func:`check_joints` — each leg's joint chain (``legs``) closes at random valid poses, its
  actuated joint's coordinate is the IK's value, its axes are unit (U: orthogonal), and
  ``leg_segments`` read the same joints;
* :func:`check_parameters` — ``with_parameters(parameters().values)`` equals the mechanism.

:func:`cell_points` draws test points inside position × orientation cells, for checking a
family's cell bounds (``leg_cell_bounds``, ``leg_cell_margins``) against its kinematics;
:func:`check_columns` checks a family's exact columns (``column_intervals``) against its IK,
and :func:`random_sixleg` draws a ``sixleg`` machine of given leg kinds around a valid nominal
pose, for property tests.
"""

from __future__ import annotations

import numpy as np

from .mechanisms import LEG_STATUS, NO_STROKE
from .poses import POSE_SIZE, as_frames, euler_to_matrix, exp_so3, log_so3

__all__ = ["random_valid_poses", "rotation_error", "check_declaration", "check_round_trip",
           "check_jacobian",
           "check_batching", "check_statuses", "check_assembly_modes", "check_bad_shapes",
           "check_joints", "check_parameters",
           "CHECKS", "run_contract", "cell_points", "check_columns", "random_sixleg"]

REASON = {v: k for k, v in LEG_STATUS.items()}


def _moves(mech) -> np.ndarray:
    """``(6,)`` 1 for the pose coordinates the mechanism's mobility frees, else 0."""
    m = np.zeros(POSE_SIZE)
    m[mech.mobility.index] = 1.0
    return m


def random_valid_poses(mech, n: int, seed: int, lin: float = 25.0, ang_deg: float = 10.0):
    """``n`` poses near the nominal pose (±``lin`` mm, ±``ang_deg`` deg in the free
    coordinates) whose inverse kinematics is valid; six coordinates each (a mobility with
    dependent coordinates: completed by ``mech.complete``)."""
    rng = np.random.default_rng(seed)
    out, total = [], 0
    for _ in range(200):
        X = mech.nominal_pose + _moves(mech) * np.concatenate(
            [rng.uniform(-lin, lin, (4 * n, 3)),
             np.radians(rng.uniform(-ang_deg, ang_deg, (4 * n, 3)))], axis=1)
        if getattr(mech.mobility, "dependent", ()):
            X = mech.complete(X)
        out.append(X[mech.inverse(X).valid])
        total += len(out[-1])
        if total >= n:
            return np.concatenate(out)[:n]
    raise AssertionError(f"fewer than {n} valid poses near the nominal pose")


def rotation_error(X1, X2):
    """Angle (rad) between the orientations of Euler poses ``X1`` and ``X2`` ``(N, 6)``."""
    R1, R2 = euler_to_matrix(X1[:, 3:]), euler_to_matrix(X2[:, 3:])
    return np.linalg.norm(log_so3(np.einsum("nji,njk->nik", R1, R2)), axis=1)


def check_declaration(mech):
    L, mob = mech.n_actuators, mech.mobility
    assert L == len(set(mech.actuator_names)), "actuator names must be distinct"
    assert L >= mob.width, (f"{L} actuators cannot drive the {mob.width} free coordinates "
                            f"({', '.join(mob.coordinates)})")
    X = random_valid_poses(mech, 8, seed=0)
    ik = mech.inverse(X)                       # raises if the kernel wrote another leg count
    assert ik.q.shape == (8, L) and ik.leg_status.shape == (8, L), ik.q.shape
    assert np.array_equal(mech.inverse(mob.free(X)).q, ik.q), "free-coordinate poses differ"
    assert mech.jacobian(X).shape == (8, L, mob.width), mech.jacobian(X).shape
    assert mech.actuator_limits.shape == (L, 2)


def check_round_trip(mech, n: int = 1000, tol: float = 1e-9):
    X = random_valid_poses(mech, n, seed=1)
    q = mech.inverse(X).q
    fk = mech.forward(q)                       # starts from the nominal pose
    assert fk.converged.all(), f"{(~fk.converged).sum()} of {n} did not converge"
    err = np.max(np.abs(fk.pose[:, :3] - X[:, :3]))
    assert err < tol, f"round trip position error {err:.3g} mm"
    err = np.max(rotation_error(fk.pose, X))
    assert err < tol, f"round trip rotation error {err:.3g} rad"
    assert np.max(fk.residual) < tol, f"FK residual {np.max(fk.residual):.3g} mm"


def _central(mech, p, R, h):
    """Central differences of the IK along the free twist components ``(N, L, width)``."""
    cols = mech.mobility.twist_columns
    out = np.empty((len(p), mech.n_actuators, len(cols)))
    for c, j in enumerate(cols):
        d = np.zeros(POSE_SIZE)
        d[j] = h
        if j < 3:
            qp = mech.inverse((p + d[:3], R), stroke=NO_STROKE).q
            qm = mech.inverse((p - d[:3], R), stroke=NO_STROKE).q
        else:
            qp = mech.inverse((p, exp_so3(d[3:]) @ R), stroke=NO_STROKE).q
            qm = mech.inverse((p, exp_so3(-d[3:]) @ R), stroke=NO_STROKE).q
        out[:, :, c] = (qp - qm) / (2 * h)
    return out


def check_jacobian(mech, n: int = 40, h: float = 1e-4, tol: float = 1e-7):
    """Analytic J against ``(4·D(h/2) - D(h))/3`` (D central differences with step h mm / rad),
    relative to each pose's largest entry, translation and rotation columns separately."""
    X = random_valid_poses(mech, n, seed=2)
    p, R = as_frames(X)
    J = mech.jacobian(X)
    Jfd = (4.0 * _central(mech, p, R, h / 2) - _central(mech, p, R, h)) / 3.0
    free = mech.mobility.twist_columns
    for group, what in ((free < 3, "translation"), (free >= 3, "rotation")):
        if not group.any():
            continue
        cols = np.flatnonzero(group)
        scale = np.max(np.abs(J[:, :, cols]), axis=(1, 2), keepdims=True)
        rel = np.abs(J[:, :, cols] - Jfd[:, :, cols]) / scale
        assert rel.max() < tol, f"Jacobian {what} columns differ from finite differences " \
                                f"by {rel.max():.3g} (relative)"


def check_batching(mech):
    X = random_valid_poses(mech, 12, seed=3)
    ik = mech.inverse(X)
    J = mech.jacobian(X)
    fk = mech.forward(ik.q)
    for i in range(len(X)):
        one = mech.inverse(X[i])
        np.testing.assert_array_equal(one.q[0], ik.q[i])
        np.testing.assert_array_equal(one.leg_status[0], ik.leg_status[i])
        np.testing.assert_array_equal(mech.jacobian(X[i])[0], J[i])
        np.testing.assert_allclose(mech.forward(ik.q[i]).pose[0], fk.pose[i], atol=1e-12)
    X = random_valid_poses(mech, 20, seed=4)
    T = np.zeros((20, 4, 4))
    T[:, :3, :3] = euler_to_matrix(X[:, 3:])
    T[:, :3, 3] = X[:, :3]
    T[:, 3, 3] = 1.0
    np.testing.assert_allclose(mech.inverse(T).q, mech.inverse(X).q, atol=1e-10)
    np.testing.assert_allclose(mech.jacobian(T), mech.jacobian(X), atol=1e-10)


def check_statuses(mech):
    # Windows entirely below / above the nominal actuator values flag every leg.
    X = np.repeat(mech.nominal_pose[None], 2, axis=0)
    q = mech.inverse(X[:1]).q[0]
    lo, hi = float(np.min(q)), float(np.max(q))
    span = mech.stroke[1] - mech.stroke[0]
    above = mech.inverse(X[:1], stroke=(lo - span, lo - 0.01 * span))
    below = mech.inverse(X[:1], stroke=(hi + 0.01 * span, hi + span))
    assert not above.valid[0] and above.reason_text[0] == "stroke above maximum"
    assert np.all(above.leg_status[0] == REASON["stroke above maximum"])
    assert not below.valid[0] and below.reason_text[0] == "stroke below minimum"
    # Values outside the window are still reported (not NaN): they are the geometry's answer.
    assert np.all(np.isfinite(above.q)) and np.all(np.isfinite(below.q))
    # Non-finite poses.
    X[1, 4] = np.nan
    ik = mech.inverse(X)
    assert ik.valid.tolist() == [True, False]
    assert ik.reason_text[1] == "non-finite pose"
    assert np.all(ik.leg_status[1] == REASON["non-finite pose"])
    # Far and wide poses: NaN exactly where there is no real solution; valid means finite.
    rng = np.random.default_rng(5)
    W = mech.nominal_pose + _moves(mech) * np.concatenate(
        [rng.uniform(-2, 2, (500, 3)) * mech.scale, rng.uniform(-np.pi, np.pi, (500, 3))],
        axis=1)
    ik = mech.inverse(W, stroke=NO_STROKE)
    nan_ok = np.isin(ik.leg_status, [REASON["no real solution"], REASON["degenerate leg "
                                                                        "geometry"]])
    assert np.array_equal(np.isnan(ik.q), nan_ok), "NaN actuator values without a status"
    assert np.all(np.isfinite(ik.q[ik.valid])), "a valid pose with a NaN actuator value"
    # Forward kinematics reports failure as data. Adjacent actuators at 1 and 5000 (mm: the
    # triangle inequality; rad: outside (-π, π], no inverse gives it) close no working loop.
    impossible = np.resize([1.0, 5000.0], mech.n_actuators)
    fk = mech.forward(np.array([q, impossible, np.full(mech.n_actuators, np.nan)]))
    assert fk.converged.tolist() == [True, False, False], fk.status
    assert np.all(np.isnan(fk.pose[1:]))
    assert all(s in ("not converged", "singular") for s in fk.status[1:])


def check_assembly_modes(mech):
    q = mech.inverse(mech.nominal_pose).q[0]
    a = mech.assembly_modes(q, starts=1000, seed=0)
    b = mech.assembly_modes(q, starts=2000, seed=1)
    assert np.allclose(a.pose[0], mech.nominal_pose, atol=1e-8), "nominal pose not first"
    assert a.working_mode[0]
    assert np.all(a.residual < 1e-9)
    assert len(a.residual) == len(b.residual), (len(a.residual), len(b.residual))
    for X in b.pose:       # every mode of the larger search is in the smaller one
        d = np.abs(a.pose[:, :3] - X[:3]).max(axis=1) + rotation_error(
            a.pose, np.repeat(X[None], len(a.pose), 0))
        assert d.min() < 1e-6
    # Each working-mode solution really closes the loops: its IK is consistent with q.
    for X in a.pose[a.working_mode]:
        np.testing.assert_allclose(mech.inverse(X).q[0], q, atol=1e-7)


def check_bad_shapes(mech):
    for shape in ((5,), (3, 5), (2, 3, 3)):
        try:
            mech.jacobian(np.zeros(shape))
        except ValueError as exc:
            assert "poses: must be an array of shape" in str(exc), str(exc)
        else:
            raise AssertionError(f"a pose array of shape {shape} was accepted")


def check_joints(mech, n: int = 12, rel: float = 1e-9):
    """The joint chains (``legs``, :mod:`pkmlab.mechanisms.joints`) close at the nominal pose
    and ``n`` random valid ones: consecutive joints are the declared link lengths apart, the
    last joint is the platform point moved by the pose, the first a base point, each actuated
    joint's coordinate (from the joint locations alone) is the IK's actuator value, R/P/U axes
    are unit and U axes orthogonal; to ``rel``·scale mm (``rel`` rad, unitless). And
    ``leg_segments`` are the legs' ``segment`` joint centres."""
    from .mechanisms.joints import chain_errors

    try:
        mech.legs()
    except NotImplementedError as exc:
        raise AssertionError(str(exc)) from exc
    X = np.concatenate([mech.nominal_pose[None], random_valid_poses(mech, n, seed=6)])
    mm = rel * mech.scale
    tol = {"link_mm": mm, "platform_mm": mm, "platform_point_mm": mm, "base_mm": mm,
           "p_direction": mm, "coordinate": mm if mech.actuator_unit == "mm" else rel,
           "axis_norm": rel, "u_orthogonal": rel, "r_reference": rel}
    start, end = mech.leg_segments(*as_frames(X))
    for k, x in enumerate(X):
        for key, value in chain_errors(mech, x).items():
            assert value <= tol[key], f"joints at pose {x.tolist()}: {key} off by {value:.3g}"
        for i, leg in enumerate(mech.legs(x)):
            a, b = leg.segment
            d = max(np.abs(start[k, i] - leg.joints[a].location).max(),
                    np.abs(end[k, i] - leg.joints[b].location).max())
            assert d <= mm, f"leg_segments of {leg.name} differ from its joints by {d:.3g} mm"


def check_parameters(mech):
    """The parameter vector round-trips (``with_parameters(parameters().values)`` equals the
    mechanism), names are distinct, units known, and a changed length is applied as given."""
    P = mech.parameters()
    assert len(set(P.names)) == len(P) == len(P.values) == len(P.units) == len(P.descriptions)
    assert set(P.units) <= {"mm", "rad", "1"}, set(P.units)
    assert np.all(np.isfinite(P.values))
    assert mech.with_parameters(P.values) == mech, "with_parameters(parameters()) differs"
    k = P.units.index("mm")
    m2 = mech.with_parameters({P.names[k]: P.values[k] + 1e-3 * mech.scale})
    assert type(m2) is type(mech) and m2 != mech
    assert m2.parameters().values[k] == P.values[k] + 1e-3 * mech.scale, P.names[k]


#: name → check, in the order :func:`run_contract` runs them
CHECKS = {"declaration": check_declaration, "round_trip": check_round_trip,
          "jacobian": check_jacobian,
          "batching": check_batching, "statuses": check_statuses,
          "assembly_modes": check_assembly_modes, "bad_shapes": check_bad_shapes,
          "joints": check_joints, "parameters": check_parameters}


def run_contract(mech, skip: tuple[str, ...] = ()) -> list[str]:
    """Run every check of :data:`CHECKS` (except ``skip``) on ``mech``; returns their names.

    Raises the first check's ``AssertionError``, prefixed with the check's name.
    """
    done = []
    for name, check in CHECKS.items():
        if name in skip:
            continue
        try:
            check(mech)
        except AssertionError as exc:
            raise AssertionError(f"{name}: {exc}") from exc
        done.append(name)
    return done


def cell_points(rng, p, R, delta, alpha, *, ball: bool = False):
    """A random point of each cell ``|p' - p| <= delta``, ``angle(R'·Rᵀ) <= alpha`` (``p (N, 3)``
    mm, ``R (N, 3, 3)``, ``delta`` and ``alpha (N,)`` mm and rad): half of them on the cell's
    boundary (the distance and the angle both at their ends), the others inside, with the
    distance uniform in ``[0, δ]`` (``ball``: the point uniform in the ball). Returns
    ``(p', R', p' - p)``."""
    n = len(p)
    u = rng.normal(size=(n, 3))
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    ax = rng.normal(size=(n, 3))
    ax /= np.linalg.norm(ax, axis=1, keepdims=True)
    edge = rng.uniform(size=n) < 0.5
    r = rng.uniform(size=n)
    dp = u * (np.where(edge, 1.0, r ** (1 / 3) if ball else r) * delta)[:, None]
    ang = np.where(edge, 1.0, rng.uniform(size=n)) * alpha
    return p + dp, exp_so3(ax * ang[:, None]) @ R, dp


def check_columns(mech, R, xs, ys, mode: str = "all", dz: float = 0.1,
                  eps: float = 1e-9) -> int:
    """The exact columns of ``mech`` (``column_intervals`` over ``xs × ys``, orientations ``R
    (M, 3, 3)``, ``mode`` "all" or "any") against its own per-pose IK; returns the number of
    pieces checked.

    Per column, the z set where the IK is valid at every (``"all"``) or some (``"any"``)
    orientation, on a grid of step ``dz`` mm over the position bounds (``position_bounds``,
    widened 1 mm), has the intervals' total length to ``2·dz`` per piece (none: no valid grid
    point); every end lies inside the grid, and the IK holds ``eps`` mm inside each end and
    fails ``eps`` mm outside it."""
    agg = np.all if mode == "all" else np.any
    lo, hi, over = mech.column_intervals(np.asarray(xs, float), np.asarray(ys, float), R, mode)
    assert over == 0, f"{over} columns overflowed"
    zb = mech.position_bounds(R)[:, :, 2]
    zs = np.arange(zb[:, 0].min() - 1.0, zb[:, 1].max() + 1.0, dz)
    M = len(R)

    def valid(x, y, z):
        p = np.column_stack([np.full(len(z), x), np.full(len(z), y), z])
        v = mech.inverse((np.repeat(p, M, axis=0), np.tile(R, (len(z), 1, 1)))).valid
        return agg(v.reshape(len(z), M), axis=1)

    pieces = 0
    for ix, iy in np.ndindex(len(xs), len(ys)):
        sel = lo[ix, iy] <= hi[ix, iy]
        a, b = lo[ix, iy][sel], hi[ix, iy][sel]
        where = f"column ({xs[ix]:.6g}, {ys[iy]:.6g}) mm, intervals {list(zip(a, b))}"
        assert np.all(a > zs[0]) and np.all(b < zs[-1]), f"{where}: outside the z grid"
        ik = valid(xs[ix], ys[iy], zs).sum() * dz
        assert abs(ik - np.sum(b - a)) <= 2 * len(a) * dz + 1e-9, \
            f"{where}: length {np.sum(b - a):.6g} mm, IK on a {dz} mm grid {ik:.6g} mm"
        for a_k, b_k in zip(a, b, strict=True):
            inside = valid(xs[ix], ys[iy], np.array([a_k + eps, b_k - eps]))
            outside = valid(xs[ix], ys[iy], np.array([a_k - eps, b_k + eps]))
            assert inside.all() and not outside.any(), \
                f"{where}: IK {eps} mm inside {inside}, outside {outside} at [{a_k}, {b_k}]"
        pieces += len(a)
    return pieces


def _unit(v):
    v = np.asarray(v, dtype=float)
    return v / np.linalg.norm(v, axis=-1, keepdims=True)


def random_sixleg(rng, kinds, lower: str, rails: str = "any", tries: int = 50):
    """A random ``sixleg`` machine (:class:`~pkmlab.mechanisms.SixLeg`) whose leg ``i`` has
    the kind ``kinds[i]`` (``"prismatic"``, ``"slider"`` or ``"crank"``; cranks with no other
    kind), built around a nominal pose at which every leg is valid.

    The shared window's lower limit is ``lower``: ``"negative"``, ``"zero"`` or ``"positive"``
    (mm; rad for cranks). Each leg takes, at the nominal pose, an actuator value in the middle
    half of its feasible window (a prismatic leg: lengths ``[max(min, 0), max]``), a random
    leg (link, rod) direction pointing up from the base side, and a random rail or servo axis.
    ``rails``: ``"vertical"`` (±z exactly), ``"inclined"`` (10°-80° above the horizontal),
    ``"horizontal"`` or ``"any"`` (one of the three per slider). Prismatic legs hang below
    their base joint (working side -1) with probability 1/4."""
    from .mechanisms.families.sixleg import SixLeg

    kinds = list(kinds)
    crank = kinds[0] == "crank"
    for _ in range(tries):
        if crank:
            lo = {"negative": -rng.uniform(0.3, 1.2), "zero": 0.0,
                  "positive": rng.uniform(0.1, 0.8)}[lower]
            hi = min(lo + rng.uniform(1.0, 2.0), np.pi)
        else:
            lo = {"negative": -rng.uniform(50.0, 400.0), "zero": 0.0,
                  "positive": rng.uniform(50.0, 250.0)}[lower]
            hi = lo + rng.uniform(300.0, 700.0)
        X0 = np.concatenate([rng.uniform(-20, 20, 2), [rng.uniform(200, 500)],
                             np.radians(rng.uniform(-5, 5, 3))])
        ang = np.arange(6) * np.pi / 3 + rng.uniform(-0.3, 0.3, 6)
        radial = np.column_stack([np.cos(ang), np.sin(ang), np.zeros(6)])
        P = radial * rng.uniform(60.0, 200.0, (6, 1))
        W = X0[:3] + P @ euler_to_matrix(X0[3:]).T
        B, axes, zero = np.zeros((6, 3)), np.zeros((6, 3)), np.zeros((6, 3))
        crank_len, link, branch = np.zeros(6), np.zeros(6), -np.ones(6)
        for i, kind in enumerate(kinds):
            qlo = max(lo, 0.0) if kind == "prismatic" else lo
            q = qlo + rng.uniform(0.25, 0.75) * (hi - qlo)
            tilt = rng.uniform(0.1, 1.1)              # leg direction: up, leaning inwards
            az = ang[i] + np.pi + rng.uniform(-0.8, 0.8)
            d = np.array([np.sin(tilt) * np.cos(az), np.sin(tilt) * np.sin(az), np.cos(tilt)])
            if kind == "prismatic":
                if rng.random() < 0.25:
                    d[2] = -d[2]
                B[i] = W[i] - q * d
            elif kind == "slider":
                style = rng.choice(["vertical", "inclined", "horizontal"]) if rails == "any" \
                    else rails
                elev = {"vertical": np.pi / 2, "horizontal": 0.0}.get(
                    style, rng.uniform(np.radians(10), np.radians(80)))
                head = rng.uniform(0, 2 * np.pi)
                e = np.array([np.cos(elev) * np.cos(head), np.cos(elev) * np.sin(head),
                              np.sin(elev)]) * rng.choice([-1.0, 1.0])
                if style == "vertical":
                    e = np.array([0.0, 0.0, e[2] / abs(e[2])])
                if abs(d @ e) < 0.2:                  # far from the serial singularity
                    d = _unit(d + 0.5 * np.sign(d @ e or 1.0) * e)
                link[i] = rng.uniform(150.0, 400.0)
                branch[i] = -np.sign(d @ e)
                axes[i] = e
                B[i] = W[i] - link[i] * d - q * e
            else:
                n = _unit(rng.normal(size=3))
                u = _unit(np.cross(n, rng.normal(size=3)))
                v = np.cross(n, u)
                crank_len[i], link[i] = rng.uniform(20.0, 80.0), rng.uniform(150.0, 350.0)
                C = crank_len[i] * (np.cos(q) * u + np.sin(q) * v)
                B[i] = W[i] - link[i] * d - C
                axes[i], zero[i] = n, u
                # the branch whose closed form gives back q
                dd = W[i] - B[i]
                E, F = 2 * crank_len[i] * dd @ u, 2 * crank_len[i] * dd @ v
                G = dd @ dd + crank_len[i] ** 2 - link[i] ** 2
                h = np.sqrt(max(E * E + F * F - G * G, 0.0))
                branch[i] = min((1.0, -1.0), key=lambda b: abs(np.angle(np.exp(1j * (
                    np.arctan2(F * G + b * E * h, E * G - b * F * h) - q)))))
        m = SixLeg(B, P, kinds, axes, zero, crank_len, link, (lo, hi), branch, nominal=X0,
                   name=f"random-{'-'.join(k[0] for k in kinds)}-{lower}")
        if m.inverse(X0[None]).valid[0]:
            return m
    raise AssertionError(f"no valid random sixleg with legs {kinds} in {tries} tries")
