"""What a linear-delta printer builder asks for, from the exact feasible set of an
:class:`~.ldelta3.LDelta3`: the largest printable cylinder and the usable radius at every
height, resolution maps (tool motion per motor step), the tower/XY speed-ratio map that
firmware uses to slow moves, and firmware values (Klipper, Marlin, RepRapFirmware).

**Usable radius** ``r(z)``: the largest disc centred on the z axis at height ``z`` (of the
tool point) inside the feasible set. For vertical towers it is closed form: at height ``z``
leg i holds where the horizontal distance ``d`` from its tower line lies in ``[d_lo, d_hi]``,

    d_lo = sqrt(max(l² - (q_max - t)², 0))     (the carriage below its endstop; none if t > q_max)
    d_hi = min(l·sin(limit), sqrt(l² - (q_min - t)²) if t < q_min else l)

(``t = z + w_z``, :mod:`.ldelta3`), and the disc of radius ``r`` about the axis, at distance
``D`` from the tower line, spans ``d ∈ [max(D - r, 0), D + r]``: ``r_i = min(D - d_lo, d_hi -
D)`` (the first term absent when ``d_lo = 0``), ``r(z) = min_i r_i`` (negative: not even
the centre). Each ``r_i`` is the minimum of a function falling with ``z`` and one rising, so
``r`` is quasi-concave in ``z``: the cylinder ``[z_0, z_0 + H]`` fits the disc of radius
``min(r(z_0), r(z_0 + H))``.

**Printable cylinder**: standing on the bed ``z_0``, the height ``H`` maximising
``π·min(r(z_0), r(z_0 + H))²·H`` (bounded scalar search, ``xatol`` 1e-6 mm), or the largest
radius for a given height. Inclined towers: the families' exact column sets give the same
numbers only through a sampled disc test; this module refuses them (``tilt``) rather than
report a sampled value as exact.

**Resolution**: one step of motor i (``1/steps_per_mm`` mm of carriage) moves the tool by
column i of ``J⁻¹`` over steps/mm; per axis the worst single step is ``max_i |J⁻¹[k, i]|``.
**Speed ratio**: the largest carriage speed per unit XY tool speed,
``max_i |J[i, :2]|`` (for a vertical tower ``d/sqrt(l² - d²)``, the tangent of the rod's
angle from the tower: Klipper's "ratio of tower to XY movement").
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ...errors import ParameterError
from ..base import NO_STROKE

__all__ = ["usable_radius", "printable_cylinder", "resolution_map", "speed_ratio_map",
           "firmware", "klipper_envelope", "PrintableCylinder"]


def _require_vertical(mech) -> None:
    if mech.family != "ldelta3":
        raise ParameterError("mechanism", "a linear delta (family 'ldelta3')", mech.family)
    if not np.all(mech.vertical):
        raise ParameterError("tilt", "vertical towers for the printer outputs (inclined "
                             "towers have exact column sets but no closed-form usable radius "
                             "here)", np.degrees(np.arccos(mech.rail_directions[:, 2])).tolist())


def usable_radius(mech, z) -> np.ndarray:
    """``r(z)`` (mm) at tool heights ``z`` (mm, array): the largest disc about the z axis in
    the feasible set (module notes; negative where the axis itself is outside)."""
    _require_vertical(mech)
    z = np.asarray(z, dtype=float)
    w = mech.tool_points @ mech._rotation.T - mech.base_points          # (3, 3)
    lo, hi = mech.stroke
    out = np.full(z.shape, np.inf)
    for i in range(3):
        l, D = mech.rod_length[i], math.hypot(w[i, 0], w[i, 1])
        t = z + w[i, 2]
        with np.errstate(invalid="ignore"):
            top = hi - t
            d_lo = np.sqrt(np.maximum(l * l - top ** 2, 0.0))
            below = lo - t
            d_hi = np.where(below > 0, np.sqrt(np.maximum(l * l - below ** 2, 0.0)), l)
            d_hi = np.where(below > l, -np.inf, np.minimum(d_hi, l * math.sin(
                mech.rod_angle_limit)))
            r = np.minimum(np.where(d_lo > 0, D - d_lo, np.inf), d_hi - D)
            r = np.where(top < 0, -np.inf, r)
        out = np.minimum(out, r)
    return out


@dataclass(frozen=True)
class PrintableCylinder:
    """The printable cylinder standing on the bed (mm): ``radius``, ``height``, ``z_bed``,
    ``volume_mm3``; ``top_z`` its top; ``method`` how it was found and to what precision."""

    radius: float
    height: float
    z_bed: float
    method: str

    @property
    def volume_mm3(self) -> float:
        return math.pi * self.radius ** 2 * self.height

    @property
    def top_z(self) -> float:
        return self.z_bed + self.height


def _top(mech, z_bed):
    """The highest tool height whose usable radius is >= 0 above ``z_bed`` (bisection to
    1e-9 mm on the quasi-concave ``r``)."""
    a = z_bed
    b = z_bed + mech.stroke[1] - mech.stroke[0] + 2 * float(np.max(mech.rod_length))
    if usable_radius(mech, a) < 0:
        return None
    while usable_radius(mech, b) >= 0:
        b += b - a
    while b - a > 1e-9:
        m = 0.5 * (a + b)
        a, b = (m, b) if usable_radius(mech, m) >= 0 else (a, m)
    return a


def printable_cylinder(mech, z_bed: float = 0.0, height: float | None = None
                       ) -> PrintableCylinder:
    """The largest cylinder standing on the bed ``z_bed`` inside the feasible set: of largest
    volume, or of largest radius for a given ``height`` (mm). Zero when the bed's centre is
    outside."""
    from scipy.optimize import minimize_scalar

    r0 = float(usable_radius(mech, z_bed))
    top = _top(mech, z_bed)
    if top is None or r0 <= 0:
        return PrintableCylinder(0.0, 0.0, z_bed, "the bed's centre is outside the set")
    if height is not None:
        if z_bed + height > top:
            return PrintableCylinder(0.0, float(height), z_bed,
                                     f"no disc at the top: the set ends {top - z_bed:.6g} mm "
                                     "above the bed")
        r = min(r0, float(usable_radius(mech, z_bed + height)))
        return PrintableCylinder(max(r, 0.0), float(height), z_bed,
                                 "closed form (quasi-concave usable radius)")

    def neg(H):
        return -min(r0, float(usable_radius(mech, z_bed + H))) ** 2 * H

    res = minimize_scalar(neg, bounds=(0.0, top - z_bed), method="bounded",
                          options={"xatol": 1e-6})
    H = float(res.x)
    r = min(r0, float(usable_radius(mech, z_bed + H)))
    return PrintableCylinder(r, H, z_bed, "largest volume: bounded scalar search on the "
                             "closed-form usable radius, height to 1e-6 mm (a local optimum "
                             "of a unimodal product)")


def _grid(mech, z, radius, n):
    g = np.linspace(-radius, radius, n)
    X, Y = np.meshgrid(g, g, indexing="ij")
    P = np.stack([X.ravel(), Y.ravel(), np.full(X.size, float(z))], axis=1)
    return g, P


def resolution_map(mech, z: float, radius: float, steps_per_mm, n: int = 81) -> dict:
    """Tool motion per motor step (mm) on an ``n × n`` grid of the square ``|x|, |y| <=
    radius`` at height ``z``: ``per_axis`` ``(n, n, 3)`` the worst single step along x, y, z
    (NaN outside the feasible set), and ``worst`` (3,) over the grid points inside the disc of
    ``radius`` (module notes). ``steps_per_mm``: one value or one per tower."""
    spm = np.broadcast_to(np.asarray(steps_per_mm, dtype=float), (3,))
    g, P = _grid(mech, z, radius, n)
    ok = mech.inverse(P).valid
    J = mech.jacobian(P)
    out = np.full((len(P), 3), np.nan)
    if ok.any():
        Jinv = np.linalg.inv(J[ok])                           # (m, 3 axes, 3 motors)
        out[ok] = np.max(np.abs(Jinv) / spm, axis=2)
    disc = np.hypot(P[:, 0], P[:, 1]) <= radius + 1e-9
    worst = np.nanmax(np.where((disc & ok)[:, None], out, np.nan), axis=0)
    return {"x": g, "y": g, "z": float(z), "per_axis": out.reshape(n, n, 3), "worst": worst,
            "all_inside": bool(np.all(ok[disc]))}


def speed_ratio_map(mech, z: float, radius: float, n: int = 81) -> dict:
    """``max_i |J[i, :2]|`` (carriage speed per unit XY tool speed) on the grid of
    :func:`resolution_map`; ``ratio`` ``(n, n)``, NaN outside the feasible set."""
    g, P = _grid(mech, z, radius, n)
    ok = mech.inverse(P, stroke=NO_STROKE).valid
    J = mech.jacobian(P)
    ratio = np.where(ok, np.max(np.linalg.norm(J[:, :, :2], axis=2), axis=1), np.nan)
    return {"x": g, "y": g, "z": float(z), "ratio": ratio.reshape(n, n)}


def _delta_radius(mech) -> float:
    w = mech.tool_points @ mech._rotation.T - mech.base_points
    D = np.hypot(w[:, 0], w[:, 1])
    if np.ptp(D) > 1e-9:
        raise ParameterError("generator", "three towers at the same distance for the firmware "
                             "values", D.tolist())
    return float(D[0])


def firmware(mech, z_bed: float = 0.0, steps_per_mm=80.0, cylinder=None) -> dict:
    """Firmware values from the exact set (vertical towers): ``values`` (delta radius, rods,
    homed height, printable radius, tower angles) and the snippets ``klipper`` (printer.cfg),
    ``marlin`` (Configuration.h) and ``reprap`` (config.g M665/M666). The printable radius is
    the largest-volume printable cylinder's (or ``cylinder``'s), the homed height the tool's
    height at the centre with every carriage at its endstop (the top of the window)."""
    _require_vertical(mech)
    cyl = cylinder or printable_cylinder(mech, z_bed)
    fk = mech.forward(np.full(3, mech.stroke[1]))
    if not fk.converged[0]:
        raise ParameterError("stroke", "a window whose top (the endstops) every carriage "
                             "reaches at the centre", list(mech.stroke))
    home = float(fk.pose[0, 2]) - z_bed
    R = _delta_radius(mech)
    ang = np.degrees(np.arctan2(mech.base_points[:, 1], mech.base_points[:, 0])) % 360
    rod = mech.rod_length
    spm = np.broadcast_to(np.asarray(steps_per_mm, dtype=float), (3,))
    v = {"delta_radius_mm": R, "rod_length_mm": rod.tolist(), "homed_height_mm": home,
         "printable_radius_mm": cyl.radius, "printable_height_mm": cyl.height,
         "tower_angles_deg": ang.tolist(), "steps_per_mm": spm.tolist()}
    same_rod = np.ptp(rod) < 1e-9
    f = lambda x: f"{x:.3f}"  # noqa: E731
    head = (f"# pkmlab: from the exact feasible set of {mech.name or mech.family}; printable "
            f"cylinder r = {cyl.radius:.3f} mm, h = {cyl.height:.3f} mm above the bed")
    kl = [head, "[printer]", "kinematics: delta", f"delta_radius: {f(R)}",
          f"print_radius: {f(cyl.radius)}", f"minimum_z_position: {f(0.0)}"]
    for i, ax in enumerate("abc"):
        kl += [f"[stepper_{ax}]", f"position_endstop: {f(home)}", f"arm_length: {f(rod[i])}",
               f"angle: {ang[i]:.3f}", f"rotation_distance: <steps: {spm[i]:g} steps/mm "
               "× full steps × microsteps>"]
    ma = [head.replace("#", "//"), f"#define DELTA_DIAGONAL_ROD {f(rod[0])}" if same_rod else
          "// rods differ: DELTA_DIAGONAL_ROD takes one value; see DELTA_DIAGONAL_ROD_TRIM_TOWER",
          f"#define DELTA_RADIUS {f(R)}", f"#define DELTA_HEIGHT {f(home)}",
          f"#define DELTA_PRINTABLE_RADIUS {f(cyl.radius)}",
          "#define DELTA_ENDSTOP_ADJ { 0, 0, 0 }",
          "#define DELTA_TOWER_ANGLE_TRIM { "
          + ", ".join(f"{a - b:.3f}" for a, b in zip(ang, (210.0, 330.0, 90.0))) + " }",
          "#define DEFAULT_AXIS_STEPS_PER_UNIT { " + ", ".join(f"{s:g}" for s in spm)
          + ", <E> }"]
    rr = [head.replace("#", ";"), f"M665 L{f(rod[0])} R{f(R)} H{f(home)} B{f(cyl.radius)} "
          f"X{ang[0] - 210.0:.3f} Y{ang[1] - 330.0:.3f} Z{ang[2] - 90.0:.3f}",
          "M666 X0 Y0 Z0", f"M92 X{spm[0]:g} Y{spm[1]:g} Z{spm[2]:g}"]
    return {"values": v, "klipper": "\n".join(kl) + "\n", "marlin": "\n".join(ma) + "\n",
            "reprap": "\n".join(rr) + "\n"}


def klipper_envelope(delta_radius, arm_length, position_endstop, print_radius=None,
                     step_distance=0.0125, minimum_z=0.0, slow_ratio=3.0):
    """Klipper's printable envelope for a delta, written from its formulas
    (klippy/kinematics/delta.py of github.com/Klipper3d/klipper, commit 84104bbb; not its
    code): returns ``r_K(z)`` (a function, mm) and its constants. Klipper allows
    ``x² + y² <= max_xy²`` with ``max_xy = min(print_radius, arm - radius,
    ratio_to_xy(4·SLOW_RATIO))``, ``ratio_to_xy(k) = k·sqrt(arm²/(k² + 1) - s²) + s - radius``
    (``s`` half a step), ``minimum_z <= z <= position_endstop``, and above ``limit_z =
    position_endstop + sqrt(arm² - radius²) - arm`` the radius ``radius - sqrt(arm² - (arm -
    (z - limit_z))²)``."""
    R, L = float(delta_radius), float(arm_length)
    pr = R if print_radius is None else float(print_radius)
    s = 0.5 * step_distance

    def ratio_to_xy(k):
        return k * math.sqrt(L * L / (k * k + 1) - s * s) + s - R

    max_xy = min(pr, L - R, ratio_to_xy(4 * slow_ratio))
    limit_z = position_endstop + math.sqrt(L * L - R * R) - L

    def r_k(z):
        z = np.asarray(z, dtype=float)
        above = z - limit_z
        with np.errstate(invalid="ignore"):
            taper = R - np.sqrt(L * L - (L - above) ** 2)
        r = np.where(above > 0, np.minimum(max_xy, taper), max_xy)
        return np.where((z < minimum_z) | (z > position_endstop), np.nan, r)

    return r_k, {"max_xy_mm": max_xy, "limit_z_mm": limit_z, "max_z_mm": float(position_endstop),
                 "min_z_mm": float(minimum_z), "slow_xy_mm": ratio_to_xy(slow_ratio),
                 "very_slow_xy_mm": ratio_to_xy(2 * slow_ratio),
                 "arm_minus_radius_mm": L - R, "speed_cap_mm": ratio_to_xy(4 * slow_ratio)}
