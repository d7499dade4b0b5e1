"""A planar mechanism in a design study (issue 24): the planar_workspace evaluator's metrics
against pkmlab.workspaces.planar and numpy.linalg.cond, the shipped 3-RPR study and template
validate, and the block is refused, naming it, for a mechanism that is not planar."""

from __future__ import annotations

import numpy as np
import pytest
import yaml
from conftest import MECH_DIR, ROOT

import pkmlab
from pkmlab import dexterity as dx
from pkmlab.errors import ParameterError
from pkmlab.study import load_study
from pkmlab.workspaces.planar import planar_workspace


def _study(tmp_path, mech_file="planar-3rpr.yaml", **block):
    data = {"study": "p", "seed": 1, "output": str(tmp_path / "out"),
            "mechanism": {"file": str(MECH_DIR / mech_file)},
            "design": {"stroke_max": {"low": "430 mm", "high": "470 mm", "path": "stroke[1]",
                                      "quantity": "length"}},
            "evaluate": {"planar_workspace": {"kind": "constant", "phi": ["10 deg"],
                                              "resolution": "10 mm", **block}},
            "objectives": [{"maximize": "planar_area_lower"}, {"maximize": "gci_planar"}],
            "optimizer": {"method": "sobol", "samples": 2}}
    p = tmp_path / "study.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


def test_study_metrics_are_the_planar_workspace_and_numpy_conditioning(tmp_path):
    from pkmlab.study import run_study
    from pkmlab.study.runners import SerialRunner

    rows = run_study(load_study(_study(tmp_path)), SerialRunner()).all()
    assert len(rows) == 3 and all(r["status"] == "ok" for r in rows)
    for row in rows:
        m = row["metrics"]
        base = pkmlab.load_mechanism(MECH_DIR / "planar-3rpr.yaml")
        mech = base.with_parameters({"stroke_max": row["params"].get("stroke_max", 450.0)})
        ref = planar_workspace(mech, "constant", np.radians(10.0), 10.0)
        assert m["planar_area"] == pytest.approx(ref.estimate / 100, rel=1e-12)
        assert m["planar_area_exact"] == pytest.approx(ref.exact / 100, rel=1e-12)
        assert m["planar_area_lower"] <= m["planar_area_exact"] <= m["planar_area_upper"]
        # κ by numpy: the Jacobian's rotation column divided by Angeles' length
        L = dx.resolve_length(mech)
        assert L.status == "angeles" and L.rotational == (2,)
        idx = np.argwhere(ref.occupancy)
        X = np.zeros((len(idx), 6))
        X[:, 0], X[:, 1], X[:, 5] = ref.xs[idx[:, 0]], ref.ys[idx[:, 1]], np.radians(10.0)
        J = mech.jacobian(X)
        J[:, :, 2] /= L.length
        kap = np.linalg.cond(J)
        assert m["gci_planar"] == pytest.approx(np.mean(1 / kap), rel=1e-10)
        assert m["sampled_planar_worst_kappa"] == pytest.approx(kap.max(), rel=1e-10)


def test_shipped_study_and_template_validate():
    for path in (ROOT / "studies" / "planar-3rpr-design.yaml",
                 ROOT / "studies" / "templates" / "rpr3-study.yaml"):
        s = load_study(path)
        assert "planar_workspace" in s.evaluation.evaluators


@pytest.mark.parametrize("mech_file, block, field", [
    ("gough-stewart-6ups.yaml", {}, "evaluate.planar_workspace"),
    ("planar-3rpr.yaml", {"kind": "reachable"}, "evaluate.planar_workspace.phi"),
])
def test_refused_naming_the_field(tmp_path, mech_file, block, field):
    with pytest.raises(ParameterError) as exc:
        load_study(_study(tmp_path, mech_file, **block))
    assert exc.value.field.startswith(field), str(exc.value)
