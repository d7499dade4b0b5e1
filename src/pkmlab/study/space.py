"""The design space: variables in internal units, derived fields, and decoding into mechanisms.

A design is a dict ``{variable name: value}`` in internal units (mm, rad, plain numbers or a
text choice). :meth:`DesignSpace.decode` writes each variable (and each derived field, an
arithmetic expression of the variables) into the typed mechanism spec and builds the
:class:`~pkmlab.mechanisms.Mechanism` directly: no YAML is written or parsed.
"""

from __future__ import annotations

import ast
import itertools
import math
import operator
import re
from collections import Counter
from dataclasses import dataclass

import numpy as np
from pydantic import BaseModel

from ..errors import ParameterError, Shown
from ..mechanisms import Mechanism

__all__ = ["Variable", "Derived", "DesignSpace", "Expression", "parse_path", "get_path",
           "with_path"]


# ---- paths into a typed spec ---------------------------------------------------------------------


def parse_path(path: str) -> tuple:
    """``"generator.base_radii[1]"`` → ``("generator", "base_radii", 1)``."""
    parts: list = []
    for piece in path.split("."):
        m = re.fullmatch(r"([A-Za-z_][A-Za-z0-9_]*)((?:\[\d+\])*)", piece)
        if not m:
            raise KeyError(path)
        parts.append(m.group(1))
        parts += [int(i) for i in re.findall(r"\[(\d+)\]", m.group(2))]
    return tuple(parts)


def get_path(node, parts: tuple):
    """The value at ``parts`` in a pydantic model / list tree (KeyError if absent)."""
    for p in parts:
        if isinstance(node, BaseModel) and isinstance(p, str) and p in type(node).model_fields:
            node = getattr(node, p)
        elif isinstance(node, list) and isinstance(p, int) and p < len(node):
            node = node[p]
        else:
            raise KeyError(p)
    return node


def with_path(node, parts: tuple, value):
    """A copy of ``node`` with ``parts`` set to ``value`` (models copied, never mutated)."""
    if not parts:
        return value
    head, rest = parts[0], parts[1:]
    if isinstance(node, BaseModel):
        return node.model_copy(update={head: with_path(getattr(node, head), rest, value)})
    new = list(node)
    new[head] = with_path(node[head], rest, value)
    return new


# ---- derived fields: a small, safe arithmetic language -----------------------------------

_BINARY = {ast.Add: operator.add, ast.Sub: operator.sub, ast.Mult: operator.mul,
           ast.Div: operator.truediv}
_UNARY = {ast.USub: operator.neg, ast.UAdd: operator.pos}
#: function name → (callable, fewest arguments, most arguments)
_FUNCTIONS = {"min": (min, 2, 16), "max": (max, 2, 16), "abs": (abs, 1, 1),
              "sqrt": (math.sqrt, 1, 1), "sin": (math.sin, 1, 1), "cos": (math.cos, 1, 1),
              "tan": (math.tan, 1, 1), "atan2": (math.atan2, 2, 2)}
_ALLOWED = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Constant, ast.Call, ast.Load, ast.Name,
            ast.Pow, *_BINARY, *_UNARY)
#: Constants an expression may use; values are internal units (mm, rad).
CONSTANTS = {"pi": math.pi, "deg": math.pi / 180.0, "rad": 1.0, "mm": 1.0, "cm": 10.0,
             "m": 1000.0, "inch": 25.4}
#: longest expression (characters), deepest nesting, largest constant exponent magnitude
MAX_CHARS = 1000
MAX_DEPTH = 32
MAX_EXPONENT = 64.0
_WHAT = ("an arithmetic expression (+ - * / **, numbers, design variables, "
         + ", ".join(sorted(_FUNCTIONS)) + ")")


def _depth(node, level: int = 0) -> int:
    """Nesting depth of ``node``, stopping as soon as it exceeds :data:`MAX_DEPTH`."""
    if level > MAX_DEPTH:
        return level
    return max([level] + [_depth(c, level + 1) for c in ast.iter_child_nodes(node)])


def _constant(node) -> float | None:
    """The value of a constant exponent (a number, a sign, a named constant), else None."""
    if isinstance(node, ast.Constant) and isinstance(node.value, int | float):
        return float(node.value)
    if isinstance(node, ast.UnaryOp) and isinstance(node.op, ast.USub | ast.UAdd):
        v = _constant(node.operand)
        return None if v is None else (-v if isinstance(node.op, ast.USub) else v)
    if isinstance(node, ast.Name) and node.id in CONSTANTS:
        return CONSTANTS[node.id]
    return None


@dataclass(frozen=True)
class Expression:
    """An arithmetic expression of design variables, evaluated in internal units (mm, rad):
    ``base_ratio * base_outer_radius``, ``platform_rotation + 10 * deg``.

    Checked at load: at most :data:`MAX_CHARS` characters and :data:`MAX_DEPTH` levels of
    nesting, known names only (number variables, constants; text variables refused), each
    function called with its number of positional arguments, every exponent a constant of
    magnitude at most :data:`MAX_EXPONENT`. Evaluated in floating point (never big integers):
    a result that is not a finite real number makes the design invalid, with the reason."""

    text: str
    names: tuple[str, ...]

    @classmethod
    def parse(cls, text: str, field: str, known: set[str],
              texts: frozenset[str] | set[str] = frozenset()) -> Expression:
        """``known``: the number variables; ``texts``: the text variables (refused)."""
        if not isinstance(text, str | int | float) or isinstance(text, bool):
            raise ParameterError(field, "an arithmetic expression of design variables", text)
        text = str(text)
        if len(text) > MAX_CHARS:
            raise ParameterError(field, f"an expression of at most {MAX_CHARS} characters",
                                 Shown(f"{len(text)} characters"))
        try:
            tree = ast.parse(text, mode="eval")
        except (SyntaxError, ValueError):
            raise ParameterError(field, _WHAT, text) from None
        except (RecursionError, MemoryError):
            raise ParameterError(field, f"an expression nested at most {MAX_DEPTH} deep",
                                 Shown("deeper")) from None
        if _depth(tree) > MAX_DEPTH:
            raise ParameterError(field, f"an expression nested at most {MAX_DEPTH} deep",
                                 Shown(f"more than {MAX_DEPTH} levels"))
        names = []
        called = {id(n.func) for n in ast.walk(tree) if isinstance(n, ast.Call)}
        for node in ast.walk(tree):
            if isinstance(node, ast.Name):
                if node.id in texts:
                    raise ParameterError(field, "an expression of number variables (arithmetic "
                                         "on a text variable is not defined)", node.id)
                if node.id in _FUNCTIONS and id(node) not in called:
                    raise ParameterError(field, f"a call of {node.id} with its arguments "
                                         f"({node.id}(...))", text)
                if id(node) in called and node.id not in _FUNCTIONS:
                    raise ParameterError(field, f"calls of {sorted(_FUNCTIONS)} only", text)
                if node.id not in known and node.id not in CONSTANTS \
                        and node.id not in _FUNCTIONS:
                    raise ParameterError(field, f"an expression of the design variables "
                                         f"{sorted(known)} and constants {sorted(CONSTANTS)}",
                                         node.id)
                if node.id in known:
                    names.append(node.id)
            elif not isinstance(node, _ALLOWED) or (
                    isinstance(node, ast.Constant) and (isinstance(node.value, bool)
                                                        or not isinstance(node.value,
                                                                          int | float))):
                raise ParameterError(field, "arithmetic only (+ - * / **, numbers, names, "
                                     "function calls)", text)
            if isinstance(node, ast.Call):
                if not (isinstance(node.func, ast.Name) and node.func.id in _FUNCTIONS):
                    raise ParameterError(field, f"calls of {sorted(_FUNCTIONS)} only", text)
                name = node.func.id
                _, lo, hi = _FUNCTIONS[name]
                if node.keywords:
                    raise ParameterError(field, f"{name} called with positional arguments "
                                         "only", text)
                if not lo <= len(node.args) <= hi:
                    n = (f"{lo} argument{'s' if lo > 1 else ''}" if lo == hi
                         else f"at least {lo} arguments")
                    raise ParameterError(field, f"a valid call ({name} takes {n})", text)
            if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Pow):
                e = _constant(node.right)
                if e is None or not abs(e) <= MAX_EXPONENT:
                    raise ParameterError(field, f"an expression whose exponents are constants "
                                         f"of magnitude at most {MAX_EXPONENT:g}",
                                         ast.get_source_segment(text, node.right) or text)
        return cls(text, tuple(dict.fromkeys(names)))

    def __call__(self, values: dict) -> float:
        env = {**CONSTANTS, **values}

        def ev(node):
            if isinstance(node, ast.Expression):
                return ev(node.body)
            if isinstance(node, ast.Constant):
                return float(node.value)
            if isinstance(node, ast.Name):
                v = env[node.id]
                if isinstance(v, bool) or not isinstance(v, int | float):
                    raise ValueError(f"{node.id} is not a number")
                return float(v)
            if isinstance(node, ast.BinOp):
                if isinstance(node.op, ast.Pow):
                    return math.pow(ev(node.left), ev(node.right))
                return _BINARY[type(node.op)](ev(node.left), ev(node.right))
            if isinstance(node, ast.UnaryOp):
                return _UNARY[type(node.op)](ev(node.operand))
            return _FUNCTIONS[node.func.id][0](*[ev(a) for a in node.args])

        try:
            out = ev(ast.parse(self.text, mode="eval"))
        except (ZeroDivisionError, ValueError, OverflowError) as exc:
            raise ParameterError(f"derived ({self.text})", "an expression with a real value "
                                 "defined for this design",
                                 Shown(f"{type(exc).__name__}: {exc}")) from None
        if not isinstance(out, float) or not math.isfinite(out):
            raise ParameterError(f"derived ({self.text})", "a finite real value", out)
        return out


# ---- variables ---------------------------------------------------------------------------------


@dataclass(frozen=True)
class Variable:
    """One design variable, in internal units.

    ``target`` is the path it writes in the mechanism spec, or ``None`` for a free parameter
    that only derived fields use. ``quantity`` is ``length`` (mm), ``angle`` (rad), ``number``
    or ``text``; ``kind`` is ``continuous``, ``integer`` or ``choice``.
    """

    name: str
    target: tuple | None
    quantity: str
    kind: str
    low: float | None = None
    high: float | None = None
    choices: tuple = ()
    levels: int = 5
    role: str = "mechanism"
    baseline: object = None

    @property
    def unit(self) -> str:
        return {"length": "mm", "angle": "deg"}.get(self.quantity, "")

    def display(self, x):
        """A value in display units (mm, deg) for tables and files."""
        return math.degrees(x) if self.quantity == "angle" else x


@dataclass(frozen=True)
class Derived:
    """A mechanism field computed from the variables: ``target`` ← ``expression``."""

    name: str
    target: tuple
    expression: Expression


class DesignSpace:
    """Variables and derived fields over a typed mechanism spec (the baseline design)."""

    def __init__(self, base_spec, variables: tuple[Variable, ...],
                 derived: tuple[Derived, ...] = ()):
        self.base_spec = base_spec
        self.variables = tuple(variables)
        self.derived = tuple(derived)

    @property
    def names(self) -> list[str]:
        return [v.name for v in self.variables]

    # ---- decoding ----------------------------------------------------------------------------
    def spec_of(self, design: dict | None):
        """The typed mechanism spec of one design (``None``: the baseline's)."""
        spec = self.base_spec
        if design is None:
            return spec
        sets = [(v.target, int(design[v.name]) if v.kind == "integer" else design[v.name])
                for v in self.variables if v.target is not None]
        sets += [(d.target, d.expression(design)) for d in self.derived]
        # the nominal pose's coordinates last: a missing nominal pose is first filled with the
        # candidate's default (level, centred), then the coordinate is set
        for target, x in sorted(sets, key=lambda s: s[0][0] == "nominal_pose"):
            if target[0] == "nominal_pose" and getattr(spec, "nominal_pose", 0) is None:
                spec = spec.model_copy(update={"nominal_pose": [
                    float(c) for c in spec.build().nominal_pose]})
            spec = with_path(spec, target, x)
        return spec

    def decode(self, design: dict | None) -> Mechanism:
        """The mechanism of one design (``None``: the baseline); raises
        :class:`ParameterError` if it is invalid."""
        return self.spec_of(design).build()

    def baseline_values(self) -> dict:
        """Each variable's value in the baseline design (``None`` for free parameters)."""
        def value(v):
            if v.target[0] == "nominal_pose" and getattr(self.base_spec, "nominal_pose",
                                                         0) is None:
                return float(self.base_spec.build().nominal_pose[v.target[1]])
            return get_path(self.base_spec, v.target)

        return {v.name: v.baseline if v.role != "mechanism" else
                None if v.target is None else value(v) for v in self.variables}

    def evaluation_choices(self, design: dict | None) -> dict:
        """``{role: value}`` of the variables that choose for the evaluation (``actuator``)
        rather than the mechanism; the baseline's when ``design`` is ``None``."""
        src = self.baseline_values() if design is None else design
        return {v.role: src[v.name] for v in self.variables if v.role != "mechanism"}

    # ---- optimiser views -----------------------------------------------------------------------
    def bounds(self) -> np.ndarray:
        """``(n, 2)`` box for continuous optimisers (integers span [low, high + 1))."""
        return np.array([[v.low, v.high + (1.0 if v.kind == "integer" else 0.0)]
                         for v in self.variables])

    def from_vector(self, x: np.ndarray) -> dict:
        return {v.name: int(min(np.floor(xi), v.high)) if v.kind == "integer" else float(xi)
                for v, xi in zip(self.variables, x)}

    def from_unit(self, u: np.ndarray) -> dict:
        out = {}
        for v, ui in zip(self.variables, u):
            if v.kind == "choice":
                out[v.name] = v.choices[min(int(ui * len(v.choices)), len(v.choices) - 1)]
            elif v.kind == "integer":
                n = int(v.high - v.low) + 1
                out[v.name] = int(v.low + min(int(ui * n), n - 1))
            else:
                out[v.name] = float(v.low + ui * (v.high - v.low))
        return out

    def grid_axes(self) -> list[list]:
        axes = []
        for v in self.variables:
            if v.kind == "choice":
                axes.append(list(v.choices))
            elif v.kind == "integer":
                axes.append([int(x) for x in np.unique(np.round(np.linspace(v.low, v.high,
                                                                            v.levels)))])
            else:
                axes.append([float(x) for x in np.linspace(v.low, v.high, v.levels)])
        return axes

    def grid_size(self) -> int:
        return math.prod(len(a) for a in self.grid_axes())

    def grid(self):
        """Every grid design, generated lazily."""
        for combo in itertools.product(*self.grid_axes()):
            yield dict(zip(self.names, combo))

    # ---- how much of the box is buildable ------------------------------------------------------
    def validity(self, samples: int = 128, seed: int = 0) -> tuple[float, list[tuple[str, int]]]:
        """Fraction of a scrambled Sobol sample of the design box that fails to build (no
        mechanism, or no level mid-stroke pose), and the most common reasons with counts."""
        from scipy.stats import qmc

        u = qmc.Sobol(d=len(self.variables), scramble=True, seed=seed).random(samples)
        reasons: Counter = Counter()
        for row in u:
            try:
                _ = self.decode(self.from_unit(row)).nominal_pose
            except ParameterError as exc:
                reasons[f"{exc.field}: must be {exc.allowed}"] += 1
        bad = sum(reasons.values())
        return bad / samples, reasons.most_common(3)
