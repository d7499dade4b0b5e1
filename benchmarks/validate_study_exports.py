"""The MuJoCo round trip on one exported design of each shipped study (issue 25).

Each shipped study (``studies/*.yaml``) is run as a user would, with ``pkmlab run``, on a copy
whose optimiser is cut to two Sobol samples (the study's own seed, evaluation and export
settings are kept). The first exported design's ``mechanism.mjcf.xml`` (the file the study
wrote, not one made again here) is loaded in MuJoCo, driven to pkmlab's IK values at
``N`` valid poses with gravity off, and compared with pkmlab's pose; then the sag with gravity.

    PYTHONPATH=src python benchmarks/validate_study_exports.py [--goldens tests/data/study_exports]

``--goldens DIR`` also copies each study's first exported ``mechanism.yaml`` to
``DIR/<study>.yaml``: the stored designs ``tests/export/test_study_exports_mujoco.py``
re-exports and round-trips in CI (regenerate them this way when a study or the optimiser's
sampling changes). The MJCF of a stored design is made again by the test with the study's
masses, as the study export does (``study.export._mechanism_formats``).
"""

from __future__ import annotations

import argparse
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

import pkmlab
from pkmlab.export import roundtrip as rt
from pkmlab.testing import random_valid_poses

ROOT = Path(__file__).resolve().parents[1]
N = 5


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--goldens", type=Path, help="copy each study's design 1 YAML here")
    args = ap.parse_args()
    tmp = Path(tempfile.mkdtemp(prefix="pkmlab-study-exports-"))
    try:
        shutil.copytree(ROOT / "studies", tmp / "studies")
        print("| study | design | position mm | rotation rad | loop gap mm | joint mm | sag tool "
              "mm | sag tool rad | sag loop gap mm | s |")
        print("|---|---|---|---|---|---|---|---|---|---|")
        worst = np.zeros(7)
        for f in sorted((ROOT / "studies").glob("*.yaml")):
            t0 = time.perf_counter()
            data = yaml.safe_load(f.read_text())
            data["optimizer"] = {"method": "sobol", "samples": 2}
            data["output"] = str(tmp / "out" / f.stem)
            copy = tmp / "studies" / f.name
            copy.write_text(yaml.safe_dump(data, sort_keys=False))
            run = subprocess.run([sys.executable, "-m", "pkmlab.cli", "run", str(copy)],
                                 capture_output=True, text=True)
            if run.returncode != 0:
                print(f"| {f.stem} | run failed: {run.stderr.strip().splitlines()[-1]} |")
                continue
            designs = sorted((tmp / "out" / f.stem / "designs").glob("*/mechanism.mjcf.xml"))
            if not designs:
                print(f"| {f.stem} | no exported design with an MJCF file |")
                continue
            d = designs[0].parent
            if args.goldens is not None:
                args.goldens.mkdir(parents=True, exist_ok=True)
                text = (d / "mechanism.yaml").read_text()
                (args.goldens / f"{f.stem}.yaml").write_text(
                    f"# Stored by benchmarks/validate_study_exports.py --goldens: design 1 "
                    f"exported by study {f.stem} (studies/{f.name}, 2 Sobol samples).\n"
                    + text)
            mech = pkmlab.load_mechanism(d / "mechanism.yaml")
            xml = (d / "mechanism.mjcf.xml").read_text()
            w = np.zeros(4)
            for X in random_valid_poses(mech, N, seed=2025):
                model, state = rt.load(mech, xml=xml)
                rt.drive(mech, model, state, X)
                c = rt.compare(mech, model, state, X)
                w = np.maximum(w, [c["position_mm"], c["rotation_rad"], c["loop_gap_mm"],
                                   c["joint_mm"]])
            model, state = rt.load(mech, xml=xml)
            s = rt.sag(mech, model, state)
            row = np.r_[w, s["tool_mm"], s["tool_rad"], s["loop_gap_mm"]]
            worst = np.maximum(worst, row)
            print(f"| {f.stem} | {d.name} | " + " | ".join(f"{v:.1e}" for v in row)
                  + f" | {time.perf_counter() - t0:.0f} |", flush=True)
        print("| **worst** | | " + " | ".join(f"{v:.1e}" for v in worst) + " | |")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
