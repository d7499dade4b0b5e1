"""Error types with one message form: the field, the allowed values or range, the value given.

Every input error reads ``<field path>: must be <allowed>; got <value>``, with the position in
the YAML file after the field path when the value came from a file:
``evaluate.workspace.resolution (study.yaml, line 12, column 5): must be …; got …``.
:func:`from_validation_error` turns pydantic's errors into that form.
"""

from __future__ import annotations

import difflib
import re
import sys
import types
from typing import Annotated, Any, Literal, Union, get_args, get_origin

__all__ = ["ParameterError", "NumericalError", "CandidateError", "Shown", "format_value",
           "format_field", "parse_field", "from_validation_error"]

_REPR_LIMIT = 200
_REPR_DEPTH = 8


class Shown(str):
    """A value already rendered for an error message (not quoted again)."""

    def __repr__(self) -> str:
        return str(self)


def format_value(value: Any, limit: int = _REPR_LIMIT) -> str:
    """Render a user-supplied value compactly for an error message.

    The cost is bounded by ``limit``, not by the value: long strings are cut before ``repr`` and
    lists, tuples and mappings are rendered item by item only until the text is long enough.
    """
    text = _bounded_repr(value, limit + 1, 0)
    return text if len(text) <= limit else text[:limit - 3] + "..."


def _bounded_repr(value: Any, budget: int, depth: int) -> str:
    kind = type(value)
    if kind is str or kind is bytes:
        return repr(value[:budget])
    if kind in (list, tuple, dict):
        if depth >= _REPR_DEPTH:
            return "[...]" if kind is list else "(...)" if kind is tuple else "{...}"
        opening, closing = {list: "[]", tuple: "()", dict: "{}"}[kind]
        parts, used = [], 2
        for item in (value.items() if kind is dict else value):
            if used > budget:
                parts.append("...")
                break
            if kind is dict:
                text = (_bounded_repr(item[0], budget - used, depth + 1) + ": "
                        + _bounded_repr(item[1], budget - used, depth + 1))
            else:
                text = _bounded_repr(item, budget - used, depth + 1)
            parts.append(text)
            used += len(text) + 2
        if kind is tuple and len(parts) == 1 and len(value) == 1:
            closing = ",)"
        return opening + ", ".join(parts) + closing
    try:
        return repr(value)
    except ValueError:  # an int too long to print (sys.set_int_max_str_digits)
        return f"<{kind.__name__} of {value.bit_length()} bits>" if kind is int else \
            f"<{kind.__name__}>"


def format_field(path: tuple | list) -> str:
    """``("a", "b", 0, "c")`` → ``a.b[0].c``."""
    out = ""
    for p in path:
        if isinstance(p, int) and not isinstance(p, bool):
            out += f"[{p}]"
        else:
            out += f".{p}" if out else str(p)
    return out


_FIELD_RE = re.compile(r"([^.\[\]\s()]+)((?:\[\d+\])*)")


def parse_field(text: str) -> tuple | None:
    """``a.b[0].c`` → ``("a", "b", 0, "c")``; None if ``text`` is not a field path."""
    parts: list = []
    if not text:
        return ()
    for piece in text.split("."):
        m = _FIELD_RE.fullmatch(piece)
        if not m or m.group(1).startswith("-"):
            return None
        parts.append(m.group(1))
        parts += [int(i) for i in re.findall(r"\d+", m.group(2))]
    return tuple(parts)


class ParameterError(ValueError):
    """A parameter is outside its allowed values.

    The message always reads ``<field>: must be <allowed>; got <value>`` so that a user can find
    the offending entry in a YAML file or a function call without reading a traceback. ``where``
    (e.g. ``"study.yaml, line 12, column 5"``) is shown after the field when known. An error
    raised while handling a located ParameterError about the same field (re-raised with a
    prefix, ``"mechanism." + exc.field``) keeps that location.
    """

    def __init__(self, field: str, allowed: str, got: Any, where: str | None = None):
        self.field = field
        self.allowed = allowed
        self.got = got
        self.where = where if where is not None else _inherited_where(field)
        super().__init__(self._message())

    def _message(self) -> str:
        at = f" ({self.where})" if self.where else ""
        return f"{self.field}{at}: must be {self.allowed}; got {format_value(self.got)}"

    def locate(self, where: str | None) -> ParameterError:
        """Set the position shown after the field (in place); returns the error."""
        self.where = where
        self.args = (self._message(),)
        return self

    def __reduce__(self):
        return type(self), (self.field, self.allowed, self.got, self.where)


def _inherited_where(field: str) -> str | None:
    cur = sys.exc_info()[1]
    if isinstance(cur, ParameterError) and cur.where and cur.field and (
            field == cur.field or field.endswith(("." + cur.field, ": " + cur.field))):
        return cur.where
    return None


# ---- pydantic's errors in the one message form --------------------------------------------------

_NOTHING = Shown("nothing")

#: pydantic error type → the allowed values, for errors whose wording needs no context
_PLAIN = {
    "bool_type": "true or false", "bool_parsing": "true or false",
    "string_type": "text", "string_unicode": "text", "str_type": "text",
    "list_type": "a list", "tuple_type": "a list", "set_type": "a list",
    "iterable_type": "a list", "dict_type": "a mapping", "mapping_type": "a mapping",
    "none_required": "null (empty)", "finite_number": "a finite number",
    "int_parsing_size": "an integer of reasonable size", "callable_type": "a function",
    "date_type": "a date", "date_parsing": "a date", "datetime_type": "a date and time",
    "datetime_parsing": "a date and time", "is_instance_of": "a value of the right type",
}
_INTEGER = {"int_type", "int_parsing", "int_from_float"}
_NUMBER = {"float_type", "float_parsing"}
_BOUNDS = {"greater_than": ("gt", ">"), "greater_than_equal": ("ge", "≥"),
           "less_than": ("lt", "<"), "less_than_equal": ("le", "≤")}


def _members(tp: Any) -> list:
    """The alternatives of an annotation, with Annotated and Optional unwrapped."""
    while get_origin(tp) is Annotated:
        tp = get_args(tp)[0]
    if get_origin(tp) in (Union, types.UnionType):
        return [m for a in get_args(tp) for m in _members(a) if m is not type(None)]
    return [tp]


def _models(cands: list) -> list:
    from pydantic import BaseModel

    return [c for c in cands if isinstance(c, type) and issubclass(c, BaseModel)]


def _tagged(model, part) -> bool:
    return part == model.__name__ or any(
        get_origin(f.annotation) is Literal and part in get_args(f.annotation)
        for f in model.model_fields.values())


def _walk(root: Any, loc: tuple) -> tuple[tuple, Any, list]:
    """Split pydantic's ``loc`` into the user's path (field names, mapping keys, list indices),
    leaving out pydantic's own entries (union tags and member labels such as
    ``function-before[parse(), list]``, ``[key]``). → ``(path, parent model, leaf types)``."""
    cands, path, model = _members(root), [], None
    for i, part in enumerate(loc):
        models = _models(cands)
        hit = next((m for m in models if part in m.model_fields), None)
        seqs = [c for c in cands if get_origin(c) in (list, tuple)]
        maps = [c for c in cands if get_origin(c) is dict]
        if hit is not None:
            path.append(part)
            model, cands = hit, _members(hit.model_fields[part].annotation)
        elif isinstance(part, int) and seqs:
            path.append(part)
            cands = _members(get_args(seqs[0])[0]) if get_args(seqs[0]) else []
        elif maps and part != "[key]":
            path.append(part)
            cands = _members(get_args(maps[0])[1]) if get_args(maps[0]) else []
        elif part == "[key]":
            cands = _members(get_args(maps[0])[0]) if maps and get_args(maps[0]) else []
        elif any(_tagged(m, part) for m in models):
            cands = [m for m in models if _tagged(m, part)]
        elif models and i == len(loc) - 1:          # a key the model does not know
            path.append(part)
            model, cands = models[0], []
        # else: the label of a union member, not part of the user's path
    return tuple(path), model, cands


def _noun(cands: list) -> str:
    return "an integer" if int in cands and float not in cands else "a number"


def _wording(err: dict, model: Any, cands: list) -> tuple[str, Any]:
    """→ ``(allowed, got)`` in plain words for one pydantic error."""
    kind, ctx, got = err["type"], err.get("ctx") or {}, err.get("input")
    if kind in ("value_error", "assertion_error"):
        cause = ctx.get("error")
        if isinstance(cause, ParameterError):
            return cause.allowed, cause.got
        text = re.sub(r"^(Value|Assertion) error, ", "", err["msg"])
        allowed, sep, given = text.removeprefix("must be ").partition("; got ")
        return allowed, (Shown(given) if sep else got)
    if kind == "missing":
        return "given (required)", _NOTHING
    if kind == "extra_forbidden":
        known = sorted(model.model_fields) if model is not None else []
        close = difflib.get_close_matches(str(err["loc"][-1]), known, n=1, cutoff=0.6)
        hint = f"did you mean {close[0]!r}? " if close else ""
        return (f"a known key ({hint}known keys: {', '.join(known)})" if known
                else "a known key"), Shown(repr(err["loc"][-1]))
    if kind == "literal_error":
        expected = ctx.get("expected", "")
        expected = {"True": "true", "False": "false"}.get(expected, expected)
        return expected, got
    if kind in _INTEGER:
        return "an integer", got
    if kind in _NUMBER:
        return "a number", got
    if kind in _BOUNDS:
        key, sign = _BOUNDS[kind]
        bound = ctx.get(key)
        bound = f"{bound:g}" if isinstance(bound, float) else bound
        return f"{_noun(cands)} {sign} {bound}", got
    if kind == "multiple_of":
        return f"a multiple of {ctx.get('multiple_of')}", got
    if kind in ("too_short", "too_long"):
        n = ctx.get("min_length" if kind == "too_short" else "max_length")
        what = "a mapping with" if ctx.get("field_type") == "Dictionary" else "a list of"
        items = ("entr" + ("y" if n == 1 else "ies")) if what == "a mapping with" else \
            ("item" + ("" if n == 1 else "s"))
        return f"{what} at {'least' if kind == 'too_short' else 'most'} {n} {items}", got
    if kind in ("string_too_short", "string_too_long"):
        n = ctx.get("min_length" if kind == "string_too_short" else "max_length")
        return f"text of at {'least' if kind == 'string_too_short' else 'most'} {n} " \
               "characters", got
    if kind == "string_pattern_mismatch":
        return f"text matching {ctx.get('pattern')}", got
    if kind in ("model_type", "model_attributes_type"):
        leaf = _models(cands)
        keys = ", ".join(leaf[0].model_fields) if leaf else ""
        return f"a mapping (keys: {keys})" if keys else "a mapping", got
    if kind == "enum":
        return f"one of {ctx.get('expected')}", got
    if kind in _PLAIN:
        return _PLAIN[kind], got
    text = err["msg"].removeprefix("Input should be ")
    return text[:1].lower() + text[1:], got


def from_validation_error(exc: Any, root: Any, prefix: str = "",
                          locate: Any = None) -> ParameterError:
    """One pydantic ``ValidationError`` → one :class:`ParameterError`.

    ``root`` is the annotation validated (a model class or a union); ``prefix`` is prepended to
    the field path. An unknown key is reported before any other error (a typo otherwise shows
    up as a missing field elsewhere); errors of the members of one union on the same field are
    joined (``a list of 3 lengths or 'centroid'``). ``locate(path, value, show)``, if given,
    returns where in a file ``value`` at ``path`` is (shown at ``show``) or None.
    """
    errs = exc.errors()
    extra = [e for e in errs if e["type"] == "extra_forbidden"]
    first = extra[0] if extra else errs[0]
    path, model, cands = _walk(root, first["loc"])
    kind = first["type"]
    allowed, got = _wording(first, model, cands)
    if kind != "extra_forbidden":
        for other in errs:
            if other is first or other["type"] == "extra_forbidden":
                continue
            p, m, c = _walk(root, other["loc"])
            if p == path and other.get("input") is first.get("input"):
                more, _ = _wording(other, m, c)
                if more not in allowed.split(" or "):
                    allowed += " or " + more
    value, show = first.get("input"), path
    if kind in ("union_tag_invalid", "union_tag_not_found"):
        disc = str((first.get("ctx") or {}).get("discriminator", "family")).strip("'\"")
        show = path + (disc,)
        tags = [repr(t) for m in _models(cands) for f in [m.model_fields.get(disc)]
                if f is not None and get_origin(f.annotation) is Literal
                for t in get_args(f.annotation)]
        allowed = "one of " + ", ".join(tags)
        if kind == "union_tag_invalid":
            got = value.get(disc) if isinstance(value, dict) and disc in value else \
                (first.get("ctx") or {}).get("tag", got)
        else:
            allowed, got = f"given ({allowed})", _NOTHING
        field_path, at = show, path
    elif kind == "missing":
        field_path, at, show = path, path[:-1], path[:-1]
    else:
        field_path, at = path, path
    start = parse_field(prefix.rstrip(".")) if prefix else ()
    where = None
    if locate is not None and start is not None:
        where = locate(start + at, value, start + show)
    field = prefix + format_field(field_path) if field_path else (prefix.rstrip(".")
                                                                   or "(top level)")
    return ParameterError(field, allowed, got, where=where)


class NumericalError(RuntimeError):
    """A declared numerical failure (singular, undefined, not converged) that makes a result
    impossible: recorded as data with its reason, never a crash or a silent NaN.

    The message reads ``<what>: <reason>``.
    """

    def __init__(self, what: str, reason: str):
        self.what = what
        self.reason = reason
        super().__init__(f"{what}: {reason}")


class CandidateError(RuntimeError):
    """A candidate's evaluation raised an undeclared exception (a programming error): the run
    stops after recording it. ``params`` is the design, ``details`` the worker's traceback."""

    def __init__(self, params: dict, details: str):
        self.params = params
        self.details = details
        super().__init__(f"evaluation of candidate {params} raised an error (recorded in the "
                         f"store); the run stops:\n{details}")
