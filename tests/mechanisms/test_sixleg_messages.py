"""``sixleg`` messages (issue 27, item 12): a huge axis is a valid direction (it used to
overflow to zero and the error blamed ``stroke``), a NaN axis names the leg and its value (it
used to report "got (6, 3)"), and leg checks number the legs from 0, as schema errors do."""

from __future__ import annotations

import pytest
from clihelp import GS
from test_sixleg import generic_yaml

import pkmlab
from pkmlab.errors import ParameterError


def _slider_legs(axis, leg=2):
    data = generic_yaml(pkmlab.load_mechanism(GS))
    for lg in data["legs"]:
        lg["actuator"] = {"kind": "slider", "axis": [0, 0, 1], "link_length": "600 mm"}
    data["legs"][leg]["actuator"]["axis"] = axis
    data["stroke"] = ["-300 mm", "300 mm"]
    return data


def test_a_huge_axis_is_the_same_direction():
    small = pkmlab.load_mechanism(_slider_legs([0, 1, 1]))
    huge = pkmlab.load_mechanism(_slider_legs([0, 1e300, 1e300]))
    assert huge.axes[2] == pytest.approx(small.axes[2], abs=1e-15)


@pytest.mark.parametrize("axis, fragment", [([0, float("nan"), 1], "nan"),
                                            ([0, float("inf"), 1], "inf"),
                                            ([0, 0, 0], "non-zero")])
def test_a_bad_axis_names_its_leg_from_0_and_its_value(axis, fragment):
    with pytest.raises(ParameterError) as exc:
        pkmlab.load_mechanism(_slider_legs(axis, leg=4))
    msg = str(exc.value)
    assert exc.value.field == "legs[4].axis", msg
    assert fragment in msg and "(6, 3)" not in msg and "stroke" not in msg


def test_leg_checks_and_schema_errors_number_the_same_leg_alike():
    data = _slider_legs([0, 0, 1])
    data["legs"][3]["actuator"]["link_length"] = "-5 mm"
    with pytest.raises(ParameterError) as check:
        pkmlab.load_mechanism(data)
    data = _slider_legs([0, 0, 1])
    data["legs"][3]["actuator"]["branch"] = 7
    with pytest.raises(ParameterError) as schema:
        pkmlab.load_mechanism(data)
    assert "legs[3]" in check.value.field and "legs[3]" in schema.value.field, \
        (check.value.field, schema.value.field)
