"""The budgets' memory estimates against measured peaks, per command at its default settings
(issue 27): each command line runs in a fresh interpreter after a warm-up command (so the
numba kernels are loaded from the cache, not compiled), and the peak resident set's rise over
the resident set before the command is compared with the largest estimate the command
checked against the budget (:func:`pkmlab.runtime.memory.require`) plus the command's fixed
output cost (:data:`pkmlab.runtime.memory.OUTPUT_BYTES`: plots, meshes, report).

    python benchmarks/memory_model.py            # prints the Markdown table of docs/validation.md

Linux only (``/proc/self/clear_refs`` resets the peak). The first run after an install also
compiles the kernels: that peak (up to 0.75 GB for the 6-RSS) is measured separately with a
cold ``NUMBA_CACHE_DIR`` and is not input-dependent, so no budget covers it.
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import yaml

from pkmlab.runtime.memory import OUTPUT_BYTES, PROCESS_BYTES
from pkmlab.runtime.peak import measure

ROOT = Path(__file__).resolve().parents[1]
M = ROOT / "studies" / "mechanisms"


def cases(tmp: Path) -> list[tuple[str, list, list]]:
    study = tmp / "study.yaml"
    study.write_text(yaml.safe_dump({
        "study": "mem", "mechanism": {"file": str(M / "hopkins-williams-6psu.yaml")},
        "design": {"link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "constant"}, "payload": {"mass": "2 kg"},
                     "motions": [{"name": "p", "paper": True}]},
        "objectives": [{"maximize": "constant_volume"}],
        "optimizer": {"method": "sobol", "samples": 4}, "output": str(tmp / "run")}))
    hw, gs = M / "hopkins-williams-6psu.yaml", M / "gough-stewart-6ups.yaml"
    warm = ["inspect", hw]
    return [
        ("inspect (6-PSU)", ["inspect", hw], [warm]),
        ("ik (6-PSU)", ["ik", hw, "--pose", "0,0,250,0,0,0"], [warm]),
        ("workspace 6-PSU", ["workspace", hw, "--out", tmp / "w1"],
         [["workspace", hw, "--resolution", "20", "--out", tmp / "w0"]]),
        ("workspace 6-UPS", ["workspace", gs, "--out", tmp / "w2"],
         [["workspace", gs, "--resolution", "40", "--out", tmp / "w0"]]),
        ("workspace 6-RSS", ["workspace", M / "instructables-servo-6rss.yaml", "--out",
                             tmp / "w3"],
         [["workspace", M / "instructables-servo-6rss.yaml", "--resolution", "20", "--out",
           tmp / "w0"]]),
        ("workspace Luzi", ["workspace", M / "luzi-3chain.yaml", "--out", tmp / "w4"],
         [["workspace", M / "luzi-3chain.yaml", "--resolution", "20", "--out", tmp / "w0"]]),
        ("dexterity 6-PSU", ["dexterity", hw, "--out", tmp / "d1"],
         [["dexterity", hw, "--resolution", "20", "--out", tmp / "d0"]]),
        ("trajectory 6-PSU paper motion", ["trajectory", hw, "--paper-motion", "--out",
                                           tmp / "t1"], [warm]),
        ("validate (study)", ["validate", study], [warm]),
        ("run (study, 5 evaluations)", ["run", study], [["validate", study]]),
    ]


def main() -> int:
    rows = ["| command (default settings) | estimate checked (MiB) | estimate + fixed (MiB) "
            "| measured rise (MiB) | ratio | before the command (MiB) |",
            "|---|---|---|---|---|---|"]
    with tempfile.TemporaryDirectory() as t:
        chosen = sys.argv[1:]
        for label, argv, warm in cases(Path(t)):
            if chosen and not any(c in label for c in chosen):
                continue
            r = measure(argv, warm)
            est = max((b for _, b in r["estimates"]), default=0.0)
            fixed = est + OUTPUT_BYTES
            rise = r["rise"]
            rows.append(f"| {label} | {est / 2**20:.1f} | {fixed / 2**20:.1f} | "
                        f"{rise / 2**20:.1f} | {fixed / max(rise, 1):.2f} | "
                        f"{r['base'] / 2**20:.0f} |")
            sys.stdout.write(rows[-1] + "\n")
            sys.stdout.flush()
    sys.stdout.write("\n".join(rows) + f"\n\nPROCESS_BYTES = {PROCESS_BYTES / 2**20:.0f} MiB\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
