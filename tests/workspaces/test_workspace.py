"""Workspace engine: exactness against sampling, analytic volumes, convergence, constraints."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from conftest import MECH_DIR as STUDIES
from typer.testing import CliRunner

from pkmlab import PSU6, UPS6, load_mechanism
from pkmlab.cli import app
from pkmlab.errors import NumericalError, ParameterError
from pkmlab.workspaces import Constraints, JointLimits, OrientationSet, workspace
from pkmlab.workspaces.constraints import segment_distances
from pkmlab.workspaces.orientations import rotations_from_parameters

HOPKINS = STUDIES / "hopkins-williams-6psu.yaml"
BOX15 = OrientationSet.box(np.radians([15.0, 15.0, 15.0]), samples=3)


@pytest.fixture(scope="module")
def hopkins():
    return load_mechanism(HOPKINS)


def random_psu(rng) -> PSU6:
    return PSU6.from_circles(
        base_radii=tuple(sorted(rng.uniform(90, 180, 2))),
        platform_radii=tuple(sorted(rng.uniform(40, 90, 2))),
        platform_rotation=rng.uniform(0.1, 1.0), base_pair_separation=rng.uniform(0, 0.4),
        link_length=rng.uniform(200, 260), stroke=(0.0, rng.uniform(60, 140)),
        tool_offset=(0.0, 0.0, rng.uniform(0, 50)))


def random_ups(rng) -> UPS6:
    return UPS6.from_circles(
        base_radii=tuple(sorted(rng.uniform(120, 200, 2))),
        platform_radii=tuple(sorted(rng.uniform(50, 100, 2))),
        platform_rotation=rng.uniform(0.1, 1.0), base_pair_separation=rng.uniform(0, 0.4),
        platform_pair_separation=rng.uniform(0, 0.4),
        stroke=(rng.uniform(180, 230), rng.uniform(300, 360)))


def _agree(col, sam):
    """Column sets and sampled voxels agree at every voxel centre of a grid covering both
    (each result is cropped to its own footprint) except at a few boundary voxels."""
    h = sam.resolution
    axes = []
    for a, b in ((col.xs, sam.xs), (col.ys, sam.ys), (col.zs, sam.zs)):
        lo, hi = min(a[0], b[0]), max(a[-1], b[-1])
        axes.append(np.arange(round(lo / h), round(hi / h) + 1) * h)
    P = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    ref, got = col.contains(P), sam.contains(P)
    assert got.sum() == sam.occupancy.sum()
    return int((ref != got).sum()), int(ref.sum())


@pytest.mark.parametrize("seed", [0, 1, 2])
@pytest.mark.parametrize("kind", ["constant", "dexterous", "reachable"])
def test_columns_match_sampling_on_random_geometries(seed, kind):
    rng = np.random.default_rng(seed)
    for mech in (random_psu(rng), random_ups(rng)):
        oset = OrientationSet.fixed(rng.uniform(-0.2, 0.2, 3)) if kind == "constant" else \
            OrientationSet.box(np.radians([10.0, 8.0, 12.0]), samples=2)
        h = 6.0 if mech.family == "psu6" else 10.0
        cons = Constraints(connected=False)
        col = workspace(mech, kind, oset, h, cons)
        sam = workspace(mech, kind, oset, h, cons, method="sampled")
        assert col.method.startswith("columns") and sam.method == "sampled voxels"
        diff, inside = _agree(col, sam)
        assert inside > 0
        assert diff <= max(2, inside // 1000)


def test_parallel_leg_psu_volume_is_a_disc_times_the_stroke():
    # b_i = u_i: every leg sees the same disc of radius l about the origin, and every column's
    # interval has length qmax - qmin. V = π l² Δq.
    ang = np.radians([0, 50, 120, 170, 240, 290])
    U = np.stack([80 * np.cos(ang), 80 * np.sin(ang), np.zeros(6)], axis=1)
    mech = PSU6(U, U, 100.0, (0.0, 40.0))
    res = workspace(mech, "constant", None, 1.0)
    exact = math.pi * 100.0**2 * 40.0
    assert res.volume == pytest.approx(exact, rel=0.005)
    assert abs(res.volume - exact) <= res.volume_error


def test_parallel_leg_ups_volume_is_a_half_spherical_shell():
    # b_i = u_i: |p| is every leg's length, so the stroke admits the shell qmin <= |p| <= qmax;
    # the working mode (platform joints above their base joints) keeps its upper half.
    ang = np.radians([0, 50, 120, 170, 240, 290])
    U = np.stack([80 * np.cos(ang), 80 * np.sin(ang), np.zeros(6)], axis=1)
    mech = UPS6(U, U, (60.0, 100.0))
    res = workspace(mech, "constant", None, 2.0)
    exact = 2 / 3 * math.pi * (100.0**3 - 60.0**3)
    assert res.components == 1
    assert res.volume == pytest.approx(exact, rel=0.005)
    assert res.metrics()["z_range_mm"] == pytest.approx([0.0, 100.0], abs=1e-9)
    # the mirror (hanging) working mode is the lower half
    down = UPS6(U, U, (60.0, 100.0), nominal=[0, 0, -80.0, 0, 0, 0])
    res = workspace(down, "constant", None, 2.0)
    assert res.volume == pytest.approx(exact, rel=0.005)
    assert res.metrics()["z_range_mm"] == pytest.approx([-100.0, 0.0], abs=1e-9)
    assert down.inverse([0, 0, 80.0, 0, 0, 0]).reason_text[0] == "leg outside the working mode"


def test_volume_converges_with_resolution(hopkins):
    vols = [workspace(hopkins, "dexterous", BOX15, h) for h in (8.0, 4.0, 2.0, 1.0)]
    v = np.array([r.volume for r in vols])
    errs = np.abs(v[:-1] - v[-1])
    assert errs[1] <= errs[0] and errs[2] <= errs[1] + 1e-9
    for r in vols[:-1]:
        assert abs(r.volume - v[-1]) <= r.volume_error
    e = [r.volume_error for r in vols]
    assert e[0] > e[1] > e[2] > e[3]


def test_mesh_is_watertight_and_matches_volume(hopkins, tmp_path):
    res = workspace(hopkins, "dexterous", BOX15, 2.5)
    mesh = res.mesh()
    assert mesh.is_watertight and mesh.is_volume
    assert abs(mesh.volume - res.volume) <= res.volume_error
    for suffix in (".stl", ".ply", ".glb"):
        path = res.save_mesh(tmp_path / f"w{suffix}")
        assert path.stat().st_size > 1000


def test_stl_written_without_trimesh_equals_trimesh_export(hopkins, tmp_path):
    """The STL is written straight from the marching-cubes triangles (cold start): it must hold
    the same triangles, normals and orientation as trimesh's export of the merged mesh."""
    import trimesh

    from pkmlab.workspaces.output.mesh import STL_HEADER

    res = workspace(hopkins, "dexterous", BOX15, 2.5)
    ours = res.save_mesh(tmp_path / "w.stl").read_bytes()
    theirs = res.mesh().export(file_type="stl")
    assert ours[:80] == STL_HEADER.ljust(80, b" ")
    assert len(ours) == len(theirs) and ours[84:] == theirs[84:]      # same bytes after header
    loaded = trimesh.load(tmp_path / "w.stl")
    assert loaded.is_watertight and loaded.volume > 0
    assert abs(loaded.volume - res.volume) <= res.volume_error


def test_dexterous_within_reachable_and_nested_sets(hopkins):
    small = workspace(hopkins, "dexterous", OrientationSet.box(np.radians([5] * 3), samples=3),
                      4.0)
    big = workspace(hopkins, "dexterous", BOX15, 4.0)
    reach = workspace(hopkins, "reachable", BOX15, 4.0)
    single = workspace(hopkins, "dexterous", OrientationSet.box(
        np.radians([15.0] * 3), "single-axis", samples=3), 4.0)
    const = workspace(hopkins, "constant", None, 4.0)
    assert big.volume < small.volume < const.volume < reach.volume
    assert big.volume <= single.volume
    # containment of points, not just volumes
    assert np.all(small.contains(big.voxel_centres()))
    assert np.all(reach.contains(const.voxel_centres()))


def test_each_constraint_shrinks_the_workspace(hopkins):
    base = workspace(hopkins, "constant", None, 4.0)
    for cons in (Constraints(link_diameter=25.0),
                 Constraints(joint_limits=JointLimits(base=math.radians(12),
                                                      platform=math.radians(12))),
                 Constraints(kappa_max=4.0)):
        res = workspace(hopkins, "constant", None, 4.0, cons)
        assert 0 < res.volume < base.volume
        assert np.all(base.contains(res.voxel_centres()))
    tiny = workspace(hopkins, "constant", None, 4.0, Constraints(link_diameter=1.0))
    assert tiny.volume == pytest.approx(base.volume)


def test_z_dependent_constraints_on_ups_are_applied_per_voxel():
    mech = load_mechanism(STUDIES / "gough-stewart-6ups.yaml")
    base = workspace(mech, "constant", None, 25.0)
    res = workspace(mech, "constant", None, 25.0,
                    Constraints(joint_limits=JointLimits(base=math.radians(20))))
    assert "voxels" in res.method
    assert 0 < res.volume < base.volume


def test_components_keep_the_nominal_one():
    from pkmlab.workspaces.engine import _components, _piece_components

    xs = ys = np.arange(10) * 2.0
    lo = np.full((10, 10, 2), np.inf)
    hi = np.full((10, 10, 2), -np.inf)
    lo[:4, :4, 0], hi[:4, :4, 0] = 0.0, 10.0          # blob A
    lo[6:, 6:, 0], hi[6:, 6:, 0] = 0.0, 10.0          # blob B, apart in x-y
    lo[:4, :4, 1], hi[:4, :4, 1] = 30.0, 40.0         # blob C above A, apart in z
    lo[4, 4, 0], hi[4, 4, 0] = 11.0, 12.0             # within h of A's top: joins A
    n, keep, inside = _piece_components(lo, hi, xs, ys, np.array([14.0, 14.0, 5.0]))
    assert n == 3 and inside
    assert keep[7, 7, 0] and not keep[0, 0, 0] and not keep[0, 0, 1]
    n, keep, inside = _piece_components(lo, hi, xs, ys, np.array([2.0, 2.0, 20.0]))
    assert not inside and keep[0, 0, 0] and keep[4, 4, 0] and not keep[0, 0, 1]
    occ = np.zeros((10, 10, 10), dtype=bool)
    occ[:3, :3, :3] = True
    occ[6:, 6:, 6:] = True
    n, keep, inside = _components(occ, xs, ys, xs, np.array([14.0, 14.0, 14.0]), 2.0)
    assert n == 2 and inside and keep[9, 9, 9] and not keep[0, 0, 0]


def test_sampled_family_luzi():
    mech = load_mechanism(STUDIES / "luzi-3chain.yaml")
    res = workspace(mech, "constant", None, 40.0)
    assert res.method == "sampled voxels" and not res.empty and res.nominal_inside
    ik = mech.inverse(np.column_stack([
        np.stack(np.meshgrid(res.xs, res.ys, res.zs, indexing="ij"), -1).reshape(-1, 3),
        np.tile(mech.nominal_pose[3:], (res.occupancy.size, 1))]))
    inside = res.occupancy.ravel()
    assert np.all(ik.valid[inside])


def test_empty_workspace_is_a_valid_answer(hopkins):
    res = workspace(hopkins, "dexterous", OrientationSet.box(np.radians([30.0] * 3), samples=3),
                    5.0)
    assert res.empty and res.volume == 0.0
    assert res.metrics()["empty"] is True
    with pytest.raises(NumericalError, match="empty"):
        res.mesh()


def test_orientation_sets():
    box = OrientationSet.box(np.radians([10, 20, 30]), samples=5)
    assert box.rotations().shape == (125, 3, 3)
    single = OrientationSet.box(np.radians([10, 20, 30]), "single-axis", samples=5)
    P = single.parameters()
    assert len(P) == 13 and np.all(np.sum(P != 0, axis=1) <= 1)
    tt = OrientationSet.tilt_torsion(math.radians(25), math.radians(10), samples=5)
    R = tt.rotations()
    tilt = np.degrees(np.arccos(np.clip(R[:, 2, 2], -1, 1)))
    assert tilt.max() == pytest.approx(25.0) and tilt.min() == pytest.approx(0.0, abs=1e-9)
    # torsion: with φ = 0 the rotation is Ry(θ)Rz(σ); recover σ from the parameters' round trip
    params = tt.parameters()
    assert np.allclose(rotations_from_parameters(tt, params), R)
    assert np.abs(params[:, 2]).max() == pytest.approx(math.radians(10))
    with pytest.raises(ParameterError, match="orientations.tilt"):
        OrientationSet.tilt_torsion(math.radians(120))


def test_segment_distance_against_dense_sampling():
    rng = np.random.default_rng(3)
    start, end = rng.normal(size=(50, 6, 3)), rng.normal(size=(50, 6, 3))
    d = segment_distances(start, end)
    s = np.linspace(0, 1, 201)
    i, j = np.triu_indices(6, 1)
    A = start[:, i, None, :] + s[:, None] * (end - start)[:, i, None, :]
    B = start[:, j, None, :] + s[:, None] * (end - start)[:, j, None, :]
    brute = np.linalg.norm(A[:, :, :, None] - B[:, :, None, :], axis=-1).min(axis=(2, 3))
    assert np.all(d <= brute + 1e-12) and np.allclose(d, brute, atol=2e-2)


def test_bad_requests_raise(hopkins):
    with pytest.raises(ParameterError, match="kind"):
        workspace(hopkins, "everything")
    with pytest.raises(ParameterError, match="resolution"):
        workspace(hopkins, resolution=0.0)
    with pytest.raises(ParameterError, match="orientations"):
        workspace(hopkins, "constant", BOX15)
    with pytest.raises(ParameterError, match="link_diameter"):
        Constraints(link_diameter=-1.0)


def test_cli_workspace_writes_outputs(tmp_path):
    out = tmp_path / "ws"
    r = CliRunner().invoke(app, ["workspace", str(HOPKINS), "--kind", "dexterous", "--box",
                                 "10,10,10", "--samples", "3", "--resolution", "4",
                                 "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    data = json.loads(r.stdout)
    assert data["volume_cm3"] > 0
    assert {p.name for p in out.iterdir()} == {"workspace.npz", "workspace.json", "slices.png",
                                               "workspace.stl"}
    with np.load(out / "workspace.npz") as z:
        assert z["occupancy"].any()
        assert json.loads(str(z["metrics"]))["volume_mm3"] == pytest.approx(data["volume_mm3"])


def test_cli_empty_workspace_exits_zero_without_mesh(tmp_path):
    out = tmp_path / "ws"
    r = CliRunner().invoke(app, ["workspace", str(HOPKINS), "--kind", "dexterous", "--box",
                                 "30,30,30", "--samples", "3", "--resolution", "5",
                                 "--out", str(out)])
    assert r.exit_code == 0, r.output
    assert "empty" in r.stdout
    assert not (out / "workspace.stl").exists()


@pytest.mark.parametrize("args, field", [
    (["--kind", "dexterous"], "--box"),
    (["--kind", "dexterous", "--box", "10,10"], "--box"),
    (["--kind", "dexterous", "--box", "10,10,10 furlong"], "--box"),
    (["--resolution", "0"], "--resolution"),
    (["--kind", "sideways"], "--kind"),
    (["--mesh", "obj"], "--mesh"),
])
def test_cli_bad_input_exits_2_and_writes_nothing(tmp_path, args, field):
    out = tmp_path / "ws"
    r = CliRunner().invoke(app, ["workspace", str(HOPKINS), *args, "--out", str(out)])
    assert r.exit_code == 2
    assert field in r.stderr
    assert not out.exists()


def _independent_check(mech, oset, pts, need_all=True):
    """Every point valid for every orientation (or one), by plain per-orientation IK."""
    ok = np.full(len(pts), need_all)
    for Rm in oset.rotations():
        frames = np.zeros((len(pts), 4, 4))
        frames[:, :3, :3] = Rm
        frames[:, :3, 3] = pts
        frames[:, 3, 3] = 1.0
        v = mech.inverse(frames).valid
        ok = ok & v if need_all else ok | v
    return ok


@pytest.mark.parametrize("name, kind, h", [("hopkins-williams-6psu", "dexterous", 2.5),
                                           ("gough-stewart-6ups", "constant", 20.0)])
def test_inscribed_box_and_cylinder_hold_on_a_fresh_sample(name, kind, h):
    mech = load_mechanism(STUDIES / f"{name}.yaml")
    res = workspace(mech, kind, BOX15 if kind == "dexterous" else None, h)
    start = res.inscribed_box(optimise=False)
    box = res.inscribed_box()
    cyl = res.inscribed_cylinder()
    assert box.volume >= start.volume and box.iterations >= 1
    assert start.status == "ok" and box.ok and cyl.ok     # verified ("not converged" may be)
    assert box.volume < res.volume and cyl.volume < res.volume
    for shape in (box, cyl):
        pts = shape.sample(4000, seed=123)          # not the seed used to verify
        assert np.all(_independent_check(mech, res.orientations, pts))
    # the box is not trivially small: at least a fifth of the workspace's bounding box edge
    bb = np.diff(np.array(res.metrics()["bbox_mm"]), axis=0)[0]
    assert np.all(box.size > 0.2 * bb)


def test_inscribed_box_respects_extra_constraints(hopkins):
    cons = Constraints(joint_limits=JointLimits(base=math.radians(12), platform=math.radians(12)))
    res = workspace(hopkins, "constant", None, 4.0, cons)
    box = res.inscribed_box(samples=3000)
    pts = box.sample(2000, seed=7)
    from pkmlab.poses import as_frames
    from pkmlab.workspaces.constraints import joint_angles

    _, Rn = as_frames(hopkins.nominal_pose)
    R = np.broadcast_to(Rn[0], (len(pts), 3, 3))
    ab, ap = joint_angles(hopkins, pts, R, cons.joint_limits)
    assert np.all(ab <= math.radians(12)) and np.all(ap <= math.radians(12))


def test_inscribed_cylinder_converges_when_a_convex_sub_problem_fails(hopkins):
    # With 5 samples per angle Clarabel could not solve the first SCP sub-problem posed in mm;
    # the enlargement stopped there and returned a shape 17 % smaller as if it were the
    # largest. The 5-sample set contains the 3-sample one, so its cylinder can be no larger,
    # and here the corner orientations (common to both) decide it: the two must agree.
    box = OrientationSet.box(np.radians([15.0] * 3), samples=5)
    five = workspace(hopkins, "dexterous", box, 5.0).inscribed_cylinder(samples=2000)
    three = workspace(hopkins, "dexterous", box.with_samples(3), 5.0).inscribed_cylinder(
        samples=2000)
    assert five.status == three.status == "ok" and "converged" in five.reason
    assert five.volume <= three.volume * (1 + 1e-6)
    assert five.volume >= 0.99 * three.volume
    assert five.as_dict()["status"] == "ok"


def test_inscribed_shapes_that_verification_shrinks_away_are_not_results(hopkins):
    import dataclasses

    res = workspace(hopkins, "dexterous", BOX15, 5.0)
    # the same voxels, checked against a stroke window that no pose of them satisfies
    lo, hi = hopkins.stroke
    other = dataclasses.replace(hopkins, stroke_window=(hi + 50.0, hi + 60.0))
    bad = dataclasses.replace(res, mechanism=other)
    for shape in (bad.inscribed_box(samples=500, optimise=False),
                  bad.inscribed_cylinder(samples=500, optimise=False)):
        assert shape.status == "failed" and not shape.ok
        assert "verification failed at every scale" in shape.reason
        assert shape.volume == 0.0 and shape.verified_samples == 0
    empty = workspace(hopkins, "dexterous", OrientationSet.box(np.radians([30.0] * 3),
                                                               samples=3), 5.0)
    e = empty.inscribed_box()
    assert e.status == "empty" and not e.ok and e.as_dict()["volume_cm3"] is None


def test_refined_extremes_are_the_limit_of_finer_sampling(hopkins):
    box = OrientationSet.box(np.radians([15.0] * 3), samples=3)
    coarse = workspace(hopkins, "dexterous", box, 2.5)
    refined = workspace(hopkins, "dexterous", box, 2.5, refine=True)
    fine = workspace(hopkins, "dexterous", box.with_samples(17), 2.5)
    # more orientations only remove positions; refinement goes further, but not past the limit
    assert refined.volume < fine.volume < coarse.volume
    assert fine.volume - refined.volume < 0.05 * (coarse.volume - refined.volume)
    assert np.all(fine.contains(refined.voxel_centres()))
    # corner-only sampling (2 per axis) misses the legs' extremes inside the box
    corners = workspace(hopkins, "dexterous", box.with_samples(2), 2.5)
    assert corners.volume > coarse.volume


def test_paper_study_runs_and_reports_the_empty_30_degree_set(tmp_path):
    r = CliRunner().invoke(app, ["workspaces", str(STUDIES.parent / "papers" /
                                                  "hopkins-williams-2002.yaml"),
                                 "--out", str(tmp_path), "--json"])
    assert r.exit_code == 0, r.output
    ws = json.loads(r.stdout)["workspaces"]
    assert ws["fig8-dexterous-30-simultaneous"]["empty"]
    assert ws["dexterous-30-single-axis"]["volume_cm3"] > 10
    assert (ws["dexterous-20-simultaneous"]["volume_cm3"]
            < ws["dexterous-30-single-axis"]["volume_cm3"]
            < ws["constant-level"]["volume_cm3"] < ws["fig7-reachable"]["volume_cm3"])
    assert (tmp_path / "hopkins-williams-2002" / "fig7-reachable" / "slices.png").exists()
    assert not (tmp_path / "hopkins-williams-2002" / "fig8-dexterous-30-simultaneous" /
                "workspace.stl").exists()


def test_stroke_window_override_reaches_the_papers_30_degree_set(hopkins):
    box30 = OrientationSet.box(np.radians([30.0] * 3), samples=5)
    assert workspace(hopkins, "dexterous", box30, 2.5, refine=True).empty
    small = workspace(hopkins, "dexterous", box30, 2.5, Constraints(stroke=(0.0, 125.0)),
                      refine=True)
    big = workspace(hopkins, "dexterous", box30, 2.5, Constraints(stroke=(0.0, 150.0)),
                    refine=True)
    assert small.empty and not big.empty
    assert big.mechanism.stroke == (0.0, 150.0) and hopkins.stroke == (0.0, 101.6)
    pts = big.voxel_centres()
    assert np.all(_independent_check(big.mechanism, big.orientations, pts))
    with pytest.raises(ParameterError, match="constraints.stroke"):
        Constraints(stroke=False)
