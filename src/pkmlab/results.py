"""A study's results in Python, for notebooks: ``pkmlab.open_results(path)``.

::

    res = pkmlab.open_results("results/hopkins-6psu-redesign")
    res.evaluations                 # every evaluation: a Table (``.to_pandas()`` for a DataFrame)
    res.pareto["dexterous_volume"]  # a column as a NumPy array (NaN where undefined)
    d = res.designs[0]              # the exported designs (1 = the knee of the front)
    d.mechanism.inverse(d.mechanism.nominal_pose[None])
    d.workspace().volume            # evaluated again with the study's request (cached)
    res.mechanism(seq=42)           # any candidate's mechanism

Reading never changes the results folder.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path

import numpy as np

from .errors import ParameterError

__all__ = ["open_results", "Results", "Design", "Table"]


class Table:
    """A small column table, DataFrame-like: ``t.columns``, ``len(t)``, ``t["col"]`` (a NumPy
    array: float with NaN for missing numbers, else object), ``t[i]`` (a row dict),
    ``t.records()``, ``t.units`` (column → unit), ``t.to_pandas()``."""

    def __init__(self, columns: list[str], rows: list[list], units: dict | None = None):
        self._names = list(columns)
        self._rows = [list(r) for r in rows]
        self.units = dict(units or {})

    @property
    def columns(self) -> list[str]:
        return list(self._names)

    def __len__(self) -> int:
        return len(self._rows)

    def __iter__(self):
        return iter(self.records())

    def __getitem__(self, key):
        if isinstance(key, str):
            if key not in self._names:
                raise KeyError(f"{key!r}: not a column (columns: {', '.join(self._names)})")
            j = self._names.index(key)
            vals = [r[j] for r in self._rows]
            if all(v is None or (isinstance(v, int | float) and not isinstance(v, bool))
                   for v in vals):
                return np.array([np.nan if v is None else float(v) for v in vals])
            return np.array(vals, dtype=object)
        return dict(zip(self._names, self._rows[key]))

    def records(self) -> list[dict]:
        return [dict(zip(self._names, r)) for r in self._rows]

    def to_pandas(self):
        """A :class:`pandas.DataFrame` (pandas is not a pkmlab dependency: install it)."""
        try:
            import pandas as pd
        except ImportError:  # pragma: no cover - depends on the environment
            raise ImportError("Table.to_pandas() needs pandas: pip install pandas") from None
        return pd.DataFrame(self._rows, columns=self._names)

    def __repr__(self) -> str:
        return f"<Table {len(self)} rows × {len(self._names)} columns: " \
               f"{', '.join(self._names[:8])}{', …' if len(self._names) > 8 else ''}>"

    def _repr_html_(self, limit: int = 20) -> str:
        def cell(v):
            if isinstance(v, float):
                return "" if math.isnan(v) else f"{v:.6g}"
            return "" if v is None else html.escape(str(v))

        head = "".join(f"<th>{html.escape(c)}" + (f" ({html.escape(self.units[c])})"
                                                  if self.units.get(c) else "") + "</th>"
                       for c in self._names)
        body = "".join("<tr>" + "".join(f"<td>{cell(v)}</td>" for v in r) + "</tr>"
                       for r in self._rows[:limit])
        more = f"<p>… {len(self) - limit} more rows</p>" if len(self) > limit else ""
        return f"<table><thead><tr>{head}</tr></thead><tbody>{body}</tbody></table>{more}"


@dataclass
class Design:
    """An exported design (``designs/NN-key/``): ``number`` (1 = the knee), ``pareto_rank``
    (its row in pareto.csv), ``why`` it was chosen, its ``params`` (internal units: mm,
    rad), ``metrics`` and ``folder``."""

    number: int
    pareto_rank: int
    why: str
    seq: int
    key: str
    params: dict
    metrics: dict
    folder: Path
    _results: Results = field(repr=False)

    @property
    def label(self) -> str:
        """Its one name in the summary, report, compare and here: ``#seq``, its evaluation
        number (``number`` and ``pareto_rank`` are positions, not names)."""
        return f"#{self.seq}"

    @cached_property
    def mechanism(self):
        """Its mechanism (:class:`pkmlab.Mechanism`)."""
        return self._results.study.space.decode(self.params)

    def workspace(self):
        """Its workspace with the study's request (evaluated on first call, then cached)."""
        return self._results._workspace(self.key, self.mechanism)

    @property
    def files(self) -> dict[str, Path]:
        return {p.name: p for p in sorted(self.folder.iterdir()) if p.is_file()}

    def mesh(self):
        """The exported hull (``trimesh.Trimesh``, mm) from workspace.ply, or None."""
        import trimesh

        p = self.folder / "workspace.ply"
        return trimesh.load(str(p), process=False, force="mesh") if p.is_file() else None


class Results:
    """A study's results folder, read-only (see the module docstring)."""

    def __init__(self, path: Path, study, records: list[dict]):
        self.path = Path(path)
        self.study = study
        self.records = records
        self._workspaces: dict = {}

    def __repr__(self) -> str:
        return (f"<Results {self.study.name}: {len(self.records)} evaluations, "
                f"{len(self.pareto)} Pareto, {len(self.designs)} designs exported at "
                f"{self.path}>")

    @cached_property
    def _front(self) -> list[dict]:
        from .study.report import pareto_records

        return pareto_records(self.study, self.records)

    def _table(self, records: list[dict], rank: bool) -> Table:
        from .study.metrics import METRICS
        from .study.run import BASELINE, feasible

        study = self.study
        names = [m for m in METRICS if any(m in r["metrics"] for r in self.records)]
        ok = feasible(study, records) if records else []
        pos = {r["seq"]: i + 1 for i, r in enumerate(self._front)}
        cols = (["rank"] if rank else []) + ["seq", "role", "status", "reason", "seconds",
                                             "feasible", "pareto_rank"]
        cols += [f"design.{v.name}" for v in study.variables] + names + ["notes"]
        units = {f"design.{v.name}": v.unit for v in study.variables}
        units.update({m: METRICS[m].unit for m in names})
        units["seconds"] = "s"
        rows = []
        for i, (r, f) in enumerate(zip(records, ok)):
            p = study.space.baseline_values() if r["params"] == BASELINE else r["params"]
            row = ([i + 1] if rank else []) + [
                r["seq"], r["role"], r["status"],
                (r["reason"] or "").splitlines()[0] if r["reason"] else "", r["seconds"],
                bool(f), pos.get(r["seq"])]
            row += [None if p.get(v.name) is None else v.display(p[v.name])
                    for v in study.variables]
            row += [r["metrics"].get(m) for m in names]
            row.append("; ".join(f"{k}: {v}" for k, v in r.get("notes", {}).items()))
            rows.append(row)
        return Table(cols, rows, units)

    @cached_property
    def evaluations(self) -> Table:
        """Every evaluation (the baseline first), design values in mm / deg."""
        return self._table(self.records, rank=False)

    @cached_property
    def pareto(self) -> Table:
        """The feasible non-dominated candidates, ``rank`` first (pareto.csv's rows)."""
        return self._table(self._front, rank=True)

    @cached_property
    def designs(self) -> list[Design]:
        """The exported designs, in the order they were chosen."""
        import json

        from .study.export import read_index

        out = []
        for e in read_index(self.path)["designs"]:
            info_path = self.path / "designs" / e["folder"] / "design.json"
            if not info_path.is_file():
                continue
            info = json.loads(info_path.read_text())
            out.append(Design(e["number"], e["pareto_rank"], e["why"], e["seq"], e["key"],
                              info["params"], info["metrics"], info_path.parent, self))
        return out

    @property
    def baseline(self) -> dict | None:
        return next((r for r in self.records if r["role"] == "baseline"), None)

    @property
    def report(self) -> Path:
        return self.path / "report.html"

    def candidate(self, seq: int) -> dict:
        """The stored record of evaluation ``seq``."""
        for r in self.records:
            if r["seq"] == seq:
                return r
        raise KeyError(f"no evaluation with seq {seq}")

    def mechanism(self, seq: int):
        """The mechanism of evaluation ``seq`` (raises ParameterError if it is invalid)."""
        from .study.run import BASELINE

        r = self.candidate(seq)
        return self.study.space.decode(None if r["params"] == BASELINE else r["params"])

    def workspace(self, seq: int):
        """The workspace of evaluation ``seq`` with the study's request (cached)."""
        return self._workspace(self.candidate(seq)["key"], self.mechanism(seq))

    def _workspace(self, key: str, mech):
        from .workspaces import workspace

        req = self.study.evaluation.request
        plan = getattr(self.study.evaluation, "planar_workspace", None)
        tri = getattr(self.study.evaluation, "tripod_workspace", None)
        if req is None and not plan and not tri:
            raise ParameterError("evaluate.workspace", "given in the study (it evaluates no "
                                 "workspace; a planar study: evaluate.planar_workspace; a "
                                 "tripod: evaluate.tripod_workspace)", None)
        if key not in self._workspaces:
            if req is None and tri:   # a tripod study: its grid and bracket
                from .workspaces.tripod import tripod_workspace

                self._workspaces[key] = tripod_workspace(
                    mech, tri.tilt, z_range=tri.z_range, resolution_z=tri.resolution_z,
                    resolution_angle=tri.resolution_angle, bracket_target=tri.target)
            elif req is None:   # a planar study: its PlanarWorkspace, with the study's request
                from .study.evaluators.planar_workspace import _phi
                from .workspaces.planar import planar_workspace

                self._workspaces[key] = planar_workspace(
                    mech, plan.kind, _phi(plan), plan.resolution, samples=plan.samples,
                    target=plan.target, max_depth=plan.max_depth)
            else:
                self._workspaces[key] = workspace(mech, **req)
        return self._workspaces[key]


def open_results(path: str | Path) -> Results:
    """A study's results (the folder, or its evaluations.sqlite / pareto.csv / report.html)."""
    from .study import study_from_mapping
    from .study.store import Store

    path = Path(path)
    folder = path if path.is_dir() else path.parent
    db = folder / "evaluations.sqlite"
    if not db.is_file():
        raise ParameterError("path", "a study results folder holding evaluations.sqlite",
                             str(path))
    store = Store(db, read_only=True)
    try:
        resolved, records = store.get_meta("resolved"), store.all()
    finally:
        store.close()
    study = study_from_mapping(resolved).with_output(folder)
    return Results(folder, study, records)
