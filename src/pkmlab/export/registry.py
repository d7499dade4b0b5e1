"""Exporters keyed by format: every file format pkmlab writes a subject in is one entry here.

An :class:`Exporter` names its format (the file suffix), the kind of subject it writes
(``"mesh"``: a triangle mesh in mm, such as a workspace hull), a one-line description with its
units (shown in ``--help`` and the report's file table), the options it
understands and its writer, which returns the file's bytes. :data:`EXPORTERS` holds them in
registration order; the built-in ones (:mod:`.meshes`) register exactly as a plugin's do,
through :func:`register_exporter` or the entry point group :data:`PLUGIN_GROUP`.

Whoever writes a subject asks the registry: ``pkmlab workspace --mesh`` takes any mesh format
registered, a study writes each exported design's hull in every mesh format whose ``study``
flag is set, the report describes the files from the descriptions, and
:func:`write` dispatches a path by its suffix, writing atomically.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from ..errors import ParameterError

__all__ = ["Exporter", "EXPORTERS", "PLUGIN_GROUP", "PLUGIN_ERRORS", "register_exporter",
           "exporters", "exporter_for", "write", "load_exporter_plugins"]

#: entry point group of exporter plugins (each names an :class:`Exporter`)
PLUGIN_GROUP = "pkmlab.exporters"
#: entry point name → why it could not be loaded
PLUGIN_ERRORS: dict[str, str] = {}
#: format → exporter, in registration order
EXPORTERS: dict[str, Exporter] = {}
SUBJECTS = ("mesh", "mechanism")


@dataclass(frozen=True)
class Exporter:
    """One file format.

    Attributes:
        format: the key and the file suffix without its dot (``"stl"``).
        subject: what it writes (``"mesh"``: an object with ``vertices (n, 3)`` in mm and
            ``faces (m, 3)``, a ``trimesh.Trimesh`` where ``trimesh`` is set).
        description: one line for people, with the file's units.
        write: ``write(subject, **options) -> bytes``.
        options: the keywords ``write`` understands (``"colors"``: ``(n, 4)`` uint8 vertex
            colours; ``"values"``: ``{name: (n,)}`` vertex values); others are not passed.
        trimesh: ``write`` needs a ``trimesh.Trimesh`` (else plain vertices and faces do).
        study: written for every design a study exports.
        files: the file suffixes a ``"mechanism"`` exporter writes (``write`` then returns
            ``{suffix: bytes}`` when there are several); default ``("." + format,)``.
        requires: a module ``write`` imports that is an optional extra (``"build123d"``):
            :meth:`available` says whether it is installed.
    """

    format: str
    subject: str
    description: str
    write: Callable[..., bytes]
    options: frozenset[str] = field(default_factory=frozenset)
    trimesh: bool = True
    study: bool = True
    files: tuple[str, ...] = ()
    requires: str | None = None

    def __post_init__(self):
        if not (self.format.isascii() and self.format.isalnum() and self.format.islower()):
            raise ValueError(f"format must be a lower-case alphanumeric suffix, got "
                             f"{self.format!r}")
        if self.subject not in SUBJECTS:
            raise ValueError(f"subject must be one of {SUBJECTS}, got {self.subject!r}")
        if not callable(self.write):
            raise TypeError(f"write of format {self.format!r} is not callable")
        object.__setattr__(self, "options", frozenset(self.options))

    @property
    def suffix(self) -> str:
        return self.files[0] if self.files else "." + self.format

    def available(self) -> tuple[bool, str]:
        """``(True, "")``, or ``(False, why)`` when its optional extra is not installed."""
        if self.requires is None:
            return True, ""
        import importlib.util

        if importlib.util.find_spec(self.requires) is None:
            return False, (f"format {self.format!r} needs the package {self.requires!r} "
                           "(pip install 'pkmlab[cad]')")
        return True, ""


def register_exporter(exporter: Exporter, *, replace: bool = False) -> Exporter:
    """Add ``exporter`` to :data:`EXPORTERS` (``replace`` to override a format)."""
    if not isinstance(exporter, Exporter):
        raise TypeError(f"{exporter!r} is not a pkmlab.export.Exporter")
    old = EXPORTERS.get(exporter.format)
    if old is not None and old is not exporter and not replace:
        raise ValueError(f"format {exporter.format!r} is already registered "
                         f"({old.write.__module__})")
    EXPORTERS[exporter.format] = exporter
    return exporter


def exporters(subject: str = "mesh", *, study: bool | None = None,
              option: str | None = None) -> dict[str, Exporter]:
    """The exporters of ``subject`` (those written by a study, or understanding ``option``,
    when asked), in registration order."""
    return {k: e for k, e in EXPORTERS.items() if e.subject == subject
            and (study is None or e.study == study) and (option is None or option in e.options)}


def exporter_for(path: str | Path, subject: str = "mesh", what: str = "mesh file") -> Exporter:
    """The exporter of ``path``'s suffix; a ParameterError naming the formats otherwise."""
    fmt = Path(path).suffix.lower().removeprefix(".")
    found = exporters(subject).get(fmt)
    if found is None:
        allowed = ", ".join("." + k for k in exporters(subject))
        raise ParameterError(what, f"a path ending in one of {allowed}", str(path))
    return found


def write(obj: Any, path: str | Path, subject: str = "mesh", **options) -> Path:
    """Write ``obj`` to ``path`` in the format of its suffix, atomically; options the format
    does not understand are dropped (a colour for an STL)."""
    from ..runtime.atomic import write_bytes

    ex = exporter_for(path, subject)
    kw = {k: v for k, v in options.items() if k in ex.options and v is not None}
    return write_bytes(Path(path), ex.write(obj, **kw))


def load_exporter_plugins() -> dict[str, Exporter]:
    """Register the exporters of the :data:`PLUGIN_GROUP` entry points (a broken one is
    logged and listed in :data:`PLUGIN_ERRORS`); returns those loaded, by format."""
    from ..plugins import load_entry_points

    loaded = load_entry_points(PLUGIN_GROUP, register_exporter, PLUGIN_ERRORS, "exporter")
    return {ex.format: ex for ex in loaded.values()}
