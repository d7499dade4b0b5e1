"""Kernel warmers: what builds a mechanism's numba kernels ahead of use (issue 28, item 4).

A warmer builds (compiles, or loads from numba's disk cache) kernels that a mechanism's
evaluation may use, without evaluating anything: ``build(mech)`` for the mechanisms where
``applies(mech)`` holds. The kernel cache's warm-up (:mod:`pkmlab.study.warm`) runs the
warmers that apply to a study's baseline, spread over processes by their ``weight`` (the
relative compile time, measured: the CPU seconds of a cold compile on the development
machine, quoted where each warmer is registered), and then evaluates the baseline, which
compiles whatever no warmer covers. Built-in kernels register their warmers exactly as a
plugin's would (:func:`register_warmer`, at import of the module that registers them).

A warmer never changes what a kernel computes: it calls the same factory, with the same
arguments, that the evaluation calls, so the kernel's cache entry (keyed by its source and
signature, :func:`pkmlab.runtime.jit.cached_kernel`) is the one the evaluation loads.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

__all__ = ["Warmer", "WARMERS", "register_warmer", "unregister_warmer", "applicable",
           "partition"]


@dataclass(frozen=True)
class Warmer:
    """``build(mech)`` builds kernels for ``mech`` where ``applies(mech)``; ``weight``: its
    relative compile cost (CPU seconds of a cold compile)."""

    name: str
    weight: float
    applies: Callable[[Any], bool]
    build: Callable[[Any], None]


#: name → warmer, in registration order
WARMERS: dict[str, Warmer] = {}


def register_warmer(name: str, weight: float, applies: Callable[[Any], bool],
                    build: Callable[[Any], None]) -> Warmer:
    """Register a warmer under ``name`` (a name registered twice is refused)."""
    if name in WARMERS:
        raise ValueError(f"a kernel warmer named {name!r} is already registered")
    if not weight > 0:
        raise ValueError(f"warmer {name!r}: weight must be > 0, got {weight!r}")
    WARMERS[name] = w = Warmer(name, float(weight), applies, build)
    return w


def unregister_warmer(name: str) -> None:
    WARMERS.pop(name, None)


def applicable(mech) -> list[Warmer]:
    """The registered warmers that apply to ``mech``, in registration order."""
    return [w for w in WARMERS.values() if w.applies(mech)]


def partition(warmers: list[Warmer], bins: int) -> list[list[Warmer]]:
    """``warmers`` spread over ``bins`` lists of about equal total weight (longest first,
    each to the lightest list); deterministic (ties by name)."""
    out: list[list[Warmer]] = [[] for _ in range(max(1, bins))]
    load = [0.0] * len(out)
    for w in sorted(warmers, key=lambda w: (-w.weight, w.name)):
        i = min(range(len(out)), key=lambda j: (load[j], j))
        out[i].append(w)
        load[i] += w.weight
    return out
