"""Delta robots (issue 24, items 1-2): the rotary ``delta3`` and linear ``ldelta3`` families
against independent computations — Klipper's carriage formula, a root search on the elbow
circle, the generic multi-start Newton, numpy determinants, brute-force IK on grids and
circles. (Both families also run the contract suite of tests/test_contract.py through their
shipped files.)"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from conftest import MECHANISMS
from scipy.optimize import brentq

from pkmlab import testing
from pkmlab.mechanisms import NO_STROKE
from pkmlab.mechanisms.families.delta3 import Delta3
from pkmlab.mechanisms.families.ldelta3 import LDelta3
from pkmlab.mechanisms.solvers import multistart_modes
from pkmlab.workspaces import Constraints, workspace
from pkmlab.workspaces.bracket.columns import volume_bracket

CLAVEL = MECHANISMS["clavel-delta3"]
KLIPPER = MECHANISMS["klipper-example-ldelta3"]
INCLINED = LDelta3.from_towers(tilt=math.radians(12), rod_angle_limit=math.radians(60))
# a smaller rotary delta (forearm 400 mm) whose forearms can lie flat: a parallel singularity
FLAT = Delta3.from_radii(base_radius=200.0, platform_radius=50.0, upper_arm=350.0,
                         forearm=400.0, stroke=(math.radians(20), math.radians(120)))


def _box_points(m, n, seed):
    box = m.position_bounds(np.eye(3)[None])[0]
    return np.random.default_rng(seed).uniform(box[0], box[1], (n, 3))


def test_linear_ik_is_klippers_carriage_formula():
    """Klipper's delta stepper: carriage = z + sqrt(arm² - (x - tx)² - (y - ty)²), towers at
    delta_radius = 174.75 mm, 210/330/90 deg (written here from the formula)."""
    p = _box_points(KLIPPER, 20000, 0)
    ik = KLIPPER.inverse(p, stroke=NO_STROKE)
    a = np.radians([210.0, 330.0, 90.0])
    t = 174.75 * np.stack([np.cos(a), np.sin(a)], axis=1)
    h2 = 333.0 ** 2 - np.sum((p[:, None, :2] - t) ** 2, axis=-1)
    ref = p[:, 2:3] + np.sqrt(np.where(h2 >= 0, h2, np.nan))
    assert np.array_equal(np.isnan(ref), np.isnan(ik.q))
    ok = ~np.isnan(ref)
    assert ok.sum() > 20000 and np.max(np.abs(ik.q[ok] - ref[ok])) < 1e-9
    assert np.all((ik.leg_status == 4) == ~ok)               # no real solution exactly there


def test_rotary_ik_is_the_elbow_out_root_of_the_rod_equation():
    """θ_i solves |P_i - E_i(θ)| = b on the elbow circle (brentq on a 720-step scan); of the
    two roots the IK takes the one with the elbow farther from the z axis (elbow out)."""
    X = testing.random_valid_poses(CLAVEL, 10, seed=1, lin=150.0)
    q = CLAVEL.inverse(X).q
    for x, qk in zip(X, q, strict=True):
        for i in range(3):
            P = x[:3] + CLAVEL.platform_points[i]

            def f(t, P=P, i=i):
                return np.linalg.norm(P - CLAVEL.driven_points(np.array([[t, t, t]]))[0, i]) \
                    - CLAVEL.rod_length[i]

            grid = np.linspace(-np.pi, np.pi, 721)
            vals = np.array([f(t) for t in grid])
            roots = [brentq(f, grid[k], grid[k + 1], xtol=1e-14)
                     for k in np.flatnonzero(np.sign(vals[:-1]) != np.sign(vals[1:]))]
            assert len(roots) == 2
            E = [np.linalg.norm(CLAVEL.driven_points(np.full((1, 3), r))[0, i, :2])
                 for r in roots]
            assert abs(roots[int(np.argmax(E))] - qk[i]) < 1e-9


@pytest.mark.parametrize("m", [CLAVEL, KLIPPER, INCLINED], ids=["rotary", "linear",
                                                                  "inclined"])
def test_closed_form_modes_are_those_newton_finds(m):
    """Both trilateration points against the generic multi-start Newton on the loop closure
    (800 starts): the same two modes to 1e-7 mm, the working one first."""
    X = testing.random_valid_poses(m, 3, seed=4)
    for x in X:
        q = m.inverse(x).q[0]
        a = m.assembly_modes(q)
        b = multistart_modes(m, q, starts=800, seed=0, tol=1e-10)
        assert len(a.pose) == 2 and a.working_mode.tolist() == [True, False]
        np.testing.assert_allclose(a.pose[0, :3], x[:3], atol=1e-8)
        for pose in a.pose:
            assert np.min(np.linalg.norm(b.pose[:, :3] - pose[:3], axis=1)) < 1e-7
        assert len(b.pose) == 2


def test_forward_reports_failure_and_the_other_mode_is_not_working():
    fk = KLIPPER.forward(np.array([[290.0, 290.0, 290.0], [0.0, 580.0, 0.0]]), modes=True)
    assert fk.converged.tolist() == [True, False] and fk.status[1] == "not converged"
    assert not fk.ambiguous.any()
    # the mirror (effector above the carriages) has the same carriages but is another mode
    q = KLIPPER.inverse(KLIPPER.nominal_pose).q[0]
    modes = KLIPPER.assembly_modes(q)
    assert modes.pose[1, 2] > q[0]


def test_joint_limits_are_a_status_of_their_own():
    """The forearm cone (rotary) and the rod angle (linear) flag JOINT_LIMIT with the
    actuator value still reported; inside them the IK is valid."""
    x = CLAVEL.nominal_pose.copy()
    W = x[:3] + CLAVEL.platform_points - CLAVEL.base_points
    n = CLAVEL.servo_axes
    ang = np.degrees(np.arcsin(np.abs(np.sum(W * n, axis=1)) / CLAVEL.rod_length))
    assert np.all(ang < 35.0)
    x[:2] += 515.0 * n[0, :2]            # along leg 1's motor axis: its forearm leans out
    ik = CLAVEL.inverse(x, stroke=NO_STROKE)
    W = x[:3] + CLAVEL.platform_points - CLAVEL.base_points
    ang = np.degrees(np.arcsin(np.abs(np.sum(W * n, axis=1)) / CLAVEL.rod_length))
    beyond = ang > 35.0
    assert beyond[0] and np.all(np.isfinite(ik.q))
    assert np.all((ik.leg_status[0] == 8) == beyond)
    assert ik.reason_text[0] == "passive joint beyond its limit"
    lim = LDelta3.from_towers(rod_angle_limit=math.radians(60))
    p = np.array([[0.0, 0.0, 100.0], [-150.0, -80.0, 100.0]])
    ik = lim.inverse(p, stroke=NO_STROKE)
    d = np.hypot(*(p[:, None, :2] + lim.platform_points[:, :2] - lim.base_points[:, :2])
                 .transpose(2, 0, 1))
    assert np.array_equal(ik.leg_status == 8, d > 333.0 * math.sin(math.radians(60)))
    assert ik.valid.tolist() == [True, False]


def test_singularity_classification():
    """Regular at the nominal poses; parallel where the two assembly modes meet (h² = 0: the
    flat forearms of FLAT); serial where a rod is at right angles to its tower. The parallel
    measure is |det| of the unit rods taken from the joints (an independent path)."""
    for m in (CLAVEL, KLIPPER, INCLINED):
        s = m.singularities(m.nominal_pose)
        assert s.kind[0] == "regular"
        X = testing.random_valid_poses(m, 5, seed=7)
        ref = []
        for x in X:
            rods = np.array([leg.joints[2].location - leg.joints[1].location
                             for leg in m.legs(x)])
            ref.append(abs(np.linalg.det(rods / np.linalg.norm(rods, axis=1)[:, None])))
        np.testing.assert_allclose(m.singularities(X).parallel, ref, atol=1e-12)
    # FLAT: forearms horizontal at cos θ = (b - R + r)/a, the modes merge
    t = math.acos((400.0 - 200.0 + 50.0) / 350.0)
    fk = FLAT.forward(np.full(3, t))
    s = FLAT.singularities(fk.pose)
    assert fk.converged[0] and s.kind[0] == "parallel" and s.parallel[0] < 1e-6
    x, h2 = FLAT._fk_candidates(np.full((1, 3), t))[:2]
    assert abs(h2[0]) < 1e-6
    # KLIPPER: the effector 333 mm (the rod) from tower A's line: rod A horizontal
    a = math.radians(210.0)
    p = np.array([174.75 * math.cos(a) + 333.0, 174.75 * math.sin(a), 50.0])
    s = KLIPPER.singularities(p)
    assert s.kind[0] == "serial" and s.serial[0, 0] < 1e-6 and s.parallel[0] > 0.05


@pytest.mark.parametrize("m,span", [(CLAVEL, 450.0), (KLIPPER, 160.0), (INCLINED, 160.0)],
                         ids=["rotary", "linear", "inclined"])
def test_exact_columns_against_the_ik(m, span):
    """Each column's z set against the IK on a 0.5 mm grid (length to 2·dz per piece) and
    1e-9 mm inside / outside each end (pkmlab.testing.check_columns)."""
    n = testing.check_columns(m, np.eye(3)[None], np.linspace(-span, span, 5),
                              np.linspace(-span, span, 4), dz=0.5)
    assert n >= 9


@pytest.mark.parametrize("m,h", [(CLAVEL, 25.0), (KLIPPER, 10.0)], ids=["rotary", "linear"])
def test_exact_workspace_contains_every_feasible_sample(m, h):
    """A plain NumPy brute force on the engine's grid (IK at every voxel centre, x, y, z
    multiples of h): every feasible sample lies in its column's exact set, and per column the
    count × h is within h per piece of the exact length."""
    w = workspace(m, "constant", resolution=h, constraints=Constraints(connected=False))
    xs, ys = w.xs, w.ys
    zs = np.arange(math.floor(w.zs.min() / h) - 2, math.ceil(w.zs.max() / h) + 3) * h
    X, Y, Z = np.meshgrid(xs, ys, zs, indexing="ij")
    ok = m.inverse(np.stack([X.ravel(), Y.ravel(), Z.ravel()], axis=1)).valid
    ok = ok.reshape(X.shape)
    inside = np.zeros_like(ok)
    for k in range(w.lo.shape[-1]):
        inside |= (Z >= w.lo[..., k:k + 1] - 1e-9) & (Z <= w.hi[..., k:k + 1] + 1e-9)
    assert ok.sum() > 1000 and not np.any(ok & ~inside)
    pieces = np.sum(w.lo <= w.hi, axis=-1)
    length = np.sum(np.where(w.lo <= w.hi, w.hi - w.lo, 0.0), axis=-1)
    assert np.all(np.abs(ok.sum(axis=-1) * h - length) <= h * pieces + 1e-6)


@pytest.mark.parametrize("m,target", [(KLIPPER, 0.01), (CLAVEL, 0.05)],
                         ids=["linear", "rotary"])
def test_volume_bracket_brackets_the_column_volume(m, target):
    """The octree bracket reaches its target and holds the engine's exact-in-z volume on a
    2 mm x-y grid (converged: it moves by < 0.05 % from 4 to 2 to 1 mm, docs/validation.md)."""
    b = volume_bracket(m, target=target, budget_s=30.0)
    assert b.stop_reason == "converged" and b.upper - b.lower <= target * b.upper
    w = workspace(m, "constant", resolution=2.0, constraints=Constraints(connected=False))
    assert b.lower <= w.volume <= b.upper


def test_usable_radius_against_circles_of_ik():
    """r(z) closed form: a 3600-point circle 1e-6 mm inside is valid, 1e-4 mm outside not."""
    from pkmlab.mechanisms.families import delta_printer as dp

    a = np.linspace(0, 2 * np.pi, 3601)
    for z in (0.0, 150.0, 260.0, 290.0):
        r = float(dp.usable_radius(KLIPPER, z))
        for rr, want in ((r - 1e-6, True), (r + 1e-4, False)):
            P = np.stack([rr * np.cos(a), rr * np.sin(a), np.full_like(a, z)], axis=1)
            assert KLIPPER.inverse(P).valid.all() == want, (z, r)


def test_klipper_example_envelope():
    """Klipper's example printer (delta_radius 174.75, arm 333, endstop 297.05): the exact set
    is Klipper's taper above limit_z to 1e-9 mm and 1.144 mm wider below it, where Klipper
    caps the radius at its tower/XY speed ratio of 12 (157.106 mm) instead of the rod's reach
    (arm - radius = 158.25 mm, a rod horizontal: serial singular)."""
    from pkmlab.mechanisms.families import delta_printer as dp

    rk, c = dp.klipper_envelope(174.75, 333.0, 297.05)
    assert c["max_xy_mm"] == pytest.approx(157.10598, abs=1e-5)
    assert c["limit_z_mm"] == pytest.approx(247.51329, abs=1e-5)
    z = np.linspace(0.0, c["limit_z_mm"], 50)
    np.testing.assert_allclose(dp.usable_radius(KLIPPER, z), 158.25, atol=1e-9)
    z = np.linspace(c["limit_z_mm"] + 1.0, 297.0, 50)
    np.testing.assert_allclose(dp.usable_radius(KLIPPER, z), rk(z), atol=1e-9)
    cyl = dp.printable_cylinder(KLIPPER)
    assert cyl.radius == pytest.approx(158.25, abs=1e-9)
    fw = dp.firmware(KLIPPER, steps_per_mm=80)
    assert fw["values"]["homed_height_mm"] == pytest.approx(297.05, abs=1e-9)
    assert "delta_radius: 174.750" in fw["klipper"] and "arm_length: 333.000" in fw["klipper"]
    assert "#define DELTA_DIAGONAL_ROD 333.000" in fw["marlin"]
    assert "M665 L333.000 R174.750 H297.050 B158.250" in fw["reprap"]
    # the speed-ratio map agrees with Klipper's d/sqrt(l² - d²) at its slow-down radius
    sr = dp.speed_ratio_map(KLIPPER, 100.0, 160.0, n=81)
    assert np.nanmax(sr["ratio"]) > 12


def test_task_cylinder_proof_and_refutation():
    from pkmlab.mechanisms.families.delta_task import contains_cylinder, cylinder_samples

    ok, why = contains_cylinder(CLAVEL, (0.0, 0.0), 300.0, -950.0, -750.0)
    assert ok is True and why is None
    assert CLAVEL.inverse(cylinder_samples((0.0, 0.0), 300.0, -950.0, -750.0, 12)).valid.all()
    ok, why = contains_cylinder(CLAVEL, (0.0, 0.0), 400.0, -1000.0, -850.0)
    assert ok is False
    x = np.array([float(v) for v in why.split("(")[1].split(")")[0].split(",")])
    assert not CLAVEL.inverse(x).valid[0]


def test_a_study_brackets_a_delta_and_still_refuses_the_tripod(tmp_path):
    """The volume_bracket block serves a family with its own position bracket (the printer):
    the study validates and the baseline's bracket holds its workspace volume."""
    import yaml

    from pkmlab.study import evaluators as ev_mod
    from pkmlab.study.spec import load_study

    data = {"study": "delta-bracket", "mechanism": {"file": str(
        Path(__file__).resolve().parents[2] / "studies/mechanisms/klipper-example-ldelta3.yaml")},
        "design": {"rod_length": {"low": "320 mm", "high": "340 mm"}},
        "evaluate": {"workspace": {"kind": "constant", "resolution": "4 mm"},
                     "volume_bracket": {"budget": 20, "target": 0.02}},
        "objectives": [{"maximize": "workspace_volume_lower"}],
        "optimizer": {"method": "sobol", "samples": 2}, "output": str(tmp_path / "out")}
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data))
    s = load_study(path)
    rec = ev_mod.evaluate_design(s.space, None, s.evaluation, s.seed)
    assert rec["status"] == "ok", rec
    m = rec["metrics"]
    assert m["workspace_volume_lower"] <= m["workspace_volume"] <= m["workspace_volume_upper"]
    assert m["workspace_volume_bracket_width"] <= 2.0


def test_printer_block_and_command(tmp_path):
    """evaluate.printer is refused for a rotary delta, naming the block; `pkmlab printer`
    prints the envelope and a firmware snippet, and refuses a rotary delta in one line."""
    import yaml
    from typer.testing import CliRunner

    from pkmlab.cli import app
    from pkmlab.errors import ParameterError
    from pkmlab.study.spec import load_study

    root = Path(__file__).resolve().parents[2] / "studies" / "mechanisms"
    data = {"study": "p", "mechanism": {"file": str(root / "clavel-delta3.yaml")},
            "design": {"forearm": {"low": "700 mm", "high": "800 mm"}},
            "evaluate": {"printer": {}}, "objectives": [{"maximize": "printable_volume"}],
            "optimizer": {"method": "sobol", "samples": 2}, "output": str(tmp_path / "o")}
    path = tmp_path / "s.yaml"
    path.write_text(yaml.safe_dump(data))
    with pytest.raises(ParameterError, match=r"evaluate.printer .*printer needs linear actuators"):
        load_study(path)
    r = CliRunner().invoke(app, ["printer", str(root / "klipper-example-ldelta3.yaml"),
                                 "--firmware", "reprap"])
    assert r.exit_code == 0 and "M665 L333.000 R174.750 H297.050 B158.250" in r.output
    r = CliRunner().invoke(app, ["printer", str(root / "klipper-example-ldelta3.yaml")])
    assert r.exit_code == 0 and "printable cylinder: r = 158.250 mm" in r.output
    r = CliRunner().invoke(app, ["printer", str(root / "clavel-delta3.yaml")])
    assert r.exit_code == 2 and "mechanism: must be a linear delta" in r.output


def test_printer_speed_ratio_on_a_serial_singularity_is_null_with_a_note(monkeypatch):
    """Klipper's example prints out to the rods' reach (158.25 mm), where a rod is level (at
    right angles to its tower): the tower/XY speed ratio on the disc is unbounded and is stored
    empty with a note saying why (it was stored empty without one). A bounded map gives its
    largest value and no note."""
    from types import SimpleNamespace

    from pkmlab.mechanisms.families import delta_printer as dp
    from pkmlab.study.evaluators.printer import Printer, PrinterSpec

    ctx = SimpleNamespace(evaluation=SimpleNamespace(printer=PrinterSpec(grid=5)), notes={})
    out = Printer().compute(KLIPPER, ctx)
    assert out["printable_radius"] == pytest.approx(333 - 174.75, abs=1e-9)
    assert out["sampled_printer_speed_ratio"] is None
    assert "right angles to its tower" in ctx.notes["sampled_printer_speed_ratio"]
    real = dp.speed_ratio_map

    def bounded(*a, **k):
        m = real(*a, **k)
        m["ratio"] = np.where(np.isfinite(m["ratio"]), m["ratio"], 7.5)
        return m

    monkeypatch.setattr(dp, "speed_ratio_map", bounded)
    ctx.notes.clear()
    out = Printer().compute(KLIPPER, ctx)
    assert 7.5 <= out["sampled_printer_speed_ratio"] < math.inf and not ctx.notes
