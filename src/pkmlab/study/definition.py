"""The typed study: everything a run needs, built once at load, in internal units (mm, rad).

:func:`pkmlab.study.load_study` returns a frozen :class:`Study`. Its :meth:`Study.resolved`
is the study written back as a study file with every default filled in and every quantity
with its unit; loading that file gives the same study (same :meth:`Study.fingerprint`).
"""

from __future__ import annotations

import hashlib
import json
import math
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from types import MappingProxyType
from typing import Any

from ..config import to_display
from .evaluators import EVALUATORS, OMIT
from .metrics import KIND_VOLUMES, METRICS
from .space import DesignSpace, Variable

__all__ = ["Study", "Evaluation", "Objective", "Constraint", "PENALTY", "Tolerances", "FINE"]

#: Objective / constraint value of a candidate without the metric (failed, invalid, undefined).
PENALTY = 1.0e12


@dataclass(frozen=True)
class Tolerances:
    """Certified tolerances of the bracketed optima: ``angle`` (rad) of the orientation
    capability, ``length`` (mm) of the needed stroke; ``worst_case``: ``"exact"`` (the
    dexterity's worst case over every sample) or ``"bound"`` (certified bounds from a subset of
    those samples, :mod:`.evaluators.worst_bound`: a tolerance ladder's coarse rung)."""

    angle: float
    length: float
    worst_case: str = "exact"

    def written(self) -> dict:
        return {"angle": f"{math.degrees(self.angle):.12g} deg", "length": f"{self.length:.12g} mm",
                "worst_case": self.worst_case}


#: the tolerances of a run without the ladder (``CAPABILITY_TOL_DEG``, ``STROKE_TOL_MM``)
FINE = Tolerances(math.radians(0.01), 0.01)


@dataclass(frozen=True)
class Evaluation:
    """What to compute for each candidate: ``plans`` maps each given ``evaluate`` block to its
    plan (what its evaluator built from the block, :mod:`.evaluators`); ``request`` is the
    built workspace request. A block's plan reads as an attribute (``evaluation.dexterity``,
    ``None`` when the block is not given). ``tolerances``: the certified tolerances of the
    bracketed optima (:class:`.ladder.Tolerances`; None: the fine ones, 0.01° and 0.01 mm);
    a study's tolerance ladder optimises with coarse ones (:meth:`with_tolerances`)."""

    plans: Mapping[str, Any]
    request: dict | None = None
    tolerances: Any = None
    #: evaluators a tolerance ladder's coarse rung leaves to the re-certification (.ladder)
    deferred: frozenset = frozenset()

    def __post_init__(self):
        object.__setattr__(self, "plans", MappingProxyType(dict(self.plans)))

    def plan(self, name: str) -> Any:
        """The plan of block ``name``, or None when it is not given."""
        return self.plans.get(name)

    def __getattr__(self, name: str) -> Any:
        if name.startswith("_") or name == "plans":
            raise AttributeError(name)
        if name in EVALUATORS:
            return self.plans.get(name)
        raise AttributeError(f"{type(self).__name__!s} has no attribute {name!r}")

    def __getstate__(self):
        return {"plans": dict(self.plans), "request": self.request,
                "tolerances": self.tolerances, "deferred": self.deferred}

    def __setstate__(self, state):
        object.__setattr__(self, "plans", MappingProxyType(state["plans"]))
        object.__setattr__(self, "request", state["request"])
        object.__setattr__(self, "tolerances", state.get("tolerances"))
        object.__setattr__(self, "deferred", state.get("deferred", frozenset()))

    def with_tolerances(self, tolerances, deferred=()) -> Evaluation:
        """This evaluation with other certified tolerances (:class:`.ladder.Tolerances`),
        without the evaluators ``deferred`` (a tolerance ladder's coarse rung leaves them to
        the re-certification: :func:`.ladder.deferred`)."""
        return Evaluation(self.plans, self.request, tolerances, frozenset(deferred))

    @property
    def angle_tolerance_deg(self) -> float:
        """Bisection tolerance of the orientation capability (deg)."""
        return math.degrees((self.tolerances or FINE).angle)

    @property
    def length_tolerance_mm(self) -> float:
        """Bisection tolerance of the needed stroke (mm)."""
        return (self.tolerances or FINE).length

    @property
    def coarse(self) -> bool:
        """The evaluation of a tolerance ladder's coarse rung (:mod:`.ladder`): each of its
        candidates is re-certified at the fine tolerances or pruned, so a check that changes
        no metric (the capability point's random-rotation check) waits for the fine rung."""
        return self.tolerances is not None

    @property
    def worst_case_exact(self) -> bool:
        """The dexterity's worst case over every sample (else certified bounds from a
        subset: a tolerance ladder's coarse rung)."""
        return (self.tolerances or FINE).worst_case == "exact"

    @property
    def evaluators(self) -> tuple[str, ...]:
        """Evaluator names in evaluation order (the registry's order)."""
        return tuple(n for n, ev in EVALUATORS.items() if ev.runs(self)
                     and n not in self.deferred)

    @property
    def metrics(self) -> tuple[str, ...]:
        """Every metric this evaluation writes a value for."""
        kind = None if self.workspace is None else self.workspace.kind
        names = self.evaluators
        return tuple(m.name for m in METRICS.values() if m.evaluator in names
                     and KIND_VOLUMES.get(m.name, kind) == kind)

    def written(self) -> dict:
        """The ``evaluate`` mapping of the resolved study file."""
        out = {}
        for name, ev in EVALUATORS.items():
            plan = self.plans.get(name)
            if plan is not None and plan is not False:
                out[name] = ev.written(plan)
            elif ev.absent is not OMIT and ev.block is not None:
                out[name] = ev.absent
        return out


@dataclass(frozen=True)
class Objective:
    metric: str
    sense: str                              # "maximize" | "minimize"


@dataclass(frozen=True)
class Constraint:
    metric: str
    min: float | None = None
    max: float | None = None

    def describe(self) -> str:
        parts = ([f"≥ {self.min:g}"] if self.min is not None else []) + \
            ([f"≤ {self.max:g}"] if self.max is not None else [])
        return f"{self.metric} " + " and ".join(parts)


@dataclass(frozen=True)
class Study:
    """A validated design study."""

    name: str
    description: str
    space: DesignSpace
    evaluation: Evaluation
    objectives: tuple[Objective, ...]
    constraints: tuple[Constraint, ...]
    optimizer: object                       # spec.OptimizerSpec
    seed: int
    output: Path
    top: int
    source: Path | None = None              # the study file
    tolerance_ladder: Any = None            # ladder.ToleranceLadder, or None

    @property
    def variables(self) -> tuple[Variable, ...]:
        return self.space.variables

    def baseline(self):
        """The mechanism the design space starts from."""
        return self.space.base_spec.build()

    def with_output(self, output: Path) -> Study:
        from dataclasses import replace

        return replace(self, output=Path(output))

    # ---- the study written back -----------------------------------------------------------
    def resolved(self) -> dict:
        """This study as a study-file mapping: every default, every unit explicit."""
        design = {}
        for v in self.space.variables:
            d: dict = {"type": v.kind, "quantity": v.quantity}
            if v.target is not None:
                d["path"] = _path_text(v.target)
            if v.role != "mechanism":
                d = {"target": v.role, "type": "choice"}
            if v.kind == "choice":
                d["choices"] = [_quantity(v, c) for c in v.choices]
            else:
                d.update(low=_quantity(v, v.low), high=_quantity(v, v.high), levels=v.levels)
            design[v.name] = d
        evaluate = self.evaluation.written()
        return {
            "study": self.name, "description": self.description,
            "mechanism": {"inline": to_display(self.space.base_spec)},
            "design": design,
            # each derived field under the name the study gave it (an alias or a path)
            "derived": {d.name: d.expression.text for d in self.space.derived},
            "evaluate": evaluate,
            "objectives": [{o.sense: o.metric} for o in self.objectives],
            "constraints": [{c.metric: {k: getattr(c, k) for k in ("min", "max")
                                        if getattr(c, k) is not None}}
                            for c in self.constraints],
            "optimizer": self.optimizer.model_dump(),
            "seed": self.seed, "output": str(self.output), "top": self.top,
            "tolerance_ladder": (None if self.tolerance_ladder is None
                                 else self.tolerance_ladder.written()),
        }

    def input_files(self) -> list[str]:
        """The files the requirement blocks read (task point set, motion recordings, actuator
        catalogue), as resolved paths."""
        ev = self.evaluation
        paths = []
        if ev.task is not None and "file" in ev.task.source:
            paths.append(ev.task.source["file"])
        if ev.motions is not None:
            paths += [m["file"] for m in ev.motions.source if "file" in m]
        if ev.actuators is not None and "catalogue" in ev.actuators.source:
            paths.append(ev.actuators.source["catalogue"])
        return paths

    def input_digests(self) -> dict:
        """``{path: SHA-256 of its bytes}`` of :meth:`input_files` (part of the fingerprint:
        editing a recording or the catalogue invalidates a resume)."""
        out = {}
        for p in self.input_files():
            try:
                out[p] = hashlib.sha256(Path(p).read_bytes()).hexdigest()
            except OSError as exc:
                out[p] = f"unreadable: {exc.strerror}"
        return out

    def fingerprint(self) -> str:
        """Hash of what determines the evaluations (mechanism, design space, evaluation,
        seed): the store refuses to resume a study whose fingerprint changed."""
        r = self.resolved()
        keep = {k: r[k] for k in ("mechanism", "design", "evaluate", "seed")}
        # by the field each sets: an alias and its path are the same study
        keep["derived"] = {_path_text(d.target): d.expression.text for d in self.space.derived}
        if r["tolerance_ladder"] is not None:    # coarse values are stored: part of the run
            keep["tolerance_ladder"] = r["tolerance_ladder"]
        keep["input_files"] = self.input_digests()
        text = json.dumps(keep, sort_keys=True, separators=(",", ":"), default=str)
        return hashlib.sha256(text.encode()).hexdigest()[:16]


def _path_text(parts: tuple) -> str:
    out = ""
    for p in parts:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else p)
    return out


def _quantity(v: Variable, x):
    if v.quantity == "length":
        return f"{x:.12g} mm"
    if v.quantity == "angle":
        return f"{v.display(x):.12g} deg"
    return x
