"""Design to requirements: task containment, inverse dynamics, actuators, study blocks.

Every check compares against an independent computation: brute-force inverse kinematics of
task samples; leg-by-leg equilibrium (6-UPS: the leg forces act along the legs) instead of the
Jacobian; finite differences of the analytic motion instead of the closed-form twists; the
platform's energy instead of the wrench.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR
from scipy.integrate import simpson
from scipy.spatial.transform import Rotation
from typer.testing import CliRunner

from pkmlab import load_mechanism
from pkmlab.cli import app
from pkmlab.errors import ParameterError
from pkmlab.mechanisms import PSU6, UPS6
from pkmlab.motion import load_motion_csv, sinusoid_motion
from pkmlab.motion.dynamics import inverse_dynamics
from pkmlab.motion.payload import GRAVITY, MassProperties
from pkmlab.requirements.actuators import ActuatorSpec, fit
from pkmlab.requirements.task import TaskRegion, task_contained, task_margins
from pkmlab.study import load_study, study_from_mapping
from pkmlab.study.evaluators import evaluate_design
from pkmlab.workspaces import OrientationSet

ROOT = Path(__file__).resolve().parents[2]


# ---- task containment against brute force ---------------------------------------------------


def _random_designs(n, seed):
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        k = len(out) % 2
        try:
            if k == 0:
                m = PSU6.from_circles(base_radii=tuple(sorted(rng.uniform(90, 170, 2))),
                                      platform_radii=tuple(sorted(rng.uniform(30, 90, 2))),
                                      platform_rotation=rng.uniform(0.1, 1.0),
                                      link_length=rng.uniform(180, 300), stroke=(0, 101.6))
            else:
                m = UPS6.from_circles(base_radii=(rng.uniform(250, 400),) * 2,
                                      platform_radii=(rng.uniform(80, 200),) * 2,
                                      stroke=(rng.uniform(350, 450), rng.uniform(650, 800)))
            _ = m.nominal_pose
        except ParameterError:
            continue
        out.append(m)
    return out


def _brute(mech, task, oset, rng, n=3000):
    """Independent: random positions of the task (plus its corners / rim) at every
    orientation sample, inverse kinematics with the stroke."""
    p0 = mech.nominal_pose[:3]
    if task.shape == "cylinder":
        c = np.asarray(task.centre) + p0
        rho = task.radius * np.sqrt(rng.random(n))
        a = rng.uniform(0, 2 * np.pi, n)
        z = rng.uniform(-task.height / 2, task.height / 2, n)
        ring = np.linspace(0, 2 * np.pi, 90, endpoint=False)
        rho = np.concatenate([rho, np.full(180, task.radius)])
        a = np.concatenate([a, ring, ring])
        z = np.concatenate([z, np.full(90, -task.height / 2), np.full(90, task.height / 2)])
        p = np.column_stack([c[0] + rho * np.cos(a), c[1] + rho * np.sin(a), c[2] + z])
    elif task.shape == "box":
        half = np.asarray(task.size) / 2
        c = np.asarray(task.centre) + p0
        corners = np.array([[i, j, k] for i in (-1, 1) for j in (-1, 1) for k in (-1, 1)])
        p = np.concatenate([c + rng.uniform(-1, 1, (n, 3)) * half, c + corners * half])
    else:
        p = task.points + p0
    _, centre = load_R(mech)
    for R in oset.centred(centre).rotations():
        Rs = np.ascontiguousarray(np.broadcast_to(R, (len(p), 3, 3)))
        if not np.all(mech.inverse((p, Rs)).valid):
            return False
    return True


def load_R(mech):
    from pkmlab.poses import as_frames, matrix_to_euler

    _, R = as_frames(mech.nominal_pose)
    return R[0], tuple(matrix_to_euler(R[0]))


def test_task_contained_never_claims_a_task_brute_force_refutes():
    rng = np.random.default_rng(11)
    agree = contained = 0
    cases = 0
    for mech in _random_designs(8, 5):
        oset = OrientationSet.box(np.radians([rng.uniform(0, 12)] * 3), samples=3)
        for shape in ("box", "cylinder", "points"):
            for _ in range(3):
                s = rng.uniform(5, 90)
                centre = tuple(rng.uniform(-15, 15, 3))
                if shape == "box":
                    t = TaskRegion("box", centre=centre, size=tuple(s * rng.uniform(0.3, 1, 3)))
                elif shape == "cylinder":
                    t = TaskRegion("cylinder", centre=centre, radius=s / 2, height=s / 2)
                else:
                    t = TaskRegion("points", points=rng.uniform(-s / 2, s / 2, (40, 3)))
                chk = task_contained(mech, t, oset)
                assert chk.method == "exact"
                brute = _brute(mech, t, oset, rng)
                cases += 1
                if chk.contained:
                    contained += 1
                    assert brute, f"false 'contained': {mech.family} {t}"
                agree += chk.contained == brute
    # both outcomes occur, and sampling misses a failure only near the boundary (rarely)
    assert 0 < contained < cases
    assert agree >= cases - 3, (agree, cases)


def test_task_margin_brackets_the_boundary():
    mech = load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
    oset = OrientationSet.box(np.radians([5, 5, 5]), samples=3)
    t = TaskRegion("box", size=(10, 10, 10))
    m = task_margins(mech, t, oset)
    d = m["margin_mm"]
    assert m["check"].contained and d > 0 and m["margin_bracket_mm"] <= 0.01
    # grown by the margin: contained; grown past the bracket: not
    assert task_contained(mech, TaskRegion("box", size=(10 + 2 * d,) * 3), oset).contained
    big = 10 + 2 * (d + m["margin_bracket_mm"] + 1e-6)
    assert not task_contained(mech, TaskRegion("box", size=(big,) * 3), oset).contained
    a = m["orientation_margin_deg"]
    assert a > 0
    wider = OrientationSet.box(np.radians([5 + a + 0.02] * 3), samples=3)
    assert not task_contained(mech, t, wider).contained


def test_luzi_falls_back_to_sampling_and_says_so():
    mech = load_mechanism(MECH_DIR / "luzi-3chain.yaml")
    chk = task_contained(mech, TaskRegion("box", size=(10, 10, 10)),
                         OrientationSet.box(np.radians([3] * 3), samples=2), resolution=5.0)
    assert chk.method == "sampled" and "can be missed" in chk.note and chk.contained


# ---- statics and dynamics against independent derivations ----------------------------------


def _ups():
    return load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")


BODY = MassProperties(150.0, np.array([12.0, -7.0, 300.0]),
                      np.array([[2.5e7, 1e5, -2e5], [1e5, 2.2e7, 3e5], [-2e5, 3e5, 1.2e7]]))


def _leg_forces(mech, p, R, F, M):
    """Independent equilibrium of a 6-UPS: the leg forces f_i act along the unit leg vectors
    n_i at the platform joints: Σ f_i n_i = F, Σ (R u_i) × f_i n_i = M (u_i about the tool)."""
    r = R @ mech.tool_points.T                   # (3, 6)
    s = p[:, None] + r - mech.base_points.T
    n = s / np.linalg.norm(s, axis=0)
    A = np.vstack([n, np.cross(r.T, n.T).T])     # (6, 6)
    return np.linalg.solve(A, np.concatenate([F, M]))


def test_static_forces_equal_leg_equilibrium_with_the_payload():
    mech = _ups()
    rng = np.random.default_rng(2)
    m = sinusoid_motion(mech, [30, 20, 10, 0.1, 0.1, 0.2], [0, 0, 0, 0, 0, 0],
                        phase=rng.uniform(0, 6, 6), duration=0.01, rate=100)
    res = inverse_dynamics(mech, m, BODY)
    assert np.all(res.ok)
    for k in range(len(m.t)):
        R = Rotation.from_euler("ZYX", m.poses[k, [5, 4, 3]]).as_matrix()
        p = m.poses[k, :3]
        rc = R @ (BODY.com - mech.tool_offset)
        F = np.array([0.0, 0.0, BODY.mass * GRAVITY * 1e-3])
        f = _leg_forces(mech, p, R, F, np.cross(rc, F))
        assert np.allclose(res.force[k], f, rtol=1e-9, atol=1e-9 * np.max(np.abs(f)))


def _independent_newton_euler(mech, A, f, ph, t, h=1e-3):
    """Wrench and energy from finite differences (5-point) of the analytic sinusoid; ω from
    Ṙ·Rᵀ, the moment from dH/dt of the angular momentum about the centre of mass."""
    nom = mech.nominal_pose
    w2 = 2 * np.pi * np.asarray(f)

    def pose(tt):
        return nom + A * np.sin(np.outer(np.atleast_1d(tt), w2) + ph)

    def frame(tt):
        X = pose(tt)
        R = Rotation.from_euler("ZYX", X[:, [5, 4, 3]]).as_matrix()
        c = X[:, :3] + R @ (BODY.com - mech.tool_offset)
        return c, R

    def d1(fun, tt):
        return (fun(tt - 2 * h) - 8 * fun(tt - h) + 8 * fun(tt + h) - fun(tt + 2 * h)) / (12 * h)

    def omega(tt):
        Rd = d1(lambda s: frame(s)[1], tt)
        W = Rd @ np.swapaxes(frame(tt)[1], 1, 2)
        return np.stack([W[:, 2, 1], W[:, 0, 2], W[:, 1, 0]], axis=1)

    def vc(tt):
        return d1(lambda s: frame(s)[0], tt)

    def H(tt):
        R = frame(tt)[1]
        return np.einsum("nij,jk,nlk,nl->ni", R, BODY.inertia, R, omega(tt))

    ac = d1(vc, t)
    F = BODY.mass * (ac + [0, 0, GRAVITY]) * 1e-3
    c, R = frame(t)
    r = c - pose(t)[:, :3]
    M = d1(H, t) * 1e-3 + np.cross(r, F)

    def energy(tt):
        c_, R_ = frame(tt)
        w_ = omega(tt)
        Ib = np.einsum("nij,jk,nlk->nil", R_, BODY.inertia, R_)
        v_ = vc(tt)
        return (0.5 * BODY.mass * np.sum(v_ * v_, 1) + 0.5 * np.einsum("ni,nij,nj->n", w_, Ib,
                                                                         w_)
                + BODY.mass * GRAVITY * c_[:, 2]) * 1e-6

    return pose(t), F, M, energy, d1


SIN = ([25.0, 15.0, 30.0, 0.12, 0.08, 0.15], [0.8, 1.1, 1.5, 0.7, 1.3, 0.9],
       [0.3, 1.0, 0.0, 2.0, 0.5, 1.2])


def test_dynamic_forces_equal_an_independent_newton_euler():
    mech = _ups()
    A, f, ph = (np.array(v) for v in SIN)
    m = sinusoid_motion(mech, A, f, ph, duration=2.0, rate=50)
    res = inverse_dynamics(mech, m, BODY)
    assert np.all(res.ok)
    X, F, M, _, _ = _independent_newton_euler(mech, A, f, ph, m.t)
    assert np.allclose(X, m.poses, atol=1e-12)
    worst = 0.0
    for k in range(len(m.t)):
        R = Rotation.from_euler("ZYX", X[k, [5, 4, 3]]).as_matrix()
        fi = _leg_forces(mech, X[k, :3], R, F[k], M[k])
        worst = max(worst, np.max(np.abs(res.force[k] - fi)) / np.max(np.abs(fi)))
    assert worst < 1e-6, worst


def test_power_balance_over_a_sinusoidal_motion():
    """Σ f·q̇ = dE/dt (E: kinetic + gravitational energy of the platform), at every sample
    and integrated over the motion, to 1e-6 relative."""
    mech = _ups()
    A, f, ph = (np.array(v) for v in SIN)
    m = sinusoid_motion(mech, A, f, ph, duration=1.7, rate=400)
    res = inverse_dynamics(mech, m, BODY)
    P = np.sum(res.power, axis=1)                             # W
    _, _, _, energy, d1 = _independent_newton_euler(mech, A, f, ph, m.t)
    dE = d1(energy, m.t)
    scale = np.max(np.abs(P))
    assert np.max(np.abs(P - dE)) < 1e-6 * scale
    work = simpson(P, x=m.t)
    e = energy(np.array([m.t[0], m.t[-1]]))
    assert abs(work - (e[1] - e[0])) < 1e-6 * scale * m.t[-1]


def test_infeasible_samples_are_data_with_a_reason():
    mech = _ups()
    m = sinusoid_motion(mech, [0, 0, 600, 0, 0, 0], [0, 0, 1, 0, 0, 0], duration=1, rate=50)
    res = inverse_dynamics(mech, m, BODY)
    assert not np.all(res.ok) and np.all(np.isnan(res.force[~res.ok]))
    assert "ik:" in res.first_problem()
    a = ActuatorSpec("x", 1e5, 1e5, 1e4)
    out = fit(a, [res])
    assert not out.fits and "infeasible" in out.notes["actuators_fit"]


def test_actuator_margins_from_the_series():
    mech = _ups()
    m = sinusoid_motion(mech, [0, 0, 40, 0, 0, 0], [0, 0, 1.0, 0, 0, 0], duration=2, rate=200)
    res = inverse_dynamics(mech, m, BODY)
    fmax, vmax = np.max(np.abs(res.force)), np.max(np.abs(res.qdot))
    lead = 10.0
    curve = ((0.0, 5000.0), (300.0, 5000.0), (400.0, 0.0))
    a = ActuatorSpec("a", 2 * fmax, 4 * vmax, 500.0, lead, 0.8, curve)
    out = fit(a, [res])
    assert out.fits
    assert out.force_margin == pytest.approx(50.0) and out.speed_margin == pytest.approx(75.0)
    om = 2 * np.pi * np.abs(res.qdot) / lead
    T = np.abs(res.force) * lead / (2 * np.pi * 0.8)
    avail = np.interp(om, [0, 300, 400], [5000, 5000, 0], right=0)
    assert out.torque_speed_margin == pytest.approx(100 * np.min(avail - T) / 5000)
    used = np.max(res.q.max(0) - res.q.min(0))
    assert out.stroke_margin == pytest.approx(500 - used)


# ---- study blocks and bad requirement files ---------------------------------------------------


def _study(tmp_path: Path, **evaluate) -> dict:
    return {"study": "req", "mechanism": {"file": str(MECH_DIR / "gough-stewart-6ups.yaml")},
            "design": {"stroke_max": {"low": 900, "high": 1000}},
            "evaluate": evaluate, "objectives": [{"maximize": "stroke_length"}],
            "optimizer": {"method": "grid"}}


def _csv(tmp_path, text, name="m.csv"):
    p = tmp_path / name
    p.write_text(text)
    return name


GOOD = "t,x,y,z,theta_x,theta_y,theta_z\n" + "".join(
    f"{k * 0.01:.2f},0,0,{10 * math.sin(k * 0.05):.6f},0,0,0\n" for k in range(50))


def _one_line(tmp_path, data, expect):
    f = tmp_path / "s.yaml"
    f.write_text(yaml.safe_dump(data))
    r = CliRunner().invoke(app, ["validate", str(f)])
    assert r.exit_code == 2, r.output
    line = r.output.strip()
    assert "\n" not in line and "Traceback" not in line, line
    assert expect in line and "must be" in line, line


@pytest.mark.parametrize("evaluate, expect", [
    ({"task": {"shape": "box", "size": ["-5 mm", 10, 10]}}, "evaluate.task.size[0]"),
    ({"task": {"shape": "cylinder", "radius": 10}}, "evaluate.task.radius"),
    ({"motions": [{"name": "a", "paper": True}], "payload": {"mass": "150 stone"}},
     "evaluate.payload.mass"),
    ({"motions": [{"name": "a", "paper": True}], "payload": {"mass": 1, "inertia": [1, 1, 5]}},
     "evaluate.payload.inertia"),
    ({"motions": [{"name": "a", "paper": True}]}, "evaluate.payload"),
    ({"motions": [{"name": "a", "paper": True}],
      "payload": {"mass": 1, "legs": {"mass": 2, "model": "rod", "platform_share": 0.4}}},
     "evaluate.payload.legs.platform_share"),
    ({"motions": [{"name": "a", "paper": True}], "payload": {"mass": 1},
      "actuators": {"spec": {"name": "s", "kind": "rotary", "torque": "2 N*m"}}},
     "evaluate.actuators.spec.angular_speed"),
    ({"motions": [{"name": "a", "paper": True}], "payload": {"mass": 1},
      "actuators": {"spec": {"name": "s", "force": "2 kN", "speed": "300 mm/s",
                             "torque": "2 N*m"}}}, "evaluate.actuators.spec.torque"),
    ({"motions": [{"name": "a", "paper": True}], "payload": {"mass": 1},
      "actuators": {"spec": {"name": "s", "force": "2 parsec", "speed": "300 mm/s"}}},
     "evaluate.actuators.spec.force"),
])
def test_validate_rejects_bad_requirements(tmp_path, evaluate, expect):
    _one_line(tmp_path, _study(tmp_path, **evaluate), expect)


@pytest.mark.parametrize("text, expect", [
    ("t,x,y,z,theta_x,theta_y\n0,0,0,0,0,0\n0.1,0,0,0,0,0\n", "missing ['theta_z']"),
    (GOOD.replace("0.20,", "0.10,", 1), "evaluate.motions[0].file column 't'"),
    (GOOD.replace("0.30,0,0,", "0.30,0,nan,", 1), "evaluate.motions[0].file column 'y'"),
    (GOOD.replace("0.30,0,0,", "0.30,0,oops,", 1), "a finite number"),
])
def test_validate_rejects_bad_motion_csv(tmp_path, text, expect):
    name = _csv(tmp_path, text)
    data = _study(tmp_path, motions=[{"name": "rec", "file": name, "frame": "nominal"}],
                  payload={"mass": 10})
    _one_line(tmp_path, data, expect)


def test_recorded_motion_derivatives_by_smoothing_match_the_signal(tmp_path):
    t = np.arange(0, 2, 0.005)
    z = 20 * np.sin(2 * np.pi * t)
    rows = "".join(f"{a:.3f},0,0,{b:.9f},0,0,0\n" for a, b in zip(t, z))
    p = tmp_path / "s.csv"
    p.write_text("t,x,y,z,theta_x,theta_y,theta_z\n" + rows)
    m = load_motion_csv(p, window=0.05, polyorder=4)
    w = 2 * np.pi
    assert "savgol" in m.derivatives
    assert np.allclose(m.twist[:, 2], 20 * w * np.cos(w * t), atol=1e-3 * 20 * w)
    assert np.allclose(m.accel[:, 2], -20 * w * w * np.sin(w * t), atol=1e-2 * 20 * w * w)


def test_motion_simulator_study_runs_and_resolves(tmp_path):
    path = ROOT / "studies" / "motion-simulator-6ups-requirements.yaml"
    s = load_study(path)
    back = study_from_mapping(yaml.safe_load(yaml.safe_dump(s.resolved())))
    assert back.fingerprint() == s.fingerprint()
    rec = evaluate_design(s.space, {"base_outer_radius": 450.0, "platform_ratio": 0.5,
                                    "actuator": "EC-S-1k"}, s.evaluation, 0)
    assert rec["status"] == "ok", rec["reason"]
    mt = rec["metrics"]
    assert mt["task_contained"] == 1.0 and mt["motions_feasible"] == 1.0
    assert mt["actuator_force_rating"] == 1000.0 and mt["actuators_fit"] == 0.0
    big = evaluate_design(s.space, {"base_outer_radius": 450.0, "platform_ratio": 0.5,
                                    "actuator": "EC-XL-10k"}, s.evaluation, 0)
    assert big["metrics"]["actuators_fit"] == 1.0
    assert big["metrics"]["peak_actuator_force"] == mt["peak_actuator_force"]


def test_actuator_choices_must_be_catalogue_entries(tmp_path):
    path = ROOT / "studies" / "motion-simulator-6ups-requirements.yaml"
    data = yaml.safe_load(path.read_text())
    data["design"]["actuator"]["choices"] = ["EC-S-1k", "nope"]
    with pytest.raises(ParameterError, match=r"design\.actuator\.choices"):
        study_from_mapping(data, path.parent)


@pytest.mark.parametrize("name", ["hopkins-williams-6psu", "gough-stewart-6ups",
                                  "instructables-servo-6rss", "luzi-3chain"])
def test_actuator_power_equals_energy_rate_on_every_family(name):
    """Σ f_i·q̇_i = dE/dt with q̇ from finite differences of the inverse kinematics (not the
    Jacobian): checks ``f = J⁻ᵀ w`` for prismatic forces and for rss6's crank torques."""
    mech = load_mechanism(MECH_DIR / f"{name}.yaml")
    S = mech.scale / 400
    A = np.array([6 * S, 4 * S, 5 * S, 0.03, 0.04, 0.05])
    f, ph = np.array([0.8, 1.1, 1.5, 0.7, 1.3, 0.9]), np.array([0.3, 1.0, 0.0, 2.0, 0.5, 1.2])
    m = sinusoid_motion(mech, A, f, ph, duration=1.0, rate=50)
    body = MassProperties(20.0, mech.tool_offset + [3.0, -2.0, 40.0], [4e5, 3e5, 2e5])
    res = inverse_dynamics(mech, m, body)
    assert np.all(res.ok)
    h = 1e-4
    w2 = 2 * np.pi * f

    def q_at(t):
        return mech.inverse(mech.nominal_pose + A * np.sin(np.outer(t, w2) + ph)).q

    qd = (q_at(m.t - 2 * h) - 8 * q_at(m.t - h) + 8 * q_at(m.t + h) - q_at(m.t + 2 * h)) / (12 * h)
    np.testing.assert_allclose(res.qdot, qd, atol=1e-6 * np.max(np.abs(qd)))
    P = np.sum(res.force * qd, axis=1) * 1e-3
    ref = np.einsum("ni,ni->n", res.wrench, m.twist) * 1e-3      # w·[v; ω], W
    assert np.max(np.abs(P - ref)) < 1e-6 * np.max(np.abs(ref))


# ---- exported outputs per design -------------------------------------------------------------


def _output_study(tmp_path):
    data = {
        "study": "req-outputs", "description": "outputs of a requirement study",
        "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
        "design": {"link_length": {"low": "200 mm", "high": "260 mm", "levels": 2}},
        "evaluate": {
            "task": {"shape": "cylinder", "radius": "20 mm", "height": "16 mm",
                     "frame": "nominal", "box": ["5 deg", "5 deg", "5 deg"], "samples": 2,
                     "resolution": "4 mm"},
            "motions": [{"name": "heave", "sinusoid": {"amplitude": {"z": "8 mm"},
                                                       "frequency": {"z": "2 Hz"}},
                         "duration": "0.5 s", "rate": "100 Hz"}],
            "payload": {"mass": "2 kg", "com": ["0 mm", "0 mm", "30 mm"]},
            "actuators": {"spec": {"name": "small", "force": "40 N", "speed": "150 mm/s",
                                   "stroke": "101.6 mm", "lead": "4 mm/rev",
                                   "efficiency": 0.9,
                                   "torque_speed": [["0 rpm", "30 N*mm"], ["3000 rpm",
                                                                         "30 N*mm"],
                                                    ["4000 rpm", "0 N*mm"]]}}},
        "objectives": [{"minimize": "peak_actuator_force"}],
        "optimizer": {"method": "grid"}, "seed": 1, "top": 1}
    return study_from_mapping(data, tmp_path)


def test_exported_design_draws_task_and_actuator_limits(tmp_path):
    import json

    import trimesh

    from pkmlab.requirements.plots import actuator_figure
    from pkmlab.study.export import export_designs
    from pkmlab.study.report import write_report

    s = _output_study(tmp_path)
    params = {"link_length": 230.0}
    rec = evaluate_design(s.space, params, s.evaluation, 0)
    assert rec["status"] == "ok", rec["reason"]
    front = [{"key": "0123456789abcdef", "seq": 1, "params": params, "metrics": rec["metrics"],
              "notes": rec["notes"], "role": "candidate", "status": "ok", "reason": "",
              "seconds": 0.0}]
    folders, problems = export_designs(tmp_path, s, front)
    assert not problems and len(folders) == 1
    d = folders[0]
    for f in ("slices.png", "task.stl", "workspace_task.glb", "actuators-heave.png",
              "actuators.json"):
        assert (d / f).is_file(), f
    # the task mesh is the task region: a 20 mm radius, 16 mm high cylinder about the
    # nominal position
    mech = s.space.decode(params)
    c = mech.nominal_pose[:3]
    b = trimesh.load(d / "task.stl").bounds
    np.testing.assert_allclose(b, [c - [20, 20, 8], c + [20, 20, 8]], atol=1e-4)
    scene = trimesh.load(d / "workspace_task.glb")
    assert set(scene.geometry) == {"workspace", "task"}
    # the limit lines drawn are the actuator's limits
    data = json.loads((d / "actuators.json").read_text())
    m = data["motions"][0]
    assert m["force_limit"] == 40.0 and m["speed_limit"] == 150.0
    assert data["actuator"]["name"] == "small"
    res = inverse_dynamics(mech, s.evaluation.motions.motions(mech)[0],
                           s.evaluation.payload.for_mechanism(mech))
    np.testing.assert_allclose(m["peak_force"], np.max(np.abs(res.force), axis=0))
    spec = s.evaluation.actuators.catalogue["small"]
    fig = actuator_figure(res, spec)
    limits = sorted({float(ln.get_ydata()[0]) for ln in fig.axes[0].lines
                     if ln.get_linestyle() == "--"})
    assert limits == [-40.0, 40.0]
    curve = [ln for ln in fig.axes[2].lines if ln.get_linestyle() == "--"][0]
    np.testing.assert_allclose(curve.get_ydata(), [0.03, 0.03, 0.0, 0.0])   # N·m
    # the task region is drawn on the slices at its heights (red lines on those panels)
    from pkmlab.requirements.task import task_outline
    assert len(task_outline(mech, s.evaluation.task.region, c[2])) == 1
    assert task_outline(mech, s.evaluation.task.region, c[2] + 9) == []
    # the margins in summary.md
    write_report(tmp_path, s, front)
    text = (tmp_path / "summary.md").read_text()
    assert "Requirement margins" in text
    row = next(ln for ln in text.splitlines() if ln.startswith("| #1 ") and
               "task_margin" not in ln and ln.count("|") > 8)
    assert f"{rec['metrics']['task_margin']:.4g}" in row
    assert f"{rec['metrics']['actuator_force_margin']:.4g}" in row


def test_editing_an_input_file_changes_the_study_fingerprint(tmp_path):
    """The recordings and the catalogue are part of what a resume must match."""
    import shutil

    src = ROOT / "studies"
    for sub in ("inputs", "actuators", "mechanisms"):
        shutil.copytree(src / sub, tmp_path / sub)
    path = tmp_path / "study.yaml"
    shutil.copy(src / "motion-simulator-6ups-requirements.yaml", path)
    fp = load_study(path).fingerprint()
    assert load_study(path).fingerprint() == fp
    csv_path = tmp_path / "inputs" / "road-bumps.csv"
    text = csv_path.read_text()
    lines = text.splitlines()
    k = next(i for i, ln in enumerate(lines) if ln and ln[0].isdigit() and i > 5)
    cells = lines[k].split(",")
    cells[3] = f"{float(cells[3]) + 0.5:.6g}"            # z of one sample, +0.5 mm
    lines[k] = ",".join(cells)
    csv_path.write_text("\n".join(lines) + "\n")
    fp2 = load_study(path).fingerprint()
    assert fp2 != fp
    cat = tmp_path / "actuators" / "electric-cylinders.yaml"
    cat.write_text(cat.read_text() + "\n# a comment changes the bytes\n")
    assert load_study(path).fingerprint() not in (fp, fp2)


def test_slender_rod_legs_in_the_power_balance():
    """6-UPS with uniform slender-rod legs (8 kg each): Σ f·q̇ (q̇ from the IK by finite
    differences) = d/dt of the platform's energy plus each rod's (m/6)|Ḃ|² + m·g·(A_z + B_z)/2,
    the rods' end points taken from ``leg_segments``; to 1e-6 relative."""
    from pkmlab.motion.payload import combine, leg_end_masses, leg_rod_masses
    from pkmlab.poses import as_frames

    mech = _ups()
    mleg = 8.0
    A, f, ph = (np.array(v) for v in SIN)
    m = sinusoid_motion(mech, A, f, ph, duration=1.3, rate=300)
    res = inverse_dynamics(mech, m, combine(BODY, leg_rod_masses(mech, mleg)))
    assert np.all(res.ok)
    _, _, _, energy, d1 = _independent_newton_euler(mech, A, f, ph, m.t)
    w2 = 2 * np.pi * f

    def pose(tt):
        return mech.nominal_pose + A * np.sin(np.outer(np.atleast_1d(tt), w2) + ph)

    def ends(tt):
        return mech.leg_segments(*as_frames(pose(tt)))

    def leg_energy(tt):
        a, b = ends(tt)
        bd = d1(lambda s: ends(s)[1], tt)
        kin = mleg / 6 * np.sum(bd * bd, axis=(1, 2))
        pot = mleg * GRAVITY * np.sum(a[..., 2] + b[..., 2], axis=1) / 2
        return (kin + pot) * 1e-6

    h = 1e-4
    qd = (mech.inverse(pose(m.t - 2 * h)).q - 8 * mech.inverse(pose(m.t - h)).q
          + 8 * mech.inverse(pose(m.t + h)).q - mech.inverse(pose(m.t + 2 * h)).q) / (12 * h)
    P = np.sum(res.force * qd, axis=1) * 1e-3
    dE = d1(energy, m.t) + d1(leg_energy, m.t)
    assert np.max(np.abs(P - dE)) < 1e-6 * np.max(np.abs(P))
    # the 'ends' model with half of each leg at its platform joint fails this balance (its
    # inertia share is m/2, the rod's m/3)
    ends_model = inverse_dynamics(mech, m, combine(BODY, leg_end_masses(mech, mleg / 2)))
    Pe = np.sum(ends_model.force * qd, axis=1) * 1e-3
    assert np.max(np.abs(Pe - dE)) > 1e-4 * np.max(np.abs(P))


def test_rod_legs_need_fixed_base_joints():
    mech = load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
    from pkmlab.motion.payload import leg_rod_masses

    with pytest.raises(ParameterError, match=r"legs\.model"):
        leg_rod_masses(mech, 1.0)


def test_rotary_servo_fit_on_rss6_and_kind_mismatch_is_refused(tmp_path):
    mech = load_mechanism(MECH_DIR / "instructables-servo-6rss.yaml")
    m = sinusoid_motion(mech, [0, 0, 5, 0.05, 0, 0], [0, 0, 1.0, 0.7, 0, 0], duration=1.5,
                        rate=200)
    res = inverse_dynamics(mech, m, MassProperties(0.5, [0, 0, 10.0], [500, 500, 800]))
    assert res.unit == "rad" and np.all(res.ok)
    tmax, wmax = np.max(np.abs(res.force)), np.max(np.abs(res.qdot))    # N·mm, rad/s
    curve = ((0.0, 4 * tmax), (2 * wmax, 4 * tmax), (4 * wmax, 0.0))
    servo = ActuatorSpec("servo", 2 * tmax, 4 * wmax, math.pi, None, 1.0, curve, "rotary")
    out = fit(servo, [res])
    assert out.fits
    assert out.force_margin == pytest.approx(50.0) and out.speed_margin == pytest.approx(75.0)
    T = np.abs(res.force)
    avail = np.interp(np.abs(res.qdot), [0, 2 * wmax, 4 * wmax], [4 * tmax, 4 * tmax, 0])
    assert out.torque_speed_margin == pytest.approx(100 * np.min(avail - T) / (4 * tmax))
    used = np.max(res.q.max(0) - res.q.min(0))
    assert out.stroke_margin == pytest.approx(math.degrees(math.pi - used))
    # a linear actuator on a rotary family: refused at load, naming the block (issue 23:
    # before, it validated and every design came back invalid)
    data = {"study": "servo", "mechanism": {"file": str(MECH_DIR /
                                                        "instructables-servo-6rss.yaml")},
            "design": {"crank_length": {"low": "20 mm", "high": "30 mm"}},
            "evaluate": {"motions": [{"name": "s", "sinusoid": {"amplitude": {"z": "3 mm"},
                                                                "frequency": {"z": "1 Hz"}},
                                      "duration": "0.2 s", "rate": "50 Hz"}],
                         "payload": {"mass": "0.2 kg"},
                         "actuators": {"spec": {"name": "lin", "force": "10 N",
                                                "speed": "10 mm/s"}}},
            "objectives": [{"minimize": "peak_actuator_force"}], "optimizer": {"method": "grid"}}
    with pytest.raises(ParameterError, match=r"evaluate.actuators: must be a block this "
                       r"mechanism can serve \(actuators needs linear actuators"):
        study_from_mapping(data, tmp_path)


def test_motion_metrics_carry_the_actuators_units(tmp_path):
    """A rotary family's motion loads are torques (N·m) and angular speeds (deg/s): they go
    to the torque metrics, and the force metrics (N, mm/s) stay null with a note; a linear
    family the other way round. The torque equals the dynamics' own peak."""
    motion = [{"name": "s", "sinusoid": {"amplitude": {"z": "3 mm"}, "frequency": {"z": "1 Hz"}},
               "duration": "0.2 s", "rate": "50 Hz"}]
    for file, rotary, var in (("instructables-servo-6rss.yaml", True, "crank_length"),
                              ("hopkins-williams-6psu.yaml", False, "link_length")):
        data = {"study": "units", "mechanism": {"file": str(MECH_DIR / file)},
                "design": {var: {"low": "20 mm", "high": "300 mm"}},
                "evaluate": {"motions": motion, "payload": {"mass": "0.2 kg"}},
                "objectives": [{"minimize": "peak_actuator_power"}],
                "optimizer": {"method": "grid"}}
        s = study_from_mapping(data, tmp_path)
        rec = evaluate_design(s.space, None, s.evaluation, 0)
        assert rec["status"] == "ok", rec.get("reason")
        m, notes = rec["metrics"], rec["notes"]
        mech = s.space.decode(None)
        dyn = inverse_dynamics(mech, s.evaluation.motions.motions(mech)[0],
                               s.evaluation.payload.for_mechanism(mech))
        peak = float(np.max(dyn.summary()["peak_force"]))
        have, null = (("peak_actuator_torque", "peak_actuator_force") if rotary else
                      ("peak_actuator_force", "peak_actuator_torque"))
        # issue 26: torques are shown in N·m (the dynamics give N·mm), forces in N
        shown = peak * (1e-3 if rotary else 1.0)
        assert m[have] == pytest.approx(shown) and m[null] is None and have in notes[null]
        assert (m["peak_actuator_angular_speed"] is None) != rotary


def test_summary_reports_which_catalogue_actuators_fit(tmp_path):
    from pkmlab.study.report import _catalogue_fits

    s = load_study(ROOT / "studies" / "motion-simulator-6ups-requirements.yaml")
    recs = [{"status": "ok", "params": {"base_outer_radius": 450.0, "platform_ratio": 0.5,
                                         "actuator": a}, "metrics": {"actuators_fit": fit_}}
            for a, fit_ in (("EC-S-1k", 0.0), ("EC-L-5k", 1.0), ("EC-L-5k", 0.0))]
    text = "\n".join(_catalogue_fits(s, recs))
    assert "EC-S-1k fits 0 of 1" in text and "EC-L-5k fits 1 of 2" in text
    assert "EC-XL-10k fits 0 of 0" in text
