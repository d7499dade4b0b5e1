"""Issue 26: one numbering of designs (item 5) and the on-bound warning (item 3).

* every design is named by its evaluation number ``#seq`` in summary.md, report.html (card
  titles, tabs, chart labels), compare and Python (``Design.label``); "Pareto 1",
  "Design 1" and "Pareto rank" no longer name designs;
* a Pareto design within 1 % of a range's end is flagged in summary.md, report.html and the
  log, and ``on_bound`` applies exactly that tolerance.
"""

from __future__ import annotations

import csv
import re

from clihelp import cli, small_study

from pkmlab.study import load_study
from pkmlab.study.flags import BOUND_SHARE, on_bound


def test_one_numbering_and_on_bound_flags(tmp_path, capsys, caplog, monkeypatch):
    path = small_study(tmp_path, objectives=[{"maximize": "constant_volume"},
                                             {"minimize": "base_outer_radius"}],
                       design={"link_length": {"low": "200 mm", "high": "260 mm", "levels": 3}},
                       optimizer={"method": "grid"}, top=2)
    with caplog.at_level("WARNING"):
        code, _, err = cli(capsys, "run", path, "--jobs", "1")
    assert code == 0, err
    out = tmp_path / "out"
    with open(out / "pareto.csv") as fh:
        seqs = [row["seq"] for row in csv.DictReader(fh)]
    assert seqs
    summary = (out / "summary.md").read_text()
    rows = [ln.split("|")[1].strip() for ln in summary.splitlines() if ln.startswith("| #")]
    assert rows and set(rows) <= {f"#{s}" for s in seqs}
    assert "Pareto 1" not in summary
    html = (out / "report.html").read_text()
    titles = re.findall(r"<h2>Design (#\d+) ", html)
    assert titles and set(titles) <= {f"#{s}" for s in seqs}
    assert "Pareto rank" not in html and "<h2>Design 1 " not in html
    import sys

    import pytest

    from pkmlab.results import open_results

    monkeypatch.setitem(sys.modules, "pandas", None)     # open_results needs no pandas
    res = open_results(out)
    assert {d.label for d in res.designs} == set(titles)
    assert {str(r["seq"]) for r in res.evaluations.records()} >= set(seqs)
    with pytest.raises(ImportError, match="needs pandas"):
        res.evaluations.to_pandas()
    # compare takes the same numbers: --designs names evaluations by seq
    code, _, err = cli(capsys, "compare", "--pareto", out / "pareto.csv", "--designs", "999")
    assert code == 2 and "--designs" in err and "evaluation numbers (seq)" in err
    # the grid samples the box's ends: the best volume sits on link_length's upper bound
    assert "lies on a bound of the design box" in summary
    # summary.md escapes the variable's name for Markdown; the log and the page show it raw
    assert "link\\_length 260 of ≤ 260 mm" in summary
    assert "lies on a bound of the design box" in html
    assert any("link_length 260 of ≤ 260 mm" in r.message for r in caplog.records)


def test_on_bound_tolerance_is_one_percent_of_the_range(tmp_path):
    s = load_study(small_study(tmp_path))
    lo, hi = 200.0, 260.0
    step = BOUND_SHARE * (hi - lo)
    assert on_bound(s, {"link_length": hi - 0.99 * step}) == ["link_length 259.4 of ≤ 260 mm"]
    assert on_bound(s, {"link_length": lo + 0.99 * step}) == ["link_length 200.6 of ≥ 200 mm"]
    assert on_bound(s, {"link_length": hi - 1.01 * step}) == []
    assert on_bound(s, {"link_length": 230.0}) == []
