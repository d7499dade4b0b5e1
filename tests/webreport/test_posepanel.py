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
