"""Actuator plots over a required motion, with the actuator's limits drawn.

Built on :class:`matplotlib.figure.Figure` (no pyplot, no global backend); the caller saves
the figure (``fig.savefig(path)``). Nothing here computes kinematics: it draws a
:class:`~.dynamics.DynamicsResult`.
"""

from __future__ import annotations

import math

import numpy as np

from .actuators import ActuatorSpec
from .dynamics import DynamicsResult

__all__ = ["actuator_figure"]


def actuator_figure(result: DynamicsResult, actuator: ActuatorSpec | None = None):
    """Force, speed and (with a torque–speed curve) motor torque against speed for the six
    actuators along one motion; limits dashed. Returns a Figure."""
    from matplotlib.figure import Figure

    curve = actuator is not None and bool(actuator.torque_speed) and actuator.lead
    fig = Figure(figsize=(11, 8 if curve else 6), layout="constrained")
    axes = fig.subplots(3 if curve else 2, 1)
    t = result.t
    for i, name in enumerate(result.actuator_names):
        axes[0].plot(t, result.force[:, i], lw=1, label=name)
        axes[1].plot(t, result.qdot[:, i], lw=1, label=name)
    axes[0].set_ylabel("force (N)")
    axes[1].set_ylabel("speed (mm/s)")
    axes[1].set_xlabel("t (s)")
    if actuator is not None:
        for ax, lim in ((axes[0], actuator.force), (axes[1], actuator.speed)):
            for s in (-1, 1):
                ax.axhline(s * lim, color="k", ls="--", lw=1)
    axes[0].legend(ncol=6, fontsize=8)
    title = f"{result.motion}: actuator force and speed"
    if actuator is not None:
        title += f" — {actuator.name} (limits dashed)"
    axes[0].set_title(title)
    if curve:
        ax = axes[2]
        w, T = np.array(actuator.torque_speed).T
        rpm = 60 / (2 * math.pi)
        ax.plot(w * rpm, T / 1e3, "k--", lw=1, label="available")
        om = 2 * math.pi * np.abs(result.qdot) / actuator.lead
        tq = np.abs(result.force) * actuator.lead / (2 * math.pi * actuator.efficiency)
        ax.plot(om.ravel() * rpm, tq.ravel() / 1e3, ".", ms=1.5, label="required")
        ax.set_xlabel("motor speed (rpm)")
        ax.set_ylabel("motor torque (N·m)")
        ax.legend(fontsize=8)
    return fig
