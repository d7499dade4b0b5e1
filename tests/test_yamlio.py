"""pkmlab's YAML reader applies its own rules, whatever PyYAML (and libyaml) is installed."""

from __future__ import annotations

import pytest
import yaml

from pkmlab import yamlio
from pkmlab.errors import ParameterError

# The example of the YAML 1.1 merge key specification (https://yaml.org/type/merge.html):
# "All the following maps are equal".
SPEC_EXAMPLE = """\
- &CENTER { x: 1, y: 2 }
- &LEFT { x: 0, y: 2 }
- &BIG { r: 10 }
- &SMALL { r: 1 }

# All the following maps are equal:

- # Explicit keys
  x: 1
  y: 2
  r: 10
  label: center/big

- # Merge one map
  << : *CENTER
  r: 10
  label: center/big

- # Merge multiple maps
  << : [ *CENTER, *BIG ]
  label: center/big

- # Override
  << : [ *BIG, *LEFT, *SMALL ]
  x: 1
  label: center/big
"""


class _DepthLimitedLoader(yaml.SafeLoader):
    """A pure-Python parser with a nesting limit of its own that it hits while reading ahead,
    as libyaml does since PyYAML 6.0.4 ("exceeded maximum nesting depth")."""

    LIMIT = 150

    def fetch_flow_collection_start(self, TokenClass):
        if self.flow_level >= self.LIMIT:
            raise yaml.scanner.ScannerError(None, None, "exceeded maximum nesting depth",
                                            self.get_mark())
        super().fetch_flow_collection_start(TokenClass)


PARSERS = {"pure-python": yaml.SafeLoader, "limited": _DepthLimitedLoader}
if hasattr(yaml, "CSafeLoader"):
    PARSERS["libyaml"] = yaml.CSafeLoader


@pytest.fixture(params=sorted(PARSERS))
def parser(request, monkeypatch):
    monkeypatch.setattr(yamlio, "_LOADER", PARSERS[request.param])
    return request.param


def _error(path) -> str:
    with pytest.raises(ParameterError) as info:
        yamlio.load_yaml(path)
    return str(info.value)


def test_merge_keys_follow_the_specification_example(tmp_path, parser):
    (tmp_path / "m.yaml").write_text(SPEC_EXAMPLE)
    data = yamlio.load_yaml(tmp_path / "m.yaml")[0]
    expected = {"x": 1, "y": 2, "r": 10, "label": "center/big"}
    assert data[4:] == [expected] * 4
    # the mapping's own keys in their written order, then the merged ones in the list's order
    assert [list(m) for m in data[4:]] == [["x", "y", "r", "label"], ["r", "label", "x", "y"],
                                           ["label", "x", "y", "r"], ["x", "label", "r", "y"]]


def test_merge_keys_precedence(tmp_path, parser):
    # own keys win wherever the merge is written; earlier merged mappings win over later ones
    text = ("a: &a {x: 1, y: 2}\nb: &b {y: 3, w: 4}\nc:\n  y: 9\n  <<: [*a, *b]\n"
            "d: {<<: *a, x: 5}\ne: {<<: [*b, *a]}\n")
    (tmp_path / "m.yaml").write_text(text)
    data, locate = yamlio.load_yaml(tmp_path / "m.yaml")
    assert data["c"] == {"y": 9, "x": 1, "w": 4} and list(data["c"]) == ["y", "x", "w"]
    assert data["d"] == {"x": 5, "y": 2} and list(data["d"]) == ["x", "y"]
    assert data["e"] == {"y": 3, "w": 4, "x": 1} and list(data["e"]) == ["y", "w", "x"]
    assert locate(("c", "y")) == (4, 3) and locate(("c", "x")) == (5, 3)   # merged: the '<<'


def test_deep_nesting_names_pkmlabs_rule_with_any_parser(tmp_path, parser):
    f = tmp_path / "deep.yaml"
    f.write_text("name: " + "[" * 50_000 + "]" * 50_000 + "\n")
    assert "deep.yaml (line 1, column 106): must be nested at most 100 levels deep" in _error(f)


def test_a_syntax_error_is_reported_with_any_parser(tmp_path, parser):
    f = tmp_path / "bad.yaml"
    f.write_text("a: [1, 2\nb: 3\n")
    message = _error(f)
    assert "bad.yaml (line " in message and "must be valid YAML; got a syntax error" in message


def test_the_limited_parser_stops_on_its_own_rule_without_the_fallback(tmp_path):
    # the situation the fallback is for: a parser whose own limit fires before pkmlab's check
    f = tmp_path / "deep.yaml"
    f.write_text("name: " + "[" * 50_000 + "]" * 50_000 + "\n")
    with pytest.raises(yaml.YAMLError, match="exceeded maximum nesting depth"):
        yamlio._build(f.read_text(), str(f), 100, 10_000, loader=_DepthLimitedLoader)
