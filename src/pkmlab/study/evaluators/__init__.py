"""Candidate evaluation: evaluators as objects in one public registry (:mod:`.registry`).

Each built-in evaluator is one module of this package declaring its ``evaluate`` block model,
its metrics, what it requires and its computation; it registers exactly as a plugin would
(:func:`register_evaluator`; installed distributions use the entry point group
``pkmlab.evaluators``). :func:`evaluate_mechanism` runs those an evaluation asks for, in
registration order, and checks that each writes exactly its declared metrics (a missing or
unexpected metric is a programming error). A value is a float, or ``None`` with a note in
``ctx.notes`` saying why (an empty workspace, a singular pose, a capped search): never a
silent NaN.

Failure policy (:func:`evaluate_design`):

* :class:`~pkmlab.runtime.memory.BudgetError` — the candidate does not fit the memory or
  time budget (an environment limit): status ``budget``, which the study driver never
  stores — it stops the run with that one line;
* :class:`~pkmlab.errors.ParameterError` — the design is geometrically invalid: status
  ``invalid`` with the reason;
* :class:`~pkmlab.errors.NumericalError` — a declared numerical failure: status ``failed``;
* anything else is a programming error: status ``error`` with the traceback; the study driver
  records it and stops the run (:class:`~pkmlab.study.run.CandidateError`).

Evaluators never print, plot or write files.
"""

from __future__ import annotations

import importlib
import time
import traceback

from ...errors import NumericalError, ParameterError
from ...runtime.memory import BudgetError
from ..metrics import metrics_of
from .registry import (
    EVALUATORS,
    MECHANISM_NEEDS,
    OMIT,
    PLUGIN_ERRORS,
    PLUGIN_GROUP,
    Context,
    Cost,
    Evaluator,
    check_budget,
    check_requirements,
    load_evaluator_plugins,
    metric,
    register_evaluator,
    unregister_evaluator,
)

#: the built-in evaluators' modules, registered in this order (the evaluation order:
#: dependencies first); each registers itself exactly as a plugin would
BUILTINS = ("geometry", "workspace", "inscribed", "orientation_capability", "needed_stroke",
            "volume_bracket", "dexterity", "payload", "trajectory", "task", "motions",
            "actuators", "planar_workspace", "printer", "delta_task", "tripod_workspace")
for _module in BUILTINS:
    importlib.import_module(f"{__name__}.{_module}")

from .orientation_capability import capability  # noqa: E402

__all__ = ["EVALUATORS", "Evaluator", "Context", "register_evaluator", "unregister_evaluator",
           "metric", "check_requirements", "load_evaluator_plugins", "PLUGIN_GROUP",
           "PLUGIN_ERRORS", "MECHANISM_NEEDS", "OMIT", "evaluate_design",
           "evaluate_mechanism", "capability", "BUILTINS", "Cost", "check_budget"]

load_evaluator_plugins()


def evaluate_mechanism(mech, evaluation, seed: int, choices: dict | None = None
                       ) -> tuple[dict, dict]:
    """Every evaluator ``evaluation`` asks for, in order → ``(metrics, notes)``.

    ``choices`` are the design's evaluation choices (``{"actuator": catalogue name}``).
    Raises :class:`ParameterError` / :class:`NumericalError` for an invalid design or a
    declared numerical failure, anything else for a programming error.
    """
    ctx = Context(evaluation, seed, choices=dict(choices or {}))
    _ = mech.nominal_pose      # ParameterError if no level pose reaches mid-stroke
    metrics: dict = {}
    for name in evaluation.evaluators:
        out = EVALUATORS[name](mech, ctx)
        declared = set(metrics_of(name)) & set(evaluation.metrics)
        if set(out) != declared:
            raise AssertionError(f"evaluator {name!r} wrote {sorted(out)}, declared "
                                 f"{sorted(declared)}")
        metrics.update(out)
    return metrics, ctx.notes


def evaluate_design(space, design: dict | None, evaluation, seed: int) -> dict:
    """Evaluate one design of ``space`` (``None``: the baseline) → a plain-data record
    ``{"status", "reason", "metrics", "notes", "seconds", "compile_seconds"}`` (see the
    module's failure policy; ``compile_seconds`` is the part of ``seconds`` spent compiling
    kernels, left out of time estimates).

    Runs unchanged in a joblib worker or on a Dask cluster.
    """
    from ...runtime.jit import compile_seconds

    t0, c0 = time.perf_counter(), compile_seconds()
    metrics: dict = {}
    notes: dict = {}
    try:
        mech = space.decode(design)
        metrics, notes = evaluate_mechanism(mech, evaluation, seed,
                                            space.evaluation_choices(design))
        status, reason = "ok", ""
    except BudgetError as exc:     # the machine's budget, not the design: never stored
        status, reason = "budget", str(exc)
        metrics = {"field": exc.field, "allowed": exc.allowed, "got": str(exc.got)}
    except ParameterError as exc:
        status, reason = "invalid", str(exc)
    except NumericalError as exc:
        status, reason = "failed", str(exc)
    except Exception as exc:  # noqa: BLE001 - recorded, then the driver stops the run
        status = "error"
        reason = f"{type(exc).__name__}: {exc}\n" + traceback.format_exc()
    # compile_seconds: the part of ``seconds`` spent compiling kernels (left out of estimates)
    return {"status": status, "reason": reason, "metrics": metrics, "notes": notes,
            "seconds": time.perf_counter() - t0, "compile_seconds": compile_seconds() - c0}
