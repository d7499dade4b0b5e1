"""Actuator plots over a required motion, with the actuator's limits drawn.

Built on :class:`matplotlib.figure.Figure` (no pyplot, no global backend); the caller saves
the figure (``fig.savefig(path)``). Nothing here computes kinematics: it draws a
:class:`~.dynamics.DynamicsResult`. :func:`actuator_plot_data` is what the figure draws, as
plain numbers (the exported ``actuators.json`` holds it, so a reader or a test can check the
limit lines against the catalogue entry).
"""

from __future__ import annotations

import math

import numpy as np

from ..motion.dynamics import DynamicsResult
from .actuators import ActuatorSpec, motor_demand

__all__ = ["actuator_figure", "actuator_plot_data"]

_RPM = 60 / (2 * math.pi)


def _units(result: DynamicsResult) -> tuple[str, str, float, float]:
    """(force label, speed label, force scale, speed scale) for display: N and mm/s for
    linear actuators; N·m (from N·mm) and deg/s (from rad/s) for rotary ones."""
    if result.unit == "rad":
        return "torque (N·m)", "speed (deg/s)", 1e-3, 180 / math.pi
    return "force (N)", "speed (mm/s)", 1.0, 1.0


def actuator_plot_data(result: DynamicsResult, actuator: ActuatorSpec | None = None) -> dict:
    """The numbers :func:`actuator_figure` draws, in its display units: the limit lines
    (``force_limit``, ``speed_limit``), the peaks per actuator and, with a torque–speed curve,
    the curve (rpm, N·m) and the smallest margin to it (N·m)."""
    fl, sl, fs, ss = _units(result)
    ok = result.ok
    out: dict = {"motion": result.motion, "force_label": fl, "speed_label": sl,
                 "samples": int(len(result.t)), "feasible_samples": int(np.sum(ok)),
                 "peak_force": (np.max(np.abs(result.force[ok]), axis=0) * fs).tolist()
                 if ok.any() else None,
                 "peak_speed": (np.max(np.abs(result.qdot[ok]), axis=0) * ss).tolist()
                 if ok.any() else None,
                 "first_problem": result.first_problem()}
    if actuator is not None:
        out.update(actuator=actuator.name, force_limit=actuator.force * fs,
                   speed_limit=actuator.speed * ss)
        if actuator.has_curve:
            w, T = np.array(actuator.torque_speed).T
            out["curve_rpm_Nm"] = np.column_stack([w * _RPM, T / 1e3]).tolist()
            if ok.any():
                om, tq = motor_demand(actuator, result.force[ok], result.qdot[ok])
                out["curve_margin_Nm"] = float(np.min(actuator.available_torque(om) - tq)) / 1e3
    return out


def actuator_figure(result: DynamicsResult, actuator: ActuatorSpec | None = None):
    """Force (torque), speed and, with a torque–speed curve, motor torque against motor speed
    for the six actuators along one motion; limits dashed. Returns a Figure."""
    from matplotlib.figure import Figure

    data = actuator_plot_data(result, actuator)
    fl, sl, fs, ss = _units(result)
    curve = actuator is not None and actuator.has_curve
    fig = Figure(figsize=(11, 8.5 if curve else 6), layout="constrained")
    axes = fig.subplots(3 if curve else 2, 1)
    t = result.t
    for i, name in enumerate(result.actuator_names):
        axes[0].plot(t, result.force[:, i] * fs, lw=1, label=name)
        axes[1].plot(t, result.qdot[:, i] * ss, lw=1, label=name)
    axes[0].set_ylabel(fl)
    axes[1].set_ylabel(sl)
    axes[1].set_xlabel("t (s)")
    if actuator is not None:
        for ax, lim in ((axes[0], data["force_limit"]), (axes[1], data["speed_limit"])):
            for s in (-1, 1):
                ax.axhline(s * lim, color="k", ls="--", lw=1, label="limit" if s > 0 else None)
    axes[0].legend(ncol=7, fontsize=8, loc="lower right")
    title = f"{result.motion}: actuator {fl.split()[0]} and speed"
    if actuator is not None:
        title += f" — {actuator.name} (limits dashed)"
    if data["first_problem"]:
        title += f"\ninfeasible samples (NaN, not drawn); first: {data['first_problem']}"
    axes[0].set_title(title, fontsize=10)
    if curve:
        ax = axes[2]
        w, T = np.array(data["curve_rpm_Nm"]).T
        w, T = np.append(w, w[-1]), np.append(T, 0.0)     # no torque beyond the curve
        ax.plot(w, T, "k--", lw=1.2, label="available (torque–speed curve)")
        ok = result.ok
        if ok.any():
            om, tq = motor_demand(actuator, result.force[ok], result.qdot[ok])
            ax.plot(om.ravel() * _RPM, tq.ravel() / 1e3, ".", ms=1.5,
                    label="required (all actuators)")
        ax.set_xlabel("motor speed (rpm)")
        ax.set_ylabel("motor torque (N·m)")
        ax.set_xlim(left=0)
        ax.set_ylim(bottom=0)
        ax.legend(fontsize=8)
        if "curve_margin_Nm" in data:
            ax.set_title(f"torque–speed: smallest margin {data['curve_margin_Nm']:.4g} N·m",
                         fontsize=9)
    return fig
