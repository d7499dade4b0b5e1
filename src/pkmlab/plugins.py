"""Loading plugins from installed distributions' entry points, one way for every registry
(families, evaluators, exporters): a plugin that fails to load is logged and recorded with its
reason, never fatal."""

from __future__ import annotations

import logging
from collections.abc import Callable, Container

log = logging.getLogger(__name__)

__all__ = ["load_entry_points"]


def load_entry_points(group: str, register: Callable, errors: dict[str, str], what: str,
                      skip: Container[str] = ()) -> dict[str, object]:
    """``register(ep.load())`` for every entry point of ``group`` not named in ``skip``;
    returns ``{entry point name: what register returned}`` for those loaded. A failure is
    logged and stored in ``errors`` (name → ``"<Type>: <message>"``); a success clears it."""
    from importlib.metadata import entry_points

    loaded = {}
    for ep in entry_points(group=group):
        if ep.name in skip:
            continue
        try:
            loaded[ep.name] = register(ep.load())
        except Exception as exc:  # a broken plugin must not break pkmlab
            errors[ep.name] = f"{type(exc).__name__}: {exc}"
            log.warning("pkmlab %s plugin %r (%s) not loaded: %s", what, ep.name, ep.value,
                        errors[ep.name])
            continue
        errors.pop(ep.name, None)
    return loaded
