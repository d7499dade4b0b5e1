"""Slice layouts scaled to each workspace (the paper's as an option) and mesh files in each
format's unit (issue "A report a designer opens in the browser", item 3)."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh
from conftest import MECH_DIR
from typer.testing import CliRunner

import pkmlab
from pkmlab.cli import app
from pkmlab.config import workspace_spec
from pkmlab.errors import ParameterError
from pkmlab.workspaces.output.mesh import STL_HEADER
from pkmlab.workspaces.output.plots import (
    SlicePicture,
    overlay_figure,
    png_bytes,
    slice_figure,
    write_slice_pictures,
)
from pkmlab.workspaces.output.slicing import MAX_PANELS, nice_ceil, slice_layout

HOPKINS = MECH_DIR / "hopkins-williams-6psu.yaml"


@pytest.fixture(scope="module")
def small():
    mech = pkmlab.load_mechanism(HOPKINS)
    return pkmlab.workspace(mech, "dexterous",
                            pkmlab.OrientationSet.box(np.radians([8.0] * 3), samples=2), 6.0)


@pytest.fixture(scope="module")
def large():
    """A large 6-UPS: the paper's 152.4 mm window gave it 70 mostly solid panels."""
    mech = pkmlab.load_mechanism(MECH_DIR / "gough-stewart-6ups.yaml")
    return pkmlab.workspace(mech, "constant", None, 30.0)


def _covers(lay, res) -> bool:
    (x0, y0, z0), (x1, y1, z1) = res.metrics()["bbox_mm"]
    cx, cy = lay.centre
    h = lay.window / 2
    return (cx - h <= x0 and x1 <= cx + h and cy - h <= y0 and y1 <= cy + h
            and np.all((z0 < lay.levels) & (lay.levels < z1)))


@pytest.mark.parametrize("which", ["small", "large"])
def test_auto_layout_is_scaled_to_the_workspace_and_never_clips(which, request):
    res = request.getfixturevalue(which)
    lay = slice_layout(res)
    assert _covers(lay, res)
    (x0, y0, _), (x1, y1, _) = res.metrics()["bbox_mm"]
    assert lay.window <= 1.5 * max(x1 - x0, y1 - y0)          # scaled, not a huge window
    assert 4 <= len(lay.levels) <= MAX_PANELS
    assert lay.spacing >= res.resolution
    assert lay.spacing in (nice_ceil(lay.spacing), res.resolution)     # a round step
    fig = slice_figure(res)
    titled = [ax for ax in fig.axes if ax.get_title().startswith("z = ")]
    assert len(titled) == len(lay.levels)


def test_the_paper_layout_stays_available(large, small):
    lay = slice_layout(large, "paper")
    assert (lay.window, lay.spacing) == (152.4, 12.7)
    assert len(lay.levels) > 60 and not _covers(lay, large)     # what the issue complained of
    assert tuple(slice_layout(small, "paper").centre) == tuple(
        small.mechanism.nominal_pose[:2])
    fig = slice_figure(small, layout="paper")
    assert "152.4 × 152.4 mm" in fig.get_suptitle()
    # explicit values override either layout
    lay = slice_layout(small, window=300.0, spacing=5.0)
    assert (lay.window, lay.spacing) == (300.0, 5.0)
    with pytest.raises(ParameterError, match="slice layout"):
        slice_layout(small, "huge")


def test_common_layout_of_several_workspaces_covers_each(small, large):
    lay = slice_layout([small, large])
    assert _covers(lay, large)
    fig = overlay_figure([small, large], ["small", "large"])
    assert sum(ax.get_title().startswith("z = ") for ax in fig.axes) == len(lay.levels)


def test_nice_ceil():
    assert [nice_ceil(x) for x in (0.3, 1.0, 1.1, 2.2, 3, 7, 55, 120)] == \
        [0.5, 1.0, 2.0, 2.5, 5.0, 10.0, 100.0, 200.0]


def test_workspace_spec_slice_options():
    spec = workspace_spec({"kind": "constant"})
    assert spec.slice_options() == {"layout": "auto", "window": None, "spacing": None}
    spec = workspace_spec({"kind": "constant", "slice_layout": "paper", "slice_window": "8 in",
                           "slice_spacing": "auto"})
    assert spec.slice_options() == {"layout": "paper", "window": pytest.approx(203.2),
                                    "spacing": None}
    with pytest.raises(ParameterError, match="slice_layout"):
        workspace_spec({"kind": "constant", "slice_layout": "big"})


def test_cli_workspace_slice_layout_and_mesh_units(tmp_path):
    out = tmp_path / "w"
    r = CliRunner().invoke(app, ["workspace", str(HOPKINS), "--resolution", "8",
                                 "--mesh", "stl,ply,glb", "--slice-layout", "paper",
                                 "--out", str(out), "--json"])
    assert r.exit_code == 0, r.output
    stl = (out / "workspace.stl").read_bytes()
    assert stl[:80].rstrip(b" \0") == STL_HEADER and b"units: mm" in stl[:80]
    assert not stl.startswith(b"solid")
    mm = trimesh.load(out / "workspace.stl")
    m = trimesh.load(out / "workspace.glb", force="mesh")
    # glTF: metres, y up (x, y, z) -> (x, z, -y)
    np.testing.assert_allclose(m.bounds[:, 0], mm.bounds[:, 0] / 1000, atol=1e-6)
    np.testing.assert_allclose(m.bounds[:, 1], mm.bounds[:, 2] / 1000, atol=1e-6)
    np.testing.assert_allclose(np.sort(-m.bounds[:, 2]), mm.bounds[:, 1] / 1000, atol=1e-6)
    assert b"comment units mm" in (out / "workspace.ply").read_bytes()[:200]
    r = CliRunner().invoke(app, ["workspace", str(HOPKINS), "--slice-layout", "big"])
    assert r.exit_code == 2 and "--slice-layout" in r.stderr


def test_ply_carries_metric_values_as_vertex_properties(small, tmp_path):
    from pkmlab.dexterity.maps import metric_map, vertex_values

    mesh = small.mesh()
    mmap = metric_map(small.mechanism, small, "kappa", 40.0)
    kappa = vertex_values(mesh, mmap)
    assert kappa.shape == (len(mesh.vertices),) and np.all(np.isfinite(kappa))
    small.save_mesh(tmp_path / "w.ply", values={"kappa": kappa})
    back = trimesh.load(tmp_path / "w.ply", process=False)
    raw = back.metadata["_ply_raw"]["vertex"]["data"]
    np.testing.assert_allclose(raw["kappa"], kappa.astype(np.float32))
    np.testing.assert_allclose(back.vertices, mesh.vertices, atol=1e-4)
    with pytest.raises(ValueError, match="vertex values"):
        small.save_mesh(tmp_path / "bad.ply", values={"kappa": kappa[:-1]})


def test_metric_slices_are_not_washed_out_by_a_few_near_singular_voxels(small):
    from pkmlab.workspaces.output.plots import _colour_range

    values = np.full(small.occupancy.shape, np.nan)
    values[small.occupancy] = np.linspace(5.0, 9.0, int(small.occupancy.sum()))
    lo, hi, extend = _colour_range(values)
    assert extend == "neither" and (lo, hi) == (5.0, 9.0)
    few = tuple(np.argwhere(small.occupancy)[:3].T)
    values[few] = 600.0                                  # three near-singular voxels
    lo, hi, extend = _colour_range(values)
    assert lo < 5.1 and hi < 10 and extend == "max"
    fig = slice_figure(small, values=values, label="κ")
    assert "percentile" in fig.axes[-1].get_ylabel()


def test_slice_pictures_drawn_on_one_grid_equal_separate_figures(small, tmp_path):
    """``write_slice_pictures`` builds the panel grid once for several colourings (the export's
    plain sections and κ map); every picture must be pixel for pixel the figure
    ``slice_figure`` draws alone, in any order (a colour bar removed gives the panels their
    places back), with the task overlay on top."""
    import matplotlib.image as mpimg

    rng = np.random.default_rng(3)
    k1 = rng.random(small.occupancy.shape) * 10
    k1[small.occupancy.nonzero()[0][0], :, :] = 900         # a few extremes: capped bar
    k2 = rng.random(small.occupancy.shape)
    square = np.array([[0.0, 0.0], [20.0, 0.0], [20.0, 20.0], [0.0, 0.0]])
    grid = {"overlay": lambda z: [square], "overlay_label": "task"}
    pics = [SlicePicture(tmp_path / "a.png"), SlicePicture(tmp_path / "b.png", k1, "κ", 110),
            SlicePicture(tmp_path / "c.png"), SlicePicture(tmp_path / "d.png", k2, "LCI")]
    assert write_slice_pictures(small, pics, **grid) == [p.path for p in pics]
    for p in pics:
        alone = tmp_path / f"alone-{p.path.name}"
        alone.write_bytes(png_bytes(slice_figure(small, values=p.values, label=p.label,
                                                 **grid), p.dpi))
        a, b = mpimg.imread(p.path), mpimg.imread(alone)
        assert a.shape == b.shape and np.array_equal(a, b), p.path.name
    assert not np.array_equal(mpimg.imread(pics[0].path), mpimg.imread(pics[2].path)[::-1])
    assert mpimg.imread(pics[1].path).shape != mpimg.imread(pics[0].path).shape   # 110 dpi


def test_auto_window_also_shows_the_task_overlay(small):
    """A task region larger than the workspace is drawn, not clipped away: the demo study's
    101.6 mm task box fell outside its 90 mm window and the title promised red outlines that
    no panel showed. The sections' heights stay the workspace's; the paper layout and an
    explicit window keep theirs."""
    from pkmlab.workspaces.output.plots import sections_layout

    task = np.array([[-150.0, -120.0], [150.0, -120.0], [150.0, 120.0], [-150.0, 120.0],
                     [-150.0, -120.0]])
    overlay = lambda z: [task]                                              # noqa: E731
    plain, drawn = slice_layout(small), sections_layout(small, overlay)
    assert plain.window < 300 <= drawn.window
    np.testing.assert_allclose(drawn.levels, plain.levels)
    fig = slice_figure(small, overlay=overlay, overlay_label="task")
    ax = fig.axes[0]
    x0, x1 = ax.get_xlim()
    y0, y1 = ax.get_ylim()
    assert x0 <= -150 and x1 >= 150 and y0 <= -120 and y1 >= 120
    assert sections_layout(small, overlay, layout="paper").window == slice_layout(
        small, "paper").window
    assert sections_layout(small, overlay, window=80.0).window == 80.0
    assert sections_layout(small, lambda z: []).window == plain.window      # nothing to cover


def test_a_long_title_wraps_inside_the_figure_and_above_the_panels(small):
    """The task overlay's note made the title's line wider than the figure: it was clipped at
    both edges of a study's kappa_slices.png. Every title line now fits the figure, and the
    title stays above the panels (the top margin grows with its lines)."""
    note = ("the task region (required positions)\nnote: the task's orientations (±30, ±30, "
            "±30° Euler box) reach beyond the workspace drawn (±15, ±15, ±15° Euler box): the "
            "outline is not a containment check on these slices (task_contained is)")
    for long in (False, True):
        fig = slice_figure(small, overlay=lambda z: [], overlay_label=note if long else "x")
        from matplotlib.backends.backend_agg import FigureCanvasAgg

        FigureCanvasAgg(fig).draw()
        r = fig.canvas.get_renderer()
        box = fig._suptitle.get_window_extent(r)
        assert box.x0 >= 0 and box.x1 <= fig.bbox.width, (box, fig.bbox)
        top = max(ax.get_tightbbox(r).y1 for ax in fig.axes if ax.get_visible())
        assert box.y0 >= top - 1, (box.y0, top)
        assert box.y1 <= fig.bbox.height


def test_the_colour_bar_label_fits_a_small_figure(small):
    """A design whose dexterous workspace has two sections got a 2-panel kappa_slices.png
    whose colour bar label ran beyond the figure's top and bottom edges (seen in a 6-RSS
    study). The label now wraps to the bar's length and stays inside the figure."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    label = "worst κ (homogenised condition number), L = 66.42 mm"
    values = np.ones((len(small.xs), len(small.ys), len(small.zs)))
    values[0, 0, 0] = 3.0
    for panels in (2, 9):
        fig = slice_figure(small, values=values, label=label, max_panels=panels)
        FigureCanvasAgg(fig).draw()
        r = fig.canvas.get_renderer()
        bar = fig.axes[-1]
        box = bar.yaxis.label.get_window_extent(r)
        assert 0 <= box.y0 and box.y1 <= fig.bbox.height, (panels, box, fig.bbox)
        assert 0 <= box.x0 and box.x1 <= fig.bbox.width, (panels, box, fig.bbox)
        assert bar.get_ylabel().replace("\n", " ") == label
