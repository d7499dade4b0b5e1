"""``dexterity``: κ, force and the global conditioning index over the workspace
(:mod:`pkmlab.dexterity`): worst cases over every voxel × orientation sample, sampled
statistics from one Monte-Carlo sample."""

from __future__ import annotations

from typing import Annotated, Any

import numpy as np
from pydantic import BaseModel, BeforeValidator, ConfigDict, Field, WithJsonSchema

from ... import dexterity as dx
from ... import limits
from ...dexterity.budget import WORST_BYTES_PER_SAMPLE, require_grid
from ...errors import NumericalError, ParameterError
from ...units import effort_limit, parse_length
from .registry import Evaluator, finite, metric, register_evaluator
from .worst_bound import worst_bound


def _auto_length(v: Any) -> float | None:
    if isinstance(v, str) and v.strip().lower() == "auto":
        return None
    x = parse_length(v, "")
    if not x > 0:
        raise ValueError(f"must be 'auto' or a length > 0 mm; got {v!r}")
    return x


class DexteritySpec(BaseModel):
    """Conditioning and force over the workspace: characteristic length, GCI samples, force
    limit."""

    model_config = ConfigDict(extra="forbid", frozen=True)

    characteristic_length: Annotated[float | None, BeforeValidator(_auto_length),
                                     WithJsonSchema({"anyOf": [{"const": "auto"},
                                                               {"type": "number"},
                                                               {"type": "string"}]})] = Field(
        None, description="'auto' (Angeles' length, the default) or a length > 0")
    gci_samples: int = Field(2000, ge=limits.GCI_SAMPLES[0], le=limits.GCI_SAMPLES[1])
    force_limit: float = Field(150.0, gt=0, allow_inf_nan=False,
                               description="linear actuator force limit (N)")
    torque_limit: float | None = Field(None, gt=0, allow_inf_nan=False,
                                       description="servo torque limit (N·m) of a rotary "
                                                   "family; no default")


_WORST = ("worst_kappa", "min_force", "singularity_free")
_OVER_WORKSPACE = ("worst_kappa", "min_force", "singularity_free", "gci", "gci_std_error",
                   "sampled_max_kappa", "sampled_min_force")


class Dexterity(Evaluator):
    name = "dexterity"
    block = DexteritySpec
    description = DexteritySpec.__doc__
    requires = frozenset({"workspace"})   # sized from the mobility (pkmlab.dexterity)
    after = ("workspace",)
    absent = None
    metrics = (
        metric("nominal_kappa", "", "exact",
               "κ of the homogenised Jacobian at the nominal pose"),
        metric("characteristic_length", "mm", "exact",
               "length L homogenising the Jacobian (Angeles' or the one given; null with a "
               "note for a mechanism without a free rotation, whose κ needs none)"),
        metric("worst_kappa", "", "worst-case",
               "largest κ over every voxel of the workspace and every end of its exact "
               "columns × every orientation sample (inf when a singular pose is found inside "
               "or on the boundary: stored as null with a note)"),
        metric("min_force", "N", "worst-case",
               "smallest force held in every direction over every voxel and column end × "
               "orientation sample (servos: with torque_limit; null without)"),
        metric("singularity_free", "", "flag",
               "0 when a singular pose is certified in the workspace or on its boundary (a "
               "singular voxel or column end, or a sign change of det J between neighbours); "
               "1 when none was found — a search, not a proof: a singularity between samples "
               "is not excluded"),
        metric("gci", "", "sampled",
               "global conditioning index: Monte-Carlo mean of 1/κ over the workspace "
               "(singular poses count 0); standard error in gci_std_error"),
        metric("gci_std_error", "", "sampled", "standard error of gci"),
        metric("sampled_max_kappa", "", "sampled",
               "largest κ among the GCI's random poses (a sample statistic; the poses are "
               "continuous, so it may exceed worst_kappa, the extreme over the grid samples)"),
        metric("sampled_min_force", "N", "sampled",
               "smallest all-direction force among the GCI's random poses (continuous "
               "poses: it may fall below min_force, the extreme over the grid samples)"),
    )

    def written(self, plan):
        L = plan.characteristic_length
        return {"characteristic_length": "auto" if L is None else f"{L:.12g} mm",
                "gci_samples": plan.gci_samples, "force_limit": plan.force_limit,
                **({} if plan.torque_limit is None else {"torque_limit": plan.torque_limit})}

    def check(self, plan, evaluation, mech) -> None:
        rotary = mech.actuator_unit == "rad"
        if rotary and "force_limit" in plan.model_fields_set:
            raise ParameterError("evaluate.dexterity.force_limit", "torque_limit (N·m) for a "
                                 "rotary family: its actuators are servos",
                                 f"{plan.force_limit:g} N")
        if not rotary and plan.torque_limit is not None:
            raise ParameterError("evaluate.dexterity.torque_limit", "force_limit (N) for a "
                                 "linear family", f"{plan.torque_limit:g} N·m")
        if plan.characteristic_length is not None and not mech.mobility.rotations:
            mob = mech.mobility
            raise ParameterError("evaluate.dexterity.characteristic_length",
                                 "'auto' for a mechanism without a free rotation (its κ needs "
                                 "no characteristic length)",
                                 f"{plan.characteristic_length:g} mm ({mob.name} mobility)")

    def compute(self, mech, ctx) -> dict:
        plan, res = ctx.evaluation.dexterity, ctx.result
        length = _length(mech, plan)
        L = length.length
        ctx.L = L
        J0 = mech.jacobian(mech.nominal_pose)
        out = {"characteristic_length": None if L is None else float(L),
               "nominal_kappa": finite(dx.condition_number(J0, length)[0])}
        if L is None:
            ctx.notes["characteristic_length"] = f"not applicable: {length.reason}"
        if out["nominal_kappa"] is None:
            ctx.notes["nominal_kappa"] = "singular at the nominal pose"
        if res.empty:
            for n in _OVER_WORKSPACE:
                ctx.notes[n] = "workspace empty"
            out.update(dict.fromkeys(_OVER_WORKSPACE))
            return out
        out.update(worst_metrics(mech, ctx, length))
        # one Monte-Carlo sample serves every sampled statistic
        p, R = dx.aggregate.sample_poses(res, plan.gci_samples,
                                         np.random.default_rng(ctx.seed))
        g = dx.gci_monte_carlo(mech, res, length, poses=(p, R))
        out["gci"] = g.gci if g.ok else None
        out["gci_std_error"] = finite(g.std_error) if g.ok else None
        out["sampled_max_kappa"] = finite(g.sampled_max_kappa) if g.ok else None
        if SAMPLED_FORCE in ctx.evaluation.deferred:    # a ladder's coarse rung (.ladder)
            out[SAMPLED_FORCE] = None
        else:
            # the GCI found no singular pose among these (same poses, J and L): the force's
            # singular rule need not compute the singular values again
            out[SAMPLED_FORCE] = _sampled_force(mech, ctx, L, p, R, g.ok and g.singular == 0)
        for n in ("gci", "gci_std_error", "sampled_max_kappa", SAMPLED_FORCE):
            if out[n] is None and not (n == SAMPLED_FORCE and n in ctx.evaluation.deferred):
                ctx.notes.setdefault(n, "a sampled pose is singular" if g.ok and
                                     n == "sampled_max_kappa" else "no valid Monte-Carlo pose")
        return out


#: the metric a tolerance ladder's coarse rung can leave to the re-certification when no
#: objective or constraint reads it (:func:`pkmlab.study.ladder.deferred`)
SAMPLED_FORCE = "sampled_min_force"


def _sampled_force(mech, ctx, L, p, R, regular: bool) -> float | None:
    """``sampled_min_force`` over the Monte-Carlo poses ``(p, R)`` (and a servo's note);
    ``regular``: the GCI over the same poses, J and L counted no singular pose (the force's
    singular rule then skips its singular values: the same forces)."""
    plan = ctx.evaluation.dexterity
    effort = effort_limit(mech.actuator_unit, plan.force_limit, plan.torque_limit)
    valid = mech.inverse((p, R)).valid
    J = mech.jacobian((p[valid], R[valid]))
    F = dx.max_force_all_directions(J, plan.force_limit if effort is None else effort, L=L,
                                    mobility=mech.mobility,
                                    singular=np.zeros(len(J), bool) if regular else None)
    if effort is None:
        ctx.notes[SAMPLED_FORCE] = _SERVO
    return float(np.min(F)) if len(F) and effort is not None else None


def sampled_force(mech, ctx) -> dict:
    """``sampled_min_force`` (with its note) as :meth:`Dexterity.compute` writes it, after the
    workspace evaluator (``ctx.result``): a tolerance ladder's re-certification computes it
    when its coarse rung left it (:data:`SAMPLED_FORCE`). The same Monte-Carlo poses (the
    seed's first draw), the force's full singular rule."""
    plan, res = ctx.evaluation.dexterity, ctx.result
    if res.empty:
        ctx.notes[SAMPLED_FORCE] = "workspace empty"
        return {SAMPLED_FORCE: None}
    length = _length(mech, plan)
    p, R = dx.aggregate.sample_poses(res, plan.gci_samples, np.random.default_rng(ctx.seed))
    value = _sampled_force(mech, ctx, length.length, p, R, False)
    if value is None:
        ctx.notes.setdefault(SAMPLED_FORCE, "no valid Monte-Carlo pose")
    return {SAMPLED_FORCE: value}


_SERVO = ("servos need evaluate.dexterity.torque_limit (N·m): a linear force limit is never "
          "applied to a servo")


def _length(mech, plan):
    length = dx.resolve_length(mech, plan.characteristic_length)
    if length.status == "fallback":
        raise NumericalError("characteristic length", length.reason)
    return length


def worst_metrics(mech, ctx, length=None) -> dict:
    """``worst_kappa``, ``min_force`` and ``singularity_free`` (with their notes) as
    :meth:`Dexterity.compute` writes them — exact, or on a tolerance ladder's coarse rung the
    certified bounds of :mod:`.worst_bound` — after the workspace evaluator (``ctx.result``).
    A ladder re-certifies these alone (:mod:`pkmlab.study.ladder`)."""
    plan, res = ctx.evaluation.dexterity, ctx.result
    length = _length(mech, plan) if length is None else length
    if res.empty:
        for n in _WORST:
            ctx.notes[n] = "workspace empty"
        return dict.fromkeys(_WORST)
    require_grid(res, "evaluate.workspace.resolution", WORST_BYTES_PER_SAMPLE)
    effort = effort_limit(mech.actuator_unit, plan.force_limit, plan.torque_limit)
    force = plan.force_limit if effort is None else effort
    if ctx.evaluation.worst_case_exact:
        out = _exact_worst(res, length, force, effort, ctx)
    else:       # a tolerance ladder's coarse rung: certified bounds (study.ladder)
        out = _worst_bounds(res, length, force, effort, ctx)
    if effort is None:
        ctx.notes["min_force"] = _SERVO
    return out


def _exact_worst(res, length, force, effort, ctx) -> dict:
    wc = dx.worst_case(res.mechanism, res, length, force)
    if wc.status != "ok":
        raise NumericalError("worst case over the workspace", wc.reason)
    out = {"worst_kappa": finite(wc.worst_kappa),
           "min_force": float(wc.min_force) if effort is not None else None,
           "singularity_free": float(not wc.singular)}
    if wc.singular:
        ctx.notes["worst_kappa"] = (f"singular pose in the workspace or on its boundary: "
                                    f"{wc.reason}")
    return out


def _worst_bounds(res, length, force, effort, ctx) -> dict:
    """The coarse rung: ``worst_kappa`` a certified lower bound, ``min_force`` an upper one,
    ``singularity_free`` 0 only when a sample of the subset is singular (a certificate), else
    1 (an upper bound: the exact pass may find one)."""
    b = worst_bound(res.mechanism, res, length, force)
    out = {"worst_kappa": finite(b.kappa_lower),
           "min_force": finite(b.force_upper) if effort is not None else None,
           "singularity_free": float(not b.singular)}
    for n in ("worst_kappa", "min_force", "singularity_free"):
        ctx.notes[n] = b.describe()
    if b.singular:
        ctx.notes["worst_kappa"] = f"a singular sample: {b.describe()}"
    return out


register_evaluator(Dexterity())
