"""The MJCF round trip: load pkmlab's MJCF export in MuJoCo (``mujoco``, the ``sim`` extra;
the core bindings, no display needed), drive it to poses and compare with pkmlab.

:func:`drive` moves the actuators along the straight pose path from the exported pose to the
target (``ctrl`` = pkmlab's IK of the interpolated pose, smoothstep in time) and lets the
model settle by simulation: gravity off, contacts off, the file's own solver settings.
:func:`project` then, optionally, closes the loops exactly with the actuated joints held:
Gauss-Newton on MuJoCo's own equality residuals and Jacobian (``efc_pos``, ``efc_J``).
:func:`compare` measures the tool site against pkmlab's pose, every loop gap (from the
equality anchors, in the base frame), and every joint anchor against the joint centres that
``mech.legs(pose)`` declares, which also shows the working mode (every leg's assembly).
:func:`sag` holds the exported pose with gravity on and reports how far the tool and the
loops give. Nothing here prints or writes files.
"""

from __future__ import annotations

import numpy as np

from ..poses import log_so3
from .mjcf import M, mjcf_text

__all__ = ["load", "drive", "project", "compare", "sag", "actuator_targets",
           "orientation_defined"]


def _mujoco():
    import mujoco

    return mujoco


def load(mech, pose=None, mass=None, *, xml: str | None = None):
    """``(model, data)`` of the MJCF export of ``mech`` (or of ``xml``), reset to ``home``."""
    mj = _mujoco()
    model = mj.MjModel.from_xml_string(xml if xml is not None else mjcf_text(mech, pose, mass))
    data = mj.MjData(model)
    mj.mj_resetDataKeyframe(model, data, 0)
    mj.mj_forward(model, data)
    return model, data


def actuator_targets(mech, poses) -> np.ndarray:
    """pkmlab's IK ``(N, L)`` in MuJoCo's units (m or rad), NaN where invalid."""
    ik = mech.inverse(np.atleast_2d(poses))
    q = ik.q * (M if mech.actuator_unit == "mm" else 1.0)
    q[~ik.valid] = np.nan
    return q


def drive(mech, model, data, pose, *, start=None, ramp: float = 0.3, settle: float = 4.0,
          gravity: bool = False, contacts: bool = False) -> None:
    """Simulate from the current state (at pose ``start``, default the nominal pose):
    ``ctrl`` follows pkmlab's IK along the pose path to ``pose`` over ``ramp`` s, then
    ``settle`` s more."""
    mj = _mujoco()
    if not gravity:
        model.opt.gravity[:] = 0.0
    if not contacts:
        model.opt.disableflags |= mj.mjtDisableBit.mjDSBL_CONTACT
    start = np.asarray(mech.nominal_pose if start is None else start, dtype=float)
    pose = np.asarray(pose, dtype=float)
    n_ramp = max(1, int(round(ramp / model.opt.timestep)))
    s = np.linspace(0.0, 1.0, n_ramp + 1)[1:]
    s = s * s * (3 - 2 * s)
    path = actuator_targets(mech, start + s[:, None] * (pose - start))
    if np.isnan(path).any():
        raise ValueError("the straight pose path leaves pkmlab's IK (invalid pose on it)")
    for q in path:
        data.ctrl[:] = q
        mj.mj_step(model, data)
    for _ in range(int(round(settle / model.opt.timestep))):
        mj.mj_step(model, data)


def _actuated_dofs(model) -> np.ndarray:
    return np.array([model.jnt_dofadr[model.actuator_trnid[i, 0]] for i in range(model.nu)])


def project(model, data, q=None, *, iterations: int = 30, tol: float = 1e-15) -> int:
    """Close the loops with the actuated joints held at ``q`` (m or rad; default where they
    are): Gauss-Newton on MuJoCo's equality residuals, least-norm steps; returns the
    iterations used."""
    mj = _mujoco()
    model.opt.jacobian = mj.mjtJacobian.mjJAC_DENSE
    act = _actuated_dofs(model)
    if q is not None:
        adr = [model.jnt_qposadr[model.actuator_trnid[i, 0]] for i in range(model.nu)]
        data.qpos[adr] = q
    for it in range(iterations):
        mj.mj_forward(model, data)
        rows = data.efc_type == mj.mjtConstraint.mjCNSTR_EQUALITY
        r = data.efc_pos[rows]
        if not len(r) or np.max(np.abs(r)) < tol:
            return it
        J = data.efc_J.reshape(data.nefc, model.nv)[rows].copy()
        J[:, act] = 0.0
        dq = -np.linalg.lstsq(J, r, rcond=None)[0]
        mj.mj_integratePos(model, data.qpos, dq, 1.0)
    mj.mj_forward(model, data)
    return iterations


def loop_gaps(model, data) -> np.ndarray:
    """Each equality's position gap (mm), in equality order: a connect's two anchors (one on
    each body, from ``eq_data``) in the base frame; a weld's translational residual."""
    mj = _mujoco()
    gaps = []
    for e in range(model.neq):
        if model.eq_type[e] == mj.mjtEq.mjEQ_CONNECT:
            b1, b2 = model.eq_obj1id[e], model.eq_obj2id[e]
            x1 = data.xpos[b1] + data.xmat[b1].reshape(3, 3) @ model.eq_data[e, 0:3]
            x2 = data.xpos[b2] + data.xmat[b2].reshape(3, 3) @ model.eq_data[e, 3:6]
            gaps.append(np.linalg.norm(x1 - x2) / M)
        else:
            rows = np.flatnonzero((data.efc_type == mj.mjtConstraint.mjCNSTR_EQUALITY)
                                  & (data.efc_id == e))
            gaps.append(np.linalg.norm(data.efc_pos[rows[:3]]) / M)
    return np.array(gaps)


def orientation_defined(mech) -> bool:
    """True when the platform's orientation is a property of the mechanism: its joint centres
    (``mech.legs()`` at the nominal pose) are not all on one line. A platform whose joints meet
    at one point (the five-bar's end point, a point tool) has none: the tool's rotation is
    then reported by :func:`compare` but means nothing (the export holds it, see
    :mod:`.mjcf`)."""
    P = np.array([j.location for leg in mech.legs() for j in leg.joints
                  if "platform" in (j.parent, j.child)])
    if len(P) < 3:
        return False
    tol = 1e-9 * max(1.0, float(mech.scale))
    return bool(np.linalg.matrix_rank(P[1:] - P[0], tol=tol) >= 2)


def compare(mech, model, data, pose) -> dict:
    """How far the settled model is from pkmlab at ``pose``: tool position (mm) and rotation
    (rad) errors, the largest loop gap (mm), the largest joint-anchor error (mm) against
    ``mech.legs(pose)``, and the largest velocity left (m/s or rad/s)."""
    mj = _mujoco()
    mj.mj_forward(model, data)
    p, R = mech._frames(np.asarray(pose, dtype=float))
    site = model.site("tool").id
    pos = np.linalg.norm(data.site_xpos[site] / M - p[0])
    rot = np.linalg.norm(log_so3(data.site_xmat[site].reshape(3, 3).T @ R[0]))
    centres = {j.name: j.location for leg in mech.legs((p, R)) for j in leg.joints}
    worst = 0.0
    for jid in range(model.njnt):
        name = model.joint(jid).name
        base = name.rsplit(".", 1)[0] if name not in centres else name
        if base in centres:     # the joint's point on the body that carries it (a slide's
            b = model.jnt_bodyid[jid]             # xanchor stays on the parent)
            x = data.xpos[b] + data.xmat[b].reshape(3, 3) @ model.jnt_pos[jid]
            worst = max(worst, float(np.linalg.norm(x / M - centres[base])))
    gaps = loop_gaps(model, data)
    return {"position_mm": float(pos), "rotation_rad": float(rot),
            "loop_gap_mm": float(gaps.max()) if len(gaps) else 0.0,
            "joint_mm": worst, "velocity": float(np.max(np.abs(data.qvel)))}


def sag(mech, model, data, *, settle: float = 4.0) -> dict:
    """Hold the exported pose with gravity on: how far the tool (mm, rad) and the loops (mm)
    give, from the home keyframe after ``settle`` s."""
    mj = _mujoco()
    mj.mj_resetDataKeyframe(model, data, 0)
    model.opt.disableflags |= mj.mjtDisableBit.mjDSBL_CONTACT
    for _ in range(int(round(settle / model.opt.timestep))):
        mj.mj_step(model, data)
    out = compare(mech, model, data, mech.nominal_pose)
    return {"tool_mm": out["position_mm"], "tool_rad": out["rotation_rad"],
            "loop_gap_mm": out["loop_gap_mm"], "velocity": out["velocity"]}
