"""The ``pkmlab compare`` page: designs side by side, their workspace hulls overlaid in 3-D,
overlaid slices (one common layout scaled to all of them)."""

from __future__ import annotations

import base64
import io
import logging
import time
from pathlib import Path

from ..escaping import plotly_text
from . import data as D
from .figures import overlay_scene
from .page import data_json, figure_json, render_page
from .posepanel import panel_model

log = logging.getLogger(__name__)

__all__ = ["compare_html"]


def _hull(res) -> dict:
    if res is None or res.empty:
        return {"vertices": None, "faces": None}
    m = res.mesh()
    return {"vertices": m.vertices, "faces": m.faces}


def _png(fig) -> str:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return "data:image/png;base64," + base64.b64encode(buf.getvalue()).decode("ascii")


def _cell(value, fmt: str, ref) -> tuple[str, str]:
    if isinstance(value, str):
        return value, ""
    if value is None:                       # a design without this metric
        return "—", ""
    text = fmt.format(value)
    if ref is None or isinstance(ref, str):
        return text, ""
    _, pct = D.difference(value, ref)
    return text, "" if pct == "—" else pct


def compare_html(rows: list[dict], path: str | Path, *, box_deg: float | None = None,
                 columns=None, title: str = "Design comparison", slices: bool = True,
                 progress=None) -> Path:
    """Write the comparison page of ``rows`` (from :func:`pkmlab.study.compare.
    compare_designs`: ``label``, ``mechanism``, the ``columns`` values and ``results``, the
    level and dexterous :class:`~pkmlab.WorkspaceResult`) to ``path``.

    Args:
        rows: one per design; the first is the reference the others' Δ % refer to.
        path: the HTML file to write (atomically).
        box_deg: the dexterous set's half-range, for the headings.
        columns: ``(key, header, format)`` rows of the table (default: the compare
            module's ``COLUMNS``).
        title: the page title.
        slices: also embed the overlaid slices (level and dexterous) as images.
        progress: optional ``progress(message)`` per step (also logged at INFO).
    """
    from ..workspaces.output.plots import overlay_figure

    t0 = time.perf_counter()

    def step(message: str) -> None:
        log.info("compare page: %s", message)
        if progress:
            progress(message)

    if columns is None:
        from ..study.compare import COLUMNS as columns
    if not rows:
        raise ValueError("compare_html needs at least one design")
    labels = [r["label"] for r in rows]
    table = []
    for key, header, fmt in columns:
        cells = []
        for i, r in enumerate(rows):
            text, pct = _cell(r.get(key), fmt, rows[0].get(key) if i else None)
            cells.append({"text": text, "pct": pct})
        table.append({"header": header, "cells": cells})
    if any("reference" in r for r in rows):
        table.append({"header": "inscribed shapes / GCI / κ / force over",
                      "cells": [{"text": r.get("reference", ""), "pct": ""} for r in rows]})
    dex_name = f"dexterous (±{box_deg:g}° simultaneous)" if box_deg is not None else "dexterous"
    figures, scenes, images = {}, [], []
    for which, name in ((1, dex_name), (0, "level (constant orientation)")):
        step(f"{name} hulls")
        results = [r["results"][which] if r.get("results") else None for r in rows]
        items = [{"label": plotly_text(lab), "mechanism": r.get("mechanism"), **_hull(res)}
                 for lab, r, res in zip(labels, rows, results)]   # legend: plotly markup
        empty = [lab for lab, res in zip(labels, results) if res is None or res.empty]
        fid = f"fig-overlay-{which}"
        figures[fid] = figure_json(overlay_scene(items, f"{name} workspaces"))
        scenes.append({"div": f"scene-overlay-{which}", "figure": fid, "title": name,
                       "empty": empty})
        if slices and any(res is not None and not res.empty for res in results):
            step(f"{name} slices")
            ok = [(lab, res) for lab, res in zip(labels, results) if res is not None]
            fig = overlay_figure([res for _, res in ok], [lab for lab, _ in ok],
                                 title=f"{name} workspaces")
            images.append({"uri": _png(fig), "caption": f"{name} sections, overlaid"})
    poses = []
    for i, r in enumerate(rows):
        if r.get("mechanism") is None:
            continue
        try:
            figures[f"pose-model-{i}"] = data_json(panel_model(r["mechanism"]))
            poses.append({"model_id": f"pose-model-{i}", "label": labels[i]})
        except Exception as exc:  # noqa: BLE001 - a panel problem never stops the page
            log.warning("compare page: no pose panel for %s: %s", labels[i], exc)
    data = {"designs": [{"label": r["label"],
                         **{k: r.get(k) for k, _, _ in columns if k in r}} for r in rows],
            "scenes": [{"div": s["div"], "figure": s["figure"]} for s in scenes]}
    path = render_page(Path(path), "compare.html.j2", title=title, kind="design comparison",
                       data=data, figures=figures, labels=labels, table=table,
                       scenes=scenes, images=images, box_deg=box_deg, poses=poses)
    log.info("compare page written in %.1f s", time.perf_counter() - t0)
    return path
