"""Requirements benchmark: task containment against the workspace itself, inverse dynamics.

Prints, in one run:

* the time of ``task_contained`` for a 50 × 50 × 50 mm box about the nominal pose at the ±15°
  simultaneous Euler box (7×7×7 orientations) on the Hopkins & Williams 6-PSU and on the
  Kotlarski 6-UPS, and the time of the dexterous workspace computation itself (same
  orientation set, 2.5 mm) — the target is ≤ 2× the workspace (median of repeats);
* the time of ``task_margins`` (the bisections behind ``task_margin`` and
  ``task_orientation_margin``) on the same request;
* inverse dynamics throughput: trajectory samples per second of ``inverse_dynamics`` on a
  10⁶-sample sinusoidal motion with a 150 kg payload (6-UPS and 6-PSU) — target ≥ 10⁶/s —
  as wall-clock rate and as rate per CPU-second (process time over all threads: what one
  core delivers, nearly independent of how loaded the machine is), against a plain NumPy
  baseline measured in the same run (the Jacobian by the family's NumPy formula, the wrench
  by :func:`~pkmlab.motion.dynamics.platform_wrench`, ``numpy.linalg.solve`` of
  ``Jᵀ f = w``) on the first 2·10⁵ samples.

Run: ``.venv/bin/python benchmarks/bench_requirements.py``.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np
from _timing import timed  # noqa: E402 - the benchmarks folder is on sys.path

from pkmlab import load_mechanism
from pkmlab.motion.dynamics import inverse_dynamics, platform_wrench
from pkmlab.motion.motions import sinusoid_motion
from pkmlab.motion.payload import MassProperties
from pkmlab.poses import as_frames
from pkmlab.requirements.task import TaskRegion, task_contained, task_margins
from pkmlab.workspaces import OrientationSet, workspace

ROOT = Path(__file__).resolve().parents[1]
MECH = ROOT / "studies" / "mechanisms"
BOX = OrientationSet.box(np.radians([15.0, 15.0, 15.0]), "simultaneous", samples=7)



def _numpy_jacobian(mech, p, R):
    """The families' former NumPy Jacobians (psu6: [a, r × a]/a_z; ups6: [n, r × n])."""
    r = np.einsum("nij,kj->nki", R, mech.tool_points)
    a = p[:, None, :] + r - mech.base_points
    if mech.family == "psu6":
        a[..., 2] = np.sqrt(mech.link_length ** 2 - a[..., 0] ** 2 - a[..., 1] ** 2)
        return np.concatenate([a, np.cross(r, a)], axis=-1) / a[..., 2:3]
    n = a / np.linalg.norm(a, axis=-1)[..., None]
    return np.concatenate([n, np.cross(r, n)], axis=-1)


def _numpy_dynamics(mech, motion, body, n):
    p, R = as_frames(motion.poses[:n])
    ik = mech.inverse((p, R))
    J = _numpy_jacobian(mech, p, R)
    w = platform_wrench(p, R, motion.twist[:n], motion.accel[:n], body, mech.tool_offset)
    f = np.linalg.solve(np.swapaxes(J, 1, 2), w[..., None])[..., 0]
    return ik, f, np.einsum("nij,nj->ni", J, motion.twist[:n])


def _cpu_rate(fn, samples: int, repeats: int = 3) -> float:
    """Samples per CPU-second (process time, all threads), best of ``repeats``."""
    best = np.inf
    for _ in range(repeats):
        c = time.process_time()
        fn()
        best = min(best, time.process_time() - c)
    return samples / best


def main() -> None:
    task = TaskRegion("box", size=(50.0, 50.0, 50.0))
    for name in ("hopkins-williams-6psu", "gough-stewart-6ups"):
        mech = load_mechanism(MECH / f"{name}.yaml")
        t_ws, res = timed(lambda mech=mech: workspace(mech, "dexterous", BOX, 2.5))
        t_task, chk = timed(lambda mech=mech: task_contained(mech, task, BOX), 21)
        t_marg, m = timed(lambda mech=mech: task_margins(mech, task, BOX), 3)
        print(f"{name}: task_contained {t_task * 1e3:.2f} ms ({chk.method}, "
              f"contained={chk.contained}) vs dexterous workspace {t_ws * 1e3:.1f} ms "
              f"(volume {res.volume / 1e3:.1f} cm³): ratio {t_task / t_ws:.3f} (target ≤ 2); "
              f"task_margins {t_marg * 1e3:.1f} ms (margin {m['margin_mm']} mm, orientation "
              f"{m['orientation_margin_deg']} deg)")
    body = MassProperties(150.0, np.array([10.0, 20.0, 300.0]),
                          np.array([[2.5e7, 1e5, 0], [1e5, 2.2e7, 0], [0, 0, 1.2e7]]))
    for name, amp in (("gough-stewart-6ups", [20, 20, 20, 0.1, 0.1, 0.1]),
                      ("hopkins-williams-6psu", [5, 5, 5, 0.05, 0.05, 0.05])):
        mech = load_mechanism(MECH / f"{name}.yaml")
        motion = sinusoid_motion(mech, amp, [1, 1.3, 0.7, 0.5, 0.9, 1.1], duration=10.0,
                                 rate=100_000)
        t, r = timed(lambda mech=mech, motion=motion: inverse_dynamics(mech, motion, body), 3)
        cpu = _cpu_rate(lambda mech=mech, motion=motion: inverse_dynamics(mech, motion, body),
                        len(motion.t))
        nb = 200_000
        def base(mech=mech, motion=motion, nb=nb):
            return _numpy_dynamics(mech, motion, body, nb)
        tb, _ = timed(base, 3)
        cpub = _cpu_rate(base, nb)
        print(f"{name}: inverse dynamics {len(motion.t) / t / 1e6:.2f} M samples/s wall, "
              f"{cpu / 1e6:.2f} M samples per CPU-second ({len(motion.t)} samples in "
              f"{t:.3f} s, {int(np.sum(r.ok))} feasible; target ≥ 1 M/s); NumPy baseline "
              f"{nb / tb / 1e6:.2f} M/s wall, {cpub / 1e6:.2f} M per CPU-s: ratio "
              f"{(len(motion.t) / t) / (nb / tb):.1f}× wall, {cpu / cpub:.1f}× CPU")


if __name__ == "__main__":
    main()
