"""Structure rules the code keeps (DEVELOPERS' guide): small modules, no hidden import cycles,
the public mechanism protocol, no global plotting state, no print in library code."""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "src" / "pkmlab"
MODULES = sorted(SRC.rglob("*.py"))


def _name(path: Path) -> str:
    parts = list(path.relative_to(SRC.parent).with_suffix("").parts)
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


NAMES = {_name(p): p for p in MODULES}


def _imports(path: Path) -> tuple[set[str], set[str]]:
    """Intra-package modules imported at module level and inside functions."""
    tree = ast.parse(path.read_text())
    me = _name(path)
    pkg = me.split(".") if path.name == "__init__.py" else me.split(".")[:-1]
    top, lazy = set(), set()
    for node in ast.walk(tree):
        if not isinstance(node, ast.ImportFrom):
            continue
        base = pkg[:len(pkg) - (node.level - 1)] if node.level else []
        target = ".".join(base + ([node.module] if node.module else [])) if node.level \
            else (node.module or "")
        found = {t for t in [target] + [f"{target}.{a.name}" for a in node.names]
                 if t in NAMES}
        (top if node in tree.body else lazy).update(found)
    return top, lazy


GRAPH = {n: _imports(p) for n, p in NAMES.items()}


def _reach(start: str) -> set[str]:
    seen, stack = set(), [start]
    while stack:
        for nxt in GRAPH[stack.pop()][0]:
            if nxt not in seen:
                seen.add(nxt)
                stack.append(nxt)
    return seen


@pytest.mark.parametrize("path", MODULES, ids=[_name(p) for p in MODULES])
def test_modules_stay_small(path):
    assert len(path.read_text().splitlines()) <= 600, f"{_name(path)}: split it by concept"


def test_no_import_cycle_is_hidden_by_a_function_level_import():
    hidden = [f"{m} -> {t}" for m, (_, lazy) in GRAPH.items() for t in lazy
              if m in _reach(t)]
    assert not hidden, hidden


def test_no_private_mechanism_method_is_used_outside_mechanisms():
    pattern = re.compile(r"\.\_(run_ik|jacobian|ik_frames_raw|tool_points|columns|"
                         r"position_bounds|leg_offsets|column_params|column_leg|gparams|"
                         r"closure|mid_stroke_pose|nominal)\b")
    hits = [f"{_name(p)}: {m.group(0)}" for p in MODULES if "mechanisms" not in p.parts
            for m in pattern.finditer(p.read_text())]
    assert not hits, hits


def test_library_code_never_touches_global_plotting_state_or_prints():
    bad = []
    for p in MODULES:
        text = p.read_text()
        if re.search(r"matplotlib\.use\(|import matplotlib\.pyplot|switch_backend", text):
            bad.append(f"{_name(p)}: pyplot / global backend")
        if "cli" not in _name(p) and re.search(r"^\s*print\(", text, re.M):
            bad.append(f"{_name(p)}: print")
    assert not bad, bad
