"""Any evaluated candidate of a study, feasible or not: its record, its mechanism and what the
study knows of its masses, for ``pkmlab export RESULTS --seq N`` and the study export."""

from __future__ import annotations

from ..errors import ParameterError
from .definition import Study
from .run import BASELINE

__all__ = ["candidate", "candidate_mechanism", "mass_model", "mechanism_spec"]


def candidate(records: list[dict], seq: int) -> dict:
    """The record with sequence number ``seq`` (as in evaluations.csv)."""
    for r in records:
        if r["seq"] == seq:
            return r
    seqs = sorted(r["seq"] for r in records)
    raise ParameterError("--seq", f"a candidate's number, {seqs[0]}..{seqs[-1]}" if seqs
                         else "a candidate's number (the store is empty)", seq)


def mechanism_spec(study: Study, record: dict, name: str | None = None):
    """The YAML model of ``record``'s mechanism (the baseline's for the baseline row)."""
    spec = study.space.spec_of(None if record["params"] == BASELINE else record["params"])
    return spec.model_copy(update={"name": name}) if name else spec


def candidate_mechanism(study: Study, record: dict, name: str | None = None):
    return mechanism_spec(study, record, name).build()


def mass_model(study: Study, link_diameter: float | None = None):
    """A :class:`pkmlab.export.model.MassModel` from the study's payload block (platform and
    payload as one body; each leg's mass) and its workspace's link diameter, else the
    documented defaults."""
    from ..export.model import MassModel

    ev = study.evaluation
    if link_diameter is None:
        link_diameter = getattr(getattr(ev.workspace, "constraints", None), "link_diameter",
                                None)
    plan = getattr(ev, "payload", None)
    if plan is None:
        return MassModel(link_diameter=link_diameter)
    from ..config import validate_model
    from ..requirements.spec import PayloadSpec

    spec = validate_model(PayloadSpec, plan.source, prefix="evaluate.payload.")
    leg = None if spec.legs is None else float(spec.legs.mass)
    return MassModel(link_diameter=link_diameter, platform=plan.body, leg_mass=leg,
                     source=f"the study's payload block (platform and payload "
                     f"{plan.body.mass:g} kg" + ("" if leg is None else
                                                f"; {leg:g} kg per leg over its links")
                     + ")")
