"""The exact κ fused with the family's Jacobian (issue 28 item 1, :mod:`pkmlab.dexterity.
_fused_exact`): the κ maps, the GCI and the trajectory check give the unfused NumPy path's values
bit for bit, on a 6-PSU and a 6-UPS design that are not the papers' (poses with no Jacobian,
out of reach and exactly singular among them), and they take the fused path (with the
mechanism's NumPy ``jacobian`` made to raise, they still run)."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR, same_result

import pkmlab
from pkmlab import dexterity as dx
from pkmlab.dexterity import _fused_exact as fe
from pkmlab.dexterity import maps, sweep
from pkmlab.dexterity.metrics import condition_number
from pkmlab.motion import check_trajectory, paper_motion, trajectory_fit
from pkmlab.poses import euler_to_matrix
from pkmlab.workspaces import OrientationSet, workspace


def _psu():
    d = yaml.safe_load((MECH_DIR / "hopkins-williams-6psu.yaml").read_text())
    d.update(name="psu6-not-the-paper", link_length="240 mm")
    d["generator"].update(base_radii=["110 mm", "160 mm"], platform_radii=["55 mm", "85 mm"],
                          platform_rotation="40 deg")
    return pkmlab.load_mechanism(d)


def _ups():
    d = yaml.safe_load((MECH_DIR / "gough-stewart-6ups.yaml").read_text())
    d.update(name="ups6-not-the-paper",
             base_points=[[0.9 * x, 0.9 * y, z] for x, y, z in d["base_points"]],
             platform_points=[[1.2 * x, 1.2 * y, z] for x, y, z in d["platform_points"]])
    return pkmlab.load_mechanism(d)


PSU, UPS = _psu(), _ups()
MECHS = pytest.mark.parametrize("mech", [PSU, UPS], ids=["psu6", "ups6"])


def _rz(theta):
    c, s = np.cos(theta), np.sin(theta)
    R = np.zeros((len(theta), 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1], R[:, 2, 2] = c, -s, s, c, 1.0
    return R


def _poses(mech, n=300, seed=4):
    """Random poses around the nominal one; one NaN position, one far out of reach, eleven
    turned by 85°-95° about z and three within 1e-9 rad of 90° (exactly 90° for the 6-UPS
    is Fichter's singularity)."""
    rng = np.random.default_rng(seed)
    p = mech.nominal_pose[:3] + rng.uniform(-90, 90, (n, 3))
    p[3] = np.nan
    p[7] = mech.nominal_pose[:3] + [0.0, 0.0, 5e3]
    R = euler_to_matrix(np.radians(rng.uniform(-35, 35, (n, 3)))).reshape(-1, 3, 3)
    p[10:24] = mech.nominal_pose[:3]
    R[10:21] = _rz(np.radians(np.linspace(85.0, 95.0, 11)))
    R[21:24] = _rz(np.pi / 2 + np.array([1e-13, 1e-11, 1e-9]))   # κ about 4e13, 4e11, 4e9
    return p, R


@MECHS
def test_kernels_equal_numpy_bit_for_bit(mech):
    p, R = _poses(mech)
    L = 95.0
    J = mech.jacobian((p, R))
    want = condition_number(J, L)
    Jout = np.empty_like(J)
    got = fe.fused_kappa(mech, p, R, L, jacobians=Jout)
    np.testing.assert_array_equal(got, want)                 # bit for bit, inf where inf
    np.testing.assert_array_equal(Jout, J)                   # NaN where NaN
    assert np.isinf(got[3]) and np.isfinite(got).sum() > 250
    if mech is UPS:                     # Fichter: 90° about z; nearby, bounds above 1e8
        assert np.isinf(got[15]) and np.isinf(got[21]) and 1e9 < got[22] < 1e12
    np.testing.assert_array_equal(fe.fused_singular(mech, p, R, L), sweep.singular(J, L))
    P, Rs = p[:40], R[:25]
    grid = condition_number(mech.jacobian((np.tile(P, (25, 1)), np.repeat(Rs, 40, axis=0))), L)
    np.testing.assert_array_equal(fe.fused_kappa_grid(mech, P, Rs, L), grid.reshape(25, 40).T)
    try:
        fe.FUSED = False
        want_max = maps._unit_kappa_max(mech, P, Rs, L)
    finally:
        fe.FUSED = True
    np.testing.assert_array_equal(fe.fused_kappa_max(mech, P, Rs, L), want_max)
    np.testing.assert_array_equal(want_max, grid.reshape(25, 40).max(axis=0))


def _workspace(mech):
    if mech is PSU:         # reachable: some orientations out of reach at a voxel
        return workspace(PSU, "reachable", OrientationSet.box(np.radians([20] * 3), samples=3),
                         8.0)
    # turned by up to 90° about z: Fichter's singularity among the samples
    return workspace(UPS, "reachable", OrientationSet.box(np.radians([5, 5, 90]), samples=3),
                     60.0)


def _motion(mech):
    """The paper motion (about 3,100 samples), with a sample without a pose, one out of the
    stroke and, for the 6-UPS, a turn through 90° about z."""
    m = paper_motion(mech)
    t, X = m.t, m.poses.copy()
    X[50] = np.nan
    X[60, 2] += 400.0
    if mech is UPS:
        X[100:141, 5] = np.radians(np.linspace(70.0, 110.0, 41))
    return t, X


def _callers(mech, res, length, t, X):
    out = {}
    for metric in ("kappa", "lci"):
        mm = dx.maps.metric_map(mech, res, metric, length)
        out[metric] = (mm.values, mm.grid)
    drawn = dx.maps.drawn_voxels(res, [float(np.mean(res.zs))])
    out["drawn"] = dx.maps.metric_map(mech, res, "kappa", length, where=drawn).values
    g = dx.kappa_grid(mech, res, length)
    out["grid"] = (g.kappa, g.valid)
    out["gci_grid"] = dx.gci_grid(mech, res, grid=g).__dict__
    out["gci_mc"] = dx.gci_monte_carlo(mech, res, length, samples=3000, seed=2).__dict__
    rep = check_trajectory(mech, t, X, characteristic_length=length, payload_mass_kg=3.0,
                           max_force=200.0)
    out["check"] = (rep.condition, rep.force, rep.status, rep.summary())
    fit = trajectory_fit(mech, t, X, characteristic_length=length)
    clean = paper_motion(mech)
    fit2 = trajectory_fit(mech, clean.t, clean.poses, characteristic_length=length)
    turn = np.tile(mech.nominal_pose, (101, 1))           # 0°-100° about z, 90° among them
    turn[:, 5] = np.radians(np.linspace(0.0, 100.0, 101))
    fit3 = trajectory_fit(mech, np.arange(101.0), turn, characteristic_length=length)
    out["fit"] = (fit.fits, fit.margin_low, fit2.fits, fit2.margin_high, fit3.fits)
    return out


@MECHS
def test_callers_fused_and_unfused_are_identical(mech):
    res = _workspace(mech)
    length = dx.resolve_length(mech)
    t, X = _motion(mech)
    out = {}
    try:
        for flag in (False, True):
            fe.FUSED = flag
            out[flag] = _callers(mech, res, length, t, X)
    finally:
        fe.FUSED = True
    assert out[True].keys() == out[False].keys()
    for key in out[True]:
        assert same_result(out[False][key], out[True][key]), key
    cond, force, status, _ = out[True]["check"]
    assert np.isinf(cond[50]) and np.isnan(force[50]).all() and "non-finite" in status[50]
    assert "stroke" in status[60] and status[0] == "ok"
    assert np.isfinite(cond).sum() > 3000 and np.isfinite(force).any()
    assert out[True]["fit"][0] is False and out[True]["fit"][2] is True
    assert out[True]["grid"][1].any() and not out[True]["grid"][1].all()
    if mech is UPS:           # Fichter's singularity in the motion, the turn and the grid
        assert np.isinf(cond[120]) and "singular" in status[120]
        assert out[True]["fit"][4] is False and out[True]["gci_grid"]["singular"] > 0


def test_the_fused_path_is_taken(monkeypatch):
    """With ``Mechanism.jacobian`` (what the unfused path calls) raising, every served caller
    still runs and gives the unfused values; a family the kernels do not serve still fails."""
    mech = UPS
    res = _workspace(mech)
    length = dx.resolve_length(mech)
    t, X = _motion(mech)
    want = _callers(mech, res, length, t, X)

    def unfused(*args, **kwargs):
        raise AssertionError("the unfused path was taken")

    monkeypatch.setattr(type(mech), "jacobian", unfused)
    monkeypatch.setattr(maps, "sweep_bounds", unfused)
    got = _callers(mech, res, length, t, X)
    for key in want:
        assert same_result(want[key], got[key]), key
    fe.FUSED = False
    try:
        with pytest.raises(AssertionError, match="unfused path"):
            dx.gci_monte_carlo(mech, res, length, samples=50)
    finally:
        fe.FUSED = True
    tri = pkmlab.load_mechanism(MECH_DIR / "tripod-3prs.yaml")
    assert not fe.serves(tri) and fe.serves(PSU) and fe.serves(UPS)
