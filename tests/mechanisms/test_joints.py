"""Joints and parameters as data (issue 23 item 2): each leg's joint chain closes at random
valid poses for every family (built-in, random ``sixleg`` machines of every leg kind, the test
plugins), the checks catch wrong declarations, the parameter vector round-trips, and a
parameter's effect on the IK matches a hand formula (central differences, step 1e-3 mm)."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import MECHANISMS

from pkmlab import testing
from pkmlab.mechanisms import NO_STROKE, PSU6, RSS6, UPS6, Luzi3
from pkmlab.mechanisms.joints import JointsMixin, chain_errors
from pkmlab.poses import as_frames

DATA = Path(__file__).resolve().parents[1] / "data"
sys.path[:0] = [str(DATA / "plugin"), str(DATA / "plugin3")]
import pkmlab_demo_family as demo  # noqa: E402
import pkmlab_tri3_family as tri3  # noqa: E402


def _randoms():
    rng = np.random.default_rng(23)
    kinds = {"crank": ["crank"] * 6, "slider-any": ["slider"] * 6,
             "prismatic": ["prismatic"] * 6, "mixed": ["prismatic", "slider"] * 3}
    out = {}
    for name, k in kinds.items():
        for lower in ("negative", "positive"):
            if name == "prismatic" and lower == "negative":
                continue
            out[f"sixleg-{name}-{lower}"] = testing.random_sixleg(rng, k, lower)
    return out


EXTRA = {**_randoms(), "tri3": tri3.reporters_tripod(
    nominal=np.array([0.0, 0.0, 400.0, 0.0, 0.0, 0.0])),
    "legs6": demo.Legs6(MECHANISMS["gough-stewart-6ups"].base_points,
                        MECHANISMS["gough-stewart-6ups"].platform_points, (400.0, 700.0))}
ALL = {**MECHANISMS, **EXTRA}


@pytest.mark.parametrize("name", sorted(EXTRA))
def test_joint_chains_close_on_random_sixlegs_and_plugins(name):
    testing.check_joints(EXTRA[name])


@pytest.mark.parametrize("name", sorted(ALL))
def test_parameters_round_trip_and_name_every_joint(name):
    m = ALL[name]
    testing.check_parameters(m)
    P = m.parameters()
    L = len(m.platform_points)
    for i in range(len(m.base_points)):
        assert {f"base{i + 1}.{c}" for c in "xyz"} <= set(P.names)
    # a five-bar's distal joints are its tool point: no platform points, no tool offset
    declared = {f.field for f in m.parameter_fields}
    for i in range(L if "platform_points" in declared else 0):
        assert {f"platform{i + 1}.{c}" for c in "xyz"} <= set(P.names)
    assert {"stroke_min", "stroke_max"} <= set(P.names)
    if "tool_offset" in declared:
        assert {"tool_offset.x", "tool_offset.z"} <= set(P.names)
    assert P.units[P.index("stroke_max")] == m.actuator_unit


def test_chain_types_and_bodies_per_family():
    types = {"psu6": ("P", "S", "U"), "ups6": ("U", "P", "S"), "rss6": ("R", "S", "S"),
             "luzi3": ("U", "P", "R", "U"), "tri3": ("U", "P", "U"), "legs6": ("U", "P", "S")}
    for m in ALL.values():
        legs = m.legs()
        assert [leg.name for leg in legs] == list(m.actuator_names)
        if m.family in types:
            assert {tuple(j.type for j in leg.joints) for leg in legs} == {types[m.family]}
    kinds = {"prismatic": ("U", "P", "S"), "slider": ("P", "S", "U"), "crank": ("R", "S", "S")}
    m = EXTRA["sixleg-mixed-positive"]
    assert [tuple(j.type for j in leg.joints) for leg in m.legs()] == \
        [kinds[k] for k in m.leg_kinds]


def test_luzi3_joints_follow_the_paper():
    """Fig. 2 of Luzi et al.: U at A_ij whose fixed axes are collinear (along the chord) and
    whose moving axes are parallel to the R axes at B_ij (the chain plane's normal); the two
    legs of a chain share the upper link and the platform U at C_i (axes t_i and k)."""
    m = MECHANISMS["luzi-3chain"]
    X = testing.random_valid_poses(m, 3, seed=4)
    for x in X:
        legs = m.legs(x)
        p, R = as_frames(x)
        for c in range(3):
            a, b = legs[2 * c], legs[2 * c + 1]
            chord = m.base_points[2 * c + 1] - m.base_points[2 * c]
            chord /= np.linalg.norm(chord)
            for leg in (a, b):
                U, _, Rj, C = leg.joints
                assert np.linalg.norm(np.cross(U.axes[0], chord)) < 1e-12
                assert abs(U.axes[1] @ Rj.axes[0]) == pytest.approx(1.0, abs=1e-12)
                normal = np.cross(chord, C.location - U.location)
                assert np.linalg.norm(np.cross(Rj.axes[0], normal)) < 1e-12 * np.linalg.norm(
                    normal)
                np.testing.assert_allclose(C.axes[1], R[0][:, 2], atol=1e-12)
            assert a.joints[3].name == b.joints[3].name == f"chain{c + 1}.platform_U"
            assert a.links[2].name == b.links[2].name == f"chain{c + 1}.upper_link"
            np.testing.assert_allclose(a.joints[3].location, b.joints[3].location, atol=1e-12)
            t = b.joints[2].location - a.joints[2].location        # B_i2 - B_i1 ∥ t_i, |.| = l
            assert np.linalg.norm(t) == pytest.approx(m.upper_link, rel=1e-12)
            np.testing.assert_allclose(a.joints[3].axes[0], t / m.upper_link, atol=1e-12)


class _Mis(Luzi3):
    """Declares the upper link's half one mm too long."""
    def _leg_templates(self):
        return tuple(t._replace(lengths=(0.0, 0.0, t.lengths[2] + 1.0))
                     for t in super()._leg_templates())


class _WrongPoint(UPS6):
    """Puts leg 1's platform joint on platform point 2."""
    def _joint_arrays(self, p, R, axes=True):
        arr = super()._joint_arrays(p, R, axes)
        c = [x.copy() for x in arr.centre]
        c[1][:, 0], c[2][:, 0] = c[1][:, 1], c[2][:, 1]         # P location and S
        return arr._replace(centre=tuple(c))


class _WrongZero(PSU6):
    """Declares the sliders' zero 1 mm low: the base point is then not a base point."""
    def _leg_templates(self):
        return tuple(t._replace(zero=t.zero - [0.0, 0.0, 1.0], base_point=t.zero - [0, 0, 1.0])
                     for t in super()._leg_templates())


class _RailSign(PSU6):
    """The rails' direction reversed (the actuated coordinate is then -q)."""
    def _joint_arrays(self, p, R, axes=True):
        arr = super()._joint_arrays(p, R, axes)
        if axes:
            arr.axes[:, :, 0, 0] *= -1.0
        return arr


class _SkewU(PSU6):
    """Platform U axes not orthogonal."""
    def _joint_arrays(self, p, R, axes=True):
        arr = super()._joint_arrays(p, R, axes)
        if axes:
            arr.axes[:, :, 2, 0] = arr.axes[:, :, 2, 1]
        return arr


class _CrankSign(RSS6):
    """The crank's reference direction reversed (angles off by π)."""
    def _leg_templates(self):
        return tuple(t._replace(reference=-t.reference) for t in super()._leg_templates())


@pytest.mark.parametrize("cls, base, what", [
    (_Mis, "luzi-3chain", "link_mm"), (_WrongPoint, "gough-stewart-6ups", "platform_mm"),
    (_WrongZero, "hopkins-williams-6psu", "base_mm"),
    (_RailSign, "hopkins-williams-6psu", "coordinate"),
    (_SkewU, "hopkins-williams-6psu", "u_orthogonal"),
    (_CrankSign, "instructables-servo-6rss", "coordinate")])
def test_the_joint_check_catches_wrong_declarations(cls, base, what):
    m = MECHANISMS[base]
    bad = cls(**{f.name: getattr(m, f.name) for f in dataclasses.fields(m) if f.init})
    assert chain_errors(bad, None)[what] > 1e-3
    with pytest.raises(AssertionError, match=what):
        testing.check_joints(bad)


def test_the_parameter_check_catches_a_lossy_vector():
    class Lossy(PSU6):
        def parameters(self):
            P = super().parameters()
            return dataclasses.replace(P, values=np.round(P.values, 3))

    m = MECHANISMS["hopkins-williams-6psu"]
    bad = Lossy(**{f.name: getattr(m, f.name) for f in dataclasses.fields(m) if f.init})
    with pytest.raises(AssertionError, match="differs"):
        testing.check_parameters(bad)


# ---- a parameter's effect on the IK, against hand formulas ----------------------------------
H = 1e-3


def _dq(m, name, X):
    """Central difference of the IK at the poses ``X`` (held fixed) in parameter ``name``."""
    v = m.parameters()[name]
    up = m.with_parameters({name: v + H}).inverse(X, stroke=NO_STROKE).q
    down = m.with_parameters({name: v - H}).inverse(X, stroke=NO_STROKE).q
    return (up - down) / (2 * H)


def _legs_at(m, X):
    return [m.legs(x) for x in X]


def _only(dq, i, expected, tol):
    """Leg ``i`` changes as ``expected``; the others do not move."""
    np.testing.assert_allclose(dq[:, i], expected, rtol=tol, atol=tol)
    others = np.delete(dq, i, axis=1)
    assert np.abs(others).max() == 0.0


def test_ups6_leg_length_against_base_and_platform_points():
    """``q_i = |W_i - B_i|``: ``∂q_i/∂B_i = -n_i``, ``∂q_i/∂P_i = Rᵀ n_i``, and ``∂q/∂O =
    -Rᵀ n`` for every leg (``n_i`` the unit leg)."""
    m = MECHANISMS["gough-stewart-6ups"]
    X = testing.random_valid_poses(m, 5, seed=8)
    _, R = as_frames(X)
    n = np.array([[(leg.joints[2].location - leg.joints[0].location) / leg.value
                   for leg in legs] for legs in _legs_at(m, X)])
    _only(_dq(m, "base3.x", X), 2, -n[:, 2, 0], 1e-7)
    _only(_dq(m, "base5.z", X), 4, -n[:, 4, 2], 1e-7)
    local = np.einsum("nji,nkj->nki", R, n)                       # Rᵀ n
    _only(_dq(m, "platform2.y", X), 1, local[:, 1, 1], 1e-7)
    np.testing.assert_allclose(_dq(m, "tool_offset.x", X), -local[..., 0], atol=1e-7)


def test_psu6_slider_against_link_length_and_rail_zero():
    """``q_i = W_iz - B_iz - h_i``, ``h_i = sqrt(l_i² - |W_i - B_i|²_xy)``: ``∂q_i/∂l_i =
    -l_i/h_i`` and ``∂q_i/∂B_iz = -1``."""
    m = MECHANISMS["hopkins-williams-6psu"]
    X = testing.random_valid_poses(m, 5, seed=9)
    h = np.array([[(leg.joints[2].location - leg.joints[1].location)[2] for leg in legs]
                  for legs in _legs_at(m, X)])
    _only(_dq(m, "link_length4", X), 3, -m.link_length[3] / h[:, 3], 1e-7)
    _only(_dq(m, "base1.z", X), 0, -1.0, 1e-9)


def test_rss6_crank_angle_against_rod_and_crank_lengths():
    """``|W - C(α)| = s`` with ``C = B + a(cos α u + sin α v)``: ``∂α/∂s = -s/(d·∂C/∂α)``
    and ``∂α/∂a = -(d·(C - B)/a)/(d·∂C/∂α)``, ``d = W - C``."""
    m = MECHANISMS["instructables-servo-6rss"]
    X = testing.random_valid_poses(m, 5, seed=10)
    q = m.inverse(X).q
    legs = _legs_at(m, X)
    k = 2
    B = m.base_points[k]
    C = np.array([lg[k].joints[1].location for lg in legs])
    W = np.array([lg[k].joints[2].location for lg in legs])
    a, s = m.crank_length[k], m.rod_length[k]
    dC = a * (-np.sin(q[:, k, None]) * m.zero_directions[k]
              + np.cos(q[:, k, None]) * m.v_directions[k])
    d = W - C
    den = np.sum(d * dC, axis=1)
    _only(_dq(m, "rod_length3", X), k, -s / den, 1e-6)
    _only(_dq(m, "crank_length3", X), k, -np.sum(d * (C - B), axis=1) / a / den, 1e-6)


def test_luzi3_leg_lengths_against_the_upper_link():
    """``q_i1 = |C_i - (l/2) t_i - A_i1|``, ``q_i2 = |C_i + (l/2) t_i - A_i2|`` with ``t_i``
    independent of ``l``: ``∂q_i1/∂l = -t_i·e_i1/(2 q_i1)``, ``∂q_i2/∂l = t_i·e_i2/(2 q_i2)``,
    ``e_ij = B_ij - A_ij``; every leg moves."""
    m = MECHANISMS["luzi-3chain"]
    X = testing.random_valid_poses(m, 5, seed=11)
    exp = []
    for legs in _legs_at(m, X):
        row = []
        for k, leg in enumerate(legs):
            t = leg.joints[3].axes[0]
            e = leg.joints[2].location - leg.joints[0].location
            row.append((1 if k % 2 else -1) * (t @ e) / (2 * leg.value))
        exp.append(row)
    np.testing.assert_allclose(_dq(m, "upper_link", X), np.array(exp), rtol=1e-6, atol=1e-9)


def test_sixleg_inclined_slider_against_its_link_length():
    """``q = d·e + b·h``, ``h = sqrt(l² - |d - (d·e)e|²)``: ``∂q/∂l = b·l/h``, ``h`` the link's
    component along the rail, ``(W - S)·e = -b·h``."""
    m = EXTRA["sixleg-slider-any-positive"]
    X = testing.random_valid_poses(m, 5, seed=12)
    k = 1
    h = np.array([-m.branch[k] * (lg[k].joints[2].location - lg[k].joints[1].location)
                  @ m.axes[k] for lg in _legs_at(m, X)])
    _only(_dq(m, "link_length2", X), k, m.branch[k] * m.link_length[k] / h, 1e-6)


def test_rss6_link_segments_are_cranks_and_rods():
    """Independently of the joints: cranks pivot → ``crank_ends(q)``, rods → the platform
    joints, exactly as before the segments read the joints."""
    m = MECHANISMS["instructables-servo-6rss"]
    X = testing.random_valid_poses(m, 50, seed=13)
    p, R = as_frames(X)
    C = m.crank_ends(m.inverse((p, R), stroke=NO_STROKE).q)
    W = p[:, None, :] + np.einsum("nij,kj->nki", R, m.tool_points)
    start, end, leg = m.link_segments(p, R)
    np.testing.assert_array_equal(start, np.concatenate(
        [np.broadcast_to(m.base_points, C.shape), C], axis=1))
    np.testing.assert_array_equal(end, np.concatenate([C, W], axis=1))
    np.testing.assert_array_equal(leg, np.tile(np.arange(6), 2))


def test_a_family_without_joints_fails_the_contract_by_name():
    class NoJoints(UPS6):
        _joint_arrays = JointsMixin._joint_arrays          # the protocol's: not declared

    m = MECHANISMS["gough-stewart-6ups"]
    bad = NoJoints(**{f.name: getattr(m, f.name) for f in dataclasses.fields(m) if f.init})
    with pytest.raises(AssertionError, match="declares no joints"):
        testing.check_joints(bad)

