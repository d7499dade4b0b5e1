"""Writing pkmlab's subjects to files: the exporter registry (:mod:`.registry`) and the
built-in formats (:mod:`.meshes`; the mechanism formats of :mod:`.mechanism`: MJCF, URDF,
joint frames, STEP), registered when this package is imported."""

from . import mechanism, meshes  # noqa: F401  (register the built-in formats)
from .mechanism import export_mechanism, mechanism_formats
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
           "exporters", "load_exporter_plugins", "register_exporter", "write",
           "export_mechanism", "mechanism_formats"]
