"""The pose panel's model and the task region traces (no browser: the page's arithmetic is
checked in test_pose_panel_browser.py)."""

from __future__ import annotations

import numpy as np
import pytest
from export_samples import FAMILIES, sample

from pkmlab.dexterity.metrics import resolve_length
from pkmlab.webreport.posepanel import pose_model, task_traces


def test_task_regions_are_drawn_even_as_a_line_or_a_point():
    """A box of zero size is a point, a flat box a rectangle, a zero-radius cylinder a segment,
    a zero-height one a circle: each gives a trace with its points (the markers), so nothing
    is dropped because it has no volume."""
    cases = [({"kind": "box", "lo": np.array([1.0, 2, 3]), "hi": np.array([1.0, 2, 3])}, 1),
             ({"kind": "box", "lo": np.array([0.0, 0, 5]), "hi": np.array([10.0, 0, 5])}, 2),
             ({"kind": "box", "lo": np.array([0.0, 0, 5]), "hi": np.array([10.0, 4, 5])}, 4),
             ({"kind": "cylinder", "centre": np.array([0.0, 0, 100]), "radius": 0.0,
               "half": 20.0}, 2),
             ({"kind": "cylinder", "centre": np.array([0.0, 0, 100]), "radius": 0.0,
               "half": 0.0}, 1),
             ({"kind": "points", "points": np.array([[1.0, 2, 3], [4, 5, 6]])}, 2)]
    for shape, n in cases:
        traces = task_traces([shape])
        marks = [t for t in traces if t.mode == "markers"]
        assert len(marks) == 1 and len(marks[0].x) == n, (shape, len(marks[0].x))
        assert all(np.isfinite(v) for v in marks[0].z)


@pytest.mark.parametrize("family", FAMILIES)
def test_model_reads_the_declaration(family):
    """Free coordinates and units from the mobility, one leg per actuator in order, the
    characteristic length pkmlab's κ uses, and each kind's branch reproducing the declared
    value at the nominal pose."""
    mech = sample(family)
    m = pose_model(mech)
    assert m["coordinates"] == list(mech.mobility.coordinates)
    assert m["free"] == list(mech.mobility.index)
    assert m["supported"], m["reason"]
    assert [leg["name"] for leg in m["legs"]] == list(mech.actuator_names)
    cl = resolve_length(mech)
    assert m["char_length"] == (None if cl.length is None else pytest.approx(cl.length))
    assert {leg["kind"] for leg in m["legs"]} <= {"distance", "rail", "crank", "pair"}


def test_pair_reads_the_joints_and_refuses_other_chains():
    """luzi3's legs are read as ``pair`` legs from their joints: both struts of a chain share
    its chord and the platform normal, and their offsets along the link are ∓l/2 (1e-9 mm).
    A chain whose R joint at B_j is not normal to the chain's plane (turned 1e-3 rad) is not
    solved, and the model names its legs."""
    import dataclasses

    from pkmlab.webreport import posepanel

    mech = sample("luzi3")
    legs = pose_model(mech)["legs"]
    half = 0.5 * mech.upper_link
    assert [leg["kind"] for leg in legs] == ["pair"] * 6
    for k in range(0, 6, 2):
        a, b = legs[k], legs[k + 1]
        assert a["a1"] == b["a1"] and a["a2"] == b["a2"] and a["normal"] == b["normal"]
        assert abs(a["offset"] + half) <= 1e-9 and abs(b["offset"] - half) <= 1e-9
    declared = mech.legs()
    j = declared[0].joints[2]
    c, s = np.cos(1e-3), np.sin(1e-3)
    turned = dataclasses.replace(j, axes=j.axes @ np.array([[c, s, 0], [-s, c, 0], [0, 0, 1]]))
    bent = dataclasses.replace(declared[0],
                               joints=(*declared[0].joints[:2], turned, declared[0].joints[3]))
    pair, why = posepanel._pair_model(bent, declared[1], np.eye(3), float(mech.scale))
    assert pair is None and why.startswith("l11, l12:"), why
