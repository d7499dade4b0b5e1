"""Joint layouts on concentric circles, shared by the 6-PSU and 6-UPS generators.

Numbering follows Hopkins & Williams (2002), Fig. 4 (counter-clockwise seen from above):

* base pair k (k = 0, 1, 2) is centred at ``β + 120°·k`` and holds ``B(2k+1)`` at
  ``-σ_b/2`` on the *outer* circle and ``B(2k+2)`` at ``+σ_b/2`` on the *inner* circle;
* platform pair k is centred at ``90° - ρ + 120°·k`` (ρ measured clockwise from the platform
  y axis, the paper's 33.7°) and holds ``P(2k+1)`` at ``+σ_p/2`` and ``P(2k)`` at ``-σ_p/2``
  (``P0`` is ``P6``): pair 0 is (P1, P6), pair 1 is (P3, P2), pair 2 is (P5, P4);
* leg i joins ``B(i)`` and ``P(i)``, so each base pair feeds two adjacent platform pairs.

``pairing="same"`` puts P1, P3, P5 on the outer platform circle (outer base joints drive outer
platform joints); ``"crossed"`` swaps the platform radii. With σ = 0 each pair lies on a radius
("aligned radially"); with inner = outer radius and σ > 0 it is the single-circle
ParaDex / classic Gough–Stewart layout.
"""

from __future__ import annotations

import numpy as np

from ...errors import ParameterError
from ..solvers import bracketed_root

__all__ = ["paired_layout", "equal_leg_base_angle", "build_paired", "PAIRED_ALIASES"]



#: study variables of the paired-circle generator (:func:`build_paired`): name → (path in the
#: mechanism spec, quantity); the families built on it add their own
PAIRED_ALIASES: dict[str, tuple[str, str]] = {
    "base_inner_radius": ("generator.base_radii[0]", "length"),
    "base_outer_radius": ("generator.base_radii[1]", "length"),
    "platform_inner_radius": ("generator.platform_radii[0]", "length"),
    "platform_outer_radius": ("generator.platform_radii[1]", "length"),
    "platform_rotation": ("generator.platform_rotation", "angle"),
    "base_pair_angle": ("generator.base_pair_angle", "angle"),
    "base_pair_separation": ("generator.base_pair_separation", "angle"),
    "platform_pair_separation": ("generator.platform_pair_separation", "angle"),
    "stroke_min": ("stroke[0]", "length"),
    "stroke_max": ("stroke[1]", "length"),
    "tool_offset_z": ("tool_offset[2]", "length"),
    "pairing": ("generator.pairing", "text"),
}

def _ring(radii: np.ndarray, angles: np.ndarray, z: float = 0.0) -> np.ndarray:
    return np.stack([radii * np.cos(angles), radii * np.sin(angles), np.full(6, z)], axis=1)


def paired_layout(base_radii, platform_radii, base_pair_angle, platform_rotation,
                  base_pair_separation=0.0, platform_pair_separation=0.0, pairing="same"):
    """Base and platform joint centres ``(6, 3)`` each (mm) for the paired concentric layout.

    Args:
        base_radii, platform_radii: (inner, outer) radii in mm.
        base_pair_angle: β, angle of base pair 0's centre line from the x axis (rad).
        platform_rotation: ρ, clockwise angle of platform pair 0 (P1, P6) from the y axis (rad).
        base_pair_separation, platform_pair_separation: σ_b, σ_p (rad).
        pairing: ``"same"`` or ``"crossed"``.
    """
    if pairing not in ("same", "crossed"):
        raise ParameterError("pairing", "one of ['same', 'crossed']", pairing)
    b_in, b_out = base_radii
    p_in, p_out = platform_radii
    k = np.arange(3)
    b_ang = np.empty(6)
    b_ang[0::2] = base_pair_angle + 2 * np.pi / 3 * k - base_pair_separation / 2
    b_ang[1::2] = base_pair_angle + 2 * np.pi / 3 * k + base_pair_separation / 2
    b_rad = np.tile([b_out, b_in], 3)
    centre = np.pi / 2 - platform_rotation + 2 * np.pi / 3 * k
    p_ang = np.empty(6)
    p_ang[0::2] = centre + platform_pair_separation / 2          # P1, P3, P5
    p_ang[[5, 1, 3]] = centre - platform_pair_separation / 2     # P6, P2, P4
    odd, even = (p_out, p_in) if pairing == "same" else (p_in, p_out)
    p_rad = np.tile([odd, even], 3)
    return _ring(b_rad, b_ang), _ring(p_rad, p_ang)


def equal_leg_base_angle(base_radii, platform_radii, platform_rotation, base_pair_separation=0.0,
                         platform_pair_separation=0.0, pairing="same") -> float:
    """The base pair angle β (rad) that makes all six horizontal leg spans equal at the level pose.

    With three-fold symmetry legs 1, 3, 5 and legs 2, 4, 6 are alike, so the condition is
    ``|B1 - P1|_xy = |B2 - P2|_xy``. Of the roots on (-π, π] the one closest to the mirror
    symmetric position ``150° - ρ`` is returned.
    """
    # The platform points do not depend on β; B1 (outer) and B2 (inner) turn with it.
    _, P = paired_layout(base_radii, platform_radii, 0.0, platform_rotation,
                         base_pair_separation, platform_pair_separation, pairing)
    b_in, b_out = base_radii

    def gap(beta):
        a1 = np.asarray(beta) - base_pair_separation / 2
        a2 = np.asarray(beta) + base_pair_separation / 2
        d1 = (b_out * np.cos(a1) - P[0, 0]) ** 2 + (b_out * np.sin(a1) - P[0, 1]) ** 2
        d2 = (b_in * np.cos(a2) - P[1, 0]) ** 2 + (b_in * np.sin(a2) - P[1, 1]) ** 2
        return d1 - d2

    grid = np.linspace(-np.pi, np.pi, 1441)
    vals = gap(grid)
    # algorithm constant: roots to round-off
    roots = [bracketed_root(gap, grid[i], grid[i + 1], xtol=1e-14)
             for i in range(len(grid) - 1) if vals[i] == 0 or vals[i] * vals[i + 1] < 0]
    if not roots:
        raise ParameterError("base_pair_angle",
                             "an explicit angle (no angle makes all legs equal for these radii)",
                             "auto")
    target = 5 * np.pi / 6 - platform_rotation
    wrap = lambda a: (a + np.pi) % (2 * np.pi) - np.pi  # noqa: E731
    return float(min(roots, key=lambda r: abs(wrap(r - target))))


def build_paired(base_radii, platform_radii, base_pair_angle, platform_rotation,
                 base_pair_separation=0.0, platform_pair_separation=0.0, pairing="same"):
    """:func:`paired_layout` with ``base_pair_angle=None`` solved for equal legs.

    Returns ``(base_points, platform_points, description)``; the description records the
    generator parameters in mm and deg for display.
    """
    import math

    auto = base_pair_angle is None
    if auto:
        base_pair_angle = equal_leg_base_angle(base_radii, platform_radii, platform_rotation,
                                               base_pair_separation, platform_pair_separation,
                                               pairing)
    B, P = paired_layout(base_radii, platform_radii, base_pair_angle, platform_rotation,
                         base_pair_separation, platform_pair_separation, pairing)
    desc = {
        "generator": "paired concentric circles",
        "base_radii_mm": list(base_radii), "platform_radii_mm": list(platform_radii),
        "base_pair_angle_deg": math.degrees(base_pair_angle),
        "base_pair_angle_source": "solved for equal legs" if auto else "given",
        "platform_rotation_deg": math.degrees(platform_rotation),
        "base_pair_separation_deg": math.degrees(base_pair_separation),
        "platform_pair_separation_deg": math.degrees(platform_pair_separation),
        "pairing": pairing,
    }
    return B, P, desc
