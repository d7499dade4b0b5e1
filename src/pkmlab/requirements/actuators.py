"""Actuator specifications, catalogues and the fit check over the required motions.

An :class:`ActuatorSpec` describes one actuator, the same on all six legs.

* ``kind="linear"`` (prismatic families, ``actuator_unit`` mm): travel ``stroke`` (mm), force
  limit ``force`` (N), speed limit ``speed`` (mm/s) and optionally the rotary motor behind a
  screw: ``lead`` (mm/rev), ``efficiency`` and a piecewise-linear torque–speed curve
  ``torque_speed`` ``[(ω rad/s, T N·mm), ...]`` (zero torque beyond its last point). Along a
  motion the motor turns at ``ω = 2π·|q̇|/lead`` and must give
  ``T = |f|·lead / (2π·efficiency)``.
* ``kind="rotary"`` (servo / motor on the crank, families with ``actuator_unit`` rad such as
  ``rss6``): ``force`` is the torque limit (N·mm), ``speed`` the angular speed limit (rad/s),
  ``stroke`` the angle range used (rad); the torque–speed curve is the shaft's own:
  ``ω = |q̇|``, ``T = |τ| / efficiency``.

Margins (:func:`fit`, over every sample of every motion and all six actuators; negative =
exceeded):

* ``force_margin`` (%) = 100·(1 − max|f| / force);
* ``speed_margin`` (%) = 100·(1 − max|q̇| / speed);
* ``torque_speed_margin`` (%) = 100·min((T_avail(ω) − T) / T_peak), ``T_peak`` the curve's
  largest torque (``None`` without a curve);
* ``stroke_margin`` (mm; deg for a rotary actuator) = stroke − the largest travel one actuator
  uses (max q − min q over all motions).

``fits`` is true when every sample of every motion is feasible and every margin ≥ 0.
A catalogue is a YAML file ``{actuators: [{name, ...}, ...]}`` (:mod:`.spec`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["ActuatorSpec", "ActuatorFit", "fit", "motor_demand"]


@dataclass(frozen=True)
class ActuatorSpec:
    name: str
    force: float                               # N
    speed: float                               # mm/s
    stroke: float | None = None                # mm
    lead: float | None = None                  # mm/rev
    efficiency: float = 1.0
    torque_speed: tuple[tuple[float, float], ...] = ()   # (rad/s, N·mm)
    kind: str = "linear"                       # "linear" or "rotary" (module docstring)

    @property
    def has_curve(self) -> bool:
        return bool(self.torque_speed) and (self.kind == "rotary" or bool(self.lead))

    def available_torque(self, omega: np.ndarray) -> np.ndarray:
        """Torque (N·mm) the motor gives at ``omega`` (rad/s), 0 beyond the curve."""
        w, T = np.array(self.torque_speed, dtype=float).T
        return np.interp(np.abs(omega), w, T, right=0.0)

    def describe(self) -> dict:
        if self.kind == "rotary":
            d = {"name": self.name, "kind": "rotary", "torque_N_mm": self.force,
                 "speed_rad_s": self.speed, "range_rad": self.stroke,
                 "efficiency": self.efficiency}
            if self.torque_speed:
                d["torque_speed"] = [[w * 60 / (2 * math.pi), T / 1e3]
                                     for w, T in self.torque_speed]
            return d
        d = {"name": self.name, "force_N": self.force, "speed_mm_s": self.speed,
             "stroke_mm": self.stroke}
        if self.torque_speed:
            d.update(lead_mm=self.lead, efficiency=self.efficiency,
                     torque_speed=[[w * 60 / (2 * math.pi), T / 1e3]
                                   for w, T in self.torque_speed])
        return d


@dataclass(frozen=True)
class ActuatorFit:
    fits: bool
    force_margin: float | None
    speed_margin: float | None
    torque_speed_margin: float | None
    stroke_margin: float | None
    notes: dict


def motor_demand(spec: ActuatorSpec, force: np.ndarray, speed: np.ndarray):
    """Motor speed (rad/s) and required motor torque (N·mm) of actuator forces / speeds (or
    of crank torques / angular speeds for a rotary actuator)."""
    if spec.kind == "rotary":
        return np.abs(speed), np.abs(force) / spec.efficiency
    omega = 2 * math.pi * np.abs(speed) / spec.lead
    torque = np.abs(force) * spec.lead / (2 * math.pi * spec.efficiency)
    return omega, torque


def fit(spec: ActuatorSpec, results) -> ActuatorFit:
    """Check ``spec`` against :class:`~.dynamics.DynamicsResult` s (module docstring)."""
    notes: dict = {}
    bad = [r.first_problem() for r in results if not np.all(r.ok)]
    if bad:
        notes["actuators_fit"] = "infeasible motion sample: " + bad[0]
    ok = [r.ok for r in results]
    fmax = max((float(np.max(np.abs(r.force[k]))) for r, k in zip(results, ok) if k.any()),
               default=math.nan)
    vmax = max((float(np.max(np.abs(r.qdot[k]))) for r, k in zip(results, ok) if k.any()),
               default=math.nan)
    fm = 100 * (1 - fmax / spec.force) if math.isfinite(fmax) else None
    sm = 100 * (1 - vmax / spec.speed) if math.isfinite(vmax) else None
    tm = None
    if spec.has_curve:
        peak = max(T for _, T in spec.torque_speed)
        worst = math.inf
        for r, k in zip(results, ok):
            if k.any():
                om, T = motor_demand(spec, r.force[k], r.qdot[k])
                worst = min(worst, float(np.min(spec.available_torque(om) - T)))
        tm = 100 * worst / peak if math.isfinite(worst) else None
    else:
        notes["actuator_torque_speed_margin"] = f"{spec.name}: no torque–speed curve"
    stm = None
    if spec.stroke is not None:
        used = [r.q[k] for r, k in zip(results, ok) if k.any()]
        if used:
            q = np.concatenate(used)
            stm = float(spec.stroke - np.max(q.max(axis=0) - q.min(axis=0)))
            if spec.kind == "rotary":
                stm = math.degrees(stm)
    else:
        notes["actuator_stroke_margin"] = f"{spec.name}: no stroke given"
    margins = [m for m in (fm, sm, tm, stm) if m is not None]
    fits = not bad and fm is not None and all(m >= 0 for m in margins)
    if not fits and not bad:
        rotary = spec.kind == "rotary"
        named = (("torque" if rotary else "force", fm, "%"), ("speed", sm, "%"),
                 ("torque–speed", tm, "%"), ("angle" if rotary else "stroke", stm,
                                             "deg" if rotary else "mm"))
        over = [f"{n} margin {m:.3g} {u}" for n, m, u in named if m is not None and m < 0]
        notes["actuators_fit"] = f"{spec.name} exceeded: " + (", ".join(over) or
                                                               "force margin undefined")
    return ActuatorFit(bool(fits), fm, sm, tm, stm, notes)
