"""The metrics a design study can optimise or constrain, and what computes each.

``METRICS[name] = (needs, unit, description)``; ``needs`` names the evaluation block that must
be present in the study's ``evaluate`` section (``None``: always available from the geometry).
"""

from __future__ import annotations

__all__ = ["METRICS", "needs_of", "ALIASES"]

METRICS: dict[str, tuple[str | None, str, str]] = {
    "workspace_volume": ("workspace", "cm³", "volume of the requested workspace"),
    "workspace_empty": ("workspace", "", "1 if the requested workspace is empty"),
    "z_span": ("workspace", "mm", "height of the workspace"),
    "inscribed_box_volume": ("inscribed", "cm³", "largest inscribed axis-aligned box"),
    "inscribed_box_edge": ("inscribed", "mm", "shortest edge of that box"),
    "inscribed_cylinder_radius": ("inscribed", "mm", "largest inscribed vertical cylinder"),
    "inscribed_cylinder_volume": ("inscribed", "cm³", "volume of that cylinder"),
    "orientation_capability": ("orientation_capability", "deg",
                               "largest ±a simultaneous Euler box with a non-empty dexterous "
                               "workspace"),
    "gci": ("dexterity", "", "global conditioning index (Monte-Carlo mean of 1/κ)"),
    "gci_std_error": ("dexterity", "", "standard error of the GCI estimate"),
    "worst_kappa": ("dexterity", "", "largest κ met by the GCI samples"),
    "nominal_kappa": ("dexterity", "", "κ at the nominal pose"),
    "min_force": ("dexterity", "N", "smallest force held in every direction (GCI samples)"),
    "paper_motion_fits": ("trajectory", "", "1 if the paper's motion fits the stroke"),
    "paper_motion_margin": ("trajectory", "mm", "smallest stroke margin along the motion"),
    "base_outer_radius": (None, "mm", "footprint: largest base joint radius"),
    "platform_outer_radius": (None, "mm", "largest platform joint radius"),
    "stroke_length": (None, "mm", "actuator travel"),
}

#: ``<kind>_volume`` names the workspace volume when the study's workspace is of that kind
ALIASES = {"dexterous_volume": "dexterous", "reachable_volume": "reachable",
           "constant_volume": "constant"}


def needs_of(name: str) -> str | None:
    if name in ALIASES:
        return "workspace"
    return METRICS[name][0]
