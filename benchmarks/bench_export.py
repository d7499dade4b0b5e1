"""Share of a small study's time spent exporting (issue 14: at most 25 % for 16 candidates).

Runs the demo study (studies/hopkins-6psu-redesign.yaml) with 16 Sobol candidates in this
process (kernels cached: run it twice after an edit), then its report: the summary, the
exported Pareto designs (meshes, slices, κ maps) and the HTML page. The export is timed twice
in the same run: as shipped (κ evaluated only on the voxels drawn, the slice layers and the
surface: ``pkmlab.dexterity.maps.drawn_voxels``) and with κ over every voxel, as before.

Then the same study as a user runs it, ``pkmlab run study.yaml --json`` in a fresh process
(best of ``--repeats``, default 3): its export seconds (the ``timings_s`` it reports) against
the command's wall time, start-up and all.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import yaml

import pkmlab.dexterity.maps as maps
from pkmlab.study import pareto_records, run_study, study_from_mapping, write_report
from pkmlab.study.export import export_designs
from pkmlab.study.runners import SerialRunner
from pkmlab.webreport import write_study_page

ROOT = Path(__file__).resolve().parents[1]


def _report(study, records, out):
    t = time.perf_counter()
    write_report(out, study, records)
    t_summary = time.perf_counter() - t
    t = time.perf_counter()
    export_designs(out, study, pareto_records(study, records))
    t_export = time.perf_counter() - t
    t = time.perf_counter()
    write_study_page(out, study, records)
    return t_summary, t_export, time.perf_counter() - t


def main() -> None:
    src = ROOT / "studies/hopkins-6psu-redesign.yaml"
    data = yaml.safe_load(src.read_text())
    data["optimizer"] = {"method": "sobol", "samples": 16}
    with tempfile.TemporaryDirectory() as tmp:
        data["output"] = str(Path(tmp) / "run")
        study = study_from_mapping(data, base=src.parent, source=src)
        print(f"load average {os.getloadavg()[0]:.2f} (2 cores)")
        t = time.perf_counter()
        store = run_study(study, SerialRunner(), overwrite=True)
        t_eval = time.perf_counter() - t
        records = store.all()
        store.close()
        out = Path(study.output)
        s, e, p = _report(study, records, out)
        full = maps.drawn_voxels
        maps.drawn_voxels = lambda res, levels: res.occupancy.copy()    # κ everywhere
        try:
            _, e_all, _ = _report(study, records, Path(tmp) / "before")
        finally:
            maps.drawn_voxels = full
        n = len(pareto_records(study, records))
        total = t_eval + s + e + p
        print(f"{len(records)} evaluations in {t_eval:.2f} s; report: summary {s:.2f} s, export "
              f"of {n} designs {e:.2f} s, HTML page {p:.2f} s")
        print(f"export share of the run: {100 * e / total:.0f} % (target <= 25 %); with κ on "
              f"every voxel the export took {e_all:.2f} s ({100 * e_all / (total - e + e_all):.0f}"
              " % of the run)")
        repeats = int(sys.argv[sys.argv.index("--repeats") + 1]) if "--repeats" in sys.argv \
            else 3
        print(f"`pkmlab run` in a fresh process, best of {repeats}: "
              + _cli_share(data, src, Path(tmp), repeats))


def _cli_share(data: dict, src: Path, tmp: Path, repeats: int) -> str:
    """The export's share of a ``pkmlab run`` command's wall time (the best of ``repeats``)."""
    data = {**data, "mechanism": {"file": str((src.parent / data["mechanism"]["file"])
                                              .resolve())}}
    study = tmp / "study.yaml"
    study.write_text(yaml.safe_dump(data, sort_keys=False, allow_unicode=True))
    env = {**os.environ, "PYTHONPATH": str(ROOT / "src")}
    runs = []
    for _ in range(repeats):
        t = time.perf_counter()
        p = subprocess.run([sys.executable, "-m", "pkmlab.cli", "run", str(study), "--json",
                            "--overwrite", "--out", str(tmp / "cli")], capture_output=True,
                           text=True, env=env, check=True)
        wall = time.perf_counter() - t
        runs.append((json.loads(p.stdout)["timings_s"], wall))
    timings, wall = min(runs, key=lambda r: r[0]["export_s"] / r[1])
    shares = ", ".join(f"{100 * t['export_s'] / w:.0f} %" for t, w in runs)
    return (f"{wall:.2f} s wall (evaluation {timings['evaluation_s']:.2f} s, summary "
            f"{timings['summary_s']:.2f} s, export {timings['export_s']:.2f} s, page "
            f"{timings['page_s']:.2f} s): export share {100 * timings['export_s'] / wall:.0f} %"
            f" (all runs: {shares}; target <= 25 %)")


if __name__ == "__main__":
    main()
