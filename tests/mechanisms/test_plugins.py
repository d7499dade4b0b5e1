"""Family plugins: a tiny package with a ``pkmlab.families`` entry point, pip-installed into a
temporary folder (offline, no build isolation), then used by ``pkmlab inspect`` and the
contract suite in a fresh process."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
PLUGIN = ROOT / "tests" / "data" / "plugin"


def _env(*paths: Path) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([*map(str, paths), str(ROOT / "src")])
    return env


@pytest.fixture(scope="module")
def site(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("plugin")
    src = tmp / "src"
    shutil.copytree(PLUGIN, src)
    target = tmp / "site"
    run = subprocess.run([sys.executable, "-m", "pip", "install", "--no-build-isolation",
                          "--no-deps", "--no-index", "--quiet", "--target", str(target),
                          str(src)], capture_output=True, text=True, timeout=300)
    assert run.returncode == 0, run.stderr
    assert (target / "pkmlab_demo_family-0.1.dist-info" / "entry_points.txt").is_file()
    return target


def test_cli_inspect_uses_the_plugin_family(site):
    run = subprocess.run([sys.executable, "-m", "pkmlab.cli", "inspect",
                          str(PLUGIN / "legs6-demo.yaml"), "--json"], capture_output=True,
                         text=True, env=_env(site), timeout=600)
    assert run.returncode == 0, run.stderr
    data = json.loads(run.stdout)
    assert data["geometry"]["family"] == "legs6"
    assert data["nominal_valid"] and data["actuator_unit"] == "mm"


def test_contract_suite_and_study_aliases_on_the_plugin(site):
    script = f"""
import pkmlab
from pkmlab.mechanisms import REGISTRY, PLUGIN_ERRORS
from pkmlab.study.spec import family_aliases
from pkmlab.testing import run_contract
m = pkmlab.load_mechanism({str(PLUGIN / "legs6-demo.yaml")!r})
assert type(m) is REGISTRY["legs6"] and not PLUGIN_ERRORS, PLUGIN_ERRORS
assert family_aliases("legs6") == {{"stroke_max": ("stroke[1]", "length"),
                                   "home_height": ("nominal_pose[2]", "length")}}
print(run_contract(m, skip=("assembly_modes",)))
"""
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env=_env(site), timeout=600)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == "['declaration', 'round_trip', 'jacobian', 'batching', " \
                                 "'statuses', 'bad_shapes', 'joints', 'parameters']"


def test_without_the_plugin_its_family_is_unknown():
    run = subprocess.run([sys.executable, "-m", "pkmlab.cli", "inspect",
                          str(PLUGIN / "legs6-demo.yaml")], capture_output=True, text=True,
                         env=_env(), timeout=600)
    assert run.returncode != 0
    assert ("must be one of 'psu6', 'ups6', 'luzi3', 'rss6', 'sixleg', 'delta3', 'ldelta3', "
            "'rpr3', 'fivebar', 'prs3'; got 'legs6'") in run.stderr


def test_a_broken_plugin_is_reported_not_fatal(tmp_path):
    info = tmp_path / "broken_family-0.1.dist-info"
    info.mkdir()
    (info / "METADATA").write_text("Metadata-Version: 2.1\nName: broken-family\nVersion: 0.1\n")
    (info / "entry_points.txt").write_text("[pkmlab.families]\nbroken = no_such_module:X\n")
    script = ("import pkmlab; from pkmlab.mechanisms import PLUGIN_ERRORS, REGISTRY; "
              "print(sorted(REGISTRY), PLUGIN_ERRORS['broken'].split(':')[0])")
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         env=_env(tmp_path), timeout=600)
    assert run.returncode == 0, run.stderr
    assert run.stdout.strip() == ("['delta3', 'fivebar', 'ldelta3', 'luzi3', 'prs3', 'psu6', "
                                  "'rpr3', 'rss6', 'sixleg', 'ups6'] ModuleNotFoundError")
    assert "not loaded" in run.stderr
