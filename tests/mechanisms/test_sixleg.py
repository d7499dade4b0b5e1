"""The generic six-leg family: the generic declaration of every shipped 6-PSU and 6-UPS gives
the same nominal pose, IK, Jacobian and workspace volumes as the fast psu6/ups6 kernels; slider
legs on inclined rails against an independent root scan; sampled workspaces against a dense
brute-force count; YAML forms and errors."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import ROOT, SHIPPED

import pkmlab
from pkmlab.errors import ParameterError
from pkmlab.mechanisms import NO_STROKE, SixLeg
from pkmlab.mechanisms.families.sixleg_layout import paired_sixleg, rail_axes
from pkmlab.poses import euler_to_matrix
from pkmlab.testing import random_valid_poses
from pkmlab.workspaces import OrientationSet, workspace

# every shipped 6-PSU / 6-UPS file (studies/papers/ refers to these files)
LINEAR = {f.stem: pkmlab.load_mechanism(f) for f in SHIPPED}
LINEAR = {k: m for k, m in LINEAR.items() if m.family in ("psu6", "ups6")}
PAPER_FILES = [p for p in (ROOT / "studies" / "papers").glob("*.yaml")]


def _mm(v):
    return [f"{float(x)!r} mm" for x in np.asarray(v, dtype=float)]


def generic_yaml(m) -> dict:
    """The explicit ``legs`` declaration of a psu6/ups6 mechanism, as a user writes it."""
    legs = []
    for i in range(6):
        link = f"{float(m.link_length[i])!r} mm" if m.family == "psu6" else None
        act = ({"kind": "slider", "axis": [0, 0, 1], "link_length": link, "branch": -1}
               if m.family == "psu6" else {"kind": "prismatic"})
        legs.append({"base": _mm(m.base_points[i]), "platform": _mm(m.platform_points[i]),
                     "actuator": act})
    return {"family": "sixleg", "name": m.name, "stroke": _mm(m.stroke),
            "tool_offset": _mm(m.tool_offset), "legs": legs}


def test_every_shipped_linear_file_is_covered():
    assert set(LINEAR) == {"hopkins-williams-6psu", "paradex-6pus", "gough-stewart-6ups"}
    for p in PAPER_FILES:        # the paper studies use those files, not geometries of their own
        assert "mechanisms/" in p.read_text()


@pytest.mark.parametrize("stem", sorted(LINEAR))
def test_generic_declaration_matches_the_fast_kernels(stem):
    m = LINEAR[stem]
    g = pkmlab.load_mechanism(generic_yaml(m))
    assert g.family == "sixleg" and g.column_method == m.column_method
    assert g.column_invariant == m.column_invariant
    np.testing.assert_allclose(g.nominal_pose, m.nominal_pose, rtol=1e-9, atol=1e-9)
    X = np.concatenate([random_valid_poses(m, 300, seed=7),
                        m.nominal_pose + np.random.default_rng(0).normal(0, [40, 40, 40, .3, .3,
                                                                            .3], (300, 6))])
    a, b = m.inverse(X), g.inverse(X)
    np.testing.assert_array_equal(a.leg_status, b.leg_status)
    fin = np.isfinite(a.q)
    np.testing.assert_array_equal(fin, np.isfinite(b.q))
    np.testing.assert_allclose(b.q[fin], a.q[fin], rtol=1e-9, atol=1e-9 * m.scale)
    Ja, Jb = m.jacobian(X[a.valid]), g.jacobian(X[a.valid])
    np.testing.assert_allclose(Jb, Ja, rtol=0, atol=1e-9 * np.abs(Ja).max())
    fk = g.forward(a.q[a.valid][:50])
    np.testing.assert_allclose(fk.pose, X[a.valid][:50], atol=1e-9)
    box = OrientationSet.box((math.radians(6),) * 3, "simultaneous", 3)
    for kind, o in (("constant", None), ("dexterous", box), ("reachable", box)):
        h = max(6.0, float(round(m.scale / 80)))           # 6 mm on the 6-PSU, ~20 on the UPS
        va = workspace(m, kind, o, resolution=h)
        vb = workspace(g, kind, o, resolution=h)
        assert va.volume > 0 and vb.method == va.method
        assert abs(vb.volume - va.volume) <= 1e-9 * va.volume, (kind, va.volume, vb.volume)


def test_generator_declaration_matches_psu6_and_ups6_generators():
    for fam, act in (("psu6", {"kind": "slider", "link_length": "225 mm"}),
                     ("ups6", {"kind": "prismatic"})):
        gen = {"base_radii": ["100 mm", "165 mm"], "platform_radii": ["50 mm", "80 mm"],
               "base_pair_angle": "auto", "platform_rotation": "33.7 deg"}
        stroke = ["0 mm", "4 in"] if fam == "psu6" else ["250 mm", "400 mm"]
        ref = pkmlab.load_mechanism({"family": fam, "generator": gen, "stroke": stroke,
                                     **({"link_length": "225 mm"} if fam == "psu6" else {})})
        g = pkmlab.load_mechanism({"family": "sixleg", "generator": {**gen, "actuator": act},
                                   "stroke": stroke})
        np.testing.assert_array_equal(g.base_points, ref.base_points)
        np.testing.assert_array_equal(g.platform_points, ref.platform_points)
        X = random_valid_poses(ref, 50, seed=3)
        np.testing.assert_allclose(g.inverse(X).q, ref.inverse(X).q, rtol=1e-12)


# ---- slider legs on inclined rails --------------------------------------------------------------

_QS = np.linspace(-1200, 1200, 48001)


def _scan_slider(d, e, l, b, qs=_QS):
    """Roots of |d - q e| = l by a dense scan and bisection (independent of the closed form):
    the smaller root for b = -1, the larger for b = +1."""
    f = np.linalg.norm(d[None] - qs[:, None] * e[None], axis=1) - l
    k = np.nonzero(np.sign(f[:-1]) != np.sign(f[1:]))[0]
    if len(k) == 0:
        return np.nan
    roots = []
    for j in (k[0], k[-1]):
        lo, hi = qs[j], qs[j + 1]
        for _ in range(60):
            mid = 0.5 * (lo + hi)
            fm = np.linalg.norm(d - mid * e) - l
            flo = np.linalg.norm(d - lo * e) - l
            lo, hi = (lo, mid) if np.sign(fm) != np.sign(flo) else (mid, hi)
        roots.append(0.5 * (lo + hi))
    return roots[0] if b < 0 else roots[1]


def _hexaglide(inclination_deg=0.0, heading="parallel"):
    return paired_sixleg(actuator="slider", base_radii=(350, 350), platform_radii=(150, 150),
                         base_pair_angle=math.radians(60), platform_rotation=math.radians(90),
                         base_pair_separation=math.radians(40),
                         platform_pair_separation=math.radians(10), link_length=400.0,
                         rail_inclination=math.radians(inclination_deg), rail_heading=heading,
                         stroke=(0.0, 300.0))


@pytest.mark.parametrize("incl", [0.0, 25.0])
def test_inclined_slider_ik_against_a_root_scan(incl):
    m = _hexaglide(incl)
    X = m.nominal_pose + np.random.default_rng(1).uniform(-1, 1, (12, 6)) * [60, 60, 60, .3,
                                                                          .3, .3]
    q = m.inverse(X, stroke=NO_STROKE).q
    R = euler_to_matrix(X[:, 3:])
    for n in range(len(X)):
        for i in range(6):
            d = X[n, :3] + R[n] @ m.tool_points[i] - m.base_points[i]
            ref = _scan_slider(d, m.axes[i], m.link_length[i], m.branch[i])
            if np.isnan(ref):
                assert np.isnan(q[n, i])
            else:
                assert abs(q[n, i] - ref) < 1e-7, (n, i, q[n, i], ref)


def test_rail_generator_conventions():
    B = np.array([[350.0, 0, 0], [-350.0, 10, 0], [0, 350, 0], [0, -350, 0], [1, 1, 0],
                  [-1, -1, 0]])
    e = rail_axes(B, math.radians(30), "outward")
    assert np.allclose(np.degrees(np.arcsin(e[:, 2])), 30.0)          # above the horizontal
    assert np.all(np.sum(e[:, :2] * B[:, :2], axis=1) > 0)            # away from the centre
    e = rail_axes(B, 0.0, "parallel")
    assert np.allclose(np.abs(e[:, 0]), 1) and np.allclose(e[:, 0], np.sign(B[:, 0] + 1e-30))
    assert np.allclose(rail_axes(B, math.pi / 2, "inward"), [0, 0, 1])
    m = _hexaglide(20.0)
    assert np.all(m.branch == 1.0) and m.column_method == "slider"  # struts reach inward
    assert np.allclose(m.axes[:, 2], math.sin(math.radians(20)))
    assert _hexaglide(60.0, "outward").branch[0] == -1.0


def _brute_volume(m, h):
    """Dense count of the voxels whose IK is valid (numpy, independent of the kernels), on the
    engine's grid anchored at the origin; the component of the nominal pose is not separated
    (these workspaces are connected)."""
    b = m.position_bounds(np.eye(3)[None])[0]
    axes = [np.arange(math.ceil(b[0, k] / h), math.floor(b[1, k] / h) + 1) * h for k in range(3)]
    P = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    d = P[:, None, :] + m.tool_points[None] - m.base_points[None]
    t = np.sum(d * m.axes, axis=-1)
    perp = d - t[..., None] * m.axes
    h2 = m.link_length**2 - np.sum(perp**2, axis=-1)
    with np.errstate(invalid="ignore"):
        hh = np.sqrt(h2)
    q = t + m.branch * hh
    az = perp[..., 2] - m.branch * hh * m.axes[:, 2]
    lo, hi = m.stroke
    ok = np.all((h2 >= 0) & (q >= lo) & (q <= hi) & (az >= 0), axis=1)
    return ok.sum() * h**3


@pytest.mark.parametrize("incl", [0.0, 20.0])
def test_sampled_workspace_against_a_dense_brute_force(incl):
    m = _hexaglide(incl)
    r = workspace(m, "constant", resolution=12.0, method="sampled")
    assert r.method == "sampled voxels" and r.components == 1
    assert r.volume == pytest.approx(_brute_volume(m, 12.0), rel=1e-12)
    fine = _brute_volume(m, 6.0)                  # the stated error covers a finer count
    assert abs(r.volume - fine) <= r.volume_error, (r.volume, fine, r.volume_error)


# ---- mixed legs, cranks, YAML ------------------------------------------------------------------

def test_mixed_prismatic_and_slider_legs():
    ups = LINEAR["gough-stewart-6ups"]
    kinds = ["prismatic", "slider"] * 3
    lo, hi = ups.stroke
    # a slider on the leg's own line whose zero sits at the base joint: q is the leg length
    m = SixLeg(ups.base_points, ups.platform_points, kinds, np.tile([0, 0, 1.0], (6, 1)),
               np.zeros((6, 3)), 0.0, 400.0, (lo, hi), -1.0)
    X = random_valid_poses(m, 40, seed=2)
    q = m.inverse(X).q
    ref = ups.inverse(X, stroke=NO_STROKE).q
    np.testing.assert_allclose(q[:, 0::2], ref[:, 0::2], rtol=1e-12)
    assert m.column_method == "quadratic"
    r = workspace(m, "constant", resolution=20.0)
    assert r.method.startswith("columns") and r.volume > 0
    s = workspace(m, "constant", resolution=20.0, method="sampled")
    assert abs(s.volume - r.volume) <= s.volume_error + r.volume_error


def test_crank_legs_match_rss6_and_refuse_linear_mixing():
    rss = pkmlab.load_mechanism(ROOT / "studies/mechanisms/instructables-servo-6rss.yaml")
    g = SixLeg.from_mechanism(rss)
    assert g.actuator_unit == "rad" and g.actuator_names[0] == "theta1"
    X = random_valid_poses(rss, 100, seed=4)
    np.testing.assert_allclose(g.inverse(X).q, rss.inverse(X).q, rtol=0, atol=1e-12)
    np.testing.assert_allclose(g.jacobian(X), rss.jacobian(X), rtol=1e-12, atol=1e-15)
    with pytest.raises(ParameterError, match="all cranks or no crank"):
        SixLeg(g.base_points, g.platform_points, ["crank"] * 5 + ["prismatic"], g.axes,
               g.zero_directions, g.crank_length, g.link_length, g.stroke)


def test_yaml_errors_name_the_field():
    base = {"family": "sixleg", "stroke": ["0 mm", "100 mm"],
            "generator": {"base_radii": ["100 mm"] * 2, "platform_radii": ["50 mm"] * 2,
                          "platform_rotation": "30 deg", "base_pair_separation": "30 deg",
                          "platform_pair_separation": "20 deg", "actuator": {"kind": "slider"}}}
    with pytest.raises(ParameterError, match="actuator.link_length"):
        pkmlab.load_mechanism(base)
    bad = {**base, "generator": {**base["generator"], "actuator": {"kind": "piston"}}}
    with pytest.raises(ParameterError, match="kind"):
        pkmlab.load_mechanism(bad)
    crank = {**base, "generator": {**base["generator"], "actuator": {
        "kind": "crank", "crank_length": "20 mm", "rod_length": "120 mm"}}}
    with pytest.raises(ParameterError, match="stroke: must be absent: these legs take "
                                             "'servo_range'"):
        pkmlab.load_mechanism(crank)
    crank.pop("stroke")
    with pytest.raises(ParameterError, match="servo_range"):
        pkmlab.load_mechanism({**crank, "servo_range": ["-100 deg", "250 deg"]})
    m = pkmlab.load_mechanism({**crank, "servo_range": ["-80 deg", "1.2 rad"]})
    assert m.stroke == pytest.approx((math.radians(-80), 1.2)) and m.actuator_unit == "rad"
    legs = generic_yaml(LINEAR["gough-stewart-6ups"])
    legs["legs"][2]["actuator"] = {"kind": "slider", "axis": [0, 0, 0], "link_length": "9 mm"}
    with pytest.raises(ParameterError, match=r"legs\[2\]\.axis"):    # numbered from 0
        pkmlab.load_mechanism(legs)


def test_inscribed_box_respects_the_slider_working_mode():
    """The inscribed-box enlargement accepts a step only where the IK is valid (found on the
    Hexaglide: grown across the rails' plane into the mirror mode, no box survived)."""
    from pkmlab.workspaces.inscribed import inscribed_box, points_feasible

    r = workspace(_hexaglide(0.0), "constant", resolution=15.0)
    box = inscribed_box(r, samples=1000)
    assert box.status != "failed", box.reason
    assert box.shrink == 1.0 and box.lower[2] >= 0.0
    corners = np.array([[x, y, z] for x in (box.lower[0], box.upper[0])
                        for y in (box.lower[1], box.upper[1])
                        for z in (box.lower[2], box.upper[2])])
    assert points_feasible(r, corners).all()


def _mixed_linear():
    """Legs 1, 3, 5 of the Kotlarski 6-UPS; legs 2, 4, 6 sliders on rails inclined 60° inward
    whose zeros sit 600 mm down the rail from the base joints, with 450 mm links."""
    ups = LINEAR["gough-stewart-6ups"]
    e = rail_axes(ups.base_points, math.radians(60), "inward")
    even = (np.arange(6) % 2 == 1)[:, None]
    return SixLeg(np.where(even, ups.base_points - 600 * e, ups.base_points),
                  ups.platform_points, ["prismatic", "slider"] * 3, np.where(even, e, 0.0),
                  np.zeros((6, 3)), 0.0, [0.0, 450.0] * 3, ups.stroke, -1.0)


def _tilted_cranks():
    """The servo hexapod with servo axes 1, 3, 5 tilted 20° about their crank zero
    directions (axes no longer horizontal nor tangent)."""
    from scipy.spatial.transform import Rotation

    g = SixLeg.from_mechanism(pkmlab.load_mechanism(
        ROOT / "studies/mechanisms/instructables-servo-6rss.yaml"))
    n = g.axes.copy()
    for i in range(0, 6, 2):
        n[i] = Rotation.from_rotvec(math.radians(20) * g.zero_directions[i]).apply(n[i])
    return SixLeg(g.base_points, g.platform_points, ["crank"] * 6, n, g.zero_directions,
                  g.crank_length, g.link_length, g.stroke, g.branch)


@pytest.mark.parametrize("make", [_mixed_linear, _tilted_cranks], ids=["mixed", "cranks"])
def test_contract_on_mixed_and_tilted_legs(make):
    from pkmlab import testing

    m = make()
    assert m.column_method == ("crank" if make is _tilted_cranks else "slider")
    testing.check_round_trip(m, 300)
    # step 1e-5: near-singular poses of the tilted cranks (|J| ~ 40) make the O(h⁴) term of
    # the default 1e-4 step reach 2e-5; at 1e-5 the difference is 2e-9
    testing.check_jacobian(m, h=1e-5)
    testing.check_batching(m)
    testing.check_statuses(m)


def test_study_variables_keep_their_units_through_the_typed_spec():
    """``servo_min`` (an angle, rad inside) and ``link_length`` set through the study's design
    space build the mechanism in internal units, and the exported display form reloads to the
    same mechanism (to the 12 digits it writes)."""
    from pkmlab.config import mechanism_spec, to_display
    from pkmlab.study.space import DesignSpace, Variable, parse_path

    spec = mechanism_spec({"family": "sixleg", "servo_range": ["-80 deg", "80 deg"],
                           "generator": {"base_radii": ["100 mm"] * 2,
                                         "platform_radii": ["75 mm"] * 2,
                                         "platform_rotation": "30 deg",
                                         "base_pair_separation": "30 deg",
                                         "platform_pair_separation": "20 deg",
                                         "actuator": {"kind": "crank", "crank_length": "25 mm",
                                                      "rod_length": "150 mm"}}})
    path, qty = SixLeg.design_aliases["servo_min"]
    rod, _ = SixLeg.design_aliases["rod_length"]
    space = DesignSpace(spec, (Variable("servo_min", parse_path(path), qty, "continuous",
                                        -1.2, -0.5),
                               Variable("rod_length", parse_path(rod), "length", "continuous",
                                        120.0, 180.0)))
    assert space.baseline_values()["servo_min"] == pytest.approx(math.radians(-80))
    design = {"servo_min": -1.0, "rod_length": 160.0}
    m = space.decode(design)
    assert m.stroke[0] == pytest.approx(-1.0) and np.allclose(m.link_length, 160.0)
    again = pkmlab.load_mechanism(to_display(space.spec_of(design)))   # 12 digits, with units
    np.testing.assert_allclose(again.stroke, m.stroke, rtol=1e-11)
    np.testing.assert_allclose(again.link_length, m.link_length, rtol=1e-11)
    np.testing.assert_allclose(again.base_points, m.base_points, atol=1e-9)
