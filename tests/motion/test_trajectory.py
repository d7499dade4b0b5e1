"""Trajectory generation, CSV input and the stroke / speed / force check (pkmlab.motion)."""

from __future__ import annotations

import json
import math
from dataclasses import dataclass

import numpy as np
import pytest
from conftest import MECH_DIR

import pkmlab
from pkmlab import PSU6, ParameterError
from pkmlab import dexterity as dx
from pkmlab.motion import (
    PAPER_AXES,
    check_trajectory,
    load_motion_csv,
    lobe_profile,
    paper_motion,
    paper_motion_phases,
    plot_actuators,
)
from pkmlab.poses import as_frames, exp_so3

HOPKINS = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
A_MM, A_RAD = 50.8, math.radians(30.0)


def symmetric_psu() -> PSU6:
    """A 6-PSU with D3 symmetry (three-fold plus mirror about the y axis), tool at the joints.

    Base pairs at 90° + 120°k ± 20° (r = 150 mm), platform pairs at 90° + 120°k ± 40°
    (r = 75 mm); the mirror x → −x maps every leg onto its pair partner.
    """
    k = np.repeat(np.arange(3), 2)
    sign = np.tile([-1.0, 1.0], 3)

    def ring(r, ang):
        return np.stack([r * np.cos(ang), r * np.sin(ang), np.zeros(6)], axis=1)

    B = ring(150.0, np.radians(90 + 120 * k + 20 * sign))
    P = ring(75.0, np.radians(90 + 120 * k + 40 * sign))
    return PSU6(B, P, 225.0, (0.0, 101.6), (0.0, 0.0, 0.0), name="d3-symmetric")


# ---------------------------------------------------------------------------------------------
# generator


def test_lobe_profile_shape():
    seg = 0.7
    tk = seg * np.arange(5)
    assert lobe_profile(tk, 3.0, seg) == pytest.approx([0, 3, 0, -3, 0], abs=1e-15)
    # zero slope at every knot, peak speed 1.5·A/seg mid-leg
    h = 1e-6
    slope = (lobe_profile(tk[1:4] + h, 3.0, seg) - lobe_profile(tk[1:4] - h, 3.0, seg)) / (2 * h)
    assert np.all(np.abs(slope) < 1e-4)
    mid = seg * 0.5
    v = (lobe_profile(mid + h, 3.0, seg) - lobe_profile(mid - h, 3.0, seg)) / (2 * h)
    assert v == pytest.approx(1.5 * 3.0 / seg, rel=1e-8)
    # cubic: 3τ² − 2τ³ at τ = 0.25 on the first leg
    assert lobe_profile(0.25 * seg, 3.0, seg) == pytest.approx(3.0 * (3 / 16 - 2 / 64))


@pytest.mark.parametrize("segment_time, dwell, rate", [(1.0, 1.0, 100.0), (0.5, 0.3, 7.0),
                                                       (0.8, 0.0, 33.0)])
def test_paper_motion_axes_in_order_and_exact_peaks(segment_time, dwell, rate):
    motion = paper_motion(HOPKINS, segment_time=segment_time, dwell=dwell, rate_hz=rate)
    t, X = motion.t, motion.poses
    nominal = HOPKINS.nominal_pose
    assert t.shape == (len(X),) and X.shape[1] == 6
    assert t[0] == 0.0 and np.all(np.diff(t) > 0)
    assert t[-1] == pytest.approx(24 * segment_time + 7 * dwell)
    assert np.diff(t).max() <= 1.0 / rate + 1e-12
    # starts and ends at nominal at rest
    np.testing.assert_allclose(X[0], nominal, atol=1e-12)
    np.testing.assert_allclose(X[-1], nominal, atol=1e-12)
    # zero velocity at both ends: the first / last step grows like h² (s(τ) <= 3τ²), not like
    # h as a non-zero end velocity would give; with a dwell it is exactly zero
    amp6 = np.where(np.arange(6) < 3, A_MM, A_RAD)
    for a, b in ((0, 1), (-1, -2)):
        h = abs(t[b] - t[a])
        step = np.abs(X[b] - X[a])
        assert np.all(step <= 3 * amp6 * (h / segment_time) ** 2 + 1e-12)
        if dwell > 0:
            assert step.max() == 0.0
    phases = paper_motion_phases(segment_time, dwell)
    assert [p[0] for p in phases] == [name for name, _ in PAPER_AXES]
    peak_times = []
    for (name, t0, t1), (_, idx) in zip(phases, PAPER_AXES):
        amp = A_RAD if name.startswith("theta") else A_MM
        inside = (t >= t0) & (t <= t1)
        dev = X[inside] - nominal
        others = np.delete(np.arange(6), idx)
        assert np.abs(dev[:, others]).max() == 0.0, name          # one axis at a time
        # exactly ±A, at the knot samples t0 + seg and t0 + 3·seg
        assert dev[:, idx].max() == pytest.approx(amp, abs=1e-12)
        assert dev[:, idx].min() == pytest.approx(-amp, abs=1e-12)
        k_max = np.argmax(dev[:, idx])
        k_min = np.argmin(dev[:, idx])
        assert t[inside][k_max] == pytest.approx(t0 + segment_time)
        assert t[inside][k_min] == pytest.approx(t0 + 3 * segment_time)
        peak_times.append(t[inside][k_max])
        # outside the phase this axis sits at nominal
        assert np.abs(X[~inside, idx] - nominal[idx]).max() == 0.0
    assert peak_times == sorted(peak_times)
    # position is continuous: no step larger than the peak speed allows
    h = np.diff(t)[:, None]
    step = np.abs(np.diff(X, axis=0))
    bound = np.where(np.arange(6) < 3, 1.5 * A_MM, 1.5 * A_RAD) / segment_time * h
    assert np.all(step <= bound * (1 + 1e-9) + 1e-12)


def test_paper_motion_bad_parameters():
    for kw in ({"segment_time": 0.0}, {"dwell": -1.0}, {"rate_hz": 0.0},
               {"amplitude_mm": math.nan}):
        with pytest.raises(ParameterError) as exc:
            paper_motion(HOPKINS, **kw)
        assert exc.value.field == next(iter(kw))


# ---------------------------------------------------------------------------------------------
# the paper's motion on the Hopkins & Williams geometry


@pytest.fixture(scope="module")
def paper_report():
    motion = paper_motion(HOPKINS)
    t, X = motion.t, motion.poses
    return check_trajectory(HOPKINS, t, X, payload_mass_kg=1.0)


def test_paper_motion_report_matches_independent_inverse(paper_report):
    rep = paper_report
    # one pose at a time (each call ~ms, so every 8th sample, every sample the report flags
    # and every sample where a margin is attained)
    picks = np.unique(np.concatenate([np.arange(0, len(rep.t), 8), np.flatnonzero(~rep.ok),
                                      rep.margin_low_index, rep.margin_high_index]))
    valid = np.empty(len(picks), dtype=bool)
    q = np.empty((len(picks), 6))
    lo, hi = HOPKINS.stroke
    for j, k in enumerate(picks):
        r = HOPKINS.inverse(rep.poses[k])
        # the report allows 1e-9 mm of round-off outside the window (stroke_tolerance)
        valid[j] = bool(np.all(np.isfinite(r.q[0])) and np.all(r.q[0] >= lo - 1e-9)
                        and np.all(r.q[0] <= hi + 1e-9))
        q[j] = r.q[0]
    np.testing.assert_array_equal(rep.ik_valid[picks], valid)
    np.testing.assert_array_equal(rep.q[picks], q)
    # the whole trajectory against the (N, 4, 4) frame path of the inverse kinematics
    p, R = as_frames(rep.poses)
    np.testing.assert_allclose(_q_of_frames(HOPKINS, p, R), rep.q, atol=1e-9)
    assert rep.fits == bool(rep.ik_valid.all())                 # no speed / force limits given
    assert (rep.violations["stroke"] is None) == bool(rep.ik_valid.all())
    if not rep.ik_valid.all():
        k = int(np.flatnonzero(~rep.ik_valid)[0])
        assert rep.violations["stroke"].index == k
        assert rep.violations["stroke"].reason == HOPKINS.inverse(rep.poses[k]).reason_text[0]
    np.testing.assert_array_equal(rep.ok, rep.ik_valid)
    np.testing.assert_allclose(rep.margin_low, (q - lo).min(axis=0))
    np.testing.assert_allclose(rep.margin_high, (hi - q).min(axis=0))
    assert not np.isnan(rep.force).any() and not np.isnan(rep.qdot).any()


def test_paper_motion_z_lobes_use_exactly_the_full_stroke(paper_report):
    """Nominal is mid-stroke (50.8 mm) and a pure z move shifts every actuator by the same
    amount, so ±2 in of z spans exactly [0, 101.6] mm: zero margin (to rounding). Every other
    axis stays strictly inside the stroke (verified)."""
    rep = paper_report
    phases = dict((p[0], p[1:]) for p in paper_motion_phases())
    t0, t1 = phases["z"]
    in_z = (rep.t >= t0) & (rep.t <= t1)
    assert np.abs(rep.margin_low).max() < 1e-9 and np.abs(rep.margin_high).max() < 1e-9
    assert np.ptp(rep.q[in_z], axis=1).max() < 1e-9             # unison motion
    assert np.all(rep.ik_valid[~in_z])
    lo, hi = HOPKINS.stroke
    q_out = rep.q[~in_z]
    assert q_out.min() > lo + 1.0 and q_out.max() < hi - 1.0
    summary = rep.summary()
    json.dumps(summary)
    assert rep.fits                                # touching the limits is allowed
    # without the round-off allowance a peak of the z lobe (t = 12 s top or 14 s bottom, where
    # q lands within ~1e-13 mm of a limit, on either side depending on rounding) may fail
    motion = paper_motion(HOPKINS)
    t, X = motion.t, motion.poses
    strict = check_trajectory(HOPKINS, t, X, stroke_tolerance=0.0)
    if not strict.fits:
        v = strict.violations["stroke"]
        assert v.index in (1200, 1400) and abs(v.value - v.limit) < 1e-9
    assert summary["min_margin_mm"]["index"] in np.flatnonzero(in_z)
    # peak speed of the z lobes: 1.5·A/segment_time (finite differences within 0.1 %)
    assert summary["peak_speed_mm_s"]["q1"] == pytest.approx(1.5 * A_MM / 1.0, rel=1e-3)


# ---------------------------------------------------------------------------------------------
# limits at the right sample


def z_ramp(mech, n, step_mm, dt=0.01):
    t = dt * np.arange(n)
    X = np.tile(mech.nominal_pose, (n, 1))
    X[:, 2] += step_mm * np.arange(n)
    return t, X


@pytest.mark.parametrize("sign, reason, limit", [(1, "stroke above maximum", 101.6),
                                                 (-1, "stroke below minimum", 0.0)])
def test_stroke_crossing_detected_at_known_sample(sign, reason, limit):
    # q = 50.8 ± k mm: the first sample outside [0, 101.6] is k = 51 (q = 101.8 / −0.2)
    t, X = z_ramp(HOPKINS, 60, sign * 1.0)
    rep = check_trajectory(HOPKINS, t, X)
    v = rep.violations["stroke"]
    assert (v.index, v.reason, v.limit) == (51, reason, limit)
    assert v.time == pytest.approx(0.51)
    assert v.value == pytest.approx(50.8 + sign * 51.0)
    assert v.actuator in HOPKINS.actuator_names
    assert rep.ok[:51].all() and not rep.ok[51:].any()
    assert all(reason in s for s in rep.status[51:])
    assert not rep.fits
    margin = rep.margin_high if sign > 0 else rep.margin_low
    np.testing.assert_allclose(margin, -(59 - 50.8), atol=1e-9)
    assert rep.violations["speed"] is None and rep.violations["force"] is None


@pytest.mark.parametrize("limit, index, value", [(15.0, 20, 20.0), (25.0, 21, 30.0)])
def test_speed_limit_detected_at_known_sample(limit, index, value):
    # z speed 10 mm/s up to sample 20, 30 mm/s after; every actuator follows z one to one.
    # Central differences: 10 before the kink, 20 at it, 30 after.
    dt, n = 0.01, 40
    t = dt * np.arange(n)
    dz = np.where(np.arange(1, n) <= 20, 10.0, 30.0) * dt
    X = np.tile(HOPKINS.nominal_pose, (n, 1))
    X[1:, 2] += np.cumsum(dz)
    rep = check_trajectory(HOPKINS, t, X, max_speed=limit)
    v = rep.violations["speed"]
    assert v is not None and (v.index, v.limit) == (index, limit)
    assert v.value == pytest.approx(value, rel=1e-9)
    assert rep.ok[:index].all() and not rep.ok[index:].any()
    assert not rep.fits and rep.violations["stroke"] is None
    # per-actuator limits: only q4 limited → q4 is named
    lim6 = np.full(6, 1e3)
    lim6[3] = limit
    rep6 = check_trajectory(HOPKINS, t, X, max_speed=lim6)
    assert (rep6.violations["speed"].index, rep6.violations["speed"].actuator) == (index, "q4")


def test_force_limit_and_no_solution_are_statuses_not_errors():
    motion = paper_motion(HOPKINS, rate_hz=20.0)
    t, X = motion.t, motion.poses
    X = X.copy()
    X[100, 0] = 1000.0                       # unreachable: no real solution
    X[200, 3] = math.nan                     # non-finite pose
    rep = check_trajectory(HOPKINS, t, X, payload_mass_kg=10.0, max_force=30.0)
    assert "no real solution" in rep.status[100] and "non-finite pose" in rep.status[200]
    assert np.isnan(rep.q[100]).all() and np.isnan(rep.force[100]).all()
    assert "Jacobian not finite" in rep.status[100]
    for k in (99, 101):
        assert "speed undefined" in rep.status[k]
    # every NaN is explained by a non-ok status
    nan_rows = np.isnan(rep.q).any(axis=1) | np.isnan(rep.qdot).any(axis=1) \
        | np.isnan(rep.force).any(axis=1)
    assert not rep.ok[nan_rows].any()
    assert rep.violations["stroke"].index == 100
    assert rep.violations["stroke"].reason == "no real solution"
    assert rep.violations["jacobian"].index == 100
    f = rep.violations["force"]
    over = np.nan_to_num(np.abs(rep.force)) > 30.0
    assert f is not None and f.index == int(np.flatnonzero(over.any(axis=1))[0])
    assert abs(f.value) > 30.0 and f.limit == 30.0
    json.dumps(rep.summary())


@dataclass(frozen=True)
class _SingularAt(PSU6):
    """Hopkins geometry whose Jacobian is made rank-deficient at z above a threshold."""

    z_singular: float = 1e9

    def _jacobian(self, p, R):
        J = super()._jacobian(p, R)
        J[p[:, 2] > self.z_singular, 5] = J[p[:, 2] > self.z_singular, 4]
        return J


def test_singular_jacobian_is_reported_not_raised():
    h = HOPKINS
    mech = _SingularAt(h.base_points, h.platform_points, h.link_length, h.stroke,
                       h.tool_offset, z_singular=h.nominal_pose[2] + 5.5)
    t, X = z_ramp(h, 10, 1.0)
    rep = check_trajectory(mech, t, X, payload_mass_kg=1.0)
    v = rep.violations["jacobian"]
    assert v is not None and v.index == 6
    assert rep.ok[:6].all() and not rep.ok[6:].any()
    assert all("singular Jacobian" in s for s in rep.status[6:])
    assert np.isnan(rep.force[6:]).all() and np.isfinite(rep.force[:6]).all()
    assert rep.violations["stroke"] is None and not rep.fits


def test_condition_is_the_dexterity_kappa_with_its_length():
    # κ along a trajectory is pkmlab's one κ: the Jacobian homogenised with Angeles' length
    # (it was the unscaled 2-norm condition number, mixing mm and rad columns)
    motion = paper_motion(HOPKINS)
    t, X = motion.t, motion.poses
    rep = check_trajectory(HOPKINS, t, X)
    L = dx.resolve_length(HOPKINS)
    J = HOPKINS.jacobian(X)
    Jh = J.copy()
    Jh[..., 3:] /= L.length
    np.testing.assert_allclose(rep.condition, np.linalg.cond(Jh), rtol=1e-9)
    np.testing.assert_allclose(rep.condition, dx.condition_number(J, L), rtol=1e-12)
    assert not np.allclose(rep.condition, np.linalg.cond(J), rtol=1e-2)
    assert rep.length.status == "angeles" and rep.length.length == L.length
    s = rep.summary()
    assert s["characteristic_length"]["length_mm"] == pytest.approx(L.length)
    assert s["kappa_max"] == pytest.approx(rep.condition.max()) and s["singular_samples"] == 0
    given = check_trajectory(HOPKINS, t[:50], X[:50], characteristic_length=80.0)
    assert given.length.status == "given"
    np.testing.assert_allclose(given.condition, dx.condition_number(J[:50], 80.0), rtol=1e-12)


# ---------------------------------------------------------------------------------------------
# static forces


def test_forces_equal_on_symmetric_geometry_and_sum_to_weight():
    mech = symmetric_psu()
    X = np.tile(mech.nominal_pose, (2, 1))
    np.testing.assert_allclose(X[0, 3:], 0.0)
    rep = check_trajectory(mech, [0.0, 1.0], X, payload_mass_kg=2.0)
    f = rep.force[0]
    assert np.ptp(f) < 1e-9 * abs(f[0])                        # six equal by symmetry
    assert f.sum() == pytest.approx(2.0 * 9.81, rel=1e-12)     # vertical: Σ f_i = m·g (N)
    # Hopkins is only three-fold symmetric: legs 1, 3, 5 alike and 2, 4, 6 alike
    rep = check_trajectory(HOPKINS, [0.0, 1.0], np.tile(HOPKINS.nominal_pose, (2, 1)),
                           payload_mass_kg=1.0)
    f = rep.force[0]
    assert np.ptp(f[0::2]) < 1e-9 and np.ptp(f[1::2]) < 1e-9
    assert f.sum() == pytest.approx(9.81, rel=1e-12)
    assert np.all(f > 0)                                       # the actuators push up
    zero = check_trajectory(HOPKINS, [0.0, 1.0], np.tile(HOPKINS.nominal_pose, (2, 1)))
    assert np.all(zero.force == 0.0)


def _q_of_frames(mech, p, R):
    T = np.zeros((len(p), 4, 4))
    T[:, :3, :3], T[:, :3, 3], T[:, 3, 3] = R, p, 1.0
    q = mech.inverse(T).q                  # the stroke is irrelevant to virtual work
    assert np.isfinite(q).all()
    return q


def test_forces_balance_wrench_and_satisfy_virtual_work():
    motion = paper_motion(HOPKINS, rate_hz=10.0)
    t, X = motion.t, motion.poses
    com = np.array([12.0, -30.0, 40.0])
    rep = check_trajectory(HOPKINS, t, X, payload_mass_kg=2.5, payload_com=com,
                           gravity=(0.0, 0.0, -9810.0))
    sel = np.flatnonzero(rep.ik_valid)
    # re-multiplication: Jᵀ f + w = 0
    J = HOPKINS.jacobian(X[sel])
    resid = np.einsum("nji,nj->ni", J, rep.force[sel]) + rep.wrench[sel]
    assert np.abs(resid).max() < 1e-9 * np.abs(rep.wrench[sel]).max()
    # the wrench: weight 2.5·9.81 N down, moment (R·com) × F in N·mm
    p, R = as_frames(X[sel])
    F = np.array([0.0, 0.0, -2.5 * 9.81])
    np.testing.assert_allclose(rep.wrench[sel, :3], np.tile(F, (len(sel), 1)), atol=1e-12)
    np.testing.assert_allclose(rep.wrench[sel, 3:], np.cross(R @ com, F), atol=1e-9)
    # independent virtual work from the inverse kinematics only (no Jacobian):
    # Σ f_i δq_i = −w·δx for δx = a z translation and a general small twist
    rng = np.random.default_rng(3)
    d = 1e-5
    for twist in (np.array([0, 0, 1.0, 0, 0, 0]), rng.normal(size=6) * [1, 1, 1, 0.01, 0.01,
                                                                         0.01]):
        dx = d * twist
        q_plus = _q_of_frames(HOPKINS, p + dx[:3], exp_so3(np.tile(dx[3:], (len(p), 1))) @ R)
        q_minus = _q_of_frames(HOPKINS, p - dx[:3], exp_so3(np.tile(-dx[3:], (len(p), 1))) @ R)
        work_act = np.sum(rep.force[sel] * (q_plus - q_minus), axis=1)
        work_load = -2.0 * rep.wrench[sel] @ dx
        scale = np.abs(rep.force[sel]).max() * np.abs(q_plus - q_minus).max()
        np.testing.assert_allclose(work_act, work_load, atol=1e-6 * scale)
    # z translation: Σ f_i = m·g because ∂q_i/∂z = 1 for every leg
    np.testing.assert_allclose(rep.force[sel].sum(axis=1), 2.5 * 9.81, rtol=1e-9)


# ---------------------------------------------------------------------------------------------
# input validation


def test_check_trajectory_rejects_malformed_input():
    X = np.tile(HOPKINS.nominal_pose, (3, 1))
    with pytest.raises(ParameterError) as exc:
        check_trajectory(HOPKINS, [0.0, 0.2, 0.1], X)
    assert exc.value.field == "t[2]"
    with pytest.raises(ParameterError, match="poses"):
        check_trajectory(HOPKINS, [0.0, 0.1], X)
    with pytest.raises(ParameterError, match="payload_mass_kg"):
        check_trajectory(HOPKINS, [0.0, 0.1, 0.2], X, payload_mass_kg=-1.0)
    with pytest.raises(ParameterError, match="max_force"):
        check_trajectory(HOPKINS, [0.0, 0.1, 0.2], X, max_force=[1.0, 2.0])
    with pytest.raises(ParameterError, match="max_speed"):
        check_trajectory(HOPKINS, [0.0, 0.1, 0.2], X, max_speed=0.0)


# ---------------------------------------------------------------------------------------------
# CSV


def test_load_csv_roundtrip(tmp_path):
    path = tmp_path / "traj.csv"
    path.write_text("# a comment\n"
                    "theta_z, t, x, y, z, theta_x, theta_y\n"
                    "0, 0.0, 1, 2, 300, 0, 0\n"
                    "\n"
                    "30, 0.5, 1.5, 2, 300, -10, 5\n")
    m = load_motion_csv(path, derivatives=False)
    t, X = m.t, m.poses
    assert m.twist is None and m.derivatives == "none"
    np.testing.assert_array_equal(t, [0.0, 0.5])
    np.testing.assert_allclose(X, [[1, 2, 300, 0, 0, 0],
                                   [1.5, 2, 300, math.radians(-10), math.radians(5),
                                    math.radians(30)]])


@pytest.mark.parametrize("text, field, line, fragment", [
    ("t,x,y,z,theta_x,theta_y\n0,0,0,0,0,0\n1,0,0,0,0,0\n", "header", 1, "theta_z"),
    ("t,x,y,z,theta_x,theta_y,theta_z,x_mm\n", "header", 1, "x_mm"),
    ("t,x,y,z,theta_x,theta_y,theta_z,t\n", "header", 1, "duplicate"),
    ("t,x,y,z,theta_x,theta_y,theta_z\n0,0,0,0,0,0,0\n1,0,abc,0,0,0,0\n", "column 'y'", 3,
     "3-character text (not shown)"),     # a word in a data cell is file content: not echoed
    ("t,x,y,z,theta_x,theta_y,theta_z\n0,0,0,0,0,0,0\n1,0,0,0,nan,0,0\n", "column 'theta_x'",
     3, "nan"),
    ("t,x,y,z,theta_x,theta_y,theta_z\n0,0,0,0,0,0,0\n1,0,0,0,0,0\n", "", 3, "6 fields"),
    ("t,x,y,z,theta_x,theta_y,theta_z\n0,0,0,0,0,0,0\n1,0,0,0,0,0,0\n1,0,0,0,0,0,0\n",
     "column 't'", 4, "1.0"),
    ("t,x,y,z,theta_x,theta_y,theta_z\n0,0,0,0,0,0,0\n2,0,0,0,0,0,0\n1,0,0,0,0,0,0\n",
     "column 't'", 4, "1.0"),
    ("t,x,y,z,theta_x,theta_y,theta_z\n0,0,0,0,0,0,0\n", "", None, "1"),
    ("# only a comment\n", "", None, "empty"),
    ("t,x,y,z,theta_x,theta_y,theta_z,x_ddot,y_ddot,z_ddot,theta_x_ddot,theta_y_ddot,"
     "theta_z_ddot\n", "header", 1, "acceleration columns only"),
])
def test_load_csv_errors_name_the_place(tmp_path, text, field, line, fragment):
    path = tmp_path / "bad.csv"
    path.write_text(text)
    with pytest.raises(ParameterError) as exc:
        load_motion_csv(path, field="--csv", derivatives=False)
    assert exc.value.field == f"--csv {field}".strip()
    assert exc.value.where.startswith(str(path))
    assert exc.value.where.endswith(f"line {line}") or line is None
    assert fragment in str(exc.value)


# ---------------------------------------------------------------------------------------------
# plot


def test_plot_actuators_writes_png(tmp_path):
    t, X = z_ramp(HOPKINS, 60, 1.0)
    rep = check_trajectory(HOPKINS, t, X)
    out = plot_actuators(rep, tmp_path / "q.png", "z ramp", phases=[("z", 0.0, 0.59)])
    data = out.read_bytes()
    assert data[:8] == b"\x89PNG\r\n\x1a\n" and len(data) > 10_000
