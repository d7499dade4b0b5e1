"""Dexterity analysis: conditioning, manipulability, singularities, force capability, stiffness.

Pure, batched NumPy functions on the velocity Jacobian of :meth:`pkmlab.Mechanism.jacobian`
(``q̇ = J·[v; ω]``, ``v`` in mm/s at the tool point, ``ω`` in rad/s, base frame) and
workspace-wide aggregates on a :class:`pkmlab.workspaces.WorkspaceResult`. Units: mm, rad, N,
N·mm. Numerical failure is reported through masks and status fields, never raised; invalid
*arguments* raise :class:`pkmlab.ParameterError`.

Modules: :mod:`.metrics` (pointwise Jacobian metrics, the one definition of κ, "singular" and
the default characteristic length), :mod:`.singularity`, :mod:`.force`, :mod:`.stiffness`,
:mod:`.aggregate` (GCI, κ statistics, well-conditioned volume), :mod:`.worst` (worst κ, smallest
force and singularities over a whole workspace grid), :mod:`.maps` (per-voxel worst-case maps),
:mod:`.report` (the analyses behind the ``inspect``, ``ik`` and ``dexterity`` commands).
"""

from .aggregate import (
    GCIResult,
    KappaGrid,
    KappaStatistics,
    WellConditionedVolume,
    gci_grid,
    gci_monte_carlo,
    kappa_grid,
    kappa_statistics,
    sample_orientations,
    well_conditioned_volume,
)
from .force import (
    ForceAlong,
    force_along,
    force_along_closed_form,
    max_force_all_directions,
    max_moment_all_directions,
    transpose_inverse,
)
from .metrics import (
    KAPPA_SINGULAR,
    LENGTH_STATUS,
    SINGULAR_RTOL,
    CharacteristicLength,
    characteristic_length,
    condition_number,
    homogenised_jacobian,
    is_singular,
    jacobian_ok,
    joint_radius,
    lci,
    manipulability,
    resolve_length,
    singular_values,
    smallest_singular_value,
)
from .singularity import (
    SingularityFlags,
    as_pose_frames,
    direct_kinematic_matrix,
    link_vectors,
    singularity_flags,
)
from .stiffness import Stiffness, stiffness
from .worst import WorstCase, worst_case

__all__ = [
    "SINGULAR_RTOL", "KAPPA_SINGULAR", "jacobian_ok", "is_singular", "homogenised_jacobian",
    "singular_values", "condition_number", "lci", "smallest_singular_value", "manipulability",
    "CharacteristicLength", "LENGTH_STATUS", "characteristic_length", "resolve_length",
    "joint_radius",
    "SingularityFlags", "singularity_flags", "direct_kinematic_matrix", "link_vectors",
    "as_pose_frames",
    "ForceAlong", "max_force_all_directions", "max_moment_all_directions", "force_along",
    "force_along_closed_form", "transpose_inverse",
    "Stiffness", "stiffness",
    "GCIResult", "KappaGrid", "KappaStatistics", "WellConditionedVolume", "kappa_grid",
    "gci_grid", "gci_monte_carlo", "sample_orientations", "kappa_statistics",
    "well_conditioned_volume", "WorstCase", "worst_case",
]
