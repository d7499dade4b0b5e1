"""Memory budget: every request estimates the memory it needs before it allocates, and a
request that would not fit is refused as bad input (with a coarser setting that would fit).

The budget is ``PKMLAB_MEMORY_LIMIT`` (bytes, or with a unit: ``"2GiB"``, ``"500 MB"``) or, by
default, :data:`pkmlab.limits.MEMORY_FRACTION` of the machine's physical memory.
"""

from __future__ import annotations

import contextlib
import math
import os
import re

from ..errors import ParameterError, Shown
from ..limits import MEMORY_FRACTION

__all__ = ["memory_limit", "format_bytes", "require", "require_command", "coarser_resolution",
           "readable_step", "BudgetError", "PROCESS_BYTES", "OUTPUT_BYTES", "COMMAND_BYTES",
           "FORMAT_BYTES", "set_command", "command_bytes", "largest_checked", "checking_for"]

_UNITS = {"": 1, "b": 1, "k": 1e3, "kb": 1e3, "m": 1e6, "mb": 1e6, "g": 1e9, "gb": 1e9,
          "t": 1e12, "tb": 1e12, "kib": 2**10, "mib": 2**20, "gib": 2**30, "tib": 2**40}
ENV = "PKMLAB_MEMORY_LIMIT"
#: resident set of a ``pkmlab`` process once the CLI is imported (interpreter, numpy, scipy,
#: numba, typer, rich): measured 130-131 MiB (benchmarks/budget_estimates.py, "resident after
#: import"); the budget does not count it — it covers what a command adds over it
PROCESS_BYTES = 136 * 2**20
#: fixed cost of a library call beside the arrays its budget checks (small work arrays):
#: a few MB
OUTPUT_BYTES = 8 * 2**20
#: fixed memory of each command beside the arrays its cost model counts: the rise of the peak
#: resident set of a fresh ``pkmlab <command>`` process over its resident set once the CLI is
#: imported, with a warm kernel cache, on an input whose arrays are negligible — the kernels it
#: loads from the cache (numba/LLVM: the bulk), the modules it imports late (matplotlib,
#: plotly, the study machinery, trimesh) and its plots, pages and files. Measured by
#: ``benchmarks/budget_estimates.py`` (2-core VM, Python 3.12, numba 0.6x) and rounded up;
#: a command not listed counts :data:`OUTPUT_BYTES`. The first run after an install also
#: compiles the kernels (up to 0.75 GB once): not counted, as it does not depend on the input.
COMMAND_BYTES = {
    "inspect": 72 * 2**20, "ik": 72 * 2**20, "fk": 64 * 2**20, "demo": 96 * 2**20,
    "validate": 96 * 2**20, "run": 480 * 2**20, "report": 180 * 2**20,
    "workspace": 120 * 2**20, "workspaces": 160 * 2**20, "dexterity": 160 * 2**20,
    "trajectory": 112 * 2**20, "compare": 320 * 2**20, "export": 64 * 2**20,
    "printer": 96 * 2**20, "optimum": 100 * 2**20,
}
#: memory an ``export`` format adds to the command's: STEP loads the CAD kernel (measured: a
#: STEP export rose 415 MiB, an MJCF one 64 MiB)
FORMAT_BYTES = {"step": 384 * 2**20}
_STATE: dict = {"command": None, "largest": 0.0, "field": None, "record": True}


class BudgetError(ParameterError):
    """A request does not fit the memory or time budget, or the budget's environment variable
    is not readable: a property of the machine and its settings, never of a design (a study
    run stops on it; it is never stored as a candidate's result)."""


def _physical() -> int:
    try:
        return int(os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES"))
    except (ValueError, OSError, AttributeError):       # pragma: no cover - not POSIX
        return 8 * 2**30


def memory_limit() -> int:
    """The memory budget in bytes (``PKMLAB_MEMORY_LIMIT`` or a share of physical memory)."""
    text = os.environ.get(ENV, "").strip()
    if not text:
        return int(MEMORY_FRACTION * _physical())
    m = re.fullmatch(r"([0-9]+(?:\.[0-9]*)?(?:[eE][+-]?[0-9]+)?)\s*([A-Za-z]*)", text)
    unit = m.group(2).lower() if m else None
    if m is None or unit not in _UNITS or not 0 < float(m.group(1)) * _UNITS[unit] < 2**62:
        raise BudgetError(ENV, "a size in bytes or with a unit (e.g. 2GiB, 500MB)", text)
    return int(float(m.group(1)) * _UNITS[unit])


def format_bytes(n: float) -> str:
    for unit, size in (("TiB", 2**40), ("GiB", 2**30), ("MiB", 2**20), ("KiB", 2**10)):
        if n >= size:
            return f"{n / size:.3g} {unit}"
    return f"{int(n)} B"


def set_command(name: str | None) -> None:
    """The command this process runs (the CLI sets it): its fixed memory,
    :data:`COMMAND_BYTES`, is added to every request checked while it runs (``None``: the
    command is over; :func:`largest_checked` keeps its estimate)."""
    _STATE.update(command=name)
    if name is not None:
        _STATE.update(largest=0.0, field=None)


@contextlib.contextmanager
def checking_for(name: str):
    """Budget checks made inside are those of command ``name`` (``validate`` checks what
    ``run`` will need: whatever validates, runs); they are not this command's estimate."""
    command, record = _STATE["command"], _STATE["record"]
    _STATE.update(command=name, record=False)
    try:
        yield
    finally:
        _STATE.update(command=command, record=record)


def command_bytes() -> float:
    """Fixed memory of the running command (0 in a library call)."""
    name = _STATE["command"]
    return 0.0 if name is None else float(COMMAND_BYTES.get(name, OUTPUT_BYTES))


def largest_checked() -> tuple[str | None, float]:
    """The largest need (bytes, the command's fixed memory included) checked against the
    budget since :func:`set_command`, and its field: the command's memory estimate."""
    return _STATE["field"], float(_STATE["largest"])


def require(field: str, need: float, what: str, got: str, hint: str = "") -> None:
    """Raise :class:`ParameterError` on ``field`` if ``need`` bytes, plus the running
    command's fixed memory (:func:`command_bytes`), exceed the budget.

    The message reads ``<field>: must be <what> fit in <limit> (<hint>); got <got> needing
    <need>``.
    """
    need = float(need) + command_bytes()
    if _STATE["record"] and need >= _STATE["largest"]:
        _STATE.update(largest=need, field=field)
    limit = memory_limit()
    if need > limit:
        if command_bytes() >= limit:        # no setting of ``field`` can help
            field, hint = ENV, (f"{_STATE['command']} alone needs "
                                f"{format_bytes(command_bytes())}: set a larger {ENV}")
        hint = f" ({hint})" if hint else ""
        raise BudgetError(field, f"{what} fit in {format_bytes(limit)}{hint}",
                          Shown(f"{got} needing {format_bytes(need)}"))


def require_command(command: str) -> None:
    """Refuse, on :data:`ENV`, a budget smaller than the running command's fixed memory
    (no setting of the command would fit it)."""
    require(ENV, 0.0, f"a budget the command's fixed memory ({command}: kernels, modules, "
            "outputs) can", format_bytes(memory_limit()), "set a larger one")


def coarser_resolution(h: float, need: float, exponent: float = 2.0) -> float:
    """A grid spacing that would fit: memory scales as ``h**-exponent``; rounded up to a
    readable value."""
    limit = memory_limit() - command_bytes()      # what the arrays may take
    return readable_step(h * (max(need, 1.0) / max(limit, 1)) ** (1.0 / exponent) * 1.05, h)


def readable_step(target: float, fallback: float) -> float:
    """The smallest of 1, 1.25, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k at least ``target``
    (``fallback`` when ``target`` is not a positive finite number)."""
    if not math.isfinite(target) or target <= 0:
        return fallback
    mag = 10 ** math.floor(math.log10(target))
    for step in (1, 1.25, 1.5, 2, 2.5, 3, 4, 5, 6, 8, 10):
        if step * mag >= target:
            return step * mag
    return 10 * mag                               # pragma: no cover
