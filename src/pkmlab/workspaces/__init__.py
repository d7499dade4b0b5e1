"""Workspace engine: orientation sets, constraints, exact column evaluation, exports."""

from .constraints import Constraints, JointLimits
from .engine import KINDS, workspace
from .orientations import OrientationSet
from .result import WorkspaceResult

__all__ = ["workspace", "KINDS", "OrientationSet", "Constraints", "JointLimits",
           "WorkspaceResult"]
