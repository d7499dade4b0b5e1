"""The budgets' memory estimates against measured peaks, for every command at its default
settings on shipped files and studies (issue 27, item 3).

What is compared (:mod:`pkmlab.runtime.peak`): each command runs in a fresh interpreter, with
its kernels already compiled in the on-disk cache (one warm-up process runs every command
first); the **measured peak** is the rise of the peak resident set (``VmHWM``, reset through
``/proc/self/clear_refs``) over the resident set once ``pkmlab.cli`` is imported; the
**estimate** is the largest need the command checked against the memory budget — its fixed
memory (:data:`pkmlab.runtime.memory.COMMAND_BYTES`) plus its largest array request.
ratio = estimate / measured; the target is [0.5, 2].

    python benchmarks/budget_estimates.py              # every command (about 10 min)
    python benchmarks/budget_estimates.py trajectory   # the rows whose label contains a word
    python benchmarks/budget_estimates.py --no-warm    # the kernel cache is warm already

Linux only. The first run after an install also compiles the kernels (up to 0.75 GB once):
not input-dependent, not counted (the warm-up process takes it).
"""

from __future__ import annotations

import sys
import tempfile
from pathlib import Path

import yaml

from pkmlab.runtime.memory import PROCESS_BYTES
from pkmlab.runtime.peak import measure, warm

ROOT = Path(__file__).resolve().parents[1]
M = ROOT / "studies" / "mechanisms"
HW, GS = M / "hopkins-williams-6psu.yaml", M / "gough-stewart-6ups.yaml"
RSS, LUZI = M / "instructables-servo-6rss.yaml", M / "luzi-3chain.yaml"


def small_study(tmp: Path) -> Path:
    """A 6-PSU study with a workspace, a payload and the paper motion, 4 Sobol candidates (a
    shipped study's default run takes minutes; its validate is measured as shipped)."""
    study = tmp / "study.yaml"
    study.write_text(yaml.safe_dump({
        "study": "mem", "mechanism": {"file": str(HW)},
        "design": {"link_length": {"low": "200 mm", "high": "260 mm"}},
        "evaluate": {"workspace": {"kind": "constant"}, "payload": {"mass": "2 kg"},
                     "motions": [{"name": "p", "paper": True}]},
        "objectives": [{"maximize": "constant_volume"}],
        "optimizer": {"method": "sobol", "samples": 4}, "output": str(tmp / "run")}))
    return study


def cases(tmp: Path) -> list[tuple[str, list]]:
    study = small_study(tmp)
    return [        # the quick ones first; the large grids last
        ("trajectory 6-PSU --paper-motion", ["trajectory", HW, "--paper-motion", "--out",
                                             tmp / "t1"]),
        ("trajectory 6-PSU --paper-motion --segment-time 10",
         ["trajectory", HW, "--paper-motion", "--segment-time", "10", "--out", tmp / "t2"]),
        ("validate (shipped: hopkins-6psu-redesign)",
         ["validate", ROOT / "studies" / "hopkins-6psu-redesign.yaml"]),
        ("validate (6-PSU study)", ["validate", study]),
        ("run (6-PSU study, 5 evaluations)", ["run", study, "--overwrite"]),
        ("report (that run)", ["report", tmp / "run"]),
        ("fk --all 6-PSU", ["fk", HW, "--all", "--actuators", ",".join(["50.8"] * 6)]),
        ("export 6-PSU mjcf", ["export", HW, "--format", "mjcf", "--out", tmp / "e1"]),
        ("printer ldelta3", ["printer", M / "klipper-example-ldelta3.yaml"]),
        ("optimum stroke 6-PSU", ["optimum", "stroke", HW]),
        ("dexterity 6-PSU", ["dexterity", HW, "--out", tmp / "d1"]),
        ("workspace 6-PSU", ["workspace", HW, "--out", tmp / "w1"]),
        ("workspace 6-RSS", ["workspace", RSS, "--out", tmp / "w3"]),
        ("inspect 6-PSU", ["inspect", HW]),
        ("ik 6-PSU", ["ik", HW, "--pose", "0,0,250,0,0,0"]),
        ("demo (shipped mechanisms)", ["demo"]),
        ("workspaces (Hopkins & Williams 2002)", ["workspaces", ROOT / "studies" / "papers" /
                                                 "hopkins-williams-2002.yaml", "--out",
                                                 tmp / "ws"]),
        ("compare 6-PSU", ["compare", HW, "--out", tmp / "c"]),
        ("export 6-PSU step", ["export", HW, "--format", "step", "--out", tmp / "e2"]),
        ("workspace 6-UPS", ["workspace", GS, "--out", tmp / "w2"]),
        ("workspace Luzi", ["workspace", LUZI, "--out", tmp / "w4"]),
    ]


def _coarse(argv: list) -> list:
    """The command at a coarse grid: it compiles the same kernels (numba compiles per type,
    not per size) in a fraction of the time."""
    if argv[0] in ("workspace", "dexterity", "compare"):
        return [*argv, "--resolution", "10"]
    return argv


def main() -> int:
    chosen = [a for a in sys.argv[1:] if a != "--no-warm"]
    rows = ["| command (default settings) | estimate (MiB) | field | measured rise (MiB) | "
            "ratio | resident after import (MiB) | exit |", "|---|---|---|---|---|---|---|"]
    sys.stdout.write("\n".join(rows) + "\n")
    with tempfile.TemporaryDirectory() as t:
        todo = [(label, argv) for label, argv in cases(Path(t))
                if not chosen or any(c in label for c in chosen)]
        if "--no-warm" not in sys.argv:     # the kernels already in the cache: skip it
            warm([_coarse(argv) for _, argv in todo])
        for label, argv in todo:
            r = measure(argv, timeout=1800.0)
            est, rise = r["estimate"], r["rise"]
            rows.append(f"| {label} | {est / 2**20:.1f} | {r['field'] or '—'} | "
                        f"{rise / 2**20:.1f} | {est / max(rise, 1):.2f} | "
                        f"{r['base'] / 2**20:.0f} | {r['code']} |")
            sys.stdout.write(rows[-1] + "\n")
            sys.stdout.flush()
    sys.stdout.write(f"\nPROCESS_BYTES (resident after import, not counted) = "
                     f"{PROCESS_BYTES / 2**20:.0f} MiB\n")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
