"""A lower-mobility mechanism through the workspace, dexterity and study layers (issue 23,
item 1 "Mobility as data"): the three-leg translational test family's constant workspace, its
κ (no characteristic length) and a small study, each against an independent computation."""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

import pkmlab
from pkmlab import dexterity as dx
from pkmlab.errors import ParameterError
from pkmlab.workspaces import OrientationSet

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "data" / "plugin3"))
import pkmlab_tri3_family as tri3  # noqa: E402
from conftest import family_registered  # noqa: E402

H = 20.0                       # mm: a coarse grid keeps the file fast (about 1 s per workspace)
B, U = tri3.circle(300.0), tri3.circle(60.0)
STROKE = (250.0, 600.0)


@pytest.fixture(scope="module")
def tripod():
    with family_registered(tri3.Tri3):
        yield tri3.reporters_tripod()


@pytest.fixture(scope="module")
def constant(tripod):
    return pkmlab.workspace(tripod, "constant", resolution=H)


def _unit_rows(p):
    """Independent Jacobian of the translating tripod: row i is the unit vector of leg i."""
    s = np.asarray(p, dtype=float) + U - B
    return s / np.linalg.norm(s, axis=1)[:, None]


def test_constant_workspace_volume_matches_a_plain_numpy_count_of_the_shells(tripod, constant):
    """The feasible set is the intersection of the spherical shells |p + u_i - b_i| in
    [250, 600] mm on the z > 0 side (the working mode): counted here on the same grid
    (centres at multiples of h), volume = count × h³. Refused before ("six free pose
    coordinates for workspaces")."""
    assert constant.method == "sampled voxels" and constant.components == 1
    g = np.arange(-1000.0, 1000.0 + H, H)
    X, Y, Z = np.meshgrid(g, g, g[g > 0], indexing="ij")
    p = np.stack([X, Y, Z], axis=-1)[..., None, :]                    # (..., 1, 3)
    d = np.linalg.norm(p + U - B, axis=-1)                            # (..., 3)
    inside = np.all((d >= STROKE[0]) & (d <= STROKE[1]), axis=-1)
    assert not inside[[0, -1]].any() and not inside[:, [0, -1]].any()  # the box holds it
    count = int(inside.sum())
    assert constant.volume == pytest.approx(count * H ** 3, rel=0, abs=0.5 * H ** 3)
    # the exact column lengths: the voxel runs cover [z_k0 - h/2, z_k1 + h/2]
    assert constant.volume / 1e6 == pytest.approx(75.032, abs=1e-9)   # litres, 20 mm grid


def test_a_translational_mechanism_has_constant_orientation_workspaces_only(tripod):
    with pytest.raises(ParameterError, match=r"kind: must be 'constant' for a mechanism "
                       r"without a free rotation .*translational mobility"):
        pkmlab.workspace(tripod, "dexterous", OrientationSet.box(np.radians([5, 5, 5])),
                         resolution=H)
    with pytest.raises(ParameterError, match="orientations: must be the nominal orientation"):
        pkmlab.workspace(tripod, "constant", OrientationSet.box(np.radians([5, 5, 5])),
                         resolution=H)


def test_kappa_needs_no_characteristic_length_and_is_the_condition_number_of_the_legs(tripod):
    """κ = σmax/σmin of the 3 × 3 matrix of unit leg directions (numpy.linalg.cond by hand)."""
    L = dx.resolve_length(tripod)
    assert L.length is None and L.status == "not-applicable" and "no rotational" in L.reason
    assert L.as_dict()["length_mm"] is None
    assert dx.resolve_length(tripod, 100.0).status == "not-applicable"     # a given L unused
    P = np.array([[0.0, 0.0, 400.0], [120.0, -80.0, 300.0], [-200.0, 150.0, 520.0],
                  [300.0, 10.0, 60.0]])
    J = tripod.jacobian(P)
    kap = dx.condition_number(J, L)
    ref = np.array([np.linalg.cond(_unit_rows(p)) for p in P])
    np.testing.assert_allclose(kap, ref, rtol=1e-12)
    np.testing.assert_allclose(dx.condition_number(J, None), ref, rtol=1e-12)
    assert L.kappa == pytest.approx(np.linalg.cond(_unit_rows(tripod.nominal_pose[:3])),
                                    rel=1e-12)
    # force: the translational wrench is a force only, F = min_i f / ‖(J⁻ᵀ)_i‖
    G = np.linalg.inv(_unit_rows(P[1])).T
    f = dx.max_force_all_directions(J[1], 150.0, None, tripod.mobility)[0]
    assert f == pytest.approx(np.min(150.0 / np.linalg.norm(G, axis=1)), rel=1e-12)
    st = dx.stiffness(J[1], 1e4, tripod.mobility)
    assert st.K.shape == (3, 3) and np.isnan(st.rotational_min)
    assert st.translational_min == pytest.approx(
        np.linalg.eigvalsh(1e4 * _unit_rows(P[1]).T @ _unit_rows(P[1]))[0], rel=1e-12)
    with pytest.raises(ParameterError, match="L: must be None or a CharacteristicLength"):
        dx.condition_number(J, 100.0)            # which of 3 columns rotate? refused


def test_worst_case_and_gci_over_the_constant_workspace_against_numpy(tripod, constant):
    """Every voxel centre (the family has no column kernel: sampled voxels, whose run faces
    are not the boundary, so no column end counts): the largest numpy.linalg.cond of the unit
    rows; the grid GCI: the mean of 1/cond over the voxel centres."""
    wc = dx.worst_case(tripod, constant, force_limit=150.0)
    assert wc.status == "ok" and not wc.singular and wc.length.status == "not-applicable"
    occ = constant.occupancy
    idx = np.argwhere(occ)
    pos = np.stack([constant.xs[idx[:, 0]], constant.ys[idx[:, 1]], constant.zs[idx[:, 2]]], 1)
    conds = np.array([np.linalg.cond(_unit_rows(p)) for p in pos])
    assert wc.grid_max_kappa == pytest.approx(conds.max(), rel=1e-9)
    k_at = np.linalg.cond(_unit_rows(wc.worst_kappa_pose[:3]))
    assert wc.worst_kappa == pytest.approx(k_at, rel=1e-9)
    assert wc.worst_kappa == pytest.approx(conds.max(), rel=1e-9) and wc.boundary_points == 0
    forces = np.array([np.min(150.0 / np.linalg.norm(np.linalg.inv(_unit_rows(p)).T, axis=1))
                       for p in pos])
    assert wc.grid_min_force == pytest.approx(forces.min(), rel=1e-9)
    g = dx.gci_grid(tripod, constant)
    assert g.gci == pytest.approx(np.mean(1.0 / conds), rel=1e-12) and g.L is None


def test_dexterity_report_on_the_tripod(tripod):
    from pkmlab.dexterity.report import dexterity_report

    rep = dexterity_report(tripod, {"kind": "constant", "resolution": H},
                           force_limit=150.0, actuator_stiffness=1e4, gci_samples=200)
    nom = rep.data["nominal"]
    assert rep.data["characteristic_length"]["status"] == "not-applicable"
    assert nom["kappa"] == pytest.approx(np.linalg.cond(_unit_rows(tripod.nominal_pose[:3])),
                                         rel=1e-12)
    assert nom["moment_all_directions_Nmm"] is None and nom["manipulability_rotational"] is None
    from pkmlab.cli.common import _kappa_text

    assert _kappa_text(nom).startswith("κ = 2.067 (no characteristic length")
    agg = rep.data["aggregates"]
    assert agg["workspace_volume_cm3"] == pytest.approx(75032.0)
    assert agg["worst_case"]["status"] == "ok" and agg["kappa"]["singular_samples"] == 0


def _study(tmp_path, **evaluate):
    data = {"study": "tri3", "seed": 1, "output": str(tmp_path / "out"),
            "mechanism": {"inline": {"family": "tri3", "base_points": B.tolist(),
                                     "platform_points": U.tolist(), "stroke": list(STROKE)}},
            "design": {"stroke_max": {"low": "550 mm", "high": "650 mm", "path": "stroke[1]",
                                      "quantity": "length"}},
            "evaluate": {"workspace": {"kind": "constant", "resolution": f"{H:g} mm"},
                         **evaluate},
            "objectives": [{"maximize": "constant_volume"}, {"minimize": "worst_kappa"}],
            "optimizer": {"method": "sobol", "samples": 2}}
    p = tmp_path / "study.yaml"
    p.write_text(yaml.safe_dump(data))
    return p


def test_a_small_study_with_workspace_and_dexterity_validates_and_runs(tripod, tmp_path):
    """Refused before ("workspace needs six free pose coordinates"); now the study runs and its
    volumes are the engine's at each design."""
    from pkmlab.study import load_study, run_study
    from pkmlab.study.runners import SerialRunner

    study = load_study(_study(tmp_path, dexterity={"gci_samples": 200}))
    store = run_study(study, SerialRunner())
    rows = store.all()
    assert [r["role"] for r in rows] == ["baseline", "candidate", "candidate"]
    assert all(r["status"] == "ok" for r in rows), [r["reason"] for r in rows]
    for row in rows:
        m = row["metrics"]
        mech = tri3.Tri3(B, U, (250.0, float(row["params"].get("stroke_max", STROKE[1]))))
        ref = pkmlab.workspace(mech, "constant", resolution=H)
        assert m["constant_volume"] == pytest.approx(ref.volume / 1e3, rel=1e-12)
        assert m["worst_kappa"] == pytest.approx(dx.worst_case(mech, ref).worst_kappa,
                                                 rel=1e-12)
        assert m["nominal_kappa"] == pytest.approx(
            np.linalg.cond(_unit_rows(mech.nominal_pose[:3])), rel=1e-12)
        assert m["characteristic_length"] is None
        assert row["notes"]["characteristic_length"].startswith("not applicable")


@pytest.mark.parametrize("evaluate, field", [
    ({"workspace": {"kind": "dexterous", "box": [5, 5, 5], "resolution": "20 mm"}},
     r"evaluate.workspace .*: must be a block this mechanism can serve \(workspace needs "
     "rotations"),
    ({"dexterity": {"characteristic_length": "100 mm"}},
     "evaluate.dexterity.characteristic_length.*: must be 'auto' for a mechanism without"),
])
def test_blocks_a_translational_mechanism_cannot_serve_are_refused_naming_the_field(
        tripod, tmp_path, evaluate, field):
    from pkmlab.study import load_study

    with pytest.raises(ParameterError, match=field):
        load_study(_study(tmp_path, **evaluate))


def test_analyses_still_on_six_coordinates_refuse_the_tripod_naming_the_mechanism(tripod):
    """Brackets, optima and trajectory checks are not yet sized from the mobility: they refuse
    (now that workspace() accepts the tripod, a bracket would otherwise run on it)."""
    from pkmlab.workspaces.bracket.columns import volume_bracket
    from pkmlab.workspaces.optima.search import orientation_capability

    for call, what in ((lambda: volume_bracket(tripod, "constant", resolution=H),
                        "volume brackets"),
                       (lambda: orientation_capability(tripod), "orientation capability")):
        with pytest.raises(ParameterError, match=f"mechanism: must be a mechanism with six "
                           f"free pose coordinates for {what}"):
            call()
