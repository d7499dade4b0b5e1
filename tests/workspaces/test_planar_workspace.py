"""Planar workspaces (issue 24): the exact area of an intersection of annuli against closed
forms, the guaranteed bracket's soundness against sampled points of its cells, and the
3-RPR's constant, reachable and dexterous areas against a dense brute force."""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECH_DIR

import pkmlab
from pkmlab.workspaces import planar
from pkmlab.workspaces.planar import annuli_area, area_per_phi, planar_workspace


@pytest.fixture(scope="module")
def mech():
    return pkmlab.load_mechanism(MECH_DIR / "planar-3rpr.yaml")


def test_annuli_area_against_closed_forms():
    # one annulus; two equal discs (the lens); an annulus inside a big disc
    assert annuli_area([[3.0, -2.0]], [20.0], [50.0]) == pytest.approx(math.pi * 2100, 1e-12)
    r, d = 10.0, 12.0
    lens = 2 * r * r * math.acos(d / (2 * r)) - 0.5 * d * math.sqrt(4 * r * r - d * d)
    assert annuli_area([[0, 0], [d, 0]], [0, 0], [r, r]) == pytest.approx(lens, rel=1e-12)
    assert annuli_area([[0, 0], [1, 1]], [5, 0], [9, 100]) == pytest.approx(math.pi * 56,
                                                                           rel=1e-12)
    assert annuli_area([[0, 0], [100, 0]], [0, 0], [10, 10]) == 0.0


def test_cell_margins_are_sound_on_sampled_points(mech):
    """Cells of random size × orientation intervals: where the margins prove the cell in,
    every sampled point of it is feasible; where they prove it out, none is."""
    rng = np.random.default_rng(0)
    n, k = 3000, 40
    c = rng.uniform(-250, 250, (n, 2))
    half = rng.uniform(0.5, 30.0, n)
    phi = rng.uniform(-1.5, 1.5, n)
    alpha = rng.uniform(0, 0.2, n)
    m, eps = mech.planar_cell_margins(c, phi, half * math.sqrt(2), alpha)
    cin, cout = np.all(m > eps, axis=1), np.any(m < -eps, axis=1)
    assert cin.sum() > 300 and cout.sum() > 300
    P = c[:, None, :] + rng.uniform(-1, 1, (n, k, 2)) * half[:, None, None]
    A = phi[:, None] + rng.uniform(-1, 1, (n, k)) * alpha[:, None]
    X = np.zeros((n * k, 6))
    X[:, :2], X[:, 5] = P.reshape(-1, 2), A.ravel()
    ok = mech.inverse(X).valid.reshape(n, k)
    assert ok[cin].all() and not ok[cout].any()


def test_constant_area_exact_inside_bracket_and_dense_brute_force(mech):
    res = planar_workspace(mech, "constant", 0.3, 10.0, target=0.005)
    assert res.lower <= res.exact <= res.upper
    assert res.upper - res.lower <= 0.005 * res.lower
    # dense brute force: cell centres of a 1 mm grid, plain numpy distances
    x = np.arange(-300.0, 300.0, 1.0) + 0.5
    X, Y = np.meshgrid(x, x, indexing="ij")
    c, rin, rout = mech.annuli(0.3)
    d = np.hypot(X[..., None] - c[:, 0], Y[..., None] - c[:, 1])
    count = np.all((d >= rin) & (d <= rout), axis=-1).sum()
    assert count == pytest.approx(res.exact, rel=2e-3)
    assert res.estimate == pytest.approx(res.exact, rel=0.02)       # a 10 mm grid estimate
    assert res.metrics()["area_exact_mm2"] == res.exact


@pytest.mark.parametrize("kind", ["reachable", "dexterous"])
def test_reachable_and_dexterous_bracket_the_dense_brute_force(mech, kind):
    """Brute force: 2.5 mm cell centres × 121 orientations of ±20°: its count lies in the
    guaranteed bracket (widened by 0.5 % for the brute force's own grid and φ sampling)."""
    lo, hi = np.radians([-20.0, 20.0])
    res = planar_workspace(mech, kind, (lo, hi), 10.0)
    h = 2.5
    x = np.arange(-300.0, 300.0, h)
    X, Y = (g.ravel() for g in np.meshgrid(x, x, indexing="ij"))
    acc = np.zeros(len(X), bool) if kind == "reachable" else np.ones(len(X), bool)
    for a in np.linspace(lo, hi, 121):
        c, rin, rout = mech.annuli(a)
        d = np.hypot(X[:, None] - c[:, 0], Y[:, None] - c[:, 1])
        ok = np.all((d >= rin) & (d <= rout), axis=1)
        acc = acc | ok if kind == "reachable" else acc & ok
    brute = acc.sum() * h * h
    assert res.lower * 0.995 <= brute <= res.upper * 1.005, (res.bracket, brute)
    assert res.upper - res.lower < 0.05 * res.lower
    const = planar_workspace(mech, "constant", 0.0, 10.0)
    if kind == "reachable":
        assert res.lower > const.upper          # more than any one orientation
    else:
        assert res.upper < const.lower


def test_area_per_phi_and_slice_plot(mech, tmp_path):
    phis = np.radians([-60.0, 0.0, 45.0])
    res = area_per_phi(mech, phis, 10.0)
    for r, a in zip(res, phis):
        assert r.phi == (a, a) and r.lower <= r.exact <= r.upper
    # at φ = -60° the platform is homothetic to the base: the whole slice is type II
    X = np.zeros((5, 6))
    X[:, :2] = np.random.default_rng(1).uniform(-100, 100, (5, 2))
    X[:, 5] = phis[0]
    assert np.all(mech.singularity(X) == 2)
    out = planar.plot_planar(mech, res, tmp_path / "slices.png")
    assert out.stat().st_size > 10_000


def test_refuses_what_it_cannot_serve(mech):
    from pkmlab.errors import ParameterError

    with pytest.raises(ParameterError, match="phi: must be one angle"):
        planar_workspace(mech, "constant", (0.0, 0.1))
    with pytest.raises(ParameterError, match="kind: must be one of"):
        planar_workspace(mech, "total", None)
    hex_ = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")
    with pytest.raises(ParameterError, match="mechanism: must be a planar mechanism"):
        planar_workspace(hex_, "constant")


def test_the_3d_engine_refuses_a_planar_mechanism_naming_the_planar_module(mech):
    from pkmlab.errors import ParameterError

    with pytest.raises(ParameterError, match="pkmlab.workspaces.planar"):
        pkmlab.workspace(mech, "constant", resolution=10.0)
