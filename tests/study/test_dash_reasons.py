"""Issue 26 item 5: every "—" in summary.md has its reason, the requirement margins of the
least-violating designs are listed when nothing is feasible, and the parallel-coordinates
charts (pareto.png and report.html) show the least-violating designs instead of an empty box.
Built from synthetic records of the rss6 template (no evaluation)."""

from __future__ import annotations

import json
import re
from pathlib import Path

import yaml

from pkmlab.study import load_study
from pkmlab.study.report import write_report
from pkmlab.study.run import BASELINE

ROOT = Path(__file__).resolve().parents[2]


def _study(tmp_path):
    t = ROOT / "studies" / "templates"
    data = yaml.safe_load((t / "rss6-study.yaml").read_text())
    data["mechanism"]["file"] = str(ROOT / "studies" / "mechanisms" /
                                    "instructables-servo-6rss.yaml")
    data["evaluate"]["actuators"]["catalogue"] = str(ROOT / "studies" / "actuators" /
                                                     "hobby-servos.yaml")
    data["design"]["free_ratio"] = {"low": 0.5, "high": 1.0, "quantity": "number"}
    data["derived"] = {"base_inner_radius": "free_ratio * base_outer_radius"}
    data["objectives"].append({"minimize": "servo_range"})        # three: parcoords
    data["output"] = str(tmp_path / "out")
    p = tmp_path / "s.yaml"
    p.write_text(yaml.safe_dump(data))
    return load_study(p)


def _records(s):
    names = s.evaluation.metrics
    out = []
    for seq in range(4):
        m = {k: 1.0 for k in names}
        m.update(task_contained=0.0, task_margin=-float(seq), servo_range=160.0 - seq,
                 actuator_torque_rating=2.0 + seq)
        m["actuator_torque_speed_margin"] = None                 # with a note
        m["actuator_angle_margin"] = None                        # without one
        params = BASELINE if seq == 0 else {
            "crank_length": 45.0 + seq, "base_outer_radius": 160.0, "servo": "S-2Nm",
            "free_ratio": 0.7}
        out.append({"seq": seq, "key": f"{seq:016x}", "role": "baseline" if seq == 0
                    else "candidate", "status": "ok", "reason": "", "seconds": 0.1,
                    "params": params, "metrics": m,
                    "notes": {"actuator_torque_speed_margin": "S-2Nm: no torque–speed curve"}})
    return out


def test_every_dash_has_a_reason_and_the_least_violating_are_listed(tmp_path):
    s = _study(tmp_path)
    recs = _records(s)
    write_report(tmp_path / "out", s, recs)
    text = (tmp_path / "out" / "summary.md").read_text()
    notes = [ln for ln in text.splitlines() if ln.startswith("- ")]
    for block in re.findall(r"((?:^\|.*\|\n)+)", text, flags=re.M):
        lines = block.strip().splitlines()
        head = [c.strip() for c in lines[0].strip("|").split("|")]
        for ln in lines[2:]:
            cells = [c.strip() for c in ln.strip("|").split("|")]
            for col, cell in zip(head[1:], cells[1:]):
                if cell == "—":
                    name = col.split(" (")[0]           # escaped, as in the notes
                    assert any(n.startswith(f"- {cells[0]}, {name}: ") for n in notes), \
                        (cells[0], name)
    # the least-violating designs' margins are in the requirement margins table
    margins = text[text.index("Requirement margins"):]
    from pkmlab.study.violations import least_violating

    least = least_violating(s, recs, s.top)
    assert least and all(f"| #{r['seq']} |" in margins for r in least)
    assert "- #1, actuator\\_torque\\_speed\\_margin: S-2Nm: no torque–speed curve" in text
    # the variable's name is a user string: escaped for Markdown (renders as free_ratio)
    assert "- baseline, free\\_ratio: a free parameter" in text


def test_parallel_coordinates_show_the_least_violating_when_nothing_is_feasible(tmp_path):
    from matplotlib.image import imread

    s = _study(tmp_path)
    recs = _records(s)
    out = tmp_path / "out"
    write_report(out, s, recs)
    assert imread(out / "pareto.png").shape[0] > 100
    from pkmlab.webreport import write_study_page

    html = write_study_page(out, s, recs).read_text()
    assert "no feasible candidate: the 3 least-violating designs" in html
    m = re.search(r'id="fig-pareto-parcoords"[^>]*>(.*?)</script>', html, flags=re.S)
    fig = json.loads(m.group(1))
    dims = fig["data"][0]["dimensions"]
    assert len(dims) == 3 and all(len(d["values"]) == 3 for d in dims)
