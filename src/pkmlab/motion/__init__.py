"""Motions: the one motion subsystem of pkmlab.

Units follow the rest of pkmlab: poses are ``(x, y, z, θx, θy, θz)`` of the tool frame in the
base frame in mm and rad (Z-Y-X Euler angles, :mod:`pkmlab.poses`), times in s, actuator values
in mm (rad for rotary actuators), forces in N and moments in N·mm.

Modules, one concept each:

* :mod:`.motions` — :class:`Motion` (poses with their twist and its derivative),
  :func:`sinusoid_motion`, :func:`differentiate`;
* :mod:`.paper` — :func:`paper_motion` (Hopkins & Williams 2002, Sect. 6 / Fig. 13),
  :func:`paper_motion_phases`, :func:`lobe_profile`;
* :mod:`.csvfile` — :func:`load_motion_csv`, the one reader of recorded motions and
  trajectory files;
* :mod:`.check` — :func:`check_trajectory` → :class:`TrajectoryReport` (actuator values,
  speeds, static forces, κ with its characteristic length, first violation of each limit,
  stroke margins);
* :mod:`.payload` and :mod:`.dynamics` — mass properties and Newton–Euler inverse dynamics
  of the platform;
* :mod:`.plot` — :func:`plot_actuators`, the paper's Fig. 13 style (Agg canvas; pyplot and the
  global backend are not touched).
"""

from .check import TrajectoryFit, TrajectoryReport, Violation, check_trajectory, trajectory_fit
from .csvfile import CSV_COLUMNS, load_motion_csv
from .motions import Motion, differentiate, sinusoid_motion
from .paper import PAPER_AXES, lobe_profile, paper_motion, paper_motion_phases
from .plot import plot_actuators

__all__ = [
    "PAPER_AXES",
    "CSV_COLUMNS",
    "Motion",
    "Violation",
    "TrajectoryReport",
    "lobe_profile",
    "paper_motion_phases",
    "paper_motion",
    "sinusoid_motion",
    "differentiate",
    "load_motion_csv",
    "check_trajectory",
    "TrajectoryFit",
    "trajectory_fit",
    "plot_actuators",
]
