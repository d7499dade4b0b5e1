"""Writing pkmlab's subjects to files: the exporter registry (:mod:`.registry`) and the
built-in formats (:mod:`.meshes`), registered when this package is imported."""

from . import meshes  # noqa: F401  (registers the built-in mesh formats)
from .registry import (
    EXPORTERS,
    PLUGIN_ERRORS,
    PLUGIN_GROUP,
    Exporter,
    exporter_for,
    exporters,
    load_exporter_plugins,
    register_exporter,
    write,
)

__all__ = ["EXPORTERS", "PLUGIN_ERRORS", "PLUGIN_GROUP", "Exporter", "exporter_for",
           "exporters", "load_exporter_plugins", "register_exporter", "write"]
