"""Delta and planar designs in ``compare`` and ``open_results`` like the six-DOF ones (issue 24).

* compare: a delta's row is computed over its level workspace (the orientation is fixed), the
  level volume the one :func:`pkmlab.workspace` gives on the same grid (to 1e-9 relative), and
  the cells that need a free rotation say ``n/a`` with the mobility; a planar design's row
  carries the area bracket of :func:`planar_workspace` (same numbers, 0.1 cm² as printed), a
  3-PRS's the (z, θx, θy) volume of :func:`tripod_workspace`; the page and the Markdown build;
* a planar study's ``evaluate.planar_workspace`` written back (study.resolved.yaml) reads the
  same φ range (it was read as degrees: ±15° came back as ±0.26°), and ``open_results``
  re-evaluates a planar design's workspace with the study's request.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from conftest import MECHANISMS, ROOT

from pkmlab.results import Results
from pkmlab.study import load_study, study_from_mapping
from pkmlab.study.compare import compare_designs, comparison_markdown, plot_overlaid_slices
from pkmlab.webreport import compare_html
from pkmlab.workspaces import workspace
from pkmlab.workspaces.planar import planar_workspace
from pkmlab.workspaces.tripod import tripod_workspace

H = 25.0


@pytest.fixture(scope="module")
def rows():
    names = ["clavel-delta3", "klipper-example-ldelta3", "fivebar-scara", "planar-3rpr",
             "tripod-3prs"]
    return {n: r for n, r in zip(names, compare_designs([(n, MECHANISMS[n]) for n in names],
                                                         box_deg=10.0, resolution=H,
                                                         samples=3), strict=True)}


@pytest.mark.parametrize("name", ["clavel-delta3", "klipper-example-ldelta3"])
def test_a_delta_row_is_over_its_level_workspace(rows, name):
    r, m = rows[name], MECHANISMS[name]
    want = workspace(m, "constant", None, H).volume / 1e3
    assert want > 0 and abs(r["constant_volume_cm3"] - want) <= 1e-9 * want
    assert r["dexterous_volume_cm3"].startswith("n/a: the orientation is fixed")
    assert r["paper_motion"].startswith("n/a")
    assert r["reference"] == "level (the orientation is fixed)"
    assert isinstance(r["gci"], float) and 0 < r["gci"] <= 1
    assert r["results"][1] is None and r["results"][0].volume / 1e3 == r["constant_volume_cm3"]


def test_planar_and_tripod_rows_carry_their_own_workspaces(rows, tmp_path):
    for name in ("fivebar-scara", "planar-3rpr"):
        lo, hi = planar_workspace(MECHANISMS[name], "constant", None, H).bracket
        text = rows[name]["constant_volume_cm3"]
        assert f"bracket {lo / 100:.1f} … {hi / 100:.1f} cm²" in text
        assert isinstance(rows[name]["gci"], float)
    m = MECHANISMS["planar-3rpr"]
    a, p0 = math.radians(10.0), float(m.nominal_pose[5])
    lo, hi = planar_workspace(m, "dexterous", (p0 - a, p0 + a), H, samples=3).bracket
    dex = rows["planar-3rpr"]["dexterous_volume_cm3"]
    assert f"bracket {lo / 100:.1f} … {hi / 100:.1f}" in dex
    assert rows["fivebar-scara"]["dexterous_volume_cm3"].startswith("n/a")
    v = tripod_workspace(MECHANISMS["tripod-3prs"], a, resolution_z=H).metrics()
    tri = rows["tripod-3prs"]["dexterous_volume_cm3"]
    lo, hi = v["volume_bracket_mm_deg2"]
    assert f"bracket {lo:.4g} … {hi:.4g} mm·deg² (sampled {v['sampled_volume_mm_deg2']:.4g})" \
        in tri
    md = comparison_markdown(list(rows.values()), 10.0)
    assert md.count("\n| ") >= 12
    planar = [rows["fivebar-scara"], rows["tripod-3prs"]]
    assert plot_overlaid_slices(planar, tmp_path / "none.png") is None
    assert not (tmp_path / "none.png").exists()
    assert plot_overlaid_slices(list(rows.values()), tmp_path / "s.png", which=1).is_file()
    assert compare_html(list(rows.values()), tmp_path / "c.html", box_deg=10.0).is_file()


def test_planar_study_round_trip_and_open_results(tmp_path):
    study = load_study(ROOT / "studies" / "planar-3rpr-design.yaml")
    plan = study.evaluation.planar_workspace
    back = study_from_mapping(study.resolved()).evaluation.planar_workspace
    np.testing.assert_allclose(back.phi, plan.phi, rtol=1e-15, atol=0)
    assert back.phi[1] == pytest.approx(math.radians(15.0), abs=1e-15)
    assert back.resolution == plan.resolution
    mech = study.baseline_mechanism if hasattr(study, "baseline_mechanism") else \
        study.space.decode(None)
    res = Results(tmp_path, study, [])._workspace("baseline", mech)
    want = planar_workspace(mech, plan.kind, tuple(plan.phi), plan.resolution,
                            samples=plan.samples, target=plan.target, max_depth=plan.max_depth)
    assert res.bracket == want.bracket and res.bracket[0] > 0
