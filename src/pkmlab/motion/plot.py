"""Actuator values against time, in the style of Hopkins & Williams (2002), Fig. 13."""

from __future__ import annotations

import logging
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from .check import TrajectoryReport
from .paper import MM_PER_IN as _MM_PER_IN

log = logging.getLogger(__name__)

__all__ = ["plot_actuators", "actuators_figure"]


def plot_actuators(report: TrajectoryReport, path: str | Path, title: str | None = None,
                   phases: Sequence[tuple[str, float, float]] | None = None) -> Path:
    """Actuator values against time, as the paper's Fig. 13 (leg length in inches vs s).

    Draws one line per actuator (left axis in inches, right axis the same in mm; a rotary
    actuator's crank angle in degrees, :func:`pkmlab.units.actuator_display`), the stroke
    limits as dashed horizontal lines labelled in both units, samples whose status is not
    ``"ok"`` as red marks, and optionally the motion phases (e.g. :func:`paper_motion_phases`)
    as labelled bands. Writes a PNG with matplotlib's Agg canvas (pyplot and the global backend
    are not touched) and returns the path.
    """
    path = Path(path)
    fig = actuators_figure(report, title, phases)
    fig.savefig(path, format="png")
    log.debug("wrote %s", path)
    return path


def actuators_figure(report: TrajectoryReport, title: str | None = None,
                     phases: Sequence[tuple[str, float, float]] | None = None):
    """The matplotlib Figure :func:`plot_actuators` writes (Agg canvas)."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    t = np.asarray(report.t)
    d = report.display
    # linear: inches on the left (the paper's axis), mm on the right; rotary: degrees only
    scale = d.value_scale if d.rotary else 1.0 / _MM_PER_IN
    q_in = np.asarray(report.q) * scale
    fig = Figure(figsize=(10, 5), dpi=120)
    FigureCanvasAgg(fig)
    ax = fig.add_subplot(1, 1, 1)
    for i, name in enumerate(report.actuator_names):
        ax.plot(t, q_in[:, i], lw=1.2, label=name)
    lim = np.asarray(report.actuator_limits)
    levels = sorted({(float(v), "min" if j == 0 else "max") for j in range(2)
                     for v in lim[:, j]})
    for v, side in levels:
        ax.axhline(v * scale, color="k", ls="--", lw=0.9)
        text = (f"{d.value} {side} {v * scale:.4g} {d.value_unit}" if d.rotary else
                f"stroke {side} {v * scale:.3g} in ({v:.4g} mm)")
        ax.annotate(text, xy=(1.0, v * scale), xycoords=("axes fraction", "data"),
                    xytext=(-4, 3 if side == "max" else -11), textcoords="offset points",
                    ha="right", fontsize=8)
    bad = ~np.asarray(report.ok)
    if bad.any():
        # every actuator value of a failing sample; samples without a solution as bottom ticks
        tb = np.repeat(t[bad], q_in.shape[1])
        qb = q_in[bad].ravel()
        fin = np.isfinite(qb)
        ax.plot(tb[fin], qb[fin], "x", color="red", ms=5, mew=1.5, label="status not ok")
        none = bad & ~np.any(np.isfinite(q_in), axis=1)
        if none.any():
            ax.plot(t[none], np.zeros(int(none.sum())), "|", color="red", ms=10,
                    transform=ax.get_xaxis_transform(), label="no solution")
    if phases:
        for n, (name, a, b) in enumerate(phases):
            if n % 2 == 0:
                ax.axvspan(a, b, color="0.92", zorder=0)
            ax.annotate(name.replace("theta_", "θ"), xy=(0.5 * (a + b), 1.0),
                        xycoords=("data", "axes fraction"), xytext=(0, 2),
                        textcoords="offset points", ha="center", va="bottom", fontsize=8)
    ax.set_xlabel("Time (s)")
    if d.rotary:
        ax.set_ylabel(d.value_name)
    else:
        ax.set_ylabel("Leg length L (in.)")
        lo_in, hi_in = ax.get_ylim()
        ax2 = ax.twinx()
        ax2.set_ylim(lo_in * _MM_PER_IN, hi_in * _MM_PER_IN)
        ax2.set_ylabel("Leg length L (mm)")
    ax.set_xlim(t[0], t[-1])
    ax.legend(loc="upper center", bbox_to_anchor=(0.5, -0.12), fontsize=8, ncol=8,
              frameon=False)
    if title:
        ax.set_title(title, pad=14 if phases else 6)
    fig.tight_layout()
    return fig
