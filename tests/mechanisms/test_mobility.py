"""Mobility as data: a three-leg translational family, written as a plugin, sizes every
kinematic result from its declaration; a kernel that writes another leg count raises."""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest
from numba.extending import register_jitable

from pkmlab.mechanisms import PLANAR, REGISTRY, SPATIAL, TRANSLATIONAL, register_family
from pkmlab.mechanisms.kernels import ik as _kernels
from pkmlab.mechanisms.mobility import Mobility
from pkmlab.testing import run_contract

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "data" / "plugin3"))
import pkmlab_tri3_family as tri3  # noqa: E402
from conftest import family_registered  # noqa: E402


@pytest.fixture(scope="module")
def tripod():
    with family_registered(tri3.Tri3):
        yield tri3.reporters_tripod()


def test_the_three_leg_family_passes_the_contract_suite(tripod):
    done = run_contract(tripod)
    assert done[0] == "declaration" and len(done) == 9, done


def test_2000_copies_of_a_reachable_pose_are_all_valid_and_sized_by_the_declaration(tripod):
    """The issue's reproduction: (N, 6) with legs 4-6 uninitialised, 49.65 % valid, before."""
    X = np.repeat([[0.0, 0.0, 400.0]], 2000, axis=0)         # free coordinates x, y, z
    ik = tripod.inverse(X)
    assert ik.q.shape == (2000, 3) and ik.leg_status.shape == (2000, 3)
    assert ik.valid.all()
    # independent: |p + u_i - b_i| by hand
    expected = np.linalg.norm(np.array([0.0, 0.0, 400.0]) + tri3.circle(60.0)
                              - tri3.circle(300.0), axis=1)
    np.testing.assert_allclose(ik.q, np.broadcast_to(expected, (2000, 3)), rtol=0, atol=1e-12)
    full = np.repeat([[0.0, 0.0, 400.0, 0.0, 0.0, 0.0]], 2000, axis=0)
    np.testing.assert_array_equal(tripod.inverse(full).q, ik.q)


def test_jacobian_forward_and_modes_are_sized_by_the_mobility(tripod):
    X = np.array([[10.0, -20.0, 380.0], [0.0, 0.0, 400.0]])
    J = tripod.jacobian(X)
    assert J.shape == (2, 3, 3)
    # a translational leg's row is its unit direction
    s = np.array([10.0, -20.0, 380.0]) + tri3.circle(60.0) - tri3.circle(300.0)
    np.testing.assert_allclose(J[0], s / np.linalg.norm(s, axis=1)[:, None], atol=1e-14)
    q = tripod.inverse(X).q
    fk = tripod.forward(q)
    assert fk.converged.all() and fk.pose.shape == (2, 6)
    np.testing.assert_allclose(fk.pose[:, :3], X, atol=1e-9)
    np.testing.assert_array_equal(fk.pose[:, 3:], 0.0)          # fixed at the nominal pose
    modes = tripod.assembly_modes(q[1], starts=200)
    # a translational 3-leg platform has two assembly modes: the mirror below the base plane
    assert len(modes.pose) == 2 and modes.working_mode[0]
    np.testing.assert_allclose(modes.pose[1, :3], [0.0, 0.0, -400.0], atol=1e-7)
    with pytest.raises(ValueError, match=r"q: must be an array of shape \(3,\) or \(N, 3\)"):
        tripod.forward(np.zeros(6))


@register_jitable(inline="always")
def _four_of_three(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st,
                   j):
    for i in range(4):              # one leg more than the three the family declares
        k = min(i, 2)
        v = math.sqrt((px - g[3 * k]) ** 2 + (py - g[3 * k + 1]) ** 2 + (pz - g[3 * k + 2]) ** 2)
        q[i * _kernels.ROW + j] = v
        st[i * _kernels.ROW + j] = _kernels.stroke_status(v, qmin, qmax)


@dataclass(frozen=True, eq=False)
class _ThreeAsSix(tri3.Tri3):
    """A three-leg kernel behind the default declaration (six actuators, spatial), as a plugin
    written from the README's six-leg example would be."""
    family = "tri3-as-six"
    mobility = SPATIAL
    actuator_names = ("q1", "q2", "q3", "q4", "q5", "q6")


@dataclass(frozen=True, eq=False)
class _FourOfThree(tri3.Tri3):
    family = "tri3-four"
    _ik_one = _four_of_three


@pytest.mark.parametrize("cls, wrote", [(_ThreeAsSix, "fewer"), (_FourOfThree, "more")])
def test_a_kernel_writing_another_leg_count_raises(cls, wrote):
    mech = cls(tri3.circle(300.0), tri3.circle(60.0), (250.0, 600.0),
               nominal=np.array([0.0, 0.0, 400.0, 0.0, 0.0, 0.0]))
    X = np.repeat([[0.0, 0.0, 400.0, 0.0, 0.0, 0.0]], 2000, axis=0)
    with pytest.raises(RuntimeError, match=f"did not write exactly the {mech.n_actuators} legs"):
        mech.inverse(X)
    with pytest.raises(RuntimeError, match="did not write exactly"):
        mech.inverse((X[:, :3], np.repeat(np.eye(3)[None], 2000, axis=0)))


def test_the_plugin_check_compares_actuators_with_the_mobility():
    @dataclass(frozen=True, eq=False)
    class TooFew(tri3.Tri3):
        family = "tri3-too-few"
        mobility = SPATIAL
        actuator_names = ("q1", "q2", "q3")

    with pytest.raises(TypeError, match="at least one distinct actuator per free coordinate"):
        register_family(TooFew)
    assert "tri3-too-few" not in REGISTRY


def test_mobility_declarations():
    assert SPATIAL.width == 6 and SPATIAL.is_spatial and SPATIAL.rotations
    assert TRANSLATIONAL.twist_columns.tolist() == [0, 1, 2] and not TRANSLATIONAL.rotations
    assert PLANAR.twist_columns.tolist() == [0, 1, 5] and PLANAR.units == ("mm", "mm", "rad")
    full = PLANAR.full([[1.0, 2.0, 0.5]], [0, 0, 300.0, 0, 0, 0.1])
    np.testing.assert_array_equal(full, [[1.0, 2.0, 300.0, 0.0, 0.0, 0.5]])
    np.testing.assert_array_equal(PLANAR.free(full), [[1.0, 2.0, 0.5]])
    for bad in (("z", "x"), ("x", "x"), ("x", "theta_x"), ("roll",)):
        with pytest.raises(ValueError):
            Mobility("bad", bad)
    with pytest.raises(ValueError, match=r"poses: must be an array of shape \(3,\)"):
        TRANSLATIONAL.full(np.zeros((2, 4)), np.zeros(6))


# the workspace, dexterity and study layers on this family: tests/mechanisms/test_low_mobility.py


def test_the_fk_mode_check_moves_the_free_coordinates_only(tripod):
    fk = tripod.forward(tripod.inverse([[5.0, 5.0, 390.0]]).q, modes=True)
    assert fk.converged.all() and not fk.ambiguous.any()     # the mirror is below the base
    assert fk.mode_starts > 1 and np.isnan(fk.next_mode).all()


def test_pkmlab_fk_takes_one_value_per_declared_actuator(tripod, tmp_path, capsys):
    """`pkmlab fk` asked for six values whatever the family declared (and then refused six)."""
    import json

    from clihelp import cli

    f = tmp_path / "tri3.yaml"
    f.write_text("family: tri3\nbase_points: " + str(tri3.circle(300.0).tolist())
                 + "\nplatform_points: " + str(tri3.circle(60.0).tolist())
                 + "\nstroke: [250, 600]\n")
    q = tripod.inverse([[0.0, 0.0, 400.0]]).q[0]
    code, out, err = cli(capsys, "fk", f, "--actuators", ",".join(f"{v:.9f}" for v in q),
                         "--json")
    assert code == 0, err
    pose = json.loads(out)["pose"]
    assert abs(pose["z"] - 400.0) < 1e-6 and abs(pose["x"]) < 1e-6
    code, _, err = cli(capsys, "fk", f, "--actuators", "1,2,3,4,5,6")
    assert code == 2 and "--actuators: must be 3 comma-separated values" in err, err


def _tri3_file(tmp_path):
    f = tmp_path / "tri3.yaml"
    f.write_text("family: tri3\nbase_points: " + str(tri3.circle(300.0).tolist())
                 + "\nplatform_points: " + str(tri3.circle(60.0).tolist())
                 + "\nstroke: [250, 600]\n")
    return f


def test_pkmlab_ik_takes_the_free_coordinates_and_prints_them(tripod, tmp_path, capsys):
    """`pkmlab ik --pose` asked for six coordinates whatever the mobility."""
    import json

    from clihelp import cli

    f = _tri3_file(tmp_path)
    code, out, err = cli(capsys, "ik", f, "--pose", "5,-3,400", "--json")
    assert code == 0, err
    data = json.loads(out)
    q = tripod.inverse([[5.0, -3.0, 400.0]]).q[0]
    assert data["valid"] and np.allclose(list(data["actuators"].values()), q, atol=1e-9)
    code, out, err = cli(capsys, "ik", f, "--pose", "5,-3,400")
    assert code == 0 and "pose: x=5.0000 y=-3.0000 z=400.0000 mm\n" in out, out
    code, _, err = cli(capsys, "ik", f, "--pose", "5,-3")
    assert code == 2 and "--pose: must be 3 comma-separated values (x,y,z) or all six" in err


def test_the_trajectory_check_balances_the_payload_on_the_tripods_three_legs(tripod):
    """check_trajectory refused any mechanism but a six-DOF one. On the tripod the paper's motion
    moves x, y, z only, and the leg forces balance the payload's weight: Σ f_i·u_i = −m·g with
    u_i the unit leg directions from an independent NumPy computation (to 1e-9 N)."""
    from pkmlab.motion import check_trajectory, paper_motion

    motion = paper_motion(tripod)
    assert np.ptp(motion.poses[:, 3:], axis=0).max() == 0.0      # the angles stay nominal
    assert np.ptp(motion.poses[:, :3], axis=0) == pytest.approx([101.6] * 3)
    rep = check_trajectory(tripod, motion.t, motion.poses, payload_mass_kg=5.0,
                           max_force=30.0)
    assert rep.q.shape == (len(motion.t), 3) and rep.force.shape == (len(motion.t), 3)
    W = motion.poses[:, None, :3] + tripod.platform_points[None] - tripod.tool_offset
    u = W - tripod.base_points[None]
    u /= np.linalg.norm(u, axis=2, keepdims=True)
    total = np.einsum("ti,tij->tj", rep.force, u)
    np.testing.assert_allclose(total, np.broadcast_to([0.0, 0.0, 5.0 * 9.81],
                                                      total.shape), atol=1e-9)
    assert rep.violations["force"] is None and rep.fits
    same = check_trajectory(tripod, motion.t, motion.poses[:, :3], payload_mass_kg=5.0)
    np.testing.assert_array_equal(same.force, rep.force)


def test_inverse_dynamics_of_the_tripod_balances_newtons_law(tripod):
    """Newton–Euler refused lower mobilities. On the translating tripod a sinusoid in x, y, z
    carrying 3 kg: Σ f_i·u_i = m·(a − g) at every sample (g = −9806.65 mm/s² ẑ), to 1e-9 N,
    from NumPy leg directions."""
    from pkmlab.motion.dynamics import inverse_dynamics
    from pkmlab.motion.motions import sinusoid_motion
    from pkmlab.motion.payload import GRAVITY, MassProperties

    m = sinusoid_motion(tripod, [20.0, -15.0, 30.0, 0, 0, 0], [1.0, 1.5, 2.0, 0, 0, 0],
                        duration=1.0, rate=100.0)
    body = MassProperties(3.0, np.zeros(3), np.eye(3) * 1e3)
    res = inverse_dynamics(tripod, m, body)
    assert res.force.shape == (101, 3) and np.all(res.code == 0)
    W = m.poses[:, None, :3] + tripod.platform_points[None] - tripod.tool_offset
    u = W - tripod.base_points[None]
    u /= np.linalg.norm(u, axis=2, keepdims=True)
    total = np.einsum("ti,tij->tj", res.force, u)                    # N
    expected = 3.0 * (m.accel[:, :3] + [0.0, 0.0, GRAVITY]) * 1e-3    # kg·mm/s² → N
    np.testing.assert_allclose(total, expected, atol=1e-9)
    np.testing.assert_allclose(res.qdot, np.einsum("tij,tj->ti", u, m.twist[:, :3]),
                               atol=1e-9)
