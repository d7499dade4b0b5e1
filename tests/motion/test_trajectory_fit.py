"""The study's lean trajectory check (issue 28): ``trajectory_fit`` gives exactly
``check_trajectory``'s ``fits`` and margins, and ``dexterity.sweep.singular`` exactly the
singular samples of ``condition_number``, on designs that fit, fail and are singular."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from conftest import MECH_DIR
from scipy.stats import qmc

import pkmlab
from pkmlab import ParameterError
from pkmlab.dexterity import condition_number
from pkmlab.dexterity.sweep import singular
from pkmlab.motion import check_trajectory, paper_motion, trajectory_fit
from pkmlab.study import load_study

STUDY = Path(__file__).resolve().parents[2] / "studies" / "hopkins-6psu-redesign.yaml"


def _designs(n):
    space = load_study(STUDY).space
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=3).random(n)
    out = []
    for r in u:
        try:
            out.append(space.decode(space.from_unit(r)))
        except ParameterError:                  # an invalid design (e.g. inner > outer radius)
            pass
    return out


def _same(mech, t, X, **kw):
    rep = check_trajectory(mech, t, X, **kw)
    fit = trajectory_fit(mech, t, X, **{k: v for k, v in kw.items()
                                        if k != "payload_mass_kg"})
    assert fit.fits == rep.fits
    np.testing.assert_array_equal(fit.margin_low, rep.margin_low)
    np.testing.assert_array_equal(fit.margin_high, rep.margin_high)
    return rep.fits


def test_trajectory_fit_matches_the_full_check_on_study_designs():
    """Bit-identical margins and the same verdict on the valid ones of 16 sampled designs of
    the demo study (some fit the paper motion, some do not), with and without a payload."""
    verdicts = []
    for mech in _designs(16):
        motion = paper_motion(mech)
        verdicts.append(_same(mech, motion.t, motion.poses))
    mech = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
    motion = paper_motion(mech)
    verdicts.append(_same(mech, motion.t, motion.poses, payload_mass_kg=2.0))
    assert any(verdicts) and not all(verdicts), verdicts      # both cases are exercised


def test_trajectory_fit_fails_on_a_singular_sample():
    """The Gough-Stewart platform turned 90° about z (Fichter's singularity: κ = inf there,
    finite before) fails both checks although every pose has valid inverse kinematics."""
    mech = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")
    X = np.tile(mech.nominal_pose, (7, 1))
    X[:, 5] = np.radians(np.linspace(60.0, 90.0, 7))
    t = np.arange(7.0)
    rep = check_trajectory(mech, t, X, stroke_tolerance=1e4)
    assert rep.ik_valid.all() and np.isfinite(rep.condition[:-1]).all()
    assert not np.isfinite(rep.condition[-1])
    assert _same(mech, t, X, stroke_tolerance=1e4) is False
    assert _same(mech, t[:-1], X[:-1], stroke_tolerance=1e4) is True


def test_singular_is_exactly_the_infinite_condition_number():
    """Random, rank-deficient, nearly singular (κ from 1e10 to 1e14, the threshold 1e12 in
    between) and non-finite 6 × 6 Jacobians: the certified shortcut flags exactly the
    matrices whose exact κ is inf."""
    rng = np.random.default_rng(5)
    J = [rng.normal(size=(40, 6, 6))]
    A = rng.normal(size=(10, 6, 6))
    A[:, 5] = A[:, 4]                                   # two equal rows: rank 5
    J.append(A)
    U, _, Vt = np.linalg.svd(rng.normal(size=(60, 6, 6)))
    kappa = np.logspace(10, 14, 60)
    S = np.ones((60, 6))
    S[:, -1] = 1.0 / kappa
    J.append(np.einsum("nij,nj,njk->nik", U, S, Vt))
    B = rng.normal(size=(4, 6, 6))
    B[0, 2, 3] = np.nan
    B[1, 0, 0] = np.inf
    J.append(B)
    J = np.concatenate(J)
    for L in (1.0, 80.0):
        ref = ~np.isfinite(condition_number(J, L))
        assert 0 < ref.sum() < len(J)
        np.testing.assert_array_equal(singular(J, L), ref)
