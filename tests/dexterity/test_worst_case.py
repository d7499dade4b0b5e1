"""Worst κ, smallest force and singularities over a whole workspace grid (dexterity.worst_case)."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECH_DIR

import pkmlab
from pkmlab import dexterity as dx
from pkmlab.dexterity._linalg import KAPPA_BRACKET, sweep_bounds
from pkmlab.poses import as_frames
from pkmlab.workspaces import OrientationSet, workspace

PSU = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
UPS = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")
F_MAX = 150.0


def brute_force(mech, res, L, fmax=F_MAX):
    """Every occupied voxel × orientation with NumPy/LAPACK only: κ (np.linalg.cond of J_h,
    inf above 1e12 or for a non-finite J), all-direction force from np.linalg.inv, det J,
    feasibility from the inverse kinematics. Arrays (V, M)."""
    pos = res.voxel_centres()
    Rs = res.orientations.rotations()
    V, M = len(pos), len(Rs)
    p = np.tile(pos, (M, 1))
    R = np.repeat(Rs, V, axis=0)
    J = mech.jacobian((p, R))
    fin = np.all(np.isfinite(J), axis=(1, 2))
    Jh = J.copy()
    Jh[..., 3:] /= L
    kap = np.full(len(J), np.inf)
    kap[fin] = np.linalg.cond(Jh[fin])
    kap[kap >= 1e12] = np.inf
    det = np.zeros(len(J))
    det[fin] = np.linalg.det(J[fin])
    force = np.full(len(J), np.nan)
    ok = fin & np.isfinite(kap)
    inv = np.linalg.inv(J[ok])                                  # G = J⁻ᵀ: G[i, :3] = inv[:3, i]
    force[ok] = np.min(fmax / np.linalg.norm(inv[:, :3, :], axis=1), axis=1)
    force[fin & ~np.isfinite(kap)] = 0.0
    valid = mech.inverse((p, R)).valid
    shape = (M, V)
    return (kap.reshape(shape).T, force.reshape(shape).T, det.reshape(shape).T,
            valid.reshape(shape).T, pos)


def brute_sign_changes(res, det, valid) -> int:
    """Sign changes of det J between face-neighbouring voxels and between neighbouring
    orientation samples of a simultaneous Euler box (n³ grid, index order i, j, k)."""
    s = np.where(valid, np.sign(det), 0)
    occ = res.occupancy
    lut = -np.ones(occ.shape, dtype=int)
    idx = np.argwhere(occ)
    lut[tuple(idx.T)] = np.arange(len(idx))
    n = 0
    for ax in range(3):
        nb = idx.copy()
        nb[:, ax] += 1
        inside = nb[:, ax] < occ.shape[ax]
        a = np.flatnonzero(inside)
        b = lut[tuple(nb[inside].T)]
        a, b = a[b >= 0], b[b >= 0]
        n += int(np.sum(s[a] * s[b] < 0))
    o = res.orientations
    if o.kind == "box" and o.semantics == "simultaneous":
        k = o.samples
        g = s.reshape(len(s), k, k, k)
        for ax in (1, 2, 3):
            a = np.take(g, range(k - 1), axis=ax)
            b = np.take(g, range(1, k), axis=ax)
            n += int(np.sum(a * b < 0))
    return n


def brute_ends(mech, res, L):
    """κ (np.linalg.cond, inf above 1e12 or for a non-finite J) at both ends of every column
    slot, masked where the inverse kinematics fails 1e-6 mm inside the slot; for a family
    whose J does not depend on z, only the columns without an occupied voxel. ``(E, M)``."""
    i, j, k = np.nonzero(res.lo <= res.hi)
    if mech.column_invariant:
        keep = ~res.occupancy.any(axis=2)[i, j]
        i, j, k = i[keep], j[keep], k[keep]
    z0, z1 = res.lo[i, j, k], res.hi[i, j, k]
    d = np.minimum(1e-6, (z1 - z0) / 2)
    ends = np.concatenate([np.column_stack([res.xs[i], res.ys[j], z0]),
                           np.column_stack([res.xs[i], res.ys[j], z1])])
    probe = ends + np.concatenate([d, -d])[:, None] * [0, 0, 1]
    Rs = res.orientations.rotations()
    E, M = len(ends), len(Rs)
    if not E:
        return np.ma.masked_array(np.empty((0, M)), np.zeros((0, M), dtype=bool))
    J = mech.jacobian((np.tile(ends, (M, 1)), np.repeat(Rs, E, axis=0)))
    fin = np.all(np.isfinite(J), axis=(1, 2))
    J[..., 3:] /= L
    kap = np.full(len(J), np.inf)
    kap[fin] = np.linalg.cond(J[fin])
    kap[kap >= 1e12] = np.inf
    ok = mech.inverse((np.tile(probe, (M, 1)), np.repeat(Rs, E, axis=0))).valid
    return np.ma.masked_array(kap.reshape(M, E).T, ~ok.reshape(M, E).T)


@pytest.fixture(scope="module")
def psu_small():
    return workspace(PSU, "dexterous", OrientationSet.box(np.radians([15] * 3), samples=3), 5.0)


@pytest.fixture(scope="module")
def ups_dexterous():
    """The 6-UPS ±10° dexterous workspace at 20 mm: a parallel singularity crosses it."""
    return workspace(UPS, "dexterous", OrientationSet.box(np.radians([10] * 3), samples=3), 20.0)


# ---- the per-pose kernel --------------------------------------------------------------------


def test_sweep_bounds_bracket_kappa_and_match_force_and_det():
    rng = np.random.default_rng(3)
    J = rng.normal(size=(2000, 6, 6))
    J[:500, :, 3:] *= 40.0                                        # mm/rad columns
    J[500:700] = J[500:700] @ np.diag([1, 1, 1, 1, 1e-7, 1e-7])    # ill-conditioned
    J[700, :, 5] = J[700, :, 4]                                   # exactly singular
    J[701, 2, 2] = np.nan
    L = 37.0
    kup, force, det = np.empty(2000), np.empty(2000), np.empty(2000)
    sweep_bounds(J, L, np.full(6, F_MAX), kup, force, det)
    Jh = J.copy()
    Jh[..., 3:] /= L
    ok = np.arange(2000) < 700
    kap = np.linalg.cond(Jh[ok])
    assert np.all(kup[ok] >= kap * (1 - 1e-9))                    # an upper bound ...
    assert np.all(kup[ok] <= KAPPA_BRACKET * kap * (1 + 1e-9))   # ... within the bracket
    assert np.median(kup[ok] / kap) < 1.2                         # and tight in practice
    np.testing.assert_allclose(det[ok], np.linalg.det(J[ok]), rtol=1e-8)
    ref = dx.max_force_all_directions(J[ok], F_MAX, L)
    well = kap < 1e6
    np.testing.assert_allclose(force[ok][well], ref[well], rtol=1e-9)
    assert kup[700] == np.inf and force[700] == 0.0 and det[700] == 0.0
    assert kup[701] == np.inf and np.isnan(force[701]) and np.isnan(det[701])


def test_sweep_bounds_on_two_threads_equal_one_thread():
    """Above SMALL_WORK poses the kernel runs on numba's threads in tasks of its own scratch
    matrices: the same numbers as one thread, bit for bit, a partial last task included."""
    import numba

    if numba.get_num_threads() < 2:
        pytest.skip("one numba thread on this machine")
    rng = np.random.default_rng(8)
    n = 5003                                     # > SMALL_WORK, not a multiple of the task
    J = rng.normal(size=(n, 6, 6))
    J[10, :, 5] = J[10, :, 4]                    # singular
    J[n - 1, 0, 0] = np.nan                      # in the last, partial task
    runs = []
    for threads in (2, 1):
        numba.set_num_threads(threads)
        try:
            out = [np.empty(n) for _ in range(3)]
            sweep_bounds(J, 50.0, np.full(6, F_MAX), *out)
        finally:
            numba.set_num_threads(numba.config.NUMBA_NUM_THREADS)
        runs.append(out)
    for a, b in zip(*runs):
        assert np.array_equal(a, b, equal_nan=True)
    assert runs[0][0][10] == np.inf and np.isnan(runs[0][1][n - 1])
    with pytest.raises(ValueError, match="kup must be a writeable C-contiguous"):
        sweep_bounds(J, 50.0, np.full(6, F_MAX), np.empty(2 * n)[::2], *runs[0][1:])


# ---- the whole grid ---------------------------------------------------------------------------


@pytest.mark.parametrize("case", ["psu-dexterous", "psu-reachable", "ups-constant"])
def test_worst_case_is_the_extreme_of_every_grid_sample(case, psu_small):
    if case == "psu-dexterous":
        mech, res = PSU, psu_small
    elif case == "psu-reachable":
        mech = PSU
        res = workspace(PSU, "reachable", OrientationSet.box(np.radians([25] * 3), samples=3),
                        8.0)
    else:
        mech, res = UPS, workspace(UPS, "constant", None, 40.0)
    L = dx.resolve_length(mech)
    w = dx.worst_case(mech, res, L, F_MAX)
    kap, force, det, valid, pos = brute_force(mech, res, L.length)
    # feasible (unit, orientation) pairs: (x, y) columns for the 6-PSU (J does not depend on
    # z), a pair counting when any voxel of the column is feasible; voxels for the 6-UPS
    idx = np.argwhere(res.occupancy)              # the order of voxel_centres()
    if mech.column_invariant:
        _, col = np.unique(idx[:, :2], axis=0, return_inverse=True)
        per_unit = np.zeros((col.max() + 1, valid.shape[1]), dtype=bool)
        np.logical_or.at(per_unit, col.ravel(), valid)
        assert w.feasible == int(per_unit.sum())
    else:
        assert w.feasible == int(valid.sum())
    if case == "psu-dexterous":
        assert valid.all()
    elif case == "psu-reachable":
        assert 0.2 < valid.mean() < 0.95      # the feasibility check matters here
    else:                                     # the base plane z = 0: edge of the working mode
        assert 0 < np.sum(~valid) < 0.05 * valid.size
    kv, fv = kap[valid], force[valid]
    n_sing = int(np.sum(~np.isfinite(kv)))
    assert w.singular_samples == n_sing
    if np.isfinite(kv).all():
        assert w.grid_max_kappa == pytest.approx(kv.max(), rel=1e-9)
    else:
        assert w.grid_max_kappa == math.inf
    assert w.grid_min_force == pytest.approx(np.nanmin(fv), rel=1e-9, abs=1e-12)
    assert w.sign_changes == brute_sign_changes(res, det, valid)
    # the column ends (the exact z ends of every slot; for the 6-PSU only of columns without
    # a voxel, whose J is not already evaluated): κ by LAPACK at the end, feasibility by the
    # inverse kinematics 1e-6 mm inside the slot
    bk = brute_ends(mech, res, L.length)
    assert w.boundary_points == bk.shape[0] and w.boundary_feasible == int(bk.count())
    kb = bk.compressed()
    assert w.boundary_singular == int(np.sum(~np.isfinite(kb)))
    if len(kb) and np.isfinite(kb).all():
        assert w.boundary_max_kappa == pytest.approx(kb.max(), rel=1e-9)
    assert w.singular == (n_sing > 0 or w.sign_changes > 0 or w.boundary_singular > 0
                          or w.boundary_sign_changes > 0)
    assert w.singularity == ("singular" if w.singular else "not excluded")
    if case == "ups-constant":               # all six legs horizontal on the base plane
        assert w.singular and w.boundary_singular > 0 and "column end" in w.reason
    if w.singular:
        assert w.worst_kappa == math.inf and w.min_force == 0.0 and w.reason
    else:
        top = max(w.grid_max_kappa, kb.max()) if len(kb) else w.grid_max_kappa
        assert w.worst_kappa == pytest.approx(top, rel=1e-12)
        assert w.min_force <= w.grid_min_force
        # the reported pose is a sample or a column end with that value
        X = w.worst_kappa_pose[None]
        assert dx.condition_number(mech.jacobian(X), L)[0] == pytest.approx(w.worst_kappa)
    assert w.voxels == len(pos) and w.orientations == kap.shape[1]
    assert w.length.status == "angeles" and w.L == L.length
    assert f"{w.voxels:,} voxels × {w.orientations:,} orientations" in w.method


def test_singularity_between_samples_is_found_where_monte_carlo_misses_it(ups_dexterous):
    res = ups_dexterous
    L = dx.resolve_length(UPS)
    w = dx.worst_case(UPS, res, L, F_MAX)
    assert w.singular and w.singular_samples == 0 and w.sign_changes > 0
    assert w.worst_kappa == math.inf and w.min_force == 0.0
    assert "det J changes sign" in w.reason
    assert w.grid_max_kappa > 1e4 and w.grid_min_force < 1.0     # near it: huge κ, ~0 N
    mc = dx.gci_monte_carlo(UPS, res, L, samples=500, seed=0)
    assert mc.ok and mc.sampled_max_kappa < 1e3                  # 500 random poses miss it
    # independent check: bisect det J along the reported pair; κ blows up at the crossing,
    # which lies inside the workspace with a valid inverse kinematics
    a, b = w.sign_change_poses
    pa, Ra = as_frames(a)
    pb, Rb = as_frames(b)
    np.testing.assert_allclose(Ra, Rb)                         # a spatial pair

    def det(t):
        return np.linalg.det(UPS.jacobian(((1 - t) * pa + t * pb, Ra))[0])

    lo, hi = 0.0, 1.0
    assert det(lo) * det(hi) < 0
    for _ in range(60):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if det(lo) * det(mid) > 0 else (lo, mid)
    p = (1 - lo) * pa + lo * pb
    Jh = UPS.jacobian((p, Ra))[0]
    Jh[:, 3:] /= L.length
    assert np.linalg.cond(Jh) > 1e10
    assert UPS.inverse((p, Ra)).valid[0] and res.contains(p)[0]


def test_worst_case_bounds_every_monte_carlo_sample_on_hopkins():
    res = workspace(PSU, "dexterous", OrientationSet.box(np.radians([15] * 3), samples=7), 2.5)
    L = dx.resolve_length(PSU)
    w = dx.worst_case(PSU, res, L, F_MAX)
    assert not w.singular and w.sign_changes == 0 and w.pairs_checked > 0
    assert 3000 > w.voxels > 2500 and w.orientations == 343
    rng = np.random.default_rng(11)
    p, R = dx.aggregate.sample_poses(res, 2000, rng)
    valid = PSU.inverse((p, R)).valid
    J = PSU.jacobian((p[valid], R[valid]))
    assert valid.mean() > 0.99
    assert np.all(dx.condition_number(J, L) <= w.worst_kappa)
    assert np.all(dx.max_force_all_directions(J, F_MAX, L) >= w.min_force)
    mc = dx.gci_monte_carlo(PSU, res, L, samples=2000, seed=11)
    assert mc.sampled_max_kappa <= w.worst_kappa
    # converges with the grid: at 5 mm the extreme is a little milder (a subset of positions)
    coarse = dx.worst_case(PSU, workspace(PSU, "dexterous", res.orientations, 5.0), L, F_MAX)
    assert coarse.worst_kappa <= w.worst_kappa < 1.1 * coarse.worst_kappa


def test_worst_case_statuses(psu_small):
    w = dx.worst_case(PSU, psu_small, 60.0, F_MAX, max_poses=10)
    assert w.status == "too large" and not w.ok and "max_poses" in w.reason
    assert math.isnan(w.worst_kappa) and math.isnan(w.min_force)
    assert w.length.status == "given"
    empty = workspace(PSU, "dexterous", OrientationSet.box(np.radians([30] * 3), samples=3), 5.0)
    assert empty.empty
    e = dx.worst_case(PSU, empty, None, F_MAX)
    assert e.status == "empty" and "empty" in e.reason and not e.singular
    d = w.as_dict()
    assert d["status"] == "too large" and d["worst_kappa"] is None
