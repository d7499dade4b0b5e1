"""Error types with one message form: the field, the allowed values or range, the value given."""

from __future__ import annotations

from typing import Any

__all__ = ["ParameterError", "NumericalError", "format_value"]


def format_value(value: Any) -> str:
    """Render a user-supplied value compactly for an error message."""
    text = repr(value)
    return text if len(text) <= 200 else text[:197] + "..."


class ParameterError(ValueError):
    """A parameter is outside its allowed values.

    The message always reads ``<field>: must be <allowed>; got <value>`` so that a user can find
    the offending entry in a YAML file or a function call without reading a traceback.
    """

    def __init__(self, field: str, allowed: str, got: Any):
        self.field = field
        self.allowed = allowed
        self.got = got
        super().__init__(f"{field}: must be {allowed}; got {format_value(got)}")


class NumericalError(RuntimeError):
    """A declared numerical failure (singular, undefined, not converged) that makes a result
    impossible: recorded as data with its reason, never a crash or a silent NaN.

    The message reads ``<what>: <reason>``.
    """

    def __init__(self, what: str, reason: str):
        self.what = what
        self.reason = reason
        super().__init__(f"{what}: {reason}")
