"""Trajectories: the paper's Cartesian test motion, CSV input, a stroke/speed/force check, plots.

Units follow the rest of pkmlab: poses are ``(x, y, z, θx, θy, θz)`` of the tool frame in the
base frame in mm and rad (Z-Y-X Euler angles, :mod:`pkmlab.poses`), times in s, actuator values
in mm, actuator speeds in mm/s, forces in N and moments in N·mm.

Modules, one concept each:

* :mod:`.motions` — :func:`paper_motion` (Hopkins & Williams 2002, Sect. 6 / Fig. 13),
  :func:`paper_motion_phases`, :func:`lobe_profile` and :func:`load_csv`;
* :mod:`.check` — :func:`check_trajectory` → :class:`TrajectoryReport` (actuator values,
  speeds, static forces, κ with its characteristic length, first violation of each limit,
  stroke margins);
* :mod:`.plot` — :func:`plot_actuators`, the paper's Fig. 13 style (Agg canvas; pyplot and the
  global backend are not touched).
"""

from .check import TrajectoryReport, Violation, check_trajectory
from .paper import (
    CSV_COLUMNS,
    PAPER_AXES,
    load_csv,
    lobe_profile,
    paper_motion,
    paper_motion_phases,
)
from .plot import plot_actuators

__all__ = [
    "PAPER_AXES",
    "CSV_COLUMNS",
    "Violation",
    "TrajectoryReport",
    "lobe_profile",
    "paper_motion_phases",
    "paper_motion",
    "load_csv",
    "check_trajectory",
    "plot_actuators",
]
