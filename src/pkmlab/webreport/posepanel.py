"""The report's pose panel: a mechanism's legs as data for the page's own inverse kinematics
(``assets/posepanel.js``), read from the declared joints (``mech.legs()``, the nominal pose),
its mobility and its parameter vector, and the study's task region as 3-D traces.

**Leg kinds.** Every leg the page can solve is one of four shapes of a declared chain, told
apart by its joints, never by the family:

* ``distance`` — an actuated P joint carried by a link (its axis turns with the leg: U–P–S,
  R–P–R, U–P–U) whose zero is the first joint's centre and whose location is the platform
  joint's: the actuator value is the distance ``|W − B|``;
* ``rail`` — an actuated P joint on the base (a fixed rail ``Z + q·a``) followed by one link of
  fixed length ``l`` to the platform joint: ``q = d·a + b·sqrt(l² − |d|² + (d·a)²)``,
  ``d = W − Z`` (P–S–U, P–S–S, P–R–S);
* ``crank`` — an actuated R joint on the base turning a crank of length ``r`` (zero direction
  ``u``, ``v = n × u``) followed by a link of length ``l`` to the platform joint:
  ``A cos q + B sin q = K`` with ``A = d·u``, ``B = d·v``, ``K = (|d|² + r² − l²)/(2r)``
  (R–S–S, R–R–R);
* ``pair`` — two U–P–R–U struts ``A_j → B_j`` that share their last link ``B_1 B_2`` and its
  platform joint ``C`` (luzi3's chains): the base U joints turn about the chord ``c = A_2 −
  A_1`` and the R joints keep the link in the plane of ``A_1, A_2, C``; the platform joint's
  platform-fixed axis ``k`` keeps it normal to ``k``, so ``t = ±k × (c × (C − A_1))/|…|``
  (``t·c ≥ 0``), ``B_j = C + s_j t`` and ``q_j = |B_j − A_j|`` (:func:`_pair_model`). The
  chain keeps the nominal sign of ``(k × (c × (C − A_1)))·c`` (else: unreachable, another
  working mode), as ``luzi3.working_branches``; a vanishing ``k × (c × (C − A_1))`` is
  unreachable (the link's direction is undefined).

The branch ``b`` (rail, crank) is the root that gives the declared actuator value at the
nominal pose. A leg whose link has a vertical component at the nominal pose keeps its sign
(``side``; otherwise the leg is in another working mode: unreachable). A passive R joint on a
rail's slider keeps the platform joint in the plane through the rail normal to its axis: such
planes are the constraints that give a mobility's dependent coordinates (the 3-PRS's ``x, y,
θz``). Passive-joint limits are read from the parameter vector (:data:`PASSIVE_LIMITS`).

The page computes, from these and the pose, each actuator's value and status (ok / out of
stroke / joint limit / unreachable), the Jacobian rows ``[L, r × L] / (L·∂E/∂q)`` (a pair's:
the derivative of ``q_j`` through ``C`` and ``t``, ``posepanel.js``) over the free
twist columns (dependent ones eliminated through the plane constraints) and κ as pkmlab
defines it (:func:`pkmlab.dexterity.metrics.condition_number`, with
:func:`~pkmlab.dexterity.metrics.resolve_length`'s characteristic length).
"""

from __future__ import annotations

import math

import numpy as np

from ..mechanisms.joints import Leg

__all__ = ["PASSIVE_LIMITS", "pose_model", "panel_model", "task_traces", "task_shapes"]

#: passive-joint limits a family declares in its parameter vector, by parameter name: what the
#: angle bounds. ``plane``: the distal link's angle out of the plane normal to a crank's axis
#: (``|L·n| <= l·sin(limit)``); ``axis``: its angle from a rail's axis (``|L × a| <=
#: l·sin(limit)``).
PASSIVE_LIMITS = {"cone_limit": "plane", "rod_angle_limit": "axis"}


def _branch(roots, value) -> float:
    """The sign (±1) whose root is nearest the declared value (angles compared mod 2π)."""
    best, sign = math.inf, 1.0
    for b, q in roots:
        d = abs(math.remainder(q - value, 2 * math.pi)) if roots.angular else abs(q - value)
        if d < best:
            best, sign = d, b
    return sign


class _Roots(list):
    angular = False


def _side(link_z: float, scale: float) -> float:
    return 0.0 if abs(link_z) <= 1e-6 * scale else math.copysign(1.0, link_z)


def _leg_model(leg: Leg, scale: float) -> tuple[dict | None, str]:
    """One leg as a kind of the module docstring, or ``(None, why not)``."""
    a, js = leg.actuated_index, leg.joints
    act, last = leg.actuated, js[-1]
    if last.mount != "platform" or last.mount_location is None:
        return None, f"{leg.name}: its last joint is not on the platform"
    W = last.location
    tol = 1e-9 * scale
    base = {"name": leg.name, "platform": last.mount_location.tolist()}
    if act.type == "P" and act.parent != "base":
        first = js[0]
        if (first.mount != "base" or a != 1 or np.linalg.norm(act.zero - first.location) > tol
                or np.linalg.norm(act.location - W) > tol):
            return None, f"{leg.name}: an actuated P joint between links that is not a strut"
        return {**base, "kind": "distance", "base": first.location.tolist(),
                "side": _side(W[2] - first.location[2], scale)}, ""
    if act.type == "P" and act.parent == "base" and a == 0 and len(js) == 3:
        Z, ax = act.zero, act.axes[0]
        if leg.links[0].length > tol or np.linalg.norm(js[1].location - act.location) > tol:
            return None, f"{leg.name}: the rail's slider joint is off the slider"
        ll = leg.links[1].length
        d = W - Z
        t = d @ ax
        h = math.sqrt(max(ll * ll - d @ d + t * t, 0.0))
        roots = _Roots([(1.0, t + h), (-1.0, t - h)])
        b = _branch(roots, leg.value)
        E = Z + leg.value * ax
        out = {**base, "kind": "rail", "zero": Z.tolist(), "axis": ax.tolist(), "link": ll,
               "branch": b, "side": _side(W[2] - E[2], scale)}
        if js[1].type == "R":                        # a hinge on the slider: a plane
            out["plane"] = js[1].axes[0].tolist()
        return out, ""
    if act.type == "R" and act.parent == "base" and a == 0 and len(js) == 3 \
            and act.reference is not None:
        C, n, u = act.location, act.axes[0], act.reference
        r, ll = leg.links[0].length, leg.links[1].length
        v = np.cross(n, u)
        d = W - C
        A, B, K = d @ u, d @ v, (d @ d + r * r - ll * ll) / (2 * r)
        h = math.sqrt(max(A * A + B * B - K * K, 0.0))
        roots = _Roots([(s, math.atan2(B * K + s * A * h, A * K - s * B * h))
                        for s in (1.0, -1.0)])
        roots.angular = True
        return {**base, "kind": "crank", "pivot": C.tolist(), "axis": n.tolist(),
                "ref": u.tolist(), "crank": r, "link": ll,
                "branch": _branch(roots, leg.value)}, ""
    return None, (f"{leg.name}: a {'-'.join(j.type for j in js)} chain with its "
                  f"{act.type} joint {a} actuated is not a leg kind the page solves")


def _pairs(declared, solved, nominal, scale: float) -> list:
    """``solved`` with the legs that are none of the single kinds read as ``pair`` legs where
    two of them end in the same last link and platform joint (:func:`_pair_model`)."""
    out = list(solved)
    groups: dict[tuple[str, str], list[int]] = {}
    for i, (leg, (m, _)) in enumerate(zip(declared, solved)):
        if m is None and leg.links:
            groups.setdefault((leg.links[-1].name, leg.joints[-1].name), []).append(i)
    from ..poses import euler_to_matrix

    R = euler_to_matrix(np.asarray(nominal[3:], float))
    for idx in groups.values():
        if len(idx) != 2:
            continue
        pair, reason = _pair_model(declared[idx[0]], declared[idx[1]], R, scale)
        for k, i in enumerate(idx):
            out[i] = (pair[k], "") if pair else (None, reason)
    return out


def _pair_model(leg1: Leg, leg2: Leg, R: np.ndarray, scale: float):
    """Two U–P–R–U legs that share their upper link (``pair``; a luzi3 chain): each a strut
    ``A_j → B_j`` (P carried by a link, zero at the base U's centre ``A_j``) whose base U turns
    about the chord ``r = A_2 − A_1`` and whose R at ``B_j`` is normal to the plane γ of
    ``A_1, A_2`` and the common platform joint ``C``: the shared link lies in γ, and in the
    plane normal to the platform joint's platform-fixed axis ``k`` (its second axis). So
    ``t = ±(k × (r × (C − A_1)))/|…|`` (sign: ``t·r ≥ 0``), ``B_j = C + s_j t`` with ``s_j``
    the signed offset of ``B_j`` along ``t`` at the nominal pose, ``q_j = |B_j − A_j|``; the
    branch is the nominal sign of ``(k × (r × (C − A_1)))·r``. Returns ``((m1, m2), "")`` or
    ``(None, why not)``."""
    tol = 1e-9 * scale
    legs = (leg1, leg2)
    A = [leg.joints[0].location for leg in legs]
    C = leg1.joints[-1].location
    r = A[1] - A[0]
    rn = float(np.linalg.norm(r))
    w = np.cross(r, C - A[0])
    n = np.cross(leg1.joints[-1].axes[1], w)
    nn = float(np.linalg.norm(n))
    why = f"{leg1.name}, {leg2.name}: "
    if rn <= tol or nn <= 1e-9 * rn * float(np.linalg.norm(C - A[0])):
        return None, why + "a shared link whose plane is not defined at the nominal pose"
    branch = 1.0 if n @ r >= 0 else -1.0
    t = branch * n / nn
    gamma = w / np.linalg.norm(w)
    models = []
    for leg, a in zip(legs, A):
        js = leg.joints
        types = "-".join(j.type for j in js)
        act, B = leg.actuated, leg.actuated.location
        s = float((B - C) @ t)
        if (types != "U-P-R-U" or leg.actuated_index != 1 or act.parent == "base"
                or js[0].mount != "base" or js[-1].mount != "platform"
                or np.linalg.norm(act.zero - a) > tol
                or abs(np.linalg.norm(B - a) - leg.value) > tol
                or np.linalg.norm(np.cross(js[0].axes[0], r / rn)) > 1e-9
                or np.linalg.norm(np.cross(js[2].axes[0], gamma)) > 1e-9
                or np.linalg.norm(js[2].location - B) > tol
                or np.linalg.norm(B - C - s * t) > tol
                or abs(abs(s) - leg.links[-1].length) > tol):
            return None, (why + f"a {types} chain sharing its last link is solved only as two "
                          "U-P-R-U struts whose base U joints turn about their common chord "
                          "and whose link lies in the chain's plane and the platform's")
        models.append({"name": leg.name, "kind": "pair", "platform": js[-1].mount_location.tolist(),
                       "base": a.tolist(), "a1": A[0].tolist(), "a2": A[1].tolist(),
                       "normal": (R.T @ js[-1].axes[1]).tolist(), "offset": s,
                       "branch": branch})
    return models, ""


def pose_model(mech) -> dict:
    """Everything ``posepanel.js`` needs for ``mech`` (JSON-ready): ``supported`` and, when not,
    ``reason``; the mobility, nominal pose, actuator window and unit, the legs, the
    characteristic length and the slider ranges."""
    from ..dexterity.metrics import resolve_length, rotational_columns

    mob = mech.mobility
    scale = float(mech.scale)
    legs, why = [], []
    declared = mech.legs()
    solved = [_leg_model(leg, scale) for leg in declared]
    solved = _pairs(declared, solved, mech.nominal_pose, scale)
    for m, reason in solved:
        if m is None:
            why.append(reason)
        else:
            legs.append(m)
    params = mech.parameters()
    limits = {}
    for name, kind in PASSIVE_LIMITS.items():
        if name in params.names:
            limits[kind] = float(params[name])
    for m in legs:
        if m["kind"] == "crank" and "plane" in limits:
            m["limit"] = {"kind": "plane", "bound": m["link"] * math.sin(limits["plane"])}
        if m["kind"] == "rail" and "axis" in limits:
            m["limit"] = {"kind": "axis", "bound": m["link"] * math.sin(limits["axis"])}
    dependent = list(getattr(mob, "dependent", ()))
    planes = [m for m in legs if "plane" in m]
    if dependent and not (dependent == ["x", "y", "theta_z"] and len(planes) == 3):
        why.append(f"dependent coordinates {dependent} are solved only as x, y, theta_z from "
                   "three hinge planes")
    cl = resolve_length(mech)
    rot = list(rotational_columns(mob))
    lo, hi = (float(v) for v in mech.stroke)
    model = {
        "name": mech.name or mech.family, "family": mech.family,
        "supported": not why, "reason": "; ".join(why),
        "coordinates": list(mob.coordinates), "free": [int(i) for i in mob.index],
        "dependent": dependent, "nominal": [float(v) for v in mech.nominal_pose],
        "tool_offset": [float(v) for v in mech.tool_offset], "unit": mech.actuator_unit,
        "stroke": [lo, hi], "names": list(mech.actuator_names), "legs": legs,
        "char_length": None if cl.length is None else float(cl.length),
        "rotational": rot if cl.length is not None else [],
        "length_source": cl.source,
        "range_mm": float(round(0.25 * scale, -int(math.floor(math.log10(0.25 * scale))))),
        "range_deg": 30.0,
    }
    return model


def panel_model(mech, shapes=()) -> dict:
    """:func:`pose_model` with the fixed part of the panel's 3-D view (``fixed_traces``, plotly
    trace dicts): the base outline (where the legs are fixed to the base) and the task regions
    (:func:`task_traces` of ``shapes``, base frame)."""
    import plotly.graph_objects as go

    from .mechanism3d import drawing

    model = pose_model(mech)
    d = drawing(mech)
    model["scene"] = _scene_box(mech, d, shapes, model["range_mm"])
    base = go.Scatter3d(x=d.base[:, 0], y=d.base[:, 1], z=d.base[:, 2], mode="lines+markers",
                        name="base", line=dict(color="#7f7f7f", width=6),
                        marker=dict(size=3, color="#7f7f7f"), hoverinfo="name")
    model["fixed_traces"] = [t.to_plotly_json() for t in [base, *task_traces(shapes)]]
    return model


def _scene_box(mech, d, shapes, reach: float) -> dict:
    """Fixed axis ranges for the panel's view (so jogging does not rescale it): the nominal
    drawing and the task, grown by the slider reach along free translations; a flat drawing
    (planar) keeps a thin z box seen from above, as the card's own view."""
    pts = [np.concatenate(d.chains), d.base.reshape(-1, 3), d.tool.reshape(1, 3)]
    pts += [_outline(s)[1] for s in shapes]
    P = np.concatenate([p for p in pts if len(p)])
    lo, hi = P.min(axis=0), P.max(axis=0)
    free = set(mech.mobility.coordinates) | set(getattr(mech.mobility, "dependent", ()))
    span = float(max(hi - lo))
    for k, c in enumerate(("x", "y", "z")):
        moves = (c in free or bool({"theta_x", "theta_y"} & free)
                 or (c != "z" and "theta_z" in free))      # a turn about z stays in its plane
        grow = 0.5 * reach if moves else 0.0
        lo[k] -= grow
        hi[k] += grow
        if hi[k] - lo[k] < 0.1 * span:               # flat: a thin box around the plane
            mid = 0.5 * (lo[k] + hi[k])
            lo[k], hi[k] = mid - 0.05 * span, mid + 0.05 * span
    ext = hi - lo
    flat = ext[2] <= 0.1 * span + 1e-9
    ax = dict(showbackground=True, backgroundcolor="#f7f7f7", gridcolor="#dddddd")
    return {"aspectmode": "manual",
            "aspectratio": dict(zip("xyz", (ext / ext.max()).tolist())),
            **{f"{c}axis": dict(range=[float(lo[k]), float(hi[k])],
                                title=dict(text=f"{c} (mm)"), **ax)
               for k, c in enumerate("xyz")},
            "camera": dict(eye=dict(x=0.3, y=-0.6, z=0.95) if flat
                           else dict(x=1.0, y=-1.0, z=0.6))}


# ---- the task region --------------------------------------------------------------------------
def task_shapes(study, mech) -> list[dict]:
    """The study's task regions in the base frame (mm): ``{"kind": "box", "lo", "hi"}``,
    ``{"kind": "cylinder", "centre", "radius", "half"}`` or ``{"kind": "points", "points"}``,
    from its ``task`` and ``delta_task`` plans; ``[]`` without one."""
    out = []
    plans = getattr(getattr(study, "evaluation", None), "plans", {}) or {}
    task = plans.get("task")
    region = getattr(task, "region", None)
    if region is not None:
        if region.shape == "cylinder":
            c, r, half = region.cylinder(mech)
            out.append({"kind": "cylinder", "centre": np.asarray(c, float), "radius": r,
                        "half": half})
        elif region.shape == "box":
            lo, hi = region.boxes(mech)
            out.append({"kind": "box", "lo": lo[0], "hi": hi[0]})
        else:
            out.append({"kind": "points", "points": region.boxes(mech)[0]})
    dt = plans.get("delta_task")
    if dt is not None:
        zc = 0.5 * (dt.z_min + dt.z_max)
        out.append({"kind": "cylinder", "centre": np.array([dt.centre[0], dt.centre[1], zc]),
                    "radius": float(dt.radius), "half": 0.5 * (dt.z_max - dt.z_min)})
    return out


def _outline(shape: dict) -> tuple[list[np.ndarray], np.ndarray]:
    """Polylines and corner points of one task shape; a flat or zero shape gives a line, a
    polygon or a point (the markers show it)."""
    if shape["kind"] == "box":
        lo, hi = np.asarray(shape["lo"], float), np.asarray(shape["hi"], float)
        c = np.array([[hi[0] if i & 1 else lo[0], hi[1] if i & 2 else lo[1],
                       hi[2] if i & 4 else lo[2]] for i in range(8)])
        edges = [(0, 1), (1, 3), (3, 2), (2, 0), (4, 5), (5, 7), (7, 6), (6, 4), (0, 4), (1, 5),
                 (2, 6), (3, 7)]
        return [c[list(e)] for e in edges], np.unique(c, axis=0)
    if shape["kind"] == "cylinder":
        c, r, h = np.asarray(shape["centre"], float), shape["radius"], shape["half"]
        t = np.linspace(0, 2 * np.pi, 49)
        ring = np.stack([r * np.cos(t), r * np.sin(t), np.zeros_like(t)], axis=1)
        lines = [c + ring + [0, 0, -h], c + ring + [0, 0, h]]
        for k in range(0, 48, 12):
            lines.append(np.array([c + ring[k] + [0, 0, -h], c + ring[k] + [0, 0, h]]))
        pts = np.unique(np.array([c + [0, 0, -h], c + [0, 0, h]]), axis=0)
        return lines, pts
    P = np.asarray(shape["points"], float)
    return [], P


def task_traces(shapes: list[dict]) -> list:
    """Plotly traces of the task regions: edges as lines and the corner (or given) points as
    markers, so a region that is a line or a point is still drawn."""
    import plotly.graph_objects as go

    traces = []
    for k, s in enumerate(shapes):
        lines, pts = _outline(s)
        lines = [seg for seg in lines if np.ptp(seg, axis=0).max() > 0.0]   # a point: none
        label = "task region" + (f" {k + 1}" if len(shapes) > 1 else "") + f" ({s['kind']})"
        if lines:
            xs, ys, zs = [], [], []
            for seg in lines:
                for p in seg:
                    xs.append(float(p[0]))
                    ys.append(float(p[1]))
                    zs.append(float(p[2]))
                xs.append(None)
                ys.append(None)
                zs.append(None)
            traces.append(go.Scatter3d(x=xs, y=ys, z=zs, mode="lines", name=label,
                                       legendgroup=f"task{k}",
                                       line=dict(color="#009E73", width=4, dash="dash"),
                                       hoverinfo="name"))
        traces.append(go.Scatter3d(
            x=pts[:, 0].tolist(), y=pts[:, 1].tolist(), z=pts[:, 2].tolist(), mode="markers",
            name=f"{label}: points",
            legendgroup=f"task{k}", showlegend=not lines,
            marker=dict(size=4, color="#009E73", symbol="circle-open"),
            hovertemplate="task (%{x:.1f}, %{y:.1f}, %{z:.1f}) mm<extra></extra>"))
    return traces
