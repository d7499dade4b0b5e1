"""The nominal pose's search (``Mechanism._mid_stroke_pose``) is bit-identical to its previous
form (issue 28, session 5: the scan's sign test is vectorised and the root search reuses one IK
driver and its buffers instead of calling ``_run_ik`` per evaluation).

The previous form is kept below verbatim; it is compared, with no tolerance, on the shipped
6-UPS and 6-PSU and on 12 sampled designs of the demo study (the other families' IK kernels
would be compiled for this alone).
"""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
from conftest import MECH_DIR
from scipy.stats import qmc

import pkmlab
from pkmlab.errors import ParameterError
from pkmlab.mechanisms.base import Mechanism
from pkmlab.mechanisms.results import NO_STROKE
from pkmlab.mechanisms.solvers import bracketed_root
from pkmlab.study import load_study
from pkmlab.tolerances import TOL

DEMO = Path(__file__).resolve().parents[2] / "studies" / "hopkins-6psu-redesign.yaml"


def _previous(self) -> np.ndarray:
    """``Mechanism._mid_stroke_pose`` before session 5 (verbatim but for the name)."""
    lo, hi = self.stroke
    mid = 0.5 * (lo + hi)
    yaw = self._level_yaw()
    Rz = np.array([[[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0],
                    [0.0, 0.0, 1.0]]])

    def mean_q(z: float) -> float:
        r = self._run_ik(np.array([[0.0, 0.0, z]]), Rz, *NO_STROKE)
        return float(np.mean(r.q[0])) - mid if r.valid[0] else np.nan

    S = self.scale
    zs = np.linspace(3.0 * S + hi, -S, 801)
    scan = self._run_ik(np.stack([np.zeros(801), np.zeros(801), zs], axis=1),
                        np.ascontiguousarray(np.broadcast_to(Rz, (801, 3, 3))), *NO_STROKE)
    vals = np.where(scan.valid, scan.q.mean(axis=1) - mid, np.nan)
    for k in range(len(zs) - 1):
        a, b = vals[k], vals[k + 1]
        if np.isfinite(a) and np.isfinite(b) and a * b <= 0:
            z = bracketed_root(mean_q, zs[k + 1], zs[k], xtol=TOL.nominal_z_mm)
            return np.array([0.0, 0.0, z, 0.0, 0.0, yaw])
    raise ParameterError("stroke", "previous", list(self.stroke))


def _both(mech):
    try:
        old = _previous(mech)
    except ParameterError:
        old = None
    try:
        new = mech._mid_stroke_pose()
    except ParameterError:
        new = None
    return old, new


def test_the_nominal_pose_search_is_bit_identical_to_its_previous_form():
    mechs = [pkmlab.load_mechanism(MECH_DIR / f) for f in ("gough-stewart-6ups.yaml",
                                                          "hopkins-williams-6psu.yaml")]
    assert all(type(m)._mid_stroke_pose is Mechanism._mid_stroke_pose for m in mechs)
    study = load_study(DEMO)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(d=len(study.space.variables), scramble=True, seed=9).random(12)
    for r in u:
        try:
            mechs.append(study.space.decode(study.space.from_unit(r)))
        except ParameterError:
            pass
    found = 0
    for m in mechs:
        old, new = _both(m)
        assert (old is None) == (new is None)
        if old is not None:
            found += 1
            assert np.array_equal(old, new), (m, old, new)
    assert found >= 12
