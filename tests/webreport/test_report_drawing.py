"""The report's 3-D mechanism drawing reads the declared joints (issue 23 item 2, issue 26
item 1 "the crank drawn in the 3-D view"), for every shipped mechanism, a ``sixleg`` of crank
legs, a mixed ``sixleg`` and the three-leg ``tri3`` plugin, from the same code.

Checked on the plotly traces the report embeds: each leg's drawn polyline has the declared
joint points as its vertices, in chain order (to 1e-9 mm); independently of the joints, its
first vertex is a base point, its last the platform joint ``p + R (P_i - O)``, and the drawn
pieces between consecutive joints have the declared link lengths (the chain closes from base to
platform); an rss6 drawing contains the cranks, pivot → ``crank_ends(q)``; one marker per
joint, the actuated ones apart. And a ``sixleg`` of crank legs has the same interference
segments (cranks included) and crank-borne joint axes as the rss6 it was built from.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import MECHANISMS

from pkmlab import testing
from pkmlab.mechanisms import NO_STROKE
from pkmlab.mechanisms.families.sixleg import SixLeg
from pkmlab.poses import as_frames
from pkmlab.webreport.figures import design_scene, mechanism_traces, overlay_scene

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "data" / "plugin3"))
import pkmlab_tri3_family as tri3  # noqa: E402

TOL = 1e-9          # mm
RSS6 = MECHANISMS["instructables-servo-6rss"]
EXTRA = {
    "tri3": tri3.reporters_tripod(nominal=np.array([0.0, 0.0, 400.0, 0.0, 0.0, 0.0])),
    "sixleg-of-rss6": SixLeg.from_mechanism(RSS6),
    "sixleg-mixed": testing.random_sixleg(np.random.default_rng(26),
                                          ["prismatic", "slider"] * 3, "positive"),
}
ALL = {**MECHANISMS, **EXTRA}


def _trace(traces, name):
    (t,) = [t for t in traces if t.name == name]
    return t


def _pieces(trace) -> list[np.ndarray]:
    """A lines trace's polylines (split at ``None``)."""
    out, cur = [], []
    for x, y, z in zip(trace.x, trace.y, trace.z, strict=True):
        if x is None:
            out.append(np.array(cur))
            cur = []
        else:
            cur.append((x, y, z))
    if cur:
        out.append(np.array(cur))
    return out


def _declared(leg) -> tuple[np.ndarray, list[int]]:
    """The declared joint points of a leg (a P joint: zero, location) and where each joint's
    ``location`` sits in that list."""
    pts, at = [], []
    for j in leg.joints:
        if j.type == "P":
            pts.append(j.zero)
        at.append(len(pts))
        pts.append(j.location)
    return np.array(pts), at


@pytest.mark.parametrize("name", sorted(ALL))
def test_each_leg_is_drawn_through_its_declared_joints(name):
    m = ALL[name]
    legs = m.legs()
    chains = _pieces(_trace(mechanism_traces(m), "legs (joint chains)"))
    assert len(chains) == m.n_actuators == len(legs)
    p, R = as_frames(m.nominal_pose)
    W = p[0] + (np.asarray(m.platform_points) - m.tool_offset) @ R[0].T  # platform joints
    base = np.asarray(m.base_points)
    for leg, V in zip(legs, chains, strict=True):
        E, at = _declared(leg)
        assert V.shape == E.shape, (leg.name, V.shape, E.shape)
        np.testing.assert_allclose(V, E, rtol=0, atol=TOL, err_msg=leg.name)
        # independently of the joints: fixed to a base point, ends on a platform joint
        assert np.min(np.linalg.norm(base - V[0], axis=1)) <= TOL, leg.name
        assert np.min(np.linalg.norm(W - V[-1], axis=1)) <= TOL, leg.name
        # consecutive joints connected: each link is drawn with its declared length
        for k, link in enumerate(leg.links):
            start = V[at[k]]
            end = V[at[k + 1] - 1] if leg.joints[k + 1].type == "P" else V[at[k + 1]]
            assert abs(np.linalg.norm(end - start) - link.length) <= TOL, (leg.name, k)
        # a P joint's travel (zero → location) is the actuator's value along its axis
        act = leg.actuated
        if act.type == "P":
            d = V[at[leg.actuated_index]] - V[at[leg.actuated_index] - 1]
            assert abs(d @ act.axes[0] - leg.value) <= TOL
    q = m.inverse(m.nominal_pose, stroke=NO_STROKE).q[0]
    np.testing.assert_allclose([leg.value for leg in legs], q, rtol=0, atol=TOL)


@pytest.mark.parametrize("name", sorted(ALL))
def test_joint_markers_by_type_actuated_apart_and_outlines(name):
    m = ALL[name]
    traces = mechanism_traces(m)
    joints = [j for leg in m.legs() for j in leg.joints]
    labels = {"S": "S joints (ball)", "U": "U joints (universal)", "R": "R joints (revolute)",
              "P": "P joints (prismatic)"}
    for kind, label in labels.items():
        want = sum(j.type == kind and not j.actuated for j in joints)
        have = [t for t in traces if t.name == label]
        assert (len(have[0].x) if have else 0) == want, kind
    act = _trace(traces, "actuators (actuated joints)")
    assert len(act.x) == m.n_actuators
    assert list(act.marker.symbol) == [{"S": "circle", "U": "diamond", "R": "square",
                                        "P": "cross"}[leg.actuated.type] for leg in m.legs()]
    base = _pieces(_trace(traces, "base"))[0]
    assert np.all(np.min(np.linalg.norm(base[:, None] - np.asarray(m.base_points)[None],
                                        axis=2), axis=1) <= TOL)
    plat = _pieces(_trace(traces, "platform (nominal pose)"))[0]
    mounted = np.array([j.location for j in joints if j.mount == "platform"])
    distinct = {tuple(np.round(x, 6)) for x in mounted}
    closed = len(distinct) >= 3
    assert len(plat) == len(distinct) + closed
    assert np.all(np.min(np.linalg.norm(plat[:, None] - mounted[None], axis=2), axis=1)
                  <= TOL)


def _has_segment(pieces, a, b) -> bool:
    return any(np.linalg.norm(P[k] - a) <= TOL and np.linalg.norm(P[k + 1] - b) <= TOL
               for P in pieces for k in range(len(P) - 1))


@pytest.mark.parametrize("name", ["instructables-servo-6rss", "sixleg-of-rss6"])
def test_the_cranks_are_drawn(name):
    """Pivot → crank end (``RSS6.crank_ends``, not the joints) in the chains and as the
    actuated members, at the nominal pose and at random valid poses: the rods do not float."""
    m = ALL[name]
    X = np.vstack([m.nominal_pose, testing.random_valid_poses(m, 3, seed=26)])
    for i, x in enumerate(X):
        traces = mechanism_traces(m, pose=None if i == 0 else x)
        chains = _pieces(_trace(traces, "legs (joint chains)"))
        moved = _pieces(_trace(traces, "actuated members"))
        C = RSS6.crank_ends(RSS6.inverse(x, stroke=NO_STROKE).q)[0]
        for k in range(len(C)):
            assert _has_segment(chains, RSS6.base_points[k], C[k]), (i, k)
            assert _has_segment(moved, RSS6.base_points[k], C[k]), (i, k)


def test_sixleg_crank_legs_interfere_and_carry_cones_as_rss6():
    """A ``sixleg`` of crank legs: its interference segments are the rss6's cranks and rods
    (they were the rods alone), and its crank-end joint axes turn with the cranks."""
    s = EXTRA["sixleg-of-rss6"]
    p, R = as_frames(testing.random_valid_poses(RSS6, 20, seed=27))
    a, b, leg = s.link_segments(p, R)
    C = RSS6.crank_ends(RSS6.inverse((p, R), stroke=NO_STROKE).q)
    W = p[:, None, :] + np.einsum("nij,kj->nki", R, RSS6.tool_points)
    np.testing.assert_allclose(a, np.concatenate([np.broadcast_to(RSS6.base_points, C.shape),
                                                  C], axis=1), rtol=0, atol=TOL)
    np.testing.assert_allclose(b, np.concatenate([C, W], axis=1), rtol=0, atol=TOL)
    np.testing.assert_array_equal(leg, np.tile(np.arange(6), 2))
    axes = np.random.default_rng(5).normal(size=(6, 3))
    axes /= np.linalg.norm(axes, axis=1, keepdims=True)
    turned = s.base_joint_axes(p, R, axes)
    # independently: in each crank's frame (crank direction, n × crank, servo axis) the axis
    # keeps its nominal coordinates
    pn, Rn = as_frames(RSS6.nominal_pose)
    Cn = RSS6.crank_ends(RSS6.inverse((pn, Rn), stroke=NO_STROKE).q)[0]
    n = RSS6.servo_axes

    def frame(c):
        u = (c - RSS6.base_points) / RSS6.crank_length[:, None]
        return np.stack([u, np.cross(n, u), n], axis=1)          # (6, 3, 3) rows

    local = np.einsum("kij,kj->ki", frame(Cn), axes)
    for t in range(len(p)):
        np.testing.assert_allclose(np.einsum("kij,kj->ki", frame(C[t]), turned[t]), local,
                                   rtol=0, atol=1e-9)


def test_lower_mobility_and_overlay_scenes():
    """The tri3 plugin in a design scene (three legs, no literal six) and two mechanisms
    overlaid on the compare page's scene: one legend entry each, hidden until chosen."""
    fig = design_scene(EXTRA["tri3"], None)
    assert len(_pieces(_trace(fig.data, "legs (joint chains)"))) == 3
    fig = overlay_scene([{"label": "a", "mechanism": EXTRA["tri3"]},
                         {"label": "b", "mechanism": RSS6}])
    for label in ("a", "b"):
        mine = [t for t in fig.data if t.legendgroup == f"mech-{label}"]
        assert sum(bool(t.showlegend) for t in mine) == 1
        assert {t.visible for t in mine} == {"legendonly"}
    assert _has_segment(_pieces(_trace(fig.data, "b: legs (joint chains)")),
                        RSS6.base_points[0],
                        RSS6.crank_ends(RSS6.inverse(RSS6.nominal_pose).q)[0, 0])


def test_sixleg_crank_interference_fails_on_the_crank_as_rss6():
    """tests/test_rss6_loads.py's machine (servo 1's crank turned towards its partner: a 20 mm
    link diameter fails on the crank only, rods 26 mm apart) as a ``sixleg``: it fails too."""
    import math

    from pkmlab.mechanisms import RSS6 as RSS6Family
    from pkmlab.workspaces.constraints import Constraints, check, segment_distances

    b = RSS6Family.from_circles(crank_plane="tangential", crank_length=40.0, rod_length=160.0,
                                base_pair_separation=math.radians(20.0))
    u = b.zero_directions.copy()
    u[0] = -u[0]
    r = RSS6Family(b.base_points, b.platform_points, np.cross(u, [0.0, 0.0, 1.0]), u,
                   b.crank_length, b.rod_length, b.stroke)
    s = SixLeg.from_mechanism(r)
    pn, Rn = as_frames(r.nominal_pose)
    assert segment_distances(*s.leg_segments(pn, Rn))[0].min() > 25.0      # the rods
    for m in (r, s):
        assert not check(m, pn, Rn, Constraints(link_diameter=20.0))[0]
        assert check(m, pn, Rn, Constraints(link_diameter=15.0))[0]


@pytest.mark.parametrize("name", ["instructables-servo-6rss", "hopkins-williams-6psu"])
def test_actuated_hover_gives_the_value_in_degrees_or_mm(name):
    """A servo's angle in degrees, a slider's position in mm (the IK's value at a random
    valid pose, to the two decimals shown)."""
    m = MECHANISMS[name]
    x = testing.random_valid_poses(m, 1, seed=8)[0]
    q = m.inverse(x).q[0]
    act = _trace(mechanism_traces(m, pose=x), "actuators (actuated joints)")
    for text, n, v in zip(act.hovertext, m.actuator_names, q, strict=True):
        shown = f"{np.degrees(v):.2f}°" if m.actuator_unit == "rad" else f"{v:.2f} mm"
        assert abs(v) > 1e-2 and f"{n} = {shown}" in text, text


def test_issue24_families_are_in_the_list_and_planar_scenes_are_not_degenerate():
    """delta3, ldelta3, rpr3, fivebar and prs3 are drawn by the tests above (shipped files);
    a planar mechanism's drawing lies in one z-plane, which ``aspectmode="data"`` made a
    degenerate view zoomed into the plane: its scene keeps x:y to scale with a z share, the
    spatial ones stay to scale ("data")."""
    fams = {m.family for m in ALL.values()}
    assert {"delta3", "ldelta3", "rpr3", "fivebar", "prs3"} <= fams
    for name, m in ALL.items():
        scene = design_scene(m, None).layout.scene
        pts = np.vstack(_pieces(_trace(mechanism_traces(m), "legs (joint chains)")))
        ext = np.ptp(pts, axis=0)
        if ext[2] < 0.05 * max(ext[:2]):
            assert scene.aspectmode == "manual", name
            r = scene.aspectratio
            assert r.z > 0 and abs(r.x / r.y - ext[0] / ext[1]) < 0.05 * ext[0] / ext[1], name
        else:
            assert scene.aspectmode == "data", name
    flat = [n for n, m in ALL.items() if m.family in ("rpr3", "fivebar")]
    assert flat and all(design_scene(ALL[n], None).layout.scene.aspectmode == "manual"
                        for n in flat)
