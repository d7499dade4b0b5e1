"""The report's interactive charts, built with plotly (rendered offline by the embedded
plotly.js): the Pareto scatter matrix and parallel coordinates, and 3-D scenes of workspace
hulls with the mechanism drawn at its nominal pose from its declared joints
(:mod:`.mechanism3d`).

Every point of the Pareto charts carries its candidate's ``seq`` as ``customdata``: the page
opens that candidate's card when it is clicked.
"""

from __future__ import annotations

import numpy as np

from .mechanism3d import mechanism_traces

__all__ = ["pareto_matrix", "pareto_parcoords", "mechanism_traces", "hull_trace",
           "design_scene", "overlay_scene", "PALETTE"]

#: Colours of overlaid designs (colour-blind safe, Okabe-Ito).
PALETTE = ("#0072B2", "#E69F00", "#009E73", "#CC79A7", "#D55E00", "#56B4E9", "#F0E442",
           "#000000")

_STYLE = {  # group → (label, marker)
    "infeasible": ("infeasible", dict(color="#b8b8b8", size=5, symbol="x-thin",
                                      line=dict(width=1, color="#9a9a9a"))),
    "pruned": ("pruned by the tolerance ladder (coarse values)",
               dict(color="#777777", size=6, symbol="cross-thin",
                    line=dict(width=1, color="#777777"))),
    "feasible": ("feasible", dict(color="#6baed6", size=6, line=dict(width=0))),
    "pareto": ("Pareto front", dict(color="#d62728", size=8, line=dict(width=0.5,
                                                                      color="#7f0000"))),
    "exported": ("exported design (card)", dict(color="rgba(0,0,0,0)", size=17,
                                                 line=dict(width=2.5, color="#111111"))),
    "baseline": ("baseline", dict(color="#111111", size=15, symbol="star",
                                  line=dict(width=1, color="#ffffff"))),
}


def _layout(**kw) -> dict:
    base = dict(template="none", font=dict(family="system-ui, sans-serif", size=12),
                paper_bgcolor="#ffffff", plot_bgcolor="#ffffff",
                margin=dict(l=60, r=20, t=40, b=50), hoverlabel=dict(align="left"))
    base.update(kw)
    return base


def pareto_matrix(axes: list[dict], points: list[dict]):
    """Scatter matrix of the objectives (lower triangle; one panel for two objectives).

    Args:
        axes: one ``{"key", "label"}`` per objective (label with unit and sense).
        points: ``{"seq", "group", "values": {key: float | None}, "hover": str,
            "text": str}``; ``group`` is one of infeasible, pruned (by a tolerance ladder,
            drawn at its coarse values), feasible, pareto, exported, baseline (an exported
            design is drawn twice: as a Pareto point and ringed).
    """
    import plotly.graph_objects as go
    from plotly.subplots import make_subplots

    m = len(axes)
    if m == 1:          # one objective: its value against the evaluation order
        axes = [{"key": "__seq__", "label": "candidate (evaluation order)"}, axes[0]]
        points = [{**p, "values": {**p["values"], "__seq__": p["seq"]}} for p in points]
        m = 2
    n = m - 1
    fig = make_subplots(rows=n, cols=n, shared_xaxes="columns", shared_yaxes="rows",
                        horizontal_spacing=0.06 if n > 1 else 0.0,
                        vertical_spacing=0.06 if n > 1 else 0.0)
    shown = set()
    # many points: WebGL markers (the same clicks and hover), SVG otherwise (crisp in print)
    Scatter = go.Scattergl if len(points) > 1500 else go.Scatter
    for r in range(n):
        for c in range(r + 1):
            ax, ay = axes[c], axes[r + 1]
            for group in ("infeasible", "pruned", "feasible", "pareto", "exported",
                          "baseline"):
                pts = [p for p in points if p["group"] == group
                       and p["values"].get(ax["key"]) is not None
                       and p["values"].get(ay["key"]) is not None]
                if not pts:
                    continue
                label, marker = _STYLE[group]
                fig.add_trace(Scatter(
                    x=[p["values"][ax["key"]] for p in pts],
                    y=[p["values"][ay["key"]] for p in pts],
                    mode="markers+text" if group == "exported" else "markers",
                    text=[p.get("text", "") for p in pts], textposition="top right",
                    textfont=dict(size=11, color="#111111"),
                    customdata=[p["seq"] for p in pts], hovertext=[p["hover"] for p in pts],
                    hovertemplate="%{hovertext}<extra></extra>", name=label, marker=marker,
                    legendgroup=group, showlegend=group not in shown), row=r + 1, col=c + 1)
                shown.add(group)
            if r == n - 1:
                fig.update_xaxes(title_text=ax["label"], row=r + 1, col=c + 1)
            if c == 0:
                fig.update_yaxes(title_text=ay["label"], row=r + 1, col=c + 1)
    side = 330 if n > 1 else 470
    fig.update_xaxes(showgrid=True, gridcolor="#eeeeee", zeroline=False, ticks="outside",
                     showline=True, linecolor="#888888")
    fig.update_yaxes(showgrid=True, gridcolor="#eeeeee", zeroline=False, ticks="outside",
                     showline=True, linecolor="#888888")
    fig.update_layout(**_layout(height=side * n + 90, clickmode="event", hovermode="closest",
                                legend=dict(orientation="h", y=1.0, yanchor="bottom", x=0),
                                margin=dict(l=80, r=20, t=50, b=60)))
    return fig


def pareto_parcoords(axes: list[dict], rows: list[dict]):
    """Parallel coordinates of the objectives over the feasible candidates, the Pareto set in
    red. ``rows``: ``{"values": {key: float}, "pareto": bool}``."""
    import plotly.graph_objects as go

    dims = []
    for a in axes:
        vals = [r["values"][a["key"]] for r in rows]
        dims.append(dict(label=a["label"], values=vals))
    colour = [1.0 if r["pareto"] else 0.0 for r in rows]
    fig = go.Figure(go.Parcoords(
        dimensions=dims, labelangle=0, labelside="top",
        line=dict(color=colour, colorscale=[[0, "#9ecae1"], [1, "#d62728"]], cmin=0, cmax=1)))
    fig.update_layout(**_layout(height=380, margin=dict(l=150, r=150, t=80, b=30)))
    return fig


def hull_trace(vertices: np.ndarray, faces: np.ndarray, intensity=None, *, label: str = "",
               colour: str | None = None, opacity: float = 0.55, name: str = "workspace",
               showscale: bool = True, ambient: float = 0.55):
    """A workspace hull (mm) as a mesh3d trace, coloured by ``intensity`` per vertex."""
    import plotly.graph_objects as go

    V = np.asarray(vertices, dtype=np.float32)
    Fc = np.asarray(faces, dtype=np.int32)
    kw: dict = {}
    if intensity is not None:
        kw = dict(intensity=np.asarray(intensity, dtype=np.float32), colorscale="Viridis",
                  showscale=showscale, colorbar=dict(title=dict(text=label, side="right"),
                                                     len=0.75, thickness=14))
    else:
        kw = dict(color=colour or PALETTE[0])
    return go.Mesh3d(x=V[:, 0], y=V[:, 1], z=V[:, 2], i=Fc[:, 0], j=Fc[:, 1], k=Fc[:, 2],
                     opacity=opacity, flatshading=False, name=name, showlegend=True,
                     lighting=dict(ambient=ambient, diffuse=0.6, specular=0.1),
                     hovertemplate="(%{x:.1f}, %{y:.1f}, %{z:.1f}) mm"
                     + ("<br>%{intensity:.3g}" if intensity is not None else "")
                     + f"<extra>{name}</extra>", **kw)


def _scene() -> dict:
    ax = dict(showbackground=True, backgroundcolor="#f7f7f7", gridcolor="#dddddd",
              zerolinecolor="#bbbbbb")
    return dict(aspectmode="data", xaxis=dict(title=dict(text="x (mm)"), **ax),
                yaxis=dict(title=dict(text="y (mm)"), **ax),
                zaxis=dict(title=dict(text="z (mm)"), **ax),
                camera=dict(eye=dict(x=1.6, y=-1.6, z=0.9)))


def _extent(traces) -> np.ndarray:
    """The ``(3,)`` extent (mm) of every drawn point of ``traces`` (NaN / None skipped)."""
    out = np.zeros(3)
    for i, k in enumerate("xyz"):
        vals = [np.asarray([v for v in getattr(t, k) if v is not None], dtype=float)
                for t in traces if getattr(t, k, None) is not None]
        c = np.concatenate(vals) if vals else np.zeros(0)
        c = c[np.isfinite(c)]
        out[i] = c.max() - c.min() if len(c) else 0.0
    return out


def _fit_scene(fig) -> None:
    """A flat drawing (planar mechanisms: every point in one z-plane) has no z extent, which
    ``aspectmode="data"`` turns into a degenerate view zoomed into the plane: give z a
    fixed share of the box and look at the plane from above."""
    ext = _extent(fig.data)
    span = max(ext[0], ext[1])
    if span > 0 and ext[2] < 0.05 * span:
        fig.update_layout(scene=dict(
            aspectmode="manual",
            aspectratio=dict(x=ext[0] / span, y=ext[1] / span, z=0.15),
            camera=dict(eye=dict(x=0.5, y=-0.9, z=1.4))))


def design_scene(mech, hull: dict | None):
    """One design: its hull (``{"vertices", "faces", "intensity", "label"}`` or None) and the
    mechanism at its nominal pose."""
    import plotly.graph_objects as go

    traces = []
    if hull is not None:
        traces.append(hull_trace(hull["vertices"], hull["faces"], hull.get("intensity"),
                                 label=hull.get("label", "")))
    traces += mechanism_traces(mech)
    fig = go.Figure(traces)
    fig.update_layout(**_layout(height=560, scene=_scene(), margin=dict(l=0, r=0, t=10, b=0),
                                legend=dict(orientation="h", x=0, y=0, yanchor="top",
                                            bgcolor="rgba(255,255,255,0.7)")))
    _fit_scene(fig)
    return fig


def overlay_scene(items: list[dict], title: str = ""):
    """Several designs' hulls overlaid (``{"label", "vertices", "faces", "mechanism"}``), each
    in its colour; mechanisms drawn but hidden until chosen in the legend."""
    import plotly.graph_objects as go

    traces = []
    for n, it in enumerate(items):
        colour = PALETTE[n % len(PALETTE)]
        if it.get("vertices") is not None:
            traces.append(hull_trace(it["vertices"], it["faces"], colour=colour, opacity=0.35,
                                     name=it["label"], ambient=0.85))
        if it.get("mechanism") is not None:
            traces += mechanism_traces(it["mechanism"], it["label"], colour,
                                       visible="legendonly", grouped=True)
    fig = go.Figure(traces)
    fig.update_layout(**_layout(height=560, scene=_scene(), margin=dict(l=0, r=0, t=30, b=0),
                                title=dict(text=title, x=0.01, font=dict(size=13)),
                                legend=dict(x=0, y=1, bgcolor="rgba(255,255,255,0.7)")))
    _fit_scene(fig)
    return fig
