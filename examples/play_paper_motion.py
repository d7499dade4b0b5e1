"""Play Hopkins & Williams' test motion (2002, Fig. 13) on a design exported to MuJoCo.

    pkmlab export results/hopkins-6psu-redesign/designs/01-*/mechanism.yaml --format mjcf -o sim
    python examples/play_paper_motion.py results/hopkins-6psu-redesign/designs/01-*/mechanism.yaml \
        sim/*.mjcf.xml [--amplitude-mm 25] [--amplitude-deg 15] [--view]

The position servos follow pkmlab's inverse kinematics of the motion (``ctrl`` interpolated
at MuJoCo's time step); the script prints how closely the simulated tool follows the
commanded pose. ``--view`` opens MuJoCo's viewer (the full ``mujoco`` package and a display;
the core bindings ``mujoco-core`` that the tests use have no viewer). Poses the design cannot
reach are reported and the motion stops there.
"""

from __future__ import annotations

import argparse
import math

import mujoco
import numpy as np

import pkmlab
from pkmlab.export.roundtrip import actuator_targets
from pkmlab.motion import paper_motion
from pkmlab.poses import log_so3


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("mechanism", help="the design's mechanism YAML")
    ap.add_argument("mjcf", help="its MJCF export (pkmlab export --format mjcf)")
    ap.add_argument("--amplitude-deg", type=float, default=30.0, help="rotation lobes (the "
                    "paper's ±30°; a design with a smaller capability needs less)")
    ap.add_argument("--amplitude-mm", type=float, default=50.8, help="translation lobes")
    ap.add_argument("--view", action="store_true", help="open MuJoCo's viewer")
    a = ap.parse_args()

    mech = pkmlab.load_mechanism(a.mechanism)
    motion = paper_motion(mech, amplitude_mm=a.amplitude_mm,
                          amplitude_rad=math.radians(a.amplitude_deg))
    t, X = motion.t, motion.poses
    q = actuator_targets(mech, X)
    bad = np.flatnonzero(np.isnan(q).any(axis=1))
    if len(bad):
        print(f"the design cannot reach the motion from t = {t[bad[0]]:.2f} s "
              f"(pose {np.round(X[bad[0]], 3)}): playing up to there")
        t, X, q = t[:bad[0]], X[:bad[0]], q[:bad[0]]
    model = mujoco.MjModel.from_xml_path(a.mjcf)
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, 0)
    site = model.site("tool").id
    viewer = None
    if a.view:
        from mujoco import viewer as mjviewer

        viewer = mjviewer.launch_passive(model, data)
    worst_mm = worst_rad = 0.0
    p, R = mech._frames(X)
    for k in range(len(t) - 1):
        while data.time < t[k + 1]:
            s = (data.time - t[k]) / (t[k + 1] - t[k])
            data.ctrl[:] = (1 - s) * q[k] + s * q[k + 1]
            mujoco.mj_step(model, data)
        worst_mm = max(worst_mm, float(np.linalg.norm(data.site_xpos[site] * 1e3 - p[k + 1])))
        worst_rad = max(worst_rad, float(np.linalg.norm(
            log_so3(data.site_xmat[site].reshape(3, 3).T @ R[k + 1]))))
        if viewer is not None:
            viewer.sync()
    print(f"played {t[-1]:.1f} s of the paper's motion ({len(t)} poses) with gravity: "
          f"worst tool tracking error {worst_mm:.3f} mm, {math.degrees(worst_rad):.3f}°")


if __name__ == "__main__":
    main()
