"""Study files: the YAML schema (pydantic) and :func:`load_study`, which builds the typed
:class:`~pkmlab.study.definition.Study` once.

Everything ``pkmlab validate`` accepts, ``pkmlab run`` runs: every check of a request
(workspace kinds and ranges, lengths, metric names, duplicate objectives) happens here, at
load, through the same functions the library uses. Errors are
:class:`~pkmlab.errors.ParameterError` naming the field path.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from ..config import mechanism_spec, read_yaml, validate_model
from ..errors import ParameterError, Shown
from ..mechanisms import REGISTRY
from ..units import parse_angle, parse_length
from .definition import Constraint, Evaluation, Objective, Study
from .evaluators import EVALUATORS, check_requirements
from .ladder import ladder_from_spec
from .metrics import KIND_VOLUMES, METRICS
from .optimisers import check_memory
from .space import Derived, DesignSpace, Expression, Variable, get_path, parse_path

__all__ = ["load_study", "study_from_mapping", "StudySpec", "study_schema", "family_aliases"]

def family_aliases(family: str) -> dict[str, tuple[str, str]]:
    """Named design variables of a family: its class's ``design_aliases`` (path in the YAML
    model, quantity), built-in or plugin alike."""
    cls = REGISTRY.get(family)
    out = dict(getattr(cls, "design_aliases", None) or {})
    mob = getattr(cls, "mobility", None)
    if mob is not None and "z" in getattr(mob, "coordinates", ()) and "home_height" not in out:
        # the nominal (home) pose's height: the frame of the task and the motions
        out["home_height"] = ("nominal_pose[2]", "length")
    return out


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)


class DesignVariableSpec(_Model):
    """One design variable: a continuous or integer range, or a list of choices."""

    low: Any = Field(None, description="lower bound, with units ('110 mm', '5 deg')")
    high: Any = Field(None, description="upper bound, with units")
    choices: list[Any] | None = Field(None, description="discrete choices instead of a range")
    type: Literal["continuous", "integer", "choice"] | None = None
    path: str | None = Field(None, description="mechanism field, e.g. generator.base_radii[1]; "
                             "none for a free parameter used by 'derived'")
    quantity: Literal["length", "angle", "number", "text"] | None = None
    target: Literal["actuator"] | None = Field(None, description="'actuator': the choices "
                                               "are catalogue entries of evaluate.actuators "
                                               "(not a mechanism field)")
    levels: int = Field(5, ge=2, le=1000, description="grid optimiser: values per variable")


class OptimizerSpec(_Model):
    method: Literal["grid", "sobol", "lhs", "nsga2", "de"]
    samples: int = Field(64, ge=1, le=10_000_000, description="sobol / lhs designs")
    population: int = Field(32, ge=4, le=100_000, description="nsga2 / de population")
    generations: int = Field(10, ge=1, le=100_000, description="nsga2 / de generations")


class MechanismSource(_Model):
    """A mechanism file plus overrides, or (``inline``) the mechanism mapping itself."""

    file: str | None = Field(None, description="mechanism YAML, relative to the study file")
    overrides: dict[str, Any] = Field(default_factory=dict)
    inline: dict[str, Any] | None = Field(None, description="a mechanism mapping (family, "
                                          "generator, ...) instead of a file")


class StudySpec(_Model):
    """A design study file (docs/studies.md): what to vary, evaluate, optimise and keep."""

    study: str = Field(pattern=r"^[A-Za-z0-9_][A-Za-z0-9._-]*$", max_length=100)
    description: str = ""
    mechanism: MechanismSource
    design: dict[str, DesignVariableSpec] = Field(min_length=1)
    derived: dict[str, Any] = Field(default_factory=dict, description="mechanism fields "
                                    "computed from the variables: {alias or path: expression}")
    evaluate: dict[str, Any] = Field(description="what to compute for each candidate: one "
                                     "block per evaluator ('pkmlab metrics' lists their "
                                     "metrics)")
    objectives: list[dict[Literal["maximize", "minimize"], str]] = Field(min_length=1)
    constraints: list[dict[str, Any]] = Field(default_factory=list)
    optimizer: OptimizerSpec
    seed: int = Field(0, ge=0, le=2**32 - 1)
    output: str | None = Field(None, description="output folder, relative to the study file "
                               "(default results/<study> in the working directory)")
    top: int = Field(5, ge=0, le=100, description="Pareto designs exported in full")
    tolerance_ladder: dict[str, Any] | None = Field(
        None, description="optimise at coarse certified tolerances, re-certify at the fine "
        "ones: {coarse: {angle: 0.1 deg, length: 0.1 mm, worst_case: bound}, prune: true} "
        "(docs/studies.md)")
    provenance: dict[str, Any] | None = Field(None, description="written by pkmlab into "
                                              "study.resolved.yaml; ignored on load")


def study_schema() -> dict:
    """JSON Schema of the study file (for editors); metric names are enumerated."""
    schema = StudySpec.model_json_schema()
    schema["properties"]["evaluate"] = _evaluate_schema(schema.setdefault("$defs", {}))
    names = sorted(METRICS)
    schema["properties"]["objectives"]["items"] = {
        "type": "object", "minProperties": 1, "maxProperties": 1,
        "properties": {s: {"enum": names} for s in ("maximize", "minimize")},
        "additionalProperties": False}
    return schema


def _evaluate_schema(defs: dict) -> dict:
    """The ``evaluate`` mapping: one property per registered block, typed by its model."""
    from pydantic import TypeAdapter

    props = {}
    for name, ev in EVALUATORS.items():
        if ev.block is None:
            continue
        sub = TypeAdapter(ev.block).json_schema(ref_template="#/$defs/{model}")
        for k, d in sub.pop("$defs", {}).items():
            if defs.setdefault(k, d) != d:
                raise ValueError(f"evaluate.{name}: two block models named {k!r}")
        if ev.description and "description" not in sub:
            sub["description"] = ev.description
        props[name] = {"anyOf": [sub, {"type": "null"}]}
    return {"type": "object", "description": StudySpec.model_fields["evaluate"].description,
            "properties": props, "additionalProperties": False}


# ---- building the typed study -------------------------------------------------------------


def _merge(base: dict, over: dict) -> dict:
    out = dict(base)
    for k, v in over.items():
        out[k] = _merge(out[k], v) if isinstance(v, dict) and isinstance(out.get(k), dict) \
            else v
    return out


#: mechanism fields no design variable or derived field may set (a candidate would be
#: evaluated as the baseline's family, and its exported YAML would not load)
IDENTITY = ("family", "name")


def _target(name: str, where: str, path: str | None, family: str, spec) -> tuple | None:
    alias = family_aliases(family).get(name)
    text = path or (alias[0] if alias else None)
    if text is None:
        return None
    try:
        parts = parse_path(text)
    except KeyError:
        parts = None
    if parts and parts[0] in IDENTITY:
        raise ParameterError(where, "a geometry field (the mechanism's family and name are "
                             "fixed by the study: give another mechanism file instead)", text)
    if parts and parts[0] == "nominal_pose" and getattr(spec, "nominal_pose", 0) is None:
        # no nominal pose in the file: the family's default (level, centred) is filled in
        # per candidate before this coordinate is set (DesignSpace.spec_of)
        if len(parts) != 2 or not isinstance(parts[1], int) or not 0 <= parts[1] < 6:
            raise ParameterError(where, "one coordinate of the nominal pose: nominal_pose[0] "
                                 "… nominal_pose[5] (x, y, z in mm, θx, θy, θz)", text)
        return parts
    try:
        if parts is None:
            raise KeyError(text)
        leaf = get_path(spec, parts)
    except KeyError:
        raise ParameterError(where, "a field present in the mechanism spec (a generator "
                             "field, stroke[0], link_length, ...)", text) from None
    if isinstance(leaf, list | dict) or hasattr(leaf, "model_fields"):
        raise ParameterError(where, "a single value (index a list: base_radii[1])", text)
    return parts


def _variable(name: str, v: DesignVariableSpec, family: str, spec,
              evaluation: Evaluation) -> Variable:
    field = f"design.{name}"
    if v.target == "actuator":
        acts = evaluation.actuators
        if acts is None or len(acts.catalogue) < 1:
            raise ParameterError(f"{field}.target", "used with an evaluate.actuators block "
                                 "that names a catalogue", v.target)
        if v.path is not None or v.quantity not in (None, "text") or not v.choices \
                or v.type not in (None, "choice"):
            raise ParameterError(field, "'choices' of catalogue entry names (no path, range "
                                 "or quantity)", v.model_dump(exclude_none=True))
        for c in v.choices:
            if c not in acts.catalogue:
                raise ParameterError(f"{field}.choices", f"catalogue entries "
                                     f"{sorted(acts.catalogue)}", c)
        return Variable(name, None, "text", "choice", choices=tuple(v.choices),
                        role="actuator", baseline=acts.default)
    alias = family_aliases(family).get(name)
    target = _target(name, f"{field}.path", v.path, family, spec)
    quantity = v.quantity or (alias[1] if alias else None)
    if target is None and alias is None and v.path is None and quantity not in (None,
                                                                                 "number"):
        raise ParameterError(f"{field}.path", "given for a non-number variable", None)
    if target is None and quantity is None:
        raise ParameterError(field, f"a known variable of family {family!r} "
                             f"{sorted(family_aliases(family))}, one with 'path' and "
                             "'quantity', or a free parameter with 'quantity: number'", name)
    if quantity is None:
        raise ParameterError(f"{field}.quantity", "one of ['length', 'angle', 'number', "
                             "'text']", None)
    kind = v.type or ("choice" if v.choices is not None else "continuous")
    if quantity == "text" and kind != "choice":
        raise ParameterError(f"{field}.choices", "a list of choices (a text variable has no "
                             "range)", None)

    def conv(x, which):
        where = f"{field}.{which}"
        if quantity == "text":
            if not isinstance(x, str):
                raise ParameterError(where, "a text choice", x)
            return x
        if quantity == "number":
            if isinstance(x, bool) or not isinstance(x, int | float) or x != x \
                    or abs(x) == float("inf"):
                raise ParameterError(where, "a finite number", x)
            return float(x)
        parse = parse_length if quantity == "length" else parse_angle
        try:
            return parse(x, where)
        except ParameterError as exc:
            raise ParameterError(where, exc.allowed, x) from None

    if kind == "choice":
        if not v.choices:
            raise ParameterError(f"{field}.choices", "a non-empty list", v.choices)
        return Variable(name, target, quantity, "choice",
                        choices=tuple(conv(c, "choices") for c in v.choices))
    for which in ("low", "high"):
        if getattr(v, which) is None:
            raise ParameterError(f"{field}.{which}", "given (a bound of the range)", None)
    lo, hi = conv(v.low, "low"), conv(v.high, "high")
    if not lo < hi:
        raise ParameterError(field, "low < high", f"low {v.low!r}, high {v.high!r}")
    if kind == "integer" and (lo != int(lo) or hi != int(hi)):
        raise ParameterError(field, "integer bounds for an integer variable", [v.low, v.high])
    return Variable(name, target, quantity, kind, lo, hi, levels=v.levels)


def _check_actuator_choices(variables, evaluation: Evaluation, mech) -> None:
    """Every catalogue entry a design variable chooses drives this mechanism's actuators
    (a rotary servo on a linear-actuator family would fail every candidate that picks it)."""
    rotary = mech.actuator_unit == "rad"
    for v in variables:
        for i, c in enumerate(v.choices if v.role == "actuator" else ()):
            kind = evaluation.actuators.catalogue[c].kind
            if (kind == "rotary") != rotary:
                need = "rotary" if rotary else "linear"
                raise ParameterError(f"design.{v.name}.choices[{i}]", f"a {need} actuator "
                                     f"(family {mech.family!r} has {need} actuators)",
                                     Shown(f"{c!r} ({kind})"))


def _metric(name: Any, where: str, evaluation: Evaluation) -> str:
    if not isinstance(name, str) or name not in METRICS:
        import difflib

        near = difflib.get_close_matches(str(name), list(METRICS), n=3, cutoff=0.6)
        hint = (f"did you mean {' or '.join(repr(n) for n in near)}? " if near else "")
        raise ParameterError(where, f"{hint}one of {sorted(METRICS)}", name)
    if name in KIND_VOLUMES and evaluation.workspace is not None \
            and evaluation.workspace.kind != KIND_VOLUMES[name]:
        raise ParameterError(where, f"the volume of the evaluated kind "
                             f"('{evaluation.workspace.kind}_volume')", name)
    if name not in evaluation.metrics:
        need = EVALUATORS[METRICS[name].evaluator].hint()
        raise ParameterError(where, f"a metric the evaluation computes (add {need})", name)
    return name


def _evaluation(data: dict, base: Path, mech) -> Evaluation:
    """The ``evaluate`` mapping → :class:`Evaluation`: each block built by its evaluator
    (:mod:`.evaluators`), then checked against what ``mech`` (the baseline) offers."""
    from difflib import get_close_matches

    from ..yamlio import where

    blocks = [n for n, ev in EVALUATORS.items() if ev.block is not None]
    for key in data:
        if key not in blocks:
            close = get_close_matches(str(key), blocks, n=1, cutoff=0.6)
            hint = f"did you mean {close[0]!r}? " if close else ""
            raise ParameterError(f"evaluate.{key}", f"a known key ({hint}known keys: "
                                 f"{', '.join(sorted(blocks))})", Shown(repr(key)),
                                 where=where(("evaluate", key)))
    plans = {}
    for name in blocks:
        if data.get(name) is not None:
            plans[name] = EVALUATORS[name].plan(data[name], base)
    ws = plans.get("workspace")
    evaluation = Evaluation(plans, None if ws is None else ws.build())
    check_requirements(evaluation, mech, data)
    return evaluation


def study_from_mapping(data: Any, base: Path | None = None,
                       source: Path | None = None) -> Study:
    """A study mapping (a parsed study file) → :class:`Study`; relative paths resolve
    against ``base`` (the study file's folder)."""
    if not isinstance(data, dict):
        raise ParameterError("(study)", "a mapping with study, mechanism, design, evaluate, "
                             "objectives, optimizer", type(data).__name__)
    spec = validate_model(StudySpec, data)
    base = Path(".") if base is None else base
    src = spec.mechanism
    if (src.file is None) == (src.inline is None):
        raise ParameterError("mechanism", "exactly one of 'file' (with optional 'overrides') "
                             "or 'inline'", sorted(k for k in ("file", "inline")
                                                   if getattr(src, k) is not None))
    if src.file is not None:
        mech_path = (base / src.file)
        if not mech_path.is_file():
            raise ParameterError("mechanism.file", "an existing mechanism YAML file", src.file)
        mech_data = read_yaml(mech_path, "mechanism")
        if not isinstance(mech_data, dict):
            raise ParameterError("mechanism.file", "a mechanism YAML mapping", src.file)
    else:
        mech_data = dict(src.inline)
    try:
        mech_spec = mechanism_spec(_merge(mech_data, src.overrides))
        baseline = mech_spec.build()
    except ParameterError as exc:     # keeps the position in the file the value came from
        raise ParameterError(f"mechanism.{exc.field}", exc.allowed, exc.got,
                             where=exc.where) from None
    family = mech_spec.family
    evaluation = _evaluation(spec.evaluate, base, baseline)
    variables = tuple(_variable(n, v, family, mech_spec, evaluation)
                      for n, v in spec.design.items())
    names = {v.name for v in variables}
    _check_actuator_choices(variables, evaluation, baseline)
    derived = []
    for key, text in spec.derived.items():
        where = f"derived.{key}"
        if key in names:
            raise ParameterError(where, "a field no design variable sets", key)
        target = _target(key, where, None if key in family_aliases(family) else key, family,
                         mech_spec)
        leaf = get_path(mech_spec, target)
        if isinstance(leaf, str | bool) or not isinstance(leaf, int | float | None):
            raise ParameterError(where, "a number field (a derived field takes the value of an "
                                 "arithmetic expression)", Shown(f"{key} = {leaf!r}"))
        texts = {v.name for v in variables if v.quantity == "text"}
        derived.append(Derived(key, target, Expression.parse(text, where, names - texts,
                                                             texts)))
    written = [v.target for v in variables if v.target is not None] + \
        [d.target for d in derived]
    if len(set(written)) != len(written):
        raise ParameterError("design", "variables and derived fields that each set a "
                             "different mechanism field", "a field set twice")
    used = {n for d in derived for n in d.expression.names}
    if sum(v.role == "actuator" for v in variables) > 1:
        raise ParameterError("design", "at most one variable with target: actuator",
                             [v.name for v in variables if v.role == "actuator"])
    for v in variables:
        if v.target is None and v.role == "mechanism" and v.name not in used:
            raise ParameterError(f"design.{v.name}", "a mechanism field (alias or 'path') or "
                                 "a parameter used by 'derived'", v.name)
    objectives = []
    for i, o in enumerate(spec.objectives):
        if len(o) != 1:
            raise ParameterError(f"objectives[{i}]", "one of {maximize: metric} or "
                                 "{minimize: metric}", o)
        (sense, name), = o.items()
        objectives.append(Objective(_metric(name, f"objectives[{i}].{sense}", evaluation),
                                    sense))
        if any(ob.metric == name for ob in objectives[:-1]):
            raise ParameterError(f"objectives[{i}].{sense}", "a metric not already an "
                                 "objective", name)
    constraints = []
    for i, c in enumerate(spec.constraints):
        if not isinstance(c, dict) or len(c) != 1:
            raise ParameterError(f"constraints[{i}]", "{metric: {min: x} | {max: x}} or "
                                 "{metric: true}", c)
        (name, rule), = c.items()
        _metric(name, f"constraints[{i}]", evaluation)
        if rule is True:
            if METRICS[name].statistic != "flag":
                raise ParameterError(f"constraints[{i}].{name}", "{min: x} or {max: x} ("
                                     "'true' is for flags such as singularity_free)", rule)
            rule = {"min": 1.0}
        if not isinstance(rule, dict) or not rule or set(rule) - {"min", "max"}:
            raise ParameterError(f"constraints[{i}].{name}", "{min: x}, {max: x} or true",
                                 rule)
        for k, x in rule.items():
            if isinstance(x, bool) or not isinstance(x, int | float) or x != x:
                raise ParameterError(f"constraints[{i}].{name}.{k}", "a number", x)
        if "min" in rule and "max" in rule and rule["min"] > rule["max"]:
            raise ParameterError(f"constraints[{i}].{name}", "min <= max", rule)
        constraints.append(Constraint(name, rule.get("min"), rule.get("max")))
    opt = spec.optimizer
    if opt.method == "de" and len(objectives) != 1:
        raise ParameterError("optimizer.method", "'nsga2', 'grid', 'sobol' or 'lhs' for "
                             "several objectives ('de' takes one)", opt.method)
    if opt.method in ("nsga2", "de") and any(v.kind == "choice" for v in variables):
        raise ParameterError("optimizer.method", "'grid', 'sobol' or 'lhs' with choice "
                             "variables", opt.method)
    check_memory(len(variables), opt)
    output = Path("results") / spec.study if spec.output is None else base / spec.output
    return Study(name=spec.study, description=spec.description,
                 space=DesignSpace(mech_spec, variables, tuple(derived)),
                 evaluation=evaluation, objectives=tuple(objectives),
                 constraints=tuple(constraints), optimizer=opt, seed=spec.seed,
                 output=output, top=spec.top, source=source,
                 tolerance_ladder=ladder_from_spec(spec.tolerance_ladder, evaluation))


def load_study(source: str | Path) -> Study:
    """Validate a study file and build its :class:`Study` (raises ParameterError)."""
    path = Path(source)
    return study_from_mapping(read_yaml(path, "study"), path.parent, path)
