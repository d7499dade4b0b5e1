"""The worst case covers the workspace up to its boundary (issue 22, item 2).

A singular set planted on the boundary of a column-method workspace — every leg horizontal on
the plane of the rails (sliders) or of the base joints (prismatic legs), the edge of the
working mode — lies between the outermost voxel centres and the boundary, where no sample
lands and no pair of samples spans it. Before the fix ``worst_case`` called such a workspace
singularity-free with a worst κ that doubled with every halving of the grid (the Hexaglide with
its rails raised 3.3 mm: 236 at 10 mm, 1,100 at 5 mm). The column ends are now evaluated too,
and a workspace is ``"singular"`` (with a certificate) or ``"not excluded"``, never "free".
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest
from conftest import MECH_DIR

import pkmlab
from pkmlab import dexterity as dx
from pkmlab.mechanisms.families.sixleg import SixLeg
from pkmlab.mechanisms.families.sixleg_layout import paired_sixleg
from pkmlab.workspaces import Constraints, workspace

HEXAGLIDE = pkmlab.load_mechanism(MECH_DIR / "hexaglide-6pus.yaml")
UPS = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")


def raised(mech, dz):
    """The same machine with its base-side points (rail zeros, base joints) raised ``dz`` mm."""
    return dataclasses.replace(mech, base_points=mech.base_points + [0.0, 0.0, dz])


def random_hexaglide(seed):
    """A Hexaglide-like 6-PUS (horizontal parallel rails, paired) with random radii, pair
    angles, link length and rail height: its constant workspace runs down to the rails'
    plane, where every link is horizontal."""
    g = np.random.default_rng(seed)
    m = paired_sixleg(actuator="slider", base_radii=(g.uniform(330, 370),) * 2,
                      platform_radii=(g.uniform(130, 160),) * 2,
                      base_pair_angle=math.radians(60), platform_rotation=math.radians(90),
                      base_pair_separation=math.radians(g.uniform(35, 45)),
                      platform_pair_separation=math.radians(g.uniform(5, 15)),
                      link_length=g.uniform(380, 420), rail_inclination=0.0,
                      rail_heading="parallel", stroke=(0.0, 300.0))
    return raised(m, g.uniform(0.5, 20.0))


def kappa_valid(mech, p, L):
    """κ (np.linalg.cond of J_h) and IK validity at positions ``p`` (N, 3), nominal
    orientation, with pkmlab's own per-pose inverse kinematics and Jacobian."""
    R = np.repeat(np.eye(3)[None], len(p), axis=0)
    J = mech.jacobian((p, R))
    J[..., 3:] /= L
    return np.linalg.cond(J), mech.inverse((p, R)).valid


# the planted machines: the shipped Hexaglide (dz = 0: voxel centres land on the plane) and
# raised by amounts that are not multiples of any grid step; random Hexaglide-like machines;
# the 6-UPS (ups6, and as a sixleg of prismatic legs) raised: every leg horizontal on the base
# plane, the edge of the working mode
PLANTED = [("hexaglide", 0.0, 10.0), ("hexaglide", 3.3, 10.0), ("hexaglide", 7.1, 5.0),
           ("hexaglide", 12.9, 10.0), ("random", 1, 10.0), ("random", 2, 10.0),
           ("random", 3, 10.0), ("ups6", 0.0, 40.0), ("ups6", 17.3, 40.0),
           ("sixleg-ups", 6.1, 40.0)]


@pytest.mark.parametrize("name, dz, h", PLANTED)
def test_worst_case_flags_a_singular_plane_on_the_workspace_boundary(name, dz, h):
    if name == "random":
        mech = random_hexaglide(int(dz))
        dz = float(mech.base_points[0, 2])
    else:
        mech = {"hexaglide": lambda: raised(HEXAGLIDE, dz), "ups6": lambda: raised(UPS, dz),
                "sixleg-ups": lambda: SixLeg.from_mechanism(raised(UPS, dz))}[name]()
    res = workspace(mech, "constant", resolution=h)
    L = dx.resolve_length(mech).length
    # independent: the lowest column ends lie on the plane z = dz (to 1e-6 mm), and 1e-4 mm
    # above it pkmlab's own IK is valid at every leg while κ (LAPACK) is beyond 1e5: the
    # singular plane is on the closure of the workspace
    slot = res.lo <= res.hi
    zmin = res.lo[slot].min()
    assert zmin == pytest.approx(dz, abs=1e-6)
    i, j, k = np.argwhere(slot & (res.lo <= dz + 1e-6))[0]
    p = np.array([[res.xs[i], res.ys[j], dz + 1e-4]])
    kap, ok = kappa_valid(mech, p, L)
    assert ok[0] and kap[0] > 1e5
    w = dx.worst_case(mech, res, L)
    assert w.ok and w.singular and w.singularity == "singular"
    assert w.worst_kappa == math.inf and w.min_force == 0.0
    assert w.boundary_singular > 0 and "column end" in w.reason
    assert w.as_dict()["singularity"] == "singular"
    if dz > 0:                             # no voxel centre on the plane: the samples are fine
        assert w.singular_samples == 0 and math.isfinite(w.grid_max_kappa)


def test_raised_hexaglide_as_in_the_issue():
    """Rails raised 3.3 mm: κ 5.8e6 at z = 3.3001 mm with every leg valid; before, worst κ 236
    (10 mm) and 1,100 (5 mm), not singular."""
    mech = raised(HEXAGLIDE, 3.3)
    L = dx.resolve_length(mech).length
    for h in (10.0, 5.0):
        w = dx.worst_case(mech, workspace(mech, "constant", resolution=h), L)
        assert w.singularity == "singular" and w.worst_kappa == math.inf
        assert 200 < w.grid_max_kappa < 2e3          # the voxel centres alone: finite
        kp = w.worst_kappa_pose
        assert kp[2] == pytest.approx(3.3, abs=1e-6)  # a column end on the plane
        kap, ok = kappa_valid(mech, np.array([kp[:3] + [0, 0, 1e-4]]), L)
        assert ok[0] and kap[0] > 1e5


def test_a_singularity_free_workspace_stays_not_excluded_and_its_kappa_converges():
    """The 6-UPS with its stroke starting at 500 mm: the legs stop before the base plane, the
    column ends are stroke limits, κ stays near 13. Its worst κ now includes the column ends:
    a dense z scan of every column with pkmlab's IK and LAPACK never exceeds it, and it
    converges (10 → 5 mm: 13.22 → 13.32; before, from the voxel centres alone, 13.02 → 13.31:
    the lower ends of the columns were missed)."""
    cons = Constraints(stroke=(500.0, 950.0))
    L = dx.resolve_length(UPS).length
    res = {h: workspace(UPS, "constant", None, h, constraints=cons) for h in (10.0, 5.0)}
    w = {h: dx.worst_case(r.mechanism, r, L) for h, r in res.items()}
    for h in w:
        assert w[h].ok and not w[h].singular and w[h].singularity == "not excluded"
        assert math.isfinite(w[h].worst_kappa) and w[h].worst_kappa < 20
        assert w[h].boundary_points > 0 and w[h].boundary_singular == 0
    assert abs(w[5.0].worst_kappa / w[10.0].worst_kappa - 1) < 0.01
    # independent: 21 points from end to end of every slot of every column at 10 mm
    r = res[10.0]
    i, j, k = np.nonzero(r.lo <= r.hi)
    t = np.linspace(0.0, 1.0, 21)
    z = r.lo[i, j, k][:, None] + t * (r.hi[i, j, k] - r.lo[i, j, k])[:, None]
    p = np.stack([np.repeat(r.xs[i], 21), np.repeat(r.ys[j], 21), z.ravel()], axis=1)
    kap, ok = kappa_valid(r.mechanism, p, L)
    inner = np.tile((t > 0) & (t < 1), len(i))
    assert ok[inner].all()                            # the slots are feasible inside
    assert kap.max() <= w[10.0].worst_kappa * (1 + 1e-9)
    assert kap.max() > w[10.0].grid_max_kappa * 1.01   # beyond the voxel centres alone


def test_sign_changes_at_the_column_ends_are_counted_and_genuine():
    """The 6-UPS ±10° dexterous workspace at 20 mm (a parallel singularity crosses it): the sign
    changes of det J between each column end and the nearest voxel centre of its slot, and
    between neighbouring orientation samples at an end, recounted with LAPACK determinants and
    a search of the slot for its voxel centres; one such pair bisected to κ > 1e10."""
    from pkmlab.workspaces import OrientationSet

    res = workspace(UPS, "dexterous", OrientationSet.box(np.radians([10] * 3), samples=3), 20.0)
    L = dx.resolve_length(UPS).length
    w = dx.worst_case(UPS, res, L)
    Rs = res.orientations.rotations()
    M = len(Rs)

    def sign(p, valid_at):
        P, R = np.repeat(p, M, axis=0), np.tile(Rs, (len(p), 1, 1))
        ok = UPS.inverse((valid_at if valid_at is not None else P, R)).valid
        return np.where(ok, np.sign(np.linalg.det(UPS.jacobian((P, R)))), 0).reshape(-1, M)

    n = 0
    first = None
    for i, j, k in np.argwhere(res.lo <= res.hi):
        z0, z1 = res.lo[i, j, k], res.hi[i, j, k]
        inside = np.flatnonzero((res.zs >= z0) & (res.zs <= z1) & res.occupancy[i, j])
        ends = np.array([[res.xs[i], res.ys[j], z0], [res.xs[i], res.ys[j], z1]])
        d = min(1e-6, (z1 - z0) / 2)
        probe = np.repeat(ends + [[0, 0, d], [0, 0, -d]], M, axis=0)
        se = sign(ends, probe)
        if len(inside):
            near = np.array([[res.xs[i], res.ys[j], res.zs[inside[0]]],
                             [res.xs[i], res.ys[j], res.zs[inside[-1]]]])
        else:
            near = ends[::-1][:1]                   # lower end ↔ upper end, once
            se = se[:1]
        sn = sign(near, None)
        hit = se * sn < 0
        n += int(hit.sum())
        if first is None and hit.any():
            q, m = np.argwhere(hit)[0]
            first = (ends[q], near[q], Rs[m])
        g = sign(ends, probe).reshape(2, 3, 3, 3)
        for ax in (1, 2, 3):
            a = np.take(g, range(2), axis=ax)
            b = np.take(g, range(1, 3), axis=ax)
            n += int(np.sum(a * b < 0))
    assert w.boundary_sign_changes == n > 0
    a, b, R = first

    def det(t):
        return np.linalg.det(UPS.jacobian((((1 - t) * a + t * b)[None], R[None]))[0])

    lo, hi = 0.0, 1.0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if det(lo) * det(mid) > 0 else (lo, mid)
    Jh = UPS.jacobian(((((1 - lo) * a + lo * b))[None], R[None]))[0]
    Jh[:, 3:] /= L
    assert np.linalg.cond(Jh) > 1e10


def test_sampled_voxel_faces_are_not_taken_for_the_boundary():
    """On the sampled method (luzi3) ``lo``/``hi`` are faces of voxel runs, which can lie
    outside the workspace (a face of a dexterous run need not be feasible at every orientation):
    no column ends are evaluated there, so the worst κ is the grid's (it took a face's before,
    e.g. 9,078 against the grid's 6,857 on this ±5° set at 10 mm)."""
    luzi = pkmlab.load_mechanism(MECH_DIR / "luzi-3chain.yaml")
    box = pkmlab.OrientationSet.box(np.radians([5.0] * 3), samples=2)
    res = workspace(luzi, "dexterous", box, resolution=20.0)
    assert res.method == "sampled voxels" and res.lo is not None and not res.exact_columns
    wc = dx.worst_case(luzi, res)
    assert wc.boundary_points == 0 and wc.boundary_sign_changes == 0
    assert wc.worst_kappa == wc.grid_max_kappa or (wc.singular and not wc.boundary_singular)
