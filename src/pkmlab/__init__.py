"""pkmlab: design-optimisation workbench for parallel manipulators."""

from .config import load_mechanism
from .errors import NumericalError, ParameterError
from .mechanisms import PSU6, REGISTRY, RSS6, UPS6, Luzi3, Mechanism
from .workspaces import Constraints, JointLimits, OrientationSet, WorkspaceResult, workspace

__version__ = "0.1.0"

from .export import load_exporter_plugins as _load_exporters  # noqa: E402
from .mechanisms import load_plugins as _load_plugins  # noqa: E402

_load_plugins()     # family plugins (entry points "pkmlab.families"), now that pkmlab is whole
_load_exporters()  # exporter plugins (entry points "pkmlab.exporters")

__all__ = ["load_mechanism", "load_study", "ParameterError", "NumericalError", "REGISTRY",
           "Mechanism", "PSU6", "UPS6", "Luzi3", "RSS6", "workspace", "OrientationSet",
           "Constraints", "JointLimits", "WorkspaceResult", "open_results", "__version__"]


def __getattr__(name: str):
    """Heavy subpackages load on first use (``pkmlab.study``, ``pkmlab.load_study``,
    ``pkmlab.open_results``)."""
    import importlib

    if name in ("study", "dexterity", "trajectory", "results", "webreport"):
        return importlib.import_module(f".{name}", __name__)
    if name == "load_study":
        return importlib.import_module(".study", __name__).load_study
    if name == "open_results":
        return importlib.import_module(".results", __name__).open_results
    raise AttributeError(f"module 'pkmlab' has no attribute {name!r}")
