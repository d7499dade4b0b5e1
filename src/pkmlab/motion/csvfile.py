"""Recorded motions and trajectories from CSV: the one motion reader of pkmlab.

``pkmlab trajectory --csv`` and a requirement study's ``motions: - file:`` read the same format
with the same meaning:

* columns ``t, x, y, z, theta_x, theta_y, theta_z`` in any order: time in s, the tool position
  in mm and its Z-Y-X Euler angles in deg. The reader returns them as written; their frame is
  stated where the file is used, with the same two choices and the same meaning: absolute
  base-frame poses (``pkmlab trajectory --csv F``; a study's ``frame: base``) or offsets from
  the nominal pose, added coordinate by coordinate (``--csv F --relative``; ``frame:
  nominal``). A study must state its file's frame;
* optionally all six ``<coordinate>_dot`` columns (mm/s, deg/s), and with them all six
  ``<coordinate>_ddot`` columns (mm/s², deg/s²); acceleration columns without velocity columns
  are refused, not ignored;
* blank lines and ``#`` lines are skipped; size, rows and encodings as
  :func:`pkmlab.tables.read_table` (which never shows the file's contents in an error).

Without derivative columns, velocities and accelerations come from
:func:`~pkmlab.motion.motions.differentiate` (Savitzky–Golay) when asked for.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np

from ..errors import ParameterError, Shown
from ..limits import LENGTH_MAX_MM, MOTION_TIME_S
from ..tables import read_table, shown
from .motions import POSE_COLUMNS, Motion, differentiate, make_motion

__all__ = ["CSV_COLUMNS", "load_motion_csv"]

#: the required columns of a motion CSV (s, mm, deg)
CSV_COLUMNS: tuple[str, ...] = ("t", *POSE_COLUMNS)
_DOT = tuple(f"{c}_dot" for c in POSE_COLUMNS)
_DDOT = tuple(f"{c}_ddot" for c in POSE_COLUMNS)
_DEG = np.array([1.0, 1.0, 1.0, math.pi / 180, math.pi / 180, math.pi / 180])


def load_motion_csv(path: str | Path, name: str | None = None, window: float = 0.05,
                    polyorder: int = 3, field: str = "file", *,
                    derivatives: bool = True) -> Motion:
    """Read a motion (see the module docstring).

    Args:
        path: the CSV file.
        name: the motion's name (default: the file's stem).
        window, polyorder: the Savitzky–Golay fit used when the file has no derivative
            columns (window in s).
        field: the input that named the file, shown in every error with the file and line.
        derivatives: False to read poses only (``twist`` and ``accel`` are then None and the
            time need not be uniform).

    Raises:
        ParameterError: missing, unknown or duplicate columns; acceleration columns without
            velocity columns; a cell that is not a finite number; time not strictly
            increasing or beyond ±1e7 s; too few rows (at least 2, and ``polyorder + 2`` to
            differentiate).
    """
    what = "a CSV file with the columns " + ",".join(CSV_COLUMNS) + " (s, mm, deg)"
    table = read_table(path, field, what=what)
    header, here = table.header, table.where()
    known = (*CSV_COLUMNS, *_DOT, *_DDOT)
    unknown = [h for h in header if h not in known]
    if unknown:
        raise ParameterError(f"{field} header", f"columns from {list(known)}",
                             Shown("unknown " + ", ".join(shown(h) for h in unknown)),
                             where=here)
    missing = [c for c in CSV_COLUMNS if c not in header]
    if missing:
        raise ParameterError(f"{field} header", "the columns " + ",".join(CSV_COLUMNS)
                             + " (s, mm, deg)", f"missing {missing}", where=here)
    have = {g: [c for c in g if c in header] for g in (_DOT, _DDOT)}
    for group, cols in have.items():
        if cols and len(cols) != len(group):
            raise ParameterError(f"{field} header", f"all or none of {list(group)}",
                                 f"only {cols}", where=here)
    if have[_DDOT] and not have[_DOT]:
        raise ParameterError(f"{field} header", "the velocity columns <coordinate>_dot "
                             "whenever the acceleration columns <coordinate>_ddot are given",
                             "acceleration columns only", where=here)
    t = table.column("t")
    need = max(2, polyorder + 2) if derivatives and not have[_DOT] else 2
    if len(t) < need:
        raise ParameterError(field, f"at least {need} data rows", len(t), where=str(path))
    big = np.flatnonzero(np.abs(t) > MOTION_TIME_S)
    if big.size:
        raise ParameterError(f"{field} column 't'", f"times within ±{MOTION_TIME_S:g} s",
                             float(t[big[0]]), where=table.where(int(big[0])))
    bad = np.flatnonzero(np.diff(t) <= 0)
    if bad.size:
        k = int(bad[0]) + 1
        raise ParameterError(f"{field} column 't'", f"strictly increasing time (> {t[k - 1]:g}"
                             " s on the previous row)", float(t[k]), where=table.where(k))
    poses = np.stack([table.column(c) for c in POSE_COLUMNS], axis=1)
    # lengths within LENGTH_MAX_MM and angles within as many degrees: beyond, the derivatives
    # and the inverse dynamics overflow (a 1e305 mm cell used to give infinite accelerations)
    far = np.abs(poses) > LENGTH_MAX_MM
    if np.any(far):
        k, j = (int(v) for v in np.argwhere(far)[0])
        unit = "mm" if j < 3 else "deg"
        raise ParameterError(f"{field} column {POSE_COLUMNS[j]!r}", f"values within "
                             f"±{LENGTH_MAX_MM:g} {unit}", float(poses[k, j]),
                             where=table.where(k))
    poses = poses * _DEG
    name = name or Path(path).stem
    if not derivatives:
        return Motion(name, t.copy(), poses, None, None, "none")
    if have[_DDOT]:
        d1 = np.stack([table.column(c) for c in _DOT], axis=1) * _DEG
        d2 = np.stack([table.column(c) for c in _DDOT], axis=1) * _DEG
        return _finite(make_motion(name, t, poses, d1, d2, "columns"), field, path)
    s1, s2, n = differentiate(t, poses, window, polyorder, field=f"{field} (smoothing)")
    how = f"savgol(window={n} samples = {n * float(np.mean(np.diff(t))):.4g} s, " \
          f"polyorder={polyorder})"
    if have[_DOT]:
        s1 = np.stack([table.column(c) for c in _DOT], axis=1) * _DEG
        how = "velocity columns; acceleration " + how
    return _finite(make_motion(name, t, poses, s1, s2, how), field, path)


def _finite(motion: Motion, field: str, path) -> Motion:
    """``motion``, refused when its twist or acceleration overflowed."""
    if not (np.all(np.isfinite(motion.twist)) and np.all(np.isfinite(motion.accel))):
        raise ParameterError(field, "a motion whose velocities and accelerations are finite "
                             "(smoother poses or smaller derivative columns)", "an overflow",
                             where=str(path))
    return motion
