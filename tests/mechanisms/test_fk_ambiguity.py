"""Issue 22 item 5: forward kinematics says when another working-mode assembly mode exists.

On the Hexaglide, Newton from the nominal pose returns a *different* valid working-mode pose
for many random valid poses (27 of 400 in the issue; 114 of 400 here, positions ±200 mm and
angles ±25° about the nominal pose), with status "ok" before the fix. The true pose is known
(the test draws it), so the check is independent of the mode search: wherever FK returns
another pose, the result must be flagged, and the reported next mode must be a genuine
working-mode solution (its IK reproduces q) no farther than the true pose.
"""

from __future__ import annotations

import json

import numpy as np
from conftest import MECH_DIR
from typer.testing import CliRunner

from pkmlab import load_mechanism
from pkmlab.cli import app
from pkmlab.poses import as_frames, log_so3

HEXAGLIDE = MECH_DIR / "hexaglide-6pus.yaml"


def _valid_poses(mech, n, seed):
    rng = np.random.default_rng(seed)
    X0 = np.asarray(mech.nominal_pose)
    out = []
    while len(out) < n:
        X = X0 + np.concatenate([rng.uniform(-200, 200, (4 * n, 3)),
                                 np.radians(rng.uniform(-25, 25, (4 * n, 3)))], axis=1)
        out.extend(X[mech.inverse(X).valid])
    return np.array(out[:n])


def _distance(mech, A, B):
    pa, Ra = as_frames(A)
    pb, Rb = as_frames(B)
    return (np.linalg.norm(pa - pb, axis=1),
            np.linalg.norm(log_so3(np.einsum("nji,njk->nik", Ra, Rb)), axis=1))


def test_hexaglide_fk_flags_every_other_mode_it_returns():
    mech = load_mechanism(HEXAGLIDE)
    X = _valid_poses(mech, 400, 5)
    q = mech.inverse(X).q
    fk = mech.forward(q, modes=True)
    ok = fk.converged
    dp, da = _distance(mech, np.where(ok[:, None], fk.pose, X), X)
    other = ok & ((dp > 1e-6) | (da > 1e-8))
    assert other.sum() >= 20                                   # measured: 114
    # the returned pose is a genuine working-mode solution: IK reproduces q
    back = mech.inverse(fk.pose[other])
    assert back.valid.all() and np.max(np.abs(back.q - q[other])) < 1e-6
    # every such result is flagged, with the distance to the next mode
    assert np.all(fk.ambiguous[other]) and np.all(fk.status[other] == "ambiguous")
    assert np.all(np.isfinite(fk.next_mode_mm[other]))
    # the next mode is a working-mode solution of q, no farther than the true pose (which is
    # another mode): |Δp| + scale·angle
    nb = mech.inverse(fk.next_mode[other])
    assert nb.valid.all() and np.max(np.abs(nb.q - q[other])) < 1e-6
    reported = fk.next_mode_mm[other] + mech.scale * np.radians(fk.next_mode_deg[other])
    assert np.all(reported <= dp[other] + mech.scale * da[other] + 1e-6)
    # unflagged results: no mode was found; the default (bulk) call does not run the check
    assert np.all(np.isinf(fk.next_mode_mm[~fk.ambiguous]))
    plain = mech.forward(q[:5])
    assert plain.ambiguous is None and set(plain.status) <= {"ok", "not converged", "singular"}


def test_fk_cli_reports_the_next_mode():
    mech = load_mechanism(HEXAGLIDE)
    X = _valid_poses(mech, 400, 5)
    q = mech.inverse(X).q
    fk = mech.forward(q)
    k = int(np.flatnonzero(fk.converged & (np.max(np.abs(fk.pose - X), axis=1) > 1e-6))[0])
    arg = ",".join(f"{v:.12f}" for v in q[k])
    res = CliRunner().invoke(app, ["fk", str(HEXAGLIDE), "--actuators", arg, "--json"])
    assert res.exit_code == 0, res.output
    d = json.loads(res.stdout)
    assert d["ambiguous"] and d["status"] == "ambiguous"
    assert d["next_mode"]["distance_mm"] > 0 and d["mode_starts"] > 1
    text = CliRunner().invoke(app, ["fk", str(HEXAGLIDE), "--actuators", arg]).output
    assert "ambiguous" in text and "mm and" in text
    # a machine with one working mode near its nominal pose says it found no other
    hop = MECH_DIR / "hopkins-williams-6psu.yaml"
    out = CliRunner().invoke(app, ["fk", str(hop), "--actuators", "50,50,50,50,50,50"]).output
    assert "no other working-mode assembly mode" in " ".join(out.split())
