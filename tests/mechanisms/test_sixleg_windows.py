"""``sixleg`` windows whose lower limit is <= 0 (issue 22, item 1), and a property suite of
random ``sixleg`` machines of every leg kind and window sign.

Before the fix, ``SixLeg._linear_params`` stored a prismatic leg's working side and squared
lower limit as one number, ``side·lo²``, and the column kernel read the side back from its
sign: with ``lo = 0`` the side was lost (the column of an upright leg was taken below its base
joint), with ``lo < 0`` the leg's lower limit became ``|lo|``. Every column of a machine mixing
prismatic legs with sliders was then wrong, and with it the volume, the guaranteed bracket and
the exact task check (docs/validation.md, "Issue 22, item 1").

The reference is pkmlab's own per-pose IK (``inverse``): on a dense z grid per column with
probes 1e-9 mm either side of every end (:func:`pkmlab.testing.check_columns`), and on voxel
grids (centres valid at every orientation sample). A voxel count's stated error is the volume
of the voxels with a neighbour (26-connected) of the other status: the boundary crosses no
other voxel where it is resolved at the voxel size.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR
from scipy import ndimage

import pkmlab
from pkmlab.errors import ParameterError
from pkmlab.mechanisms import LEG_STATUS
from pkmlab.mechanisms.families.sixleg import SixLeg
from pkmlab.poses import as_frames, matrix_to_euler
from pkmlab.requirements.task import TaskRegion, task_contained
from pkmlab.testing import check_columns, random_sixleg
from pkmlab.workspaces import Constraints, OrientationSet, workspace
from pkmlab.workspaces.bracket.columns import volume_bracket


def _mixed(lo: float, hi: float) -> SixLeg:
    """The 6-UPS of the motion-simulator study (two 430 mm / 250 mm circles) with legs 2, 4
    and 6 turned into sliders on vertical rails at their base joints, 300 mm links, the shared
    window ``[lo, hi]`` mm (the reporter's construction)."""
    d = yaml.safe_load((MECH_DIR / "gough-stewart-6ups.yaml").read_text())
    d.pop("base_points"), d.pop("platform_points")
    d["generator"] = {"base_radii": ["430 mm"] * 2, "platform_radii": ["250 mm"] * 2,
                      "base_pair_angle": "90 deg", "platform_rotation": "60 deg",
                      "base_pair_separation": "20 deg", "platform_pair_separation": "20 deg"}
    ups = pkmlab.load_mechanism(d)
    even = np.arange(6) % 2 == 1
    return SixLeg(ups.base_points, ups.platform_points, np.where(even, "slider", "prismatic"),
                  np.where(even[:, None], [0.0, 0.0, 1.0], 0.0), np.zeros((6, 3)), 0.0,
                  np.where(even, 300.0, 0.0), (lo, hi), -1.0, name="mixed-vertical-rails")


def _voxels(m, R, n: float = 2e5):
    """Voxel count of the positions valid at every rotation ``R (M, 3, 3)``, about ``n``
    voxels over the position bounds: ``(volume, stated error, voxel size, valid centres)``
    (mm³, mm³, mm, ``(N, 3)``)."""
    b = m.position_bounds(R)
    lo, hi = b[:, 0].max(axis=0), b[:, 1].min(axis=0)
    h = float((np.prod(hi - lo) / n) ** (1 / 3))
    G = np.stack(np.meshgrid(*[np.arange(lo[k] + h / 2, hi[k], h) for k in range(3)],
                             indexing="ij"), axis=-1)
    P = G.reshape(-1, 3)
    v = np.ones(len(P), bool)
    for Rm in R:
        v &= m.inverse((P, np.broadcast_to(Rm, (len(P), 3, 3)))).valid
    v = v.reshape(G.shape[:3])
    full = np.ones((3, 3, 3), bool)
    edge = ndimage.binary_dilation(v, full) & ~ndimage.binary_erosion(v, full, border_value=0)
    return v.sum() * h**3, edge.sum() * h**3, h, P[v.ravel()]


def _inner_points(b, n, rng):
    """``n`` random points of the bracket's inner set."""
    col, lo, hi = b.inner
    k = rng.integers(0, len(col), n)
    xy = b.cells[col[k]] + rng.uniform(-b.resolution / 2, b.resolution / 2, (n, 2))
    return np.column_stack([xy, lo[k] + rng.uniform(0, 1, n) * (hi[k] - lo[k])])


def _check_constant_bracket(m, b, n_voxels=2e5):
    """The constant-orientation bracket ``b`` of ``m`` against the IK voxel count: the count
    within its stated error of ``[lower, upper]``, 4,000 random valid voxel centres in the
    outer set and 300 random points of the inner set valid."""
    rng = np.random.default_rng(0)
    _, Rn = as_frames(m.nominal_pose)
    V, err, h, valid = _voxels(m, Rn, n_voxels)
    assert V > 0
    assert b.lower - err <= V <= b.upper + err, (b.lower, b.upper, V, err)
    valid = valid[rng.choice(len(valid), min(len(valid), 4000), replace=False)]
    out = ~b.contains(valid, "outer")
    assert not out.any(), f"{out.sum()} of {len(valid)} valid voxel centres outside the " \
        f"outer set, e.g. {valid[out][:3]}"
    assert b.lower > 0
    P = _inner_points(b, 300, rng)
    assert m.inverse((P, np.broadcast_to(Rn[0], (len(P), 3, 3)))).valid.all()
    return V, err


# ---- the reporter's example ----------------------------------------------------------------------

@pytest.mark.parametrize("window", [(0.0, 820.0), (-300.0, 820.0)], ids=["zero", "negative"])
def test_mixed_vertical_rails_with_a_nonpositive_lower_limit(window):
    """Legs 2, 4, 6 on vertical rails, stroke [0, 820] / [-300, 820] mm. Before the fix: at 0
    the columns, the volume and the bracket were empty ([0, 0] cm³ against 497 cm³ counted by
    the IK on 2.5 mm voxels) and a 10 mm task at the nominal pose was "not contained" though
    every one of its 21³ grid points is valid; at -300 the prismatic legs stopped at 300 mm
    (bracket [504, 506] cm³ against 583 cm³)."""
    m = _mixed(*window)
    assert m.column_method == "quadratic" and m.column_radial
    _, Rn = as_frames(m.nominal_pose)
    c = m.nominal_pose[:2]
    xs, ys = c[0] + np.array([-15.0, -8.0, 0.0, 5.0]), c[1] + np.array([-8.0, 0.0, 6.0])
    assert check_columns(m, Rn, xs, ys, "all") >= 10
    b = volume_bracket(m, "constant", None, 5.0, budget_s=30, max_evaluations=3e5)
    _check_constant_bracket(m, b)
    r = workspace(m, "constant", resolution=5.0)
    assert b.lower <= r.volume <= b.upper
    g = np.linspace(-5.0, 5.0, 21)
    G = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    G += m.nominal_pose[:3]
    assert m.inverse((G, np.broadcast_to(Rn[0], (len(G), 3, 3)))).valid.all()
    t = task_contained(m, TaskRegion("box", size=(10.0, 10.0, 10.0)))
    assert t.method == "exact" and t.contained, t


def test_window_rules_for_prismatic_legs():
    """All prismatic: the window is a length window, min > 0 (as ups6). Mixed with sliders,
    min <= 0 is accepted and bounds no prismatic length (the IK accepts a 50 mm leg with the
    window [-300, 820] mm), and a window with max <= 0 leaves the prismatic legs no length:
    empty columns, as the IK says."""
    m = _mixed(-300.0, 820.0)
    with pytest.raises(ParameterError, match="0 < min"):
        SixLeg(m.base_points, m.platform_points, ["prismatic"] * 6, np.zeros((6, 3)),
               np.zeros((6, 3)), 0.0, 0.0, (0.0, 820.0))
    # leg 1 (prismatic) 50 mm long, straight above its base joint; the others unchecked
    p = m.base_points[0] - m.platform_points[0] + [0.0, 0.0, 50.0]
    res = m.inverse((p[None], np.eye(3)[None]))
    assert res.q[0, 0] == pytest.approx(50.0) and LEG_STATUS[res.leg_status[0, 0]] == "ok"
    neg = SixLeg(m.base_points, m.platform_points, m.kinds, m.axes, m.zero_directions, 0.0,
                 m.link_length, (-400.0, -1.0), -1.0, nominal=m.nominal_pose)
    R = np.eye(3)[None]
    xs = np.linspace(-100.0, 100.0, 5)
    lo, hi, _ = neg.column_intervals(xs, xs, R, "all")
    assert np.all(lo > hi)
    X, Y, Z = np.meshgrid(xs, xs, np.linspace(-800.0, 800.0, 161), indexing="ij")
    P = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    assert not neg.inverse((P, np.broadcast_to(R[0], (len(P), 3, 3)))).valid.any()


# ---- property suite: random machines of every leg kind and window sign ------------------------

FAMILIES = {
    # prismatic legs and sliders on vertical rails: radial columns, bracket, exact task check
    "vertical": ("prismatic|slider", "vertical"),
    # prismatic legs and sliders on rails of any direction (vertical, inclined, horizontal)
    "rails": ("prismatic|slider", "any"),
    "crank": ("crank", "any"),
}
CASES = [(f, lower, seed) for f in FAMILIES for lower in ("negative", "zero", "positive")
         for seed in ((0, 1) if f == "vertical" else (0,))]


def _draw(family, lower, seed):
    rng = np.random.default_rng([22, seed, list(FAMILIES).index(family),
                                 ("negative", "zero", "positive").index(lower)])
    kinds, rails = FAMILIES[family]
    kinds = [str(rng.choice(kinds.split("|"))) for _ in range(6)]
    if kinds[0] != "crank" and lower != "positive" and "slider" not in kinds:
        kinds[int(rng.integers(6))] = "slider"     # all prismatic: the window must be > 0
    if family == "rails":
        kinds[int(rng.integers(6))] = "slider"
    return random_sixleg(rng, kinds, lower, rails)


@pytest.mark.parametrize("family,lower,seed", CASES)
def test_random_sixleg_columns_and_bracket_against_the_ik(family, lower, seed):
    """On a random machine: every column method agrees with the IK (dexterous and reachable
    columns over a small orientation box, at columns around the nominal position), and where
    the bracket applies (radial columns) it holds against the IK voxel count, constant and
    dexterous, and the exact task check agrees with the IK; elsewhere the bracket is
    refused."""
    m = _draw(family, lower, seed)
    rng = np.random.default_rng(seed)
    assert m.column_method is not None             # exact columns for every leg kind
    _, Rn = as_frames(m.nominal_pose)
    reach = 10.0 if family == "crank" else 60.0
    deg = 1.0 if family == "crank" else 3.0
    box = OrientationSet.box(np.radians([deg] * 3), "simultaneous", samples=2)
    R = np.concatenate([Rn, box.centred(tuple(matrix_to_euler(Rn[0]))).rotations()])
    c = m.nominal_pose[:2]
    xs = np.sort(np.append(c[0] + rng.uniform(-reach, reach, 2), c[0]))
    ys = np.sort(np.append(c[1] + rng.uniform(-reach, reach, 2), c[1]))
    pieces = sum(check_columns(m, R, xs, ys, mode, dz=0.25) for mode in ("all", "any"))
    assert pieces >= 1
    if not m.column_radial:
        with pytest.raises(ParameterError, match="bracket"):
            volume_bracket(m, "constant")
        return
    # exact task check: the nominal position (valid by construction) is contained; a 10 mm
    # box is contained only if every point of its 1 mm grid is valid
    point = task_contained(m, TaskRegion("points", points=np.zeros((1, 3))))
    assert point.method == "exact" and point.contained, point
    g = np.linspace(-5.0, 5.0, 11)
    G = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    G += m.nominal_pose[:3]
    if task_contained(m, TaskRegion("box", size=(10.0, 10.0, 10.0))).contained:
        assert m.inverse((G, np.broadcast_to(Rn[0], (len(G), 3, 3)))).valid.all()
    free = Constraints(connected=False)
    b = volume_bracket(m, "constant", None, 8.0, free, budget_s=10, max_evaluations=2e5)
    _check_constant_bracket(m, b)
    # dexterous over the continuous box: below the count at the box's samples (a superset),
    # inner points valid at random orientations of the box
    d = volume_bracket(m, "dexterous", box, 8.0, free, budget_s=10, max_evaluations=2e5)
    V, err, _, _ = _voxels(m, R)
    assert d.lower <= V + err
    P = _inner_points(d, 200, rng)
    for _ in range(5):
        Rr = box.centred(tuple(matrix_to_euler(Rn[0]))).rotations_at(
            rng.uniform(-1, 1, (len(P), 3)) * math.radians(deg))
        assert m.inverse((P, Rr)).valid.all()


def _end_certificates(m, res, L):
    """Independently: for each exact column slot, its two ends (1e-6 mm inside) and the voxel
    centres nearest them in the slot; ``(singular end, sign change end <-> centre, κ of every
    feasible end and centre)`` with κ = numpy.linalg.cond of the homogenised Jacobian and the
    sign from numpy.linalg.det."""
    _, Rn = as_frames(m.nominal_pose)
    scale = np.array([1.0, 1.0, 1.0, 1 / L, 1 / L, 1 / L])
    i, j, k = np.nonzero(res.lo <= res.hi)
    lo, hi = res.lo[i, j, k], res.hi[i, j, k]
    d = np.minimum(1e-6, 0.5 * (hi - lo))
    zs, h = res.zs, res.resolution
    first = zs[0] + np.ceil((lo - zs[0]) / h - 1e-9) * h      # voxel centres inside the slot
    last = zs[0] + np.floor((hi - zs[0]) / h + 1e-9) * h
    xy = np.stack([res.xs[i], res.ys[j]], axis=1)
    P = np.concatenate([np.column_stack([xy, lo + d]), np.column_stack([xy, hi - d]),
                        np.column_stack([xy, first]), np.column_stack([xy, last])])
    R = np.broadcast_to(Rn[0], (len(P), 3, 3))
    ok = m.inverse((P, R)).valid
    J = m.jacobian((P, R)) * scale
    fin = ok & np.all(np.isfinite(J), axis=(1, 2))
    with np.errstate(all="ignore"):
        det = np.where(fin, np.linalg.det(np.where(fin[:, None, None], J, np.eye(6))), np.nan)
        cond = np.array([np.linalg.cond(Jm) if f else np.inf for Jm, f in zip(J, fin)])
    n = len(lo)
    end_ok, cen_ok = ok[:2 * n], ok[2 * n:] & (np.concatenate([first, last])
                                               <= np.concatenate([hi, hi])) & (
        np.concatenate([first, last]) >= np.concatenate([lo, lo]))
    singular_end = bool(np.any(end_ok & ~(cond[:2 * n] < 1e12)))
    flips = end_ok & cen_ok & (np.sign(det[:2 * n]) * np.sign(det[2 * n:]) < 0)
    kappas = np.concatenate([cond[:2 * n][end_ok], cond[2 * n:][cen_ok]])
    return singular_end, bool(np.any(flips)), kappas


@pytest.mark.parametrize("family,lower,seed", CASES)
def test_random_sixleg_worst_case_covers_the_column_ends(family, lower, seed):
    """On every random machine (every leg kind and window sign; all of them reach a singular
    set on their constant workspace's boundary), the worst case covers the exact column ends:
    where an independent computation (IK 1e-6 mm inside each end, numpy's det and cond of the
    homogenised Jacobian at the end and at the nearest voxel centre of its slot) finds a
    singular end or a sign change of det J, the worst case is singular with a boundary
    certificate; otherwise its worst κ is at least every feasible end's and centre's κ."""
    from pkmlab import dexterity as dx

    m = _draw(family, lower, seed)
    res = workspace(m, "constant", resolution=12.0)
    if res.empty:
        pytest.skip("empty constant workspace")
    assert res.exact_columns
    wc = dx.worst_case(m, res)
    singular_end, flip, kappas = _end_certificates(m, res, wc.length.length)
    if singular_end or flip:                       # a certificate exists on the boundary
        assert wc.singular and (wc.boundary_singular or wc.boundary_sign_changes), wc.reason
    if not wc.singular:
        assert wc.worst_kappa >= np.max(kappas) * (1 - 1e-9), (wc.worst_kappa, np.max(kappas))
