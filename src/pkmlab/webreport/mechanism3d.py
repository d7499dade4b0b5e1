"""The mechanism drawn in 3-D from its declared joints (``mech.legs(pose)``,
:mod:`pkmlab.mechanisms.joints`), the same code for every family, plugins and lower-mobility
mechanisms included.

* each leg is one polyline through its joint chain from the base to the platform
  (:func:`~pkmlab.mechanisms.joints.chain_points`: every joint's ``location``, a P joint's
  ``zero`` then its ``location``), so cranks, sliders and shared links are drawn as declared;
* each joint is a marker whose symbol says its type (S ball: circle, U: diamond, R: square,
  P: cross, at the middle of its travel ``zero → location``); the actuated joint is drawn
  larger in the actuator colour, with its value in the hover, and the member it moves (the
  crank of an actuated R, the travel of an actuated P) is drawn over the chain in that colour;
* an actuated P joint mounted on the base shows its rail over the actuator window;
* the base outline joins the points where the legs are fixed to the base, the platform
  outline the platform joints (each once), in angular order in their best-fit plane.

:func:`drawing` gives these as arrays (no plotting library), :func:`mechanism_traces` as plotly
traces.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..mechanisms.joints import chain_points

__all__ = ["Drawing", "JointMark", "drawing", "mechanism_traces", "outline"]

#: plotly ``scatter3d`` marker symbol and legend label of each joint type
JOINT_STYLE = {"S": ("circle", "S joints (ball)"), "U": ("diamond", "U joints (universal)"),
               "R": ("square", "R joints (revolute)"), "P": ("cross", "P joints (prismatic)")}
CHAIN, ACTUATOR, JOINT, BASE = "#E69F00", "#D55E00", "#333333", "#7f7f7f"


@dataclass(frozen=True)
class JointMark:
    """One joint marker: ``leg`` its leg's name, ``point`` where it is drawn (mm)."""

    leg: str
    name: str
    type: str
    point: np.ndarray
    actuated: bool
    text: str


@dataclass(frozen=True)
class Drawing:
    """The mechanism at one pose, in the base frame (mm): ``chains`` each leg's polyline
    ``(K, 3)`` (leg order), ``actuated`` the moved members as ``(start, end)`` pairs, ``rails``
    the base-mounted actuated P joints' windows, ``base`` / ``platform`` closed outlines,
    ``tool`` the tool point."""

    chains: tuple[np.ndarray, ...]
    joints: tuple[JointMark, ...]
    actuated: tuple[tuple[np.ndarray, np.ndarray], ...]
    rails: tuple[tuple[np.ndarray, np.ndarray], ...]
    base: np.ndarray
    platform: np.ndarray
    tool: np.ndarray


def outline(points: np.ndarray) -> np.ndarray:
    """Distinct points (to 1e-6 mm) in angular order about their centroid in their best-fit
    plane, closed (the first point repeated); one or two points are returned as they are."""
    P = np.asarray(points, dtype=float).reshape(-1, 3)
    keep = [i for i in range(len(P))
            if not np.any(np.linalg.norm(P[:i] - P[i], axis=1) <= 1e-6)]
    P = P[keep]
    if len(P) < 3:
        return P
    c = P.mean(axis=0)
    _, _, vt = np.linalg.svd(P - c)
    u, v = (P - c) @ vt[0], (P - c) @ vt[1]
    P = P[np.argsort(np.arctan2(v, u))]
    return np.vstack([P, P[:1]])


def _num(v: float, digits: int) -> str:
    """``v`` to ``digits`` decimals, never ``-0.0``."""
    text = f"{v:.{digits}f}"
    return text.lstrip("-") if float(text) == 0.0 else text


def _value_text(mech, name: str, q: float) -> str:
    lo, hi = mech.stroke
    if mech.actuator_unit == "rad":
        return (f"{name} = {_num(math.degrees(q), 2)}° (window {math.degrees(lo):g} … "
                f"{math.degrees(hi):g}°)")
    return f"{name} = {_num(q, 2)} mm (window {lo:g} … {hi:g} mm)"


def drawing(mech, pose=None) -> Drawing:
    """The :class:`Drawing` of ``mech`` at ``pose`` (any one pose ``inverse`` takes; default
    the nominal pose), read from ``mech.legs(pose)`` only."""
    X = mech.nominal_pose if pose is None else pose
    p, _ = mech._frames(X)
    legs = mech.legs(X)
    chains, marks, moved, rails, fixed, top = [], [], [], [], [], []
    for leg in legs:
        pts = chain_points(leg)
        chains.append(pts)
        first = leg.joints[0]
        fixed.append(first.zero if first.type == "P" else first.location)
        for j in leg.joints:
            at = 0.5 * (j.zero + j.location) if j.type == "P" else j.location
            where = "(" + ", ".join(_num(v, 1) for v in j.location) + ") mm"
            text = f"{j.name}: {j.type} joint at {where}"
            if j.actuated:
                text = f"{text}<br>actuated: {_value_text(mech, leg.name, leg.value)}"
            marks.append(JointMark(leg.name, j.name, j.type, at, j.actuated, text))
            if j.mount == "platform":
                top.append(j.location)
        act, k = leg.actuated, leg.actuated_index
        if act.type == "P":
            moved.append((act.zero, act.location))
            if act.parent == "base":
                lo, hi = mech.stroke
                rails.append((act.zero + lo * act.axes[0], act.zero + hi * act.axes[0]))
        elif k + 1 < len(leg.joints):        # the member the actuated joint turns
            nxt = leg.joints[k + 1]
            moved.append((act.location, nxt.zero if nxt.type == "P" else nxt.location))
    return Drawing(tuple(chains), tuple(marks), tuple(moved), tuple(rails),
                   outline(np.array(fixed)), outline(np.array(top)), p[0].copy())


def _polyline(pieces) -> tuple[list, list, list]:
    """Polylines (each ``(K, 3)``) as one trace's coordinates, broken by ``None``."""
    xs, ys, zs = [], [], []
    for piece in pieces:
        for a in np.asarray(piece, dtype=float):
            xs.append(float(a[0]))
            ys.append(float(a[1]))
            zs.append(float(a[2]))
        xs.append(None)
        ys.append(None)
        zs.append(None)
    return xs, ys, zs


def mechanism_traces(mech, name: str = "", colour: str = "#333333", visible=True,
                     grouped: bool = False, pose=None) -> list:
    """The mechanism at ``pose`` (default nominal) as plotly traces (:func:`drawing`): base
    and platform outlines, the legs' joint chains (trace ``"legs (joint chains)"``), the
    actuated members, rails, one marker trace per joint type, the actuated joints and the
    tool point.

    ``grouped``: one legend entry for the whole mechanism (``name: mechanism``), which shows
    or hides it at once; otherwise one entry per part."""
    import plotly.graph_objects as go

    d = drawing(mech, pose)
    label = f"{name}: " if name else ""
    where = "nominal pose" if pose is None else "pose"
    kw: dict = dict(visible=visible)
    if grouped:
        kw["legendgroup"] = f"mech-{name}"

    def lines(pieces, part, col, width, hover=True):
        x, y, z = _polyline(pieces)
        return go.Scatter3d(x=x, y=y, z=z, mode="lines", line=dict(color=col, width=width),
                            name=f"{label}{part}", hoverinfo="name" if hover else "skip",
                            **kw)

    traces = [lines([d.base], "base", BASE, 6),
              lines([d.platform], f"platform ({where})", colour, 8)]
    if d.rails:
        traces.append(lines([np.array(r) for r in d.rails], "actuator rails", "#bbbbbb", 4))
    traces.append(lines(d.chains, "legs (joint chains)", CHAIN, 5))
    traces.append(lines([np.array(m) for m in d.actuated], "actuated members", ACTUATOR, 9))
    for kind, (symbol, part) in JOINT_STYLE.items():
        js = [j for j in d.joints if j.type == kind and not j.actuated]
        if js:
            P = np.array([j.point for j in js])
            traces.append(go.Scatter3d(
                x=P[:, 0], y=P[:, 1], z=P[:, 2], mode="markers", name=f"{label}{part}",
                marker=dict(size=4.5, color=JOINT, symbol=symbol),
                hovertext=[j.text for j in js], hovertemplate="%{hovertext}<extra></extra>",
                **kw))
    js = [j for j in d.joints if j.actuated]
    P = np.array([j.point for j in js])
    traces.append(go.Scatter3d(
        x=P[:, 0], y=P[:, 1], z=P[:, 2], mode="markers",
        name=f"{label}actuators (actuated joints)",
        marker=dict(size=6, color=ACTUATOR, symbol=[JOINT_STYLE[j.type][0] for j in js],
                    line=dict(width=1, color="#000000")),
        hovertext=[j.text for j in js], hovertemplate="%{hovertext}<extra></extra>", **kw))
    traces.append(go.Scatter3d(
        x=[float(d.tool[0])], y=[float(d.tool[1])], z=[float(d.tool[2])], mode="markers",
        marker=dict(size=5, color="#000000", symbol="diamond"), name=f"{label}tool point",
        hovertemplate="tool point (%{x:.1f}, %{y:.1f}, %{z:.1f}) mm<extra></extra>", **kw))
    if grouped:
        for i, t in enumerate(traces):
            t.update(showlegend=i == 0, name=f"{label}mechanism ({where})" if i == 0
                     else t.name)
    return traces
