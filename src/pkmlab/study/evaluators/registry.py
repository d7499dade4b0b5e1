"""Evaluators as objects in one public registry.

An :class:`Evaluator` is what a design study computes for each candidate under one ``evaluate``
block. It declares, beside its computation:

* ``name`` — the key of its ``evaluate`` block;
* ``block`` — the type of that block's YAML value (a pydantic model, ``bool`` for an on/off
  block, ``list[Model]``), read by ``pkmlab schema``; ``None`` for an evaluator that always
  runs (``geometry``);
* ``metrics`` — the :class:`~pkmlab.study.metrics.Metric` s it writes (name, unit, kind,
  meaning; declared with :func:`metric`);
* ``requires`` — what the study must offer: ``"rotations"`` (a free orientation coordinate),
  ``"spatial"`` (all six pose coordinates free), ``"bracket"`` (spatial, or a family with its
  own position bracket: ``cube_margin``), ``"rotary actuator"`` / ``"linear actuator"``
  (the mechanism's actuators), or another evaluator's name (its block must be given);
  :func:`pkmlab.study.load_study` refuses a study that asks an evaluator what the mechanism or
  the study cannot offer, naming ``evaluate.<name>``;
* ``after`` — the evaluators whose results it reads from the :class:`Context`: they run first,
  and it runs only when they do;
* ``compute(mech, ctx) -> {metric: value}`` — a value is a float, or ``None`` with a note in
  ``ctx.notes`` saying why;
* ``cost(plan, evaluation, mech) -> [Cost]`` — its cost model: the peak memory and the time
  one candidate's block needs, each tied to the setting that drives it; :func:`check_budget`
  (at load, so at ``validate``, and again before a run starts) refuses a block over the
  memory or time budget (:mod:`pkmlab.runtime.memory`, :mod:`pkmlab.runtime.time_budget`),
  naming the field and a setting that fits.

:data:`EVALUATORS` holds them in registration order, which is the evaluation order (an
evaluator can only name registered evaluators in ``after``, so dependencies come first). The
built-in evaluators (one module each in this package) register exactly as a plugin's do:
:func:`register_evaluator`, or an entry point of the group :data:`PLUGIN_GROUP` naming an
:class:`Evaluator` subclass or instance.
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, ClassVar

from pydantic import BaseModel

from ...config import validate_model
from ...errors import ParameterError
from ..metrics import METRICS, Metric

__all__ = ["Evaluator", "Context", "EVALUATORS", "PLUGIN_GROUP", "PLUGIN_ERRORS",
           "metrics_markdown", "MECHANISM_NEEDS", "register_evaluator", "unregister_evaluator",
           "metric", "load_evaluator_plugins", "check_requirements", "finite", "OMIT", "Cost",
           "check_budget"]

#: entry point group of evaluator plugins (each names an :class:`Evaluator` class or instance)
PLUGIN_GROUP = "pkmlab.evaluators"
#: entry point name → why it could not be loaded
PLUGIN_ERRORS: dict[str, str] = {}
#: evaluate block name → evaluator, in registration order (= evaluation order)
EVALUATORS: dict[str, Evaluator] = {}

#: what an evaluator can require of the mechanism, checked in this order
MECHANISM_NEEDS = ("rotations", "rotary actuator", "linear actuator", "spatial", "bracket")

#: ``Evaluator.absent``: nothing written back when the block is not given
OMIT = object()


@dataclass
class Context:
    """What one candidate's evaluators share: the plan, the seed, intermediate results."""

    evaluation: object          # pkmlab.study.definition.Evaluation
    seed: int
    result: object = None       # the WorkspaceResult, once computed
    L: float | None = None      # characteristic length used (mm)
    notes: dict = field(default_factory=dict)
    choices: dict = field(default_factory=dict)   # evaluation choices: {"actuator": name}
    dynamics: list = field(default_factory=list)  # DynamicsResult per required motion
    task_centre: object = None  # the task's centre as placed (base frame, mm), once computed


@dataclass(frozen=True)
class Cost:
    """What one candidate's block needs, by its evaluator's cost model: peak ``bytes`` of its
    arrays and ``seconds``, driven by the setting ``field`` = ``value`` ``unit`` (``got``
    describes the request), where the need scales as ``value ** power`` (negative: a larger
    value needs less, like a grid spacing)."""

    field: str
    value: float
    unit: str
    power: float
    bytes: float = 0.0
    seconds: float = 0.0
    got: str = ""
    integer: bool = False

    def fits(self, need: float, limit: float) -> str:
        """A setting of ``field`` whose need would fit ``limit`` (``try <= x`` / ``>= x``)."""
        from ...runtime.memory import readable_step

        if not need > limit:                # it fits as it is: no other setting to suggest
            return ""
        x = self.value * (max(limit, 1e-300) / max(need, 1e-300)) ** (1.0 / self.power)
        if not math.isfinite(x):
            return ""
        if self.power < 0:
            x = readable_step(x * 1.05, self.value)
            text = f"try >= {x:g}"
        else:
            x = x * 0.9
            x = math.floor(x) if self.integer else float(f"{x:.2g}")
            text = f"try <= {x:g}"
        return f"{text} {self.unit}".rstrip()


def metric(name: str, unit: str, statistic: str, description: str) -> Metric:
    """One metric an evaluator declares (its evaluator is filled in at registration)."""
    return Metric(name, "", unit, statistic, description)


def finite(x) -> float | None:
    """``float(x)``, or ``None`` when it is not finite (the caller adds the note)."""
    x = float(x)
    return x if math.isfinite(x) else None


class Evaluator:
    """One ``evaluate`` block: its YAML model, metrics, requirements and computation (see the
    module docstring). Subclass it, set the class attributes, define :meth:`compute`, and
    register an instance with :func:`register_evaluator`."""

    name: ClassVar[str] = ""
    block: ClassVar[Any] = None
    description: ClassVar[str] = ""
    metrics: ClassVar[tuple[Metric, ...]] = ()
    requires: ClassVar[frozenset[str]] = frozenset()
    after: ClassVar[tuple[str, ...]] = ()
    #: what ``Study.resolved()`` writes for this block when it is not given (kept as it was
    #: for the built-ins, so study fingerprints do not change); :data:`OMIT`: nothing
    absent: ClassVar[Any] = OMIT

    # ---- the block -----------------------------------------------------------------------
    def plan(self, data: Any, base: Path) -> Any:
        """The block's YAML value (not null) → what :meth:`compute` reads as
        ``ctx.evaluation.<name>`` (default: the validated block; ``False`` turns it off).
        Errors name ``evaluate.<name>...``; relative paths resolve against ``base``."""
        where = f"evaluate.{self.name}"
        if self.block is bool:
            if not isinstance(data, bool):
                raise ParameterError(where, "true or false", data)
            return data
        if isinstance(self.block, type) and issubclass(self.block, BaseModel):
            return validate_model(self.block, data, prefix=where + ".")
        from pydantic import TypeAdapter, ValidationError

        from ...errors import from_validation_error

        try:
            return TypeAdapter(self.block).validate_python(data)
        except ValidationError as exc:
            raise from_validation_error(exc, self.block, where + ".") from None

    def written(self, plan: Any) -> Any:
        """The block as written back in ``study.resolved.yaml`` (loading it gives ``plan``)."""
        return plan.model_dump() if isinstance(plan, BaseModel) else plan

    def requirements(self, plan: Any) -> frozenset[str]:
        """What this block asks of the study (default :attr:`requires`)."""
        return frozenset(self.requires)

    def check(self, plan: Any, evaluation: Any, mech: Any) -> None:
        """Further load-time checks of the block against the evaluation and the baseline
        mechanism (raise :class:`ParameterError` naming the field)."""

    def runs(self, evaluation: Any) -> bool:
        """Whether this evaluator runs for ``evaluation``: its block is given (always, without
        a block) and every evaluator of :attr:`after` runs."""
        if self.block is not None and evaluation.plan(self.name) in (None, False):
            return False
        return all(EVALUATORS[a].runs(evaluation) for a in self.after)

    def hint(self) -> str:
        """The blocks to add for this evaluator's metrics (for error messages)."""
        need = [self.name] + [n for n in self.after if EVALUATORS[n].block is not None]
        need += sorted(r for r in self.requires if r in EVALUATORS and r not in need)
        return " and ".join(f"evaluate.{n}" for n in need)

    def cost(self, plan: Any, evaluation: Any, mech: Any) -> list[Cost]:
        """The cost model of one candidate's block on ``mech`` (the baseline): one
        :class:`Cost` per setting that drives memory or time (default: none — a block whose
        cost does not grow with its settings)."""
        return []

    # ---- the computation ---------------------------------------------------------------
    def compute(self, mech, ctx: Context) -> dict:
        raise NotImplementedError

    def __call__(self, mech, ctx: Context) -> dict:
        return self.compute(mech, ctx)

    def __repr__(self) -> str:
        return f"<evaluator {self.name!r} ({type(self).__module__})>"


def register_evaluator(ev: Evaluator | type[Evaluator], *, replace: bool = False
                       ) -> Evaluator:
    """Add ``ev`` (an :class:`Evaluator` instance or class) to :data:`EVALUATORS` and its
    metrics to :data:`~pkmlab.study.metrics.METRICS` (``replace`` to override a name)."""
    if isinstance(ev, type) and issubclass(ev, Evaluator):
        ev = ev()
    if not isinstance(ev, Evaluator):
        raise TypeError(f"{ev!r} is not a pkmlab.study.evaluators.Evaluator")
    name = ev.name
    if not (isinstance(name, str) and name.isidentifier() and name.islower()):
        raise ValueError(f"evaluator name must be a lower-case identifier, got {name!r}")
    old = EVALUATORS.get(name)
    if old is not None and not replace:
        raise ValueError(f"evaluator {name!r} is already registered ({type(old).__module__})")
    if not ev.metrics:
        raise ValueError(f"evaluator {name!r} declares no metrics")
    for a in ev.after:
        if a not in EVALUATORS or a == name:
            raise ValueError(f"evaluator {name!r}: 'after' names {a!r}, which is not a "
                             f"registered evaluator ({list(EVALUATORS)})")
    for r in ev.requires:
        if r not in MECHANISM_NEEDS and (r not in EVALUATORS or r == name):
            raise ValueError(f"evaluator {name!r}: requirement {r!r} is none of "
                             f"{MECHANISM_NEEDS} nor a registered evaluator")
    mine = [dataclasses.replace(m, evaluator=name) for m in ev.metrics]
    for m in mine:
        owner = METRICS.get(m.name)
        if owner is not None and owner.evaluator != name:
            raise ValueError(f"evaluator {name!r}: metric {m.name!r} is already written by "
                             f"{owner.evaluator!r}")
    if len({m.name for m in mine}) != len(mine):
        raise ValueError(f"evaluator {name!r} declares a metric twice")
    if old is not None:
        _drop_metrics(name)
    EVALUATORS[name] = ev
    METRICS.update((m.name, m) for m in mine)
    return ev


def unregister_evaluator(name: str) -> Evaluator:
    """Remove evaluator ``name`` and its metrics (refused while another evaluator needs it)."""
    users = [e.name for e in EVALUATORS.values() if name in e.after or name in e.requires]
    if users:
        raise ValueError(f"evaluator {name!r} is needed by {users}")
    ev = EVALUATORS.pop(name)
    _drop_metrics(name)
    return ev


def _drop_metrics(name: str) -> None:
    for k in [k for k, m in METRICS.items() if m.evaluator == name]:
        del METRICS[k]


def load_evaluator_plugins() -> dict[str, Evaluator]:
    """Register the evaluators of the :data:`PLUGIN_GROUP` entry points (a broken one is
    logged and listed in :data:`PLUGIN_ERRORS`); returns those loaded, by name."""
    from ...plugins import load_entry_points

    loaded = load_entry_points(PLUGIN_GROUP, register_evaluator, PLUGIN_ERRORS, "evaluator")
    return {ev.name: ev for ev in loaded.values()}


# ---- what the mechanism must offer -------------------------------------------------------------

_NEED_TEXT = {"rotations": "rotations (a free orientation coordinate)",
              "spatial": "six free pose coordinates (x, y, z, theta_x, theta_y, theta_z)",
              "rotary actuator": "rotary actuators", "linear actuator": "linear actuators",
              "bracket": "six free pose coordinates (x, y, z, theta_x, theta_y, theta_z), or "
                         "a family bracketing its positions (cube margins: delta3, ldelta3)"}


def _offers(mech, need: str) -> bool:
    if need == "rotations":
        return bool(mech.mobility.rotations)
    if need == "spatial":
        return bool(mech.mobility.is_spatial)
    if need == "bracket":
        return bool(mech.mobility.is_spatial) or getattr(mech, "cube_margin", None) is not None
    rotary = mech.actuator_unit == "rad"
    return rotary if need == "rotary actuator" else not rotary


def _has(mech, need: str) -> str:
    if need in ("rotations", "spatial", "bracket"):
        mob = mech.mobility
        return f"{mob.name} mobility ({', '.join(mob.coordinates)})"
    return ("rotary actuators (rad)" if mech.actuator_unit == "rad"
            else f"linear actuators ({mech.actuator_unit})")


def check_requirements(evaluation, mech, given: dict) -> None:
    """Refuse, naming ``evaluate.<name>``, a block whose evaluator needs what ``mech`` (the
    baseline mechanism) or the evaluation does not offer. ``given`` maps each given block to
    its YAML value (shown in the error). Mechanism needs are checked in the order of
    :data:`MECHANISM_NEEDS` over all blocks (so the most specific refusal is named first:
    rotations before six coordinates), then the blocks each block requires."""
    from ...yamlio import where

    asked = [ev for ev in EVALUATORS.values()
             if ev.block is not None and evaluation.plan(ev.name) not in (None, False)]
    for need in MECHANISM_NEEDS:
        for ev in asked:
            if need in ev.requirements(evaluation.plan(ev.name)) and not _offers(mech, need):
                raise ParameterError(
                    f"evaluate.{ev.name}", f"a block this mechanism can serve ({ev.name} "
                    f"needs {_NEED_TEXT[need]}; family {mech.family!r} has "
                    f"{_has(mech, need)})",
                    given.get(ev.name), where=where(("evaluate", ev.name)))
    for ev in asked:
        for need in sorted(ev.requirements(evaluation.plan(ev.name))):
            if need in EVALUATORS and evaluation.plan(need) in (None, False):
                raise ParameterError(f"evaluate.{ev.name}", f"used with an evaluate.{need} "
                                     f"block ({ev.name} needs it)", f"no {need}",
                                     where=where(("evaluate", ev.name)))
    for ev in asked:
        ev.check(evaluation.plan(ev.name), evaluation, mech)
    check_budget(evaluation, mech)


def check_budget(evaluation, mech) -> list[Cost]:
    """Refuse (:class:`~pkmlab.runtime.memory.BudgetError`, naming the field and a setting
    that fits) a block whose cost model on ``mech`` exceeds the memory or time budget; log a
    long estimate. Returns every evaluator's costs."""
    costs = [c for ev in EVALUATORS.values() if ev.runs(evaluation)
             for c in ev.cost(evaluation.plan(ev.name), evaluation, mech)]
    return check_costs(costs)


def check_costs(costs: list[Cost]) -> list[Cost]:
    """Refuse the first of ``costs`` over the memory (the running command's fixed memory
    added) or time budget, naming its field and a setting that fits; log long estimates."""
    from ...runtime.memory import command_bytes, memory_limit, require
    from ...runtime.time_budget import require_time, time_limit

    mem, secs = memory_limit() - command_bytes(), time_limit()   # what the arrays may take
    for c in costs:
        require(c.field, c.bytes, "a request whose arrays", c.got, c.fits(c.bytes, mem))
        require_time(c.field, c.seconds, "a request", c.got, c.fits(c.seconds, secs))
    return costs


def metrics_markdown() -> str:
    """The README's metric table (``pkmlab metrics``), in registration order."""
    rows = ["| metric | unit | evaluate block | kind | meaning |", "|---|---|---|---|---|"]
    for m in METRICS.values():
        block = "(always)" if EVALUATORS[m.evaluator].block is None else m.evaluator
        rows.append(f"| `{m.name}` | {m.unit or '—'} | {block} | {m.statistic} | "
                    f"{m.description} |")
    return "\n".join(rows) + "\n"
