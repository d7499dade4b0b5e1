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


def test_swapped_radii_are_shown_with_their_unit():
    """The value of the [inner, outer] error is shown in mm, short: a study's invalid
    candidates list it ("got [58.2662 mm, 47.208 mm]", not the floats' 16 digits)."""
    d = copy.deepcopy(spec("hopkins-williams-6psu"))
    d["generator"]["platform_radii"] = [58.26622933814151, 47.207980628773704]
    with pytest.raises(ParameterError) as info:
        pkmlab.load_mechanism(d)
    assert str(info.value).endswith("; got [58.2662 mm, 47.208 mm]"), str(info.value)


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


# ---- reading YAML (pkmlab.yamlio) and pydantic's errors in plain words ----------------------

ROOT = MECH_DIR.parents[1]


def test_load_yaml_reads_what_safe_load_reads():
    from pkmlab.yamlio import load_yaml

    files = sorted((ROOT / "studies").rglob("*.yaml"))
    assert len(files) >= 5
    for f in files:
        assert load_yaml(f)[0] == yaml.safe_load(f.read_text()), f.name


def test_load_yaml_locates_fields(tmp_path):
    from pkmlab.yamlio import load_yaml

    f = tmp_path / "s.yaml"
    f.write_text("study: s\nevaluate:\n  workspace:\n    kind: constant\n"
                 "    resolution: 5 mm\n  box: [1, {a: 2}]\n")
    data, locate = load_yaml(f)
    assert data["evaluate"]["workspace"]["resolution"] == "5 mm"
    assert locate(("evaluate", "workspace", "resolution")) == (5, 5)
    assert locate(("evaluate", "box", 1, "a")) == (6, 13)
    assert locate(("evaluate", "box", 1)) == (6, 12)
    assert locate(("evaluate", "workspace", "samples")) == (3, 3)   # nearest present
    assert locate(("evaluate", "workspace", "samples"), nearest=False) is None


def test_utf16_with_a_byte_order_mark_is_read(tmp_path):
    src = MECH_DIR / "hopkins-williams-6psu.yaml"
    f = tmp_path / "utf16.yaml"
    f.write_bytes(src.read_text().encode("utf-16"))
    assert pkmlab.load_mechanism(f) == pkmlab.load_mechanism(src)


def test_limits_are_configurable(tmp_path, monkeypatch):
    from pkmlab import yamlio

    f = tmp_path / "m.yaml"
    f.write_text("a: [[[1]]]\nb: &x [1, 2, 3]\nc: [*x, *x]\n")
    assert yamlio.load_yaml(f)[0]["c"] == [[1, 2, 3]] * 2
    with pytest.raises(ParameterError, match=r"m\.yaml: must be at most 10 bytes"):
        yamlio.load_yaml(f, max_bytes=10)
    with pytest.raises(ParameterError, match=r"\(line 1, column 5\): must be nested at most 2 "):
        yamlio.load_yaml(f, max_depth=2)
    monkeypatch.setattr(yamlio, "MAX_ALIAS_NODES", 5)
    with pytest.raises(ParameterError, match=r"\(line 3, column 9\): must be at most 5 values "
                                             r"expanded from aliases"):
        yamlio.load_yaml(f)


def test_format_value_cost_does_not_grow_with_the_value():
    import time

    from pkmlab.errors import format_value

    nested = ["lol"] * 9
    for _ in range(6):
        nested = [nested] * 9        # 9**7 strings, shared as an alias bomb shares them
    for value in (nested, "x" * 10**7, {i: [i] * 1000 for i in range(10**4)}, 10**5000):
        t = time.perf_counter()
        text = format_value(value)
        assert time.perf_counter() - t < 0.05
        assert len(text) <= 200
    assert format_value([1, "a", (2,), {"k": None}]) == "[1, 'a', (2,), {'k': None}]"


_WS = {"kind": "constant"}
WORDING = [
    ({"samples": "x"}, "samples: must be an integer; got 'x'"),
    ({"samples": 1.5}, "samples: must be an integer; got 1.5"),
    ({"samples": 0}, "samples: must be an integer ≥ 1; got 0"),
    ({"samples": 500}, "samples: must be an integer ≤ 101; got 500"),
    ({"kind": "foo"}, "kind: must be 'constant', 'reachable' or 'dexterous'; got 'foo'"),
    ({"constraints": {"connected": "maybe"}},
     "constraints.connected: must be true or false; got 'maybe'"),
    ({"constraints": {"kappa_max": 0.5}}, "constraints.kappa_max: must be a number ≥ 1; got 0.5"),
    ({"constraints": 3}, "constraints: must be a mapping (keys: stroke, joint_limits, "
                         "link_diameter, kappa_max, characteristic_length, connected); got 3"),
    ({"resolutoin": 2, "samples": "x"}, "resolutoin: must be a known key (did you mean "
                                        "'resolution'? known keys: box, constraints, kind, "),
]


@pytest.mark.parametrize("change, message", WORDING, ids=[m.split(":")[0] + str(i)
                                                          for i, (_, m) in enumerate(WORDING)])
def test_pydantic_errors_in_plain_words(change, message):
    with pytest.raises(ParameterError) as info:
        pkmlab.config.workspace_spec({**_WS, **change})
    assert str(info.value).startswith(message), str(info.value)
    assert "Input should" not in str(info.value)


MECH_WORDING = [
    ("luzi-3chain", {"tool_offset": [1, 2]},
     "tool_offset: must be a list of 3 lengths (mm or with units) or 'centroid'; got [1, 2]"),
    ("luzi-3chain", {"strok": [1, 2], "stroke": None},
     "strok: must be a known key (did you mean 'stroke'? known keys: base_points, family, "),
    ("luzi-3chain", {"family": None},
     "family: must be given (one of 'psu6', 'ups6', 'luzi3', 'rss6', 'sixleg', 'delta3', "
     "'ldelta3', 'rpr3', 'fivebar', 'prs3'); got nothing"),
    ("luzi-3chain", {"family": "luzi"}, "family: must be one of 'psu6', 'ups6', 'luzi3', 'rss6', "
                                        "'sixleg', 'delta3', 'ldelta3', 'rpr3', 'fivebar', "
                                        "'prs3'; got 'luzi'"),
    ("hopkins-williams-6psu", {"name": [1]}, "name: must be text; got [1]"),
    ("hopkins-williams-6psu", {"generator": {"pairing": "x"}},
     "generator.pairing: must be 'same' or 'crossed'; got 'x'"),
    ("hopkins-williams-6psu", {"generator": {"phi": 1}},
     "generator.phi: must be a known key (known keys: base_pair_angle, base_pair_separation, "),
]


@pytest.mark.parametrize("name, change, message", MECH_WORDING,
                         ids=[m.split(":")[0] for _, _, m in MECH_WORDING])
def test_mechanism_errors_name_the_key_the_user_wrote(name, change, message, monkeypatch):
    from pkmlab.mechanisms import REGISTRY

    # the built-in families only: other test modules register plugin families (tri3) in the
    # same process, in an order that depends on how the suite is split between processes
    for k in [k for k, f in REGISTRY.items() if not f.__module__.startswith("pkmlab.")]:
        monkeypatch.delitem(REGISTRY, k)
    d = spec(name)
    for k, v in change.items():
        if isinstance(v, dict):
            d[k].update(v)
        elif v is None:
            d.pop(k)
        else:
            d[k] = v
    with pytest.raises(ParameterError) as info:
        pkmlab.load_mechanism(d)
    assert str(info.value).startswith(message), str(info.value)
    assert "function-" not in str(info.value) and "Input should" not in str(info.value)


def test_study_errors_carry_the_line_and_column(tmp_path):
    f = tmp_path / "s.yaml"
    f.write_text(f"study: s\nmechanism: {{file: {MECH_DIR / 'luzi-3chain.yaml'}}}\n"
                 "design: {upper_link: {low: 90 mm, high: 110 mm}}\nevaluate: {}\n"
                 "objectives: []\noptimizer: {method: sobol}\n")
    with pytest.raises(ParameterError) as info:
        pkmlab.study.load_study(f)
    assert info.value.field == "objectives"
    assert str(info.value) == ("objectives (s.yaml, line 5, column 1): must be a list of at "
                               "least 1 item; got []")
    # the same content as a mapping, not read from a file: no position
    f.write_text((MECH_DIR / "luzi-3chain.yaml").read_text().replace("family: luzi3", "family: x"))
    with pytest.raises(ParameterError, match=r"^family \(s\.yaml, line \d+, column 1\): must be"):
        pkmlab.load_mechanism(f)
    with pytest.raises(ParameterError, match=r"^family: must be one of"):
        pkmlab.load_mechanism(yaml.safe_load(f.read_text()))
