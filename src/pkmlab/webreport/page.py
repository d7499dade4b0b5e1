"""Assembling a self-contained page: Jinja2 templates, the embedded plotly.js, the page's own
script and style (shipped in this package), figures and data as JSON blocks, images as data
URIs. The result makes no network request."""

from __future__ import annotations

import base64
import json
import math
import platform
import re
import time
from functools import cache
from importlib import resources
from pathlib import Path

import numpy as np

from .. import __version__
from ..runtime import atomic

__all__ = ["render_page", "figure_json", "data_json", "png_uri", "hull_of_ply",
           "colour_option"]


@cache
def _asset(name: str) -> str:
    return resources.files(__package__).joinpath("assets", name).read_text(encoding="utf-8")


@cache
def _env():
    import jinja2

    return jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(resources.files(__package__).joinpath("templates"))),
        autoescape=jinja2.select_autoescape(default=True), trim_blocks=True, lstrip_blocks=True)


@cache
def _plotly_js() -> tuple[str, str]:
    import plotly
    from plotly.offline import get_plotlyjs

    js = get_plotlyjs()
    if "</script" in js.lower():      # never expected; the page would break
        raise RuntimeError("plotly.js contains '</script'")
    m = re.search(r"plotly\.js v([0-9][0-9A-Za-z.\-]*)", js[:400])
    return js, m.group(1) if m else f"(plotly.py {plotly.__version__})"


def _script_safe(text: str) -> str:
    """JSON inside ``<script>``: ``</`` and ``<!--`` cannot end or comment the element."""
    return text.replace("</", "<\\/").replace("<!--", "<\\!--")


def figure_json(fig) -> str:
    """A plotly figure as JSON for a ``<script type="application/json">`` block (numpy arrays
    as base64 typed arrays, which plotly.js decodes)."""
    return _script_safe(fig.to_json(validate=False))


def _clean(obj):
    if isinstance(obj, float):
        return obj if math.isfinite(obj) else None
    if isinstance(obj, dict):
        return {str(k): _clean(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_clean(v) for v in obj]
    if isinstance(obj, np.generic):
        return _clean(obj.item())
    if isinstance(obj, np.ndarray):
        return _clean(obj.tolist())
    return obj


def data_json(data: dict) -> str:
    """The page's data as strict JSON (non-finite numbers as null)."""
    return _script_safe(json.dumps(_clean(data), separators=(",", ":"), allow_nan=False))


def png_uri(path: Path) -> str:
    return "data:image/png;base64," + base64.b64encode(Path(path).read_bytes()).decode("ascii")


def hull_of_ply(path: Path) -> dict:
    """A workspace PLY written by pkmlab → ``{"vertices", "faces", "values": {name: array}}``
    (mm; the values are the float vertex properties besides x, y, z)."""
    import trimesh

    mesh = trimesh.load(str(path), process=False, force="mesh")
    raw = mesh.metadata.get("_ply_raw", {}).get("vertex", {}).get("data")
    values = {}
    if raw is not None and raw.dtype.names:
        for name in raw.dtype.names:
            if name not in ("x", "y", "z", "red", "green", "blue", "alpha"):
                values[name] = np.asarray(raw[name], dtype=float)
    return {"vertices": np.asarray(mesh.vertices), "faces": np.asarray(mesh.faces),
            "values": values}


def colour_option(label: str, values: np.ndarray, digits: int = 4) -> dict:
    """A hull colouring: values (non-finite ones at the top of the scale) and a colour range
    from the 1st to the 99th percentile, so that a few near-singular poses do not wash the
    scale out."""
    v = np.asarray(values, dtype=float)
    finite = np.isfinite(v)
    if not finite.any():
        return {"label": label, "values": [0.0] * len(v), "cmin": 0.0, "cmax": 1.0}
    lo, hi = np.percentile(v[finite], [1, 99])
    hi = hi if hi > lo else lo + 1e-9
    v = np.where(finite, v, np.max(v[finite]))
    return {"label": label, "values": [float(f"{x:.{digits}g}") for x in v],
            "cmin": float(lo), "cmax": float(hi)}


def render_page(path: Path, template: str, *, title: str, kind: str, data: dict,
                figures: dict, **context) -> Path:
    """Render ``template`` with the embedded script, style, plotly.js, figures and data and
    write it atomically to ``path``."""
    js, plotly_version = _plotly_js()
    html = _env().get_template(template).render(
        title=title, kind=kind, version=__version__, plotly_version=plotly_version,
        built=time.strftime("%Y-%m-%d %H:%M:%S %z"), machine=platform.node(),
        python=platform.python_version(), platform_name=platform.platform(),
        css=_asset("report.css"), js=_asset("report.js"), plotly_js=js,
        pose_css=_asset("posepanel.css"), pose_js=_asset("posepanel.js"),
        data_json=data_json(data), figures=figures, **context)
    return atomic.write_text(Path(path), html)
