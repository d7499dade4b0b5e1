"""The 3-PRS tripod in a design study (issue 24): the ``tripod_workspace`` evaluator's volume
bracket against :func:`~pkmlab.workspaces.tripod.tripod_volume_bracket` and an independent
finer grid count, its parasitic bounds against the feasible grid and random feasible points
(and a deliberately narrowed enclosure that the same check catches), the block refused on a
family without dependent coordinates, and the prs3 and ldelta3 templates run."""

from __future__ import annotations

import math
from types import SimpleNamespace

import numpy as np
import pytest
import yaml
from clihelp import cli, one_line
from conftest import MECH_DIR, ROOT

import pkmlab
from pkmlab.study import load_study
from pkmlab.study.evaluators import EVALUATORS, Context
from pkmlab.study.evaluators.tripod_workspace import DEG2, TripodWorkspaceSpec
from pkmlab.study.metrics import metrics_of
from pkmlab.workspaces.tripod import tripod_volume_bracket, tripod_workspace

TILT = math.radians(15.0)


@pytest.fixture(scope="module")
def mech():
    return pkmlab.load_mechanism(MECH_DIR / "tripod-3prs.yaml")


def _evaluate(mech, **block):
    plan = TripodWorkspaceSpec(**{"tilt": f"{math.degrees(TILT)} deg", "resolution_z": "5 mm",
                                  "resolution_angle": "1.5 deg", "target": 0.01, **block})
    ctx = Context(SimpleNamespace(tripod_workspace=plan), seed=0)
    return EVALUATORS["tripod_workspace"].compute(mech, ctx), ctx.notes


@pytest.fixture(scope="module")
def evaluated(mech):
    return _evaluate(mech)


def test_bracket_is_tripod_volume_bracket_and_contains_the_grid_counts(mech, evaluated):
    m, notes = evaluated
    ref = tripod_volume_bracket(mech, TILT, target=0.01, max_boxes=1_000_000, budget_s=10.0)
    assert ref.stop_reason == "converged" and "tripod_volume_lower" not in notes
    assert m["tripod_volume_lower"] == pytest.approx(ref.lower * DEG2, rel=1e-12)
    assert m["tripod_volume_upper"] == pytest.approx(ref.upper * DEG2, rel=1e-12)
    assert m["tripod_volume_bracket_width"] <= 1.0 + 1e-9
    assert m["tripod_volume_lower"] <= m["sampled_tripod_volume"] <= m["tripod_volume_upper"]
    # an independent, finer grid (4 mm, 0.75°): its count lies in the bracket too
    fine = tripod_workspace(mech, TILT, resolution_z=4.0, resolution_angle=math.radians(0.75),
                            bracket_target=None)
    assert not fine.notes
    assert m["tripod_volume_lower"] <= fine.volume * DEG2 <= m["tripod_volume_upper"]
    assert fine.volume * DEG2 == pytest.approx(m["sampled_tripod_volume"], rel=0.01)


def test_parasitic_bounds_hold_over_feasible_points_and_are_tight(mech, evaluated):
    m, notes = evaluated
    up = np.array([m["parasitic_x_upper"], m["parasitic_y_upper"],
                   math.radians(m["parasitic_theta_z_upper"])])
    grid = np.array([m["sampled_parasitic_x_max"], m["sampled_parasitic_y_max"],
                     math.radians(m["sampled_parasitic_theta_z_max"])])
    assert np.all(grid <= up) and np.all(grid > 0)
    assert "parasitic_x_upper" not in notes              # refined to the tolerance
    assert np.all(up <= grid * 1.01 + np.array([1e-3, 1e-3, 1e-5]) + 1e-12)
    # random points (uniform in z and the tilt box), the feasible ones by the IK
    rng = np.random.default_rng(5)
    F = np.column_stack([rng.uniform(-400, 300, 200_000),
                         rng.uniform(-TILT, TILT, (200_000, 2))])
    X = np.zeros((len(F), 6))
    X[:, 2:5] = F
    ok = mech.inverse(X).valid
    P = np.abs(mech.parasitic(F[ok]))
    assert ok.sum() > 10_000
    assert np.all(P.max(axis=0) <= up)
    # the corners of the tilt box at a height where they are feasible: the known maximum
    C = np.array([[-100.0, sx * TILT, sy * TILT] for sx in (-1, 1) for sy in (-1, 1)])
    X = np.zeros((4, 6))
    X[:, 2:5] = C
    assert mech.inverse(X).valid.all()
    assert np.all(np.abs(mech.parasitic(C)).max(axis=0) <= up)


def test_a_narrowed_enclosure_is_caught(mech, monkeypatch):
    """The check above can fail: 'enclosures' that are the rectangles' centre values (a
    sampled maximum passed off as a bound) fall below the feasible grid's excursions."""
    from pkmlab.mechanisms.families import prs3_boxes
    from pkmlab.mechanisms.kernels.interval_arith import Iv

    real = prs3_boxes.parasitic_enclosure

    def narrowed(mech, lo, hi):
        never, *ivs = real(mech, lo, hi)
        return (never, *[Iv(0.5 * (v.lo + v.hi)) for v in ivs])

    monkeypatch.setattr(prs3_boxes, "parasitic_enclosure", narrowed)
    m, _ = _evaluate(mech, resolution_angle="5 deg", target=0.05)
    assert m["parasitic_x_upper"] < m["sampled_parasitic_x_max"]


def _study(tmp_path, mech_file, **over):
    data = {"study": "t", "seed": 0, "output": str(tmp_path / "out"),
            "mechanism": {"file": str(MECH_DIR / mech_file)},
            "design": {"link_length": {"low": "220 mm", "high": "280 mm"}},
            "evaluate": {"tripod_workspace": {"tilt": "10 deg", "resolution_z": "10 mm",
                                              "resolution_angle": "5 deg"}},
            "objectives": [{"maximize": "tripod_volume_lower"}],
            "optimizer": {"method": "sobol", "samples": 2}, **over}
    p = tmp_path / "study.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


def test_validate_refuses_the_block_without_dependent_coordinates(tmp_path, capsys):
    path = _study(tmp_path, "hopkins-williams-6psu.yaml")
    code, _, err = cli(capsys, "validate", path)
    one_line(code, err, "evaluate.tripod_workspace", "dependent coordinates", "'psu6'")


def test_validate_refuses_a_tilt_of_90_deg(tmp_path, capsys):
    path = _study(tmp_path, "tripod-3prs.yaml",
                  evaluate={"tripod_workspace": {"tilt": "90 deg"}})
    code, _, err = cli(capsys, "validate", path)
    one_line(code, err, "evaluate.tripod_workspace.tilt")


@pytest.mark.parametrize("name, evaluator", [("prs3-study.yaml", "tripod_workspace"),
                                             ("ldelta3-study.yaml", "printer")])
def test_templates_validate_and_run(tmp_path, name, evaluator):
    from pkmlab.study import run_study
    from pkmlab.study.runners import SerialRunner

    data = yaml.safe_load((ROOT / "studies" / "templates" / name).read_text())
    data["mechanism"]["file"] = str(ROOT / "studies" / "templates" / data["mechanism"]["file"])
    data.update(output=str(tmp_path / "out"), optimizer={"method": "sobol", "samples": 2})
    p = tmp_path / name
    p.write_text(yaml.safe_dump(data))
    s = load_study(p)
    assert evaluator in s.evaluation.evaluators
    rows = run_study(s, SerialRunner()).all()
    assert len(rows) == 3 and all(r["status"] == "ok" for r in rows), rows
    for r in rows:
        assert set(r["metrics"]) >= set(s.evaluation.metrics)
        assert all(v is not None or k in r["notes"] for k, v in r["metrics"].items()
                   if k in metrics_of(evaluator)), (r["metrics"], r["notes"])
    # the summary's footer states the units of the columns it shows (it said "volumes in
    # cm³" for the tripod's mm·deg² volumes)
    from pkmlab.study.report import write_report

    write_report(tmp_path / "out", s, rows)
    foot = (tmp_path / "out" / "summary.md").read_text().splitlines()[-1]
    want = {"tripod_workspace": "mm·deg²", "printer": "cm³"}[evaluator]
    assert want in foot and ("cm³" in foot) == (evaluator == "printer"), foot
    if evaluator == "tripod_workspace":    # open_results gives the tripod's workspace
        from pkmlab import open_results

        ws = open_results(tmp_path / "out").workspace(rows[0]["seq"])
        m = rows[0]["metrics"]
        assert ws.volume * DEG2 == pytest.approx(m["sampled_tripod_volume"], rel=1e-12)
        assert ws.bracket.lower * DEG2 == pytest.approx(m["tripod_volume_lower"], rel=1e-12)


def test_exported_design_draws_the_tripod_sections(mech, tmp_path):
    from pkmlab.study.export import _tripod_slices

    plan = TripodWorkspaceSpec(tilt="10 deg", resolution_z="20 mm", resolution_angle="5 deg")
    files, info = [], {}
    _tripod_slices(tmp_path, mech, plan, files, info)
    assert files == ["parasitic_slices.png"]
    assert (tmp_path / files[0]).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    grid = info["tripod_workspace"]
    assert grid["points"] > 0 and "bracket" not in grid
    assert grid["parasitic_x_max_mm"] > 0
