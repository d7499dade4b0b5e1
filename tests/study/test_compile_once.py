"""Issue 28 item 4 (compile once): after ``python -m pkmlab.study.warm`` (what ``make`` runs
after installing), a study run with two workers compiles nothing, in any of its processes.

The run is a reduced demo study: the demo's evaluation block unchanged, a design box of large
footprints (so that candidates take the tiled column kernel, which the paper's baseline does
not), four candidates and one exported design. numba's cache log (``NUMBA_DEBUG_CACHE``, which
the workers inherit) says which cache entries each process loaded and which it saved (a save
follows every compile of a cached function). The check does not depend on what the test
session's cache already holds: every entry the run touched must have been touched (loaded or
compiled) by the warm-up too, and the run must save none. A kernel the warm-up misses fails
it either way: with a cold cache the run compiles and saves it, with a warm one the warm-up's
log lacks it.
"""

from __future__ import annotations

import os
import re
import subprocess
import sys
from pathlib import Path

import yaml

ROOT = Path(__file__).resolve().parents[2]
DEMO = ROOT / "studies" / "hopkins-6psu-redesign.yaml"
ENTRY = re.compile(r"\[cache\] data (loaded from|saved to) '([^']+)'")


def _reduced_demo(tmp_path: Path) -> Path:
    data = yaml.safe_load(DEMO.read_text())
    data["mechanism"] = {"file": str((DEMO.parent / data["mechanism"]["file"]).resolve())}
    # a corner of the demo's box with more than 20,000 columns of 2.5 mm (the tiled kernel)
    data["design"] = {"base_outer_radius": {"low": "110 mm", "high": "115 mm"},
                      "platform_inner_radius": {"low": "55 mm", "high": "60 mm"},
                      "platform_outer_radius": {"low": "85 mm", "high": "90 mm"},
                      "platform_rotation": {"low": "55 deg", "high": "60 deg"},
                      "link_length": {"low": "290 mm", "high": "300 mm"}}
    data.update(optimizer={"method": "sobol", "samples": 4}, top=1,
                output=str(tmp_path / "out"))
    path = tmp_path / "reduced-demo.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def _entries(text: str) -> tuple[set[str], set[str]]:
    """``(loaded, saved)`` cache data files named in a ``NUMBA_DEBUG_CACHE`` log."""
    loaded, saved = set(), set()
    for kind, path in ENTRY.findall(text):
        (loaded if kind.startswith("loaded") else saved).add(path)
    return loaded, saved


def _run(args: list[str]) -> subprocess.CompletedProcess:
    env = {**os.environ, "NUMBA_DEBUG_CACHE": "1"}
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, env=env,
                          cwd=ROOT, timeout=900)


def test_a_run_after_the_warm_up_compiles_nothing_in_any_process(tmp_path):
    study = _reduced_demo(tmp_path)
    warm = _run(["-m", "pkmlab.study.warm", str(study)])
    assert warm.returncode == 0, warm.stderr[-2000:]
    warm_loaded, warm_saved = _entries(warm.stdout)
    run = _run(["-m", "pkmlab.cli", "run", str(study), "--jobs", "2"])
    assert run.returncode == 0, run.stderr[-2000:]
    loaded, saved = _entries(run.stdout)
    names = {Path(p).name.split("-")[0] for p in loaded}
    # the log covers the workers and the kernels the baseline does not use
    assert loaded and "tiles.tiled_all" in {n.rsplit("_", 1)[0] for n in names}, names
    assert saved == set(), f"the run compiled what the warm-up did not: {sorted(saved)}"
    missed = loaded - warm_loaded - warm_saved
    assert not missed, f"kernels the warm-up did not touch: {sorted(missed)}"
    # and said nothing about compiling
    said = re.findall(r"^pkmlab: (?:compil|still compiling).*", run.stderr, re.M)
    assert said == [], said
