"""Shared fixtures: one instance of every registered family (the contract suite runs on each)."""

from __future__ import annotations

from pathlib import Path

import pytest

import pkmlab
from pkmlab.mechanisms import REGISTRY, Luzi3
from pkmlab.testing import random_valid_poses  # noqa: F401 (used by the test modules)

ROOT = Path(__file__).resolve().parents[1]
MECH_DIR = ROOT / "studies" / "mechanisms"

# Every shipped mechanism file, plus the Luzi geometry with the upper link (200 mm) that the
# paper's Table 1 ψ columns were computed with (rows 1-2; docs/validation.md).
SHIPPED = sorted(MECH_DIR.glob("*.yaml"))


def _instances() -> dict[str, pkmlab.Mechanism]:
    mechs = {f.stem: pkmlab.load_mechanism(f) for f in SHIPPED}
    mechs["luzi-3chain-l200"] = Luzi3.from_paper(upper_link=200.0, stroke=(750.0, 1150.0))
    return mechs


MECHANISMS = _instances()
# The contract must cover every registered family.
assert {m.family for m in MECHANISMS.values()} == set(REGISTRY), "a family has no test instance"


@pytest.fixture(params=sorted(MECHANISMS), ids=sorted(MECHANISMS))
def mech(request):
    return MECHANISMS[request.param]


# ---- one tiny study run through the CLI, shared by the report tests ---------------------------

TINY_STUDY = {
    "study": "tiny-report",
    "description": "A tiny study for the report tests.",
    "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
    "design": {"base_outer_radius": {"low": "120 mm", "high": "165 mm"},
               "platform_outer_radius": {"low": "55 mm", "high": "90 mm"},
               "link_length": {"low": "200 mm", "high": "260 mm"}},
    "evaluate": {"workspace": {"kind": "dexterous", "box": ["8 deg"] * 3, "samples": 2,
                               "resolution": "8 mm"}},
    "objectives": [{"maximize": "dexterous_volume"}, {"minimize": "base_outer_radius"},
                   {"maximize": "z_span"}],
    "constraints": [{"base_outer_radius": {"max": 160}}],
    "optimizer": {"method": "sobol", "samples": 8},
    "seed": 5,          # 5 Pareto designs, 3 exported, 2 infeasible candidates
    "top": 3,
}


@pytest.fixture(scope="session")
def tiny_report(tmp_path_factory):
    """``(out, run)``: the tiny study's results folder after ``pkmlab run`` (no terminal), and
    the CLI result (its stderr holds the progress lines)."""
    import yaml
    from typer.testing import CliRunner

    from pkmlab.cli import app

    d = tmp_path_factory.mktemp("tiny-report")
    path = d / "study.yaml"
    path.write_text(yaml.safe_dump({**TINY_STUDY, "output": str(d / "out")}))
    r = CliRunner().invoke(app, ["run", str(path), "--json"])
    assert r.exit_code == 0, r.output
    return d / "out", r
