"""pkmlab: design-optimisation workbench for parallel manipulators."""

from .config import load_mechanism
from .errors import ParameterError
from .mechanisms import PSU6, REGISTRY, UPS6, Luzi3, Mechanism
from .workspaces import Constraints, JointLimits, OrientationSet, WorkspaceResult, workspace

__version__ = "0.1.0"

__all__ = ["load_mechanism", "ParameterError", "REGISTRY", "Mechanism", "PSU6", "UPS6", "Luzi3",
           "workspace", "OrientationSet", "Constraints", "JointLimits", "WorkspaceResult",
           "__version__"]
