"""Candidate evaluation: pure evaluators, each declaring the metrics it writes.

An evaluator is a function ``(mech, ctx) -> {metric: value}`` registered with the name of its
``evaluate`` block; the metrics it may write are those :mod:`.metrics` lists under that name,
and :func:`evaluate_design` checks that it writes exactly those (a missing or unexpected metric
is a programming error). A value is a float, or ``None`` with a note in ``ctx.notes`` saying
why (an empty workspace, a singular pose, a capped search): never a silent NaN.

Failure policy (:func:`evaluate_design`):

* :class:`~pkmlab.errors.ParameterError` — the design is geometrically invalid: status
  ``invalid`` with the reason;
* :class:`~pkmlab.errors.NumericalError` — a declared numerical failure: status ``failed``;
* anything else is a programming error: status ``error`` with the traceback; the study driver
  records it and stops the run (:class:`~pkmlab.study.run.CandidateError`).

Evaluators never print, plot or write files.
"""

from __future__ import annotations

import dataclasses
import logging
import math
import time
import traceback
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from .. import dexterity as dx
from ..errors import NumericalError, ParameterError
from ..limits import CAPABILITY_MAX_DEG
from ..requirements.actuators import fit as actuator_fit
from ..requirements.dynamics import inverse_dynamics
from ..requirements.static import static_loads
from ..requirements.task import task_margins
from ..trajectory import check_trajectory, paper_motion
from ..workspaces import OrientationSet, workspace
from ..workspaces.bracket import volume_bracket
from ..workspaces.engine import SINGULAR_NOTE
from ..workspaces.optima import orientation_capability, stroke_needed, supports_continuous
from .metrics import metrics_of

log = logging.getLogger(__name__)

__all__ = ["EVALUATORS", "Context", "evaluate_design", "evaluate_mechanism", "capability"]


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


#: name → evaluator; the order is the evaluation order (dependencies first)
EVALUATORS: dict[str, Callable] = {}


def _evaluator(name: str):
    def register(fn):
        EVALUATORS[name] = fn
        return fn
    return register


def _finite(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


@_evaluator("geometry")
def _geometry(mech, ctx: Context) -> dict:
    fp = mech.footprint()
    travel = float(mech.stroke[1] - mech.stroke[0])
    rotary = mech.actuator_unit == "rad"
    notes = {} if ctx is None else ctx.notes          # the geometry needs no context
    if rotary:
        notes["stroke_length"] = "rotary actuators: their travel is servo_range (deg)"
    else:
        notes["servo_range"] = "prismatic actuators: their travel is stroke_length (mm)"
    return {"base_outer_radius": fp["base_radius"],
            "platform_outer_radius": fp["platform_radius"],
            "stroke_length": None if rotary else travel,
            "servo_range": math.degrees(travel) if rotary else None}


@_evaluator("workspace")
def _workspace(mech, ctx: Context) -> dict:
    ev = ctx.evaluation
    res = workspace(mech, **ev.request)
    ctx.result = res
    vol = res.volume / 1e3
    zr = res.metrics()["z_range_mm"]
    out = {"workspace_volume": vol, "workspace_volume_error": res.volume_error / 1e3,
           "workspace_empty": float(res.empty),
           "z_span": 0.0 if zr is None else float(zr[1] - zr[0])}
    out[f"{res.kind}_volume"] = vol
    for note in res.notes:
        if note.startswith(SINGULAR_NOTE):
            ctx.notes["workspace_volume"] = note
    return out


@_evaluator("volume_bracket")
def _volume_bracket(mech, ctx: Context) -> dict:
    plan = ctx.evaluation.volume_bracket
    req = ctx.evaluation.request
    b = volume_bracket(mech, req["kind"], req["orientations"], req["resolution"],
                       req["constraints"], target=plan.target, budget_s=plan.budget)
    lo, hi = b.lower / 1e3, b.upper / 1e3
    k = req["kind"]
    if b.stop_reason != "converged":
        ctx.notes["workspace_volume_lower"] = (
            f"bracket stopped: {b.stop_reason} at {100 * b.relative_width:.2f} % width "
            f"(final cell {b.resolution:g} mm)")
    for n in b.notes:
        ctx.notes["workspace_volume_upper"] = n
    return {"workspace_volume_lower": lo, "workspace_volume_upper": hi,
            "workspace_volume_bracket_width": 100 * b.relative_width,
            f"{k}_volume_lower": lo, f"{k}_volume_upper": hi}


@_evaluator("inscribed")
def _inscribed(mech, ctx: Context) -> dict:
    res = ctx.result
    names = metrics_of("inscribed")
    if res.empty:
        for n in names:
            ctx.notes[n] = "workspace empty"
        return dict.fromkeys(names, 0.0)
    box = res.inscribed_box(samples=2000, seed=ctx.seed)
    cyl = res.inscribed_cylinder(samples=2000, seed=ctx.seed)
    out = {"inscribed_box_volume": box.volume / 1e3, "inscribed_box_edge": float(box.size.min()),
           "inscribed_cylinder_radius": float(cyl.radius),
           "inscribed_cylinder_volume": cyl.volume / 1e3}
    if not box.volume > 0:
        for n in ("inscribed_box_volume", "inscribed_box_edge"):
            out[n] = None
            ctx.notes[n] = "no box survived verification (the workspace is thinner than a voxel)"
    if not cyl.volume > 0:
        for n in ("inscribed_cylinder_radius", "inscribed_cylinder_volume"):
            out[n] = None
            ctx.notes[n] = "no cylinder survived verification"
    return out


def capability(mech, request: dict, iterations: int = 8) -> tuple[float, float, str]:
    """Largest ``a`` (deg) whose ±a simultaneous Euler box has a non-empty dexterous workspace
    on ``request``'s grid, by bisection → ``(a, bracket, note)``: the fallback for families
    without radial column intervals or with constraints beyond the stroke (radial families
    use :func:`pkmlab.workspaces.optima.orientation_capability`, continuous positions).

    The verified level ``a`` is non-empty and ``a + bracket`` was found empty (so the value is
    a lower bound of the grid's capability to within ``bracket``); ``note`` is non-empty when
    the search hit :data:`~pkmlab.limits.CAPABILITY_MAX_DEG` (bracket 0, the value a lower
    bound only) or the nominal orientation itself has no workspace.
    """
    oset = request["orientations"]
    samples = oset.samples if oset.kind == "box" else 7

    def ok(a_deg: float) -> bool:
        o = OrientationSet.box(np.radians([a_deg] * 3), "simultaneous", samples)
        return not workspace(mech, "dexterous", o, request["resolution"],
                             request["constraints"]).empty

    if not ok(0.0):
        return 0.0, 0.0, "no workspace at the nominal orientation"
    lo, hi = 0.0, 60.0
    if ok(hi):
        lo, hi = hi, CAPABILITY_MAX_DEG
        if ok(hi):
            return hi, 0.0, (f"not bounded by the search: the ±{hi:g}° box (all of SO(3)) "
                             "has a dexterous workspace")
        iterations += 1                             # same resolution over a 120° bracket
    for _ in range(iterations):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo, hi - lo, ""


@_evaluator("orientation_capability")
def _capability(mech, ctx: Context) -> dict:
    req = ctx.evaluation.request
    oset = req["orientations"]
    samples = oset.samples if oset.kind == "box" else 7
    if supports_continuous(mech, req["constraints"]):
        # continuous positions, one compiled search, certified bracket (workspaces.optima)
        b = orientation_capability(mech, samples)
        a, upper, note = b.lower, b.upper, b.note
    else:
        a, bracket, note = capability(mech, req)
        upper = a + bracket
        note = "; ".join(filter(None, [note, "grid bisection (no continuous search for this "
                                       "family or these constraints)"]))
    if note:
        ctx.notes["orientation_capability"] = note
    out = {"orientation_capability": a, "orientation_capability_upper": _finite(upper),
           "orientation_capability_bracket": _finite(upper - a)}
    for name in ("orientation_capability_upper", "orientation_capability_bracket"):
        if out[name] is None:
            ctx.notes[name] = "no upper end: the search's largest box has a dexterous position"
    return out


@_evaluator("needed_stroke")
def _needed_stroke(mech, ctx: Context) -> dict:
    """The needed travel over continuous positions (:func:`pkmlab.workspaces.optima.
    stroke_needed`), the lower limit of the workspace's actuator window kept; null with a
    note for other families or constraints, or when no upper limit up to the search's cap
    gives a position."""
    req = ctx.evaluation.request
    names = metrics_of("needed_stroke")
    why = None
    cons = req["constraints"].resolved(mech)
    if cons.stroke is not True:          # the workspace's window: its lower limit is kept
        mech = dataclasses.replace(mech, stroke_window=cons.stroke)
    if not supports_continuous(mech, req["constraints"]):
        why = (f"no continuous search for family {mech.family!r} or constraints beyond the "
               "stroke")
    else:
        try:
            b = stroke_needed(mech, req["orientations"])
        except ParameterError as exc:
            why = f"no needed stroke: {exc}"
    if why is not None:
        for n in names:
            ctx.notes[n] = why
        return dict.fromkeys(names)
    q0 = float(mech.stroke[0])
    if b.note:
        ctx.notes["needed_stroke_bracket"] = b.note
    return {"needed_stroke": b.upper - q0, "needed_stroke_lower": b.lower - q0,
            "needed_stroke_bracket": b.width}


@_evaluator("dexterity")
def _dexterity(mech, ctx: Context) -> dict:
    plan, res = ctx.evaluation.dexterity, ctx.result
    length = dx.resolve_length(mech, plan.characteristic_length)
    if length.status == "fallback":
        raise NumericalError("characteristic length", length.reason)
    L = length.length
    ctx.L = L
    J0 = mech.jacobian(mech.nominal_pose)
    out = {"characteristic_length": float(L),
           "nominal_kappa": _finite(dx.condition_number(J0, L)[0])}
    if out["nominal_kappa"] is None:
        ctx.notes["nominal_kappa"] = "singular at the nominal pose"
    names = ("worst_kappa", "min_force", "singularity_free", "gci", "gci_std_error",
             "sampled_max_kappa", "sampled_min_force")
    if res.empty:
        for n in names:
            ctx.notes[n] = "workspace empty"
        out.update(dict.fromkeys(names))
        return out
    wc = dx.worst_case(res.mechanism, res, length, plan.force_limit)
    if wc.status != "ok":
        raise NumericalError("worst case over the workspace", wc.reason)
    out["worst_kappa"] = _finite(wc.worst_kappa)
    out["min_force"] = float(wc.min_force)
    out["singularity_free"] = float(not wc.singular)
    if wc.singular:
        ctx.notes["worst_kappa"] = (f"singular pose in the workspace or on its boundary: "
                                    f"{wc.reason}")
    # one Monte-Carlo sample serves every sampled statistic
    p, R = dx.aggregate.sample_poses(res, plan.gci_samples, np.random.default_rng(ctx.seed))
    g = dx.gci_monte_carlo(mech, res, length, poses=(p, R))
    out["gci"] = g.gci if g.ok else None
    out["gci_std_error"] = _finite(g.std_error) if g.ok else None
    out["sampled_max_kappa"] = _finite(g.sampled_max_kappa) if g.ok else None
    valid = mech.inverse((p, R)).valid
    F = dx.max_force_all_directions(mech.jacobian((p[valid], R[valid])), plan.force_limit,
                                    L=L)
    out["sampled_min_force"] = float(np.min(F)) if len(F) else None
    for n in ("gci", "gci_std_error", "sampled_max_kappa", "sampled_min_force"):
        if out[n] is None:
            ctx.notes.setdefault(n, "a sampled pose is singular" if g.ok and
                                 n == "sampled_max_kappa" else "no valid Monte-Carlo pose")
    return out


@_evaluator("trajectory")
def _trajectory(mech, ctx: Context) -> dict:
    plan = ctx.evaluation.trajectory
    t, X = paper_motion(mech, segment_time=plan.segment_time)
    rep = check_trajectory(mech, t, X, payload_mass_kg=plan.payload)
    margins = np.concatenate([rep.margin_low, rep.margin_high])
    out = {"paper_motion_fits": float(rep.fits),
           "paper_motion_margin": _finite(np.min(margins)) if np.all(np.isfinite(margins))
           else None}
    if out["paper_motion_margin"] is None:
        ctx.notes["paper_motion_margin"] = "a pose of the motion has no inverse kinematics"
    return out


@_evaluator("task")
def _task(mech, ctx: Context) -> dict:
    plan = ctx.evaluation.task
    m = task_margins(mech, plan.region, plan.orientations, plan.resolution)
    chk = m["check"]
    if chk.note:
        ctx.notes["task_contained"] = chk.note
    ctx.notes.update(m["notes"])
    return {"task_contained": float(chk.contained), "task_margin": m["margin_mm"],
            "task_orientation_margin": m["orientation_margin_deg"]}


@_evaluator("motions")
def _motions(mech, ctx: Context) -> dict:
    ev = ctx.evaluation
    body = ev.payload.for_mechanism(mech)
    ctx.dynamics = [inverse_dynamics(mech, m, body) for m in ev.motions.motions(mech)]
    bad = [r.first_problem() for r in ctx.dynamics if not np.all(r.ok)]
    out = {"motions_feasible": float(not bad)}
    if bad:
        ctx.notes["motions_feasible"] = bad[0]
    sums = [r.summary() for r in ctx.dynamics if np.any(r.ok)]
    rotary = mech.actuator_unit == "rad"
    for linear, turning, key in _MOTION_METRICS:
        name, other = (turning, linear) if rotary else (linear, turning)
        out[name] = float(max(np.max(s[key]) for s in sums)) if sums else None
        if not sums:
            ctx.notes[name] = "no feasible sample in any motion"
        if other != name:
            out[other] = None
            ctx.notes[other] = (f"{'rotary' if rotary else 'linear'} actuators: see {name}")
    return out


#: (linear actuators' metric, rotary actuators' metric, DynamicsResult.summary() key)
_MOTION_METRICS = (("peak_actuator_force", "peak_actuator_torque", "peak_force"),
                   ("rms_actuator_force", "rms_actuator_torque", "rms_force"),
                   ("peak_actuator_speed", "peak_actuator_angular_speed", "peak_speed"),
                   ("peak_actuator_power", "peak_actuator_power", "peak_power"))


@_evaluator("payload")
def _payload(mech, ctx: Context) -> dict:
    """Peak static servo torque over the workspace (:mod:`pkmlab.requirements.static`)."""
    res = ctx.result
    if mech.actuator_unit != "rad":
        ctx.notes["peak_servo_torque"] = ("prismatic actuators: no servo torque (forces: "
                                          "peak_actuator_force with evaluate.motions)")
        return {"peak_servo_torque": None}
    if res.empty:
        ctx.notes["peak_servo_torque"] = "workspace empty"
        return {"peak_servo_torque": None}
    loads = static_loads(res.mechanism, res, ctx.evaluation.payload.for_mechanism(mech))
    if loads.singular:
        ctx.notes["peak_servo_torque"] = "singular pose inside the workspace: unbounded torque"
        return {"peak_servo_torque": None}
    if loads.poses == 0:
        ctx.notes["peak_servo_torque"] = "no valid pose on the workspace grid"
        return {"peak_servo_torque": None}
    return {"peak_servo_torque": loads.peak}


@_evaluator("actuators")
def _actuators(mech, ctx: Context) -> dict:
    plan = ctx.evaluation.actuators
    name = ctx.choices.get("actuator", plan.default)
    spec = plan.catalogue[name]
    if (spec.kind == "rotary") != (mech.actuator_unit == "rad"):
        need = "rotary" if mech.actuator_unit == "rad" else "linear"
        raise ParameterError("evaluate.actuators", f"a {need} actuator for family "
                             f"{mech.family!r}", f"{spec.name} ({spec.kind})")
    f = actuator_fit(spec, ctx.dynamics)
    ctx.notes.update(f.notes)
    return {"actuators_fit": float(f.fits), "actuator_force_margin": f.force_margin,
            "actuator_speed_margin": f.speed_margin,
            "actuator_torque_speed_margin": f.torque_speed_margin,
            "actuator_stroke_margin": f.stroke_margin, "actuator_force_rating": spec.force}


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
    ``{"status", "reason", "metrics", "notes", "seconds"}`` (see the module's failure policy).

    Runs unchanged in a joblib worker or on a Dask cluster.
    """
    t0 = time.perf_counter()
    metrics: dict = {}
    notes: dict = {}
    try:
        mech = space.decode(design)
        metrics, notes = evaluate_mechanism(mech, evaluation, seed,
                                            space.evaluation_choices(design))
        status, reason = "ok", ""
    except ParameterError as exc:
        status, reason = "invalid", str(exc)
    except NumericalError as exc:
        status, reason = "failed", str(exc)
    except Exception as exc:  # noqa: BLE001 - recorded, then the driver stops the run
        status = "error"
        reason = f"{type(exc).__name__}: {exc}\n" + traceback.format_exc()
    return {"status": status, "reason": reason, "metrics": metrics, "notes": notes,
            "seconds": time.perf_counter() - t0}
