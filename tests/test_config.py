"""YAML loading: units converted once, and every bad-geometry case raises a named error."""

from __future__ import annotations

import copy
import math

import pytest
import yaml
from conftest import MECH_DIR

import pkmlab
from pkmlab.errors import ParameterError
from pkmlab.units import parse_angle, parse_length


def spec(name: str) -> dict:
    return yaml.safe_load((MECH_DIR / f"{name}.yaml").read_text())


@pytest.mark.parametrize("text, mm", [(225, 225.0), ("225 mm", 225.0), ("4 in", 101.6),
                                      ("2.5cm", 25.0), ("0.43 m", 430.0), (-3, -3.0)])
def test_lengths(text, mm):
    assert parse_length(text, "f") == pytest.approx(mm)


@pytest.mark.parametrize("text, rad", [(30, math.pi / 6), ("33.7 deg", math.radians(33.7)),
                                       ("0.5 rad", 0.5)])
def test_angles(text, rad):
    assert parse_angle(text, "f") == pytest.approx(rad)


@pytest.mark.parametrize("bad", ["225 furlongs", "abc", True, None, [1], "nan mm"])
def test_bad_quantity_names_field(bad):
    with pytest.raises(ParameterError, match=r"^link: must be .*; got"):
        parse_length(bad, "link")


def test_units_convert_once_at_load():
    d = spec("hopkins-williams-6psu")
    d["stroke"] = [0, "4 in"]
    d["link_length"] = "22.5 cm"
    m = pkmlab.load_mechanism(d)
    assert m.stroke == (0.0, pytest.approx(101.6))
    assert m.link_length[0] == pytest.approx(225.0)


def explicit(name: str) -> dict:
    """A shipped generator-based mechanism rewritten with explicit joint coordinates."""
    m = pkmlab.load_mechanism(MECH_DIR / f"{name}.yaml")
    d = {"family": m.family, "base_points": m.base_points.tolist(),
         "platform_points": m.platform_points.tolist(), "stroke": list(m.stroke),
         "tool_offset": m.tool_offset.tolist()}
    if m.family == "psu6":
        d["link_length"] = float(m.link_length[0])
    if m.family == "luzi3":
        d["upper_link"] = m.upper_link
    return d


def test_explicit_coordinates_reproduce_generator():
    for name in ("hopkins-williams-6psu", "luzi-3chain", "paradex-6pus"):
        gen = pkmlab.load_mechanism(MECH_DIR / f"{name}.yaml")
        exp = pkmlab.load_mechanism(explicit(name))
        X = gen.nominal_pose
        assert exp.inverse(X).q == pytest.approx(gen.inverse(X).q, abs=1e-9)


BAD_CASES = [
    # (base mechanism, mutation, field in the message, fragment of the allowed text)
    ("hopkins-williams-6psu", {"link_length": -5}, "link_length", "> 0 mm"),
    ("hopkins-williams-6psu", {"link_length": 0}, "link_length", "> 0 mm"),
    ("hopkins-williams-6psu", {"link_length": 50}, "link_length", "longer than leg"),
    ("hopkins-williams-6psu", {"stroke": [100, 0]}, "stroke", "min < max"),
    ("hopkins-williams-6psu", {"stroke": [5, 5]}, "stroke", "min < max"),
    ("hopkins-williams-6psu", {"stroke": [0]}, "stroke", "a list of 2 lengths"),
    ("hopkins-williams-6psu", {"family": "hexapod"}, "family", "one of"),
    ("hopkins-williams-6psu", {"colour": "red"}, "colour", "a known key"),
    ("hopkins-williams-6psu", {"generator": {"base_radii": [165, 100]}}, "generator.base_radii",
     "inner <= outer"),
    ("hopkins-williams-6psu", {"generator": {"base_radii": [-1, 100]}}, "generator.base_radii",
     "radii > 0"),
    ("hopkins-williams-6psu", {"generator": {"pairing": "zigzag"}}, "generator.pairing", "same"),
    ("hopkins-williams-6psu", {"generator": {"platform_rotation": "33.7 furlongs"}},
     "generator.platform_rotation", "unit"),
    ("hopkins-williams-6psu", {"tool_offset": [0, 47]}, "tool_offset", "3 lengths"),
    ("luzi-3chain", {"upper_link": -100}, "upper_link", "> 0 mm"),
    ("luzi-3chain", {"upper_link": 700}, "upper_link", "base chord"),
    ("luzi-3chain", {"generator": {"phi": 130}}, "generator.phi", "(0°, 120°)"),
    ("luzi-3chain", {"stroke": [0, 1000]}, "stroke", "0 < min"),
    ("gough-stewart-6ups", {"stroke": [-10, 900]}, "stroke", "0 < min"),
]


@pytest.mark.parametrize("base, change, field, allowed", BAD_CASES,
                         ids=[f"{b}-{f}-{i}" for i, (b, _, f, _) in enumerate(BAD_CASES)])
def test_bad_geometry_names_field_range_and_value(base, change, field, allowed):
    d = copy.deepcopy(spec(base))
    for k, v in change.items():
        if isinstance(v, dict):
            d[k].update(v)
        else:
            d[k] = v
    with pytest.raises(ParameterError) as info:
        pkmlab.load_mechanism(d)
    msg = str(info.value)
    assert msg.startswith(f"{field}: must be "), msg
    assert allowed in msg and "; got " in msg, msg


@pytest.mark.parametrize("name", ["hopkins-williams-6psu", "gough-stewart-6ups", "luzi-3chain"])
def test_explicit_point_errors(name):
    d = explicit(name) if name != "gough-stewart-6ups" else spec(name)
    pts = d["base_points"]
    n = len(pts)
    cases = {
        "count": (pts[:-1], f"shape ({n}, 3)"),
        "coincident": ([pts[0]] + [pts[0]] + pts[2:], "distinct joint centres"),
        "shape": ([p[:2] for p in pts], "[x, y, z] points"),
    }
    for what, (value, allowed) in cases.items():
        bad = copy.deepcopy(d)
        bad["base_points"] = value
        with pytest.raises(ParameterError) as info:
            pkmlab.load_mechanism(bad)
        assert str(info.value).startswith("base_points: must be "), (what, str(info.value))
        assert allowed in str(info.value), (what, str(info.value))
    bad = copy.deepcopy(d)
    bad["platform_points"] = d["platform_points"][:-1]
    with pytest.raises(ParameterError, match=r"^platform_points: must be an array of shape"):
        pkmlab.load_mechanism(bad)


def test_generator_and_points_together_rejected():
    d = spec("hopkins-williams-6psu")
    d["base_points"] = explicit("hopkins-williams-6psu")["base_points"]
    with pytest.raises(ParameterError, match=r"^generator: must be given alone"):
        pkmlab.load_mechanism(d)


def test_missing_file_and_bad_yaml(tmp_path):
    with pytest.raises(ParameterError, match=r"^path: must be an existing mechanism YAML file"):
        pkmlab.load_mechanism(tmp_path / "nope.yaml")
    f = tmp_path / "bad.yaml"
    f.write_text("family: [psu6\n")
    with pytest.raises(ParameterError, match="must be valid YAML"):
        pkmlab.load_mechanism(f)


def test_python_constructor_validates_too():
    from pkmlab.mechanisms import PSU6

    m = pkmlab.load_mechanism(MECH_DIR / "hopkins-williams-6psu.yaml")
    with pytest.raises(ParameterError, match=r"^link_length: must be a length > 0 mm"):
        PSU6(m.base_points, m.platform_points, -1.0, (0, 100))
    with pytest.raises(ParameterError, match=r"^stroke: must be \[min, max\] with min < max"):
        PSU6(m.base_points, m.platform_points, 225.0, (100, 0))
