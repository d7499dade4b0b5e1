"""Evaluate one candidate design: a pure function from a mechanism mapping to metrics.

It never raises: an invalid geometry is recorded with status ``"invalid"`` and its reason, any
other failure with ``"failed"``. Inputs and outputs are plain data, so the function runs
unchanged in a joblib worker or on a Dask cluster.
"""

from __future__ import annotations

import logging
import math
import time

import numpy as np

from ..config import load_mechanism, set_path, workspace_spec
from ..errors import ParameterError

log = logging.getLogger(__name__)

__all__ = ["candidate_mapping", "evaluate_candidate"]


def candidate_mapping(base: dict, variables: list[dict], values: dict) -> dict:
    """The mechanism mapping with each design variable written at its path (mm, deg)."""
    data = base
    for v in variables:
        x = values[v["name"]]
        if v["quantity"] == "text":
            data = set_path(data, v["path"], x)
            continue
        if v["quantity"] == "angle":
            x = math.degrees(x)                  # bare numbers in mechanism files are degrees
        data = set_path(data, v["path"], int(x) if v["type"] == "integer" else float(x))
    return data


def _finite(x) -> float | None:
    x = float(x)
    return x if math.isfinite(x) else None


def evaluate_candidate(mech_data: dict, evaluate: dict, seed: int) -> dict:
    """Metrics of one design → ``{"status", "reason", "metrics", "seconds"}``."""
    t0 = time.perf_counter()
    try:
        mech = load_mechanism(mech_data)
        metrics = _metrics(mech, evaluate, seed)
        status, reason = "ok", ""
    except ParameterError as exc:
        metrics, status, reason = {}, "invalid", str(exc)
    except Exception as exc:  # noqa: BLE001 - a failed candidate is data, never fatal
        log.warning("candidate failed: %s", exc)
        metrics, status, reason = {}, "failed", f"{type(exc).__name__}: {exc}"
    return {"status": status, "reason": reason, "metrics": metrics,
            "seconds": time.perf_counter() - t0}


def _metrics(mech, ev: dict, seed: int) -> dict:
    from .. import dexterity as dx
    from ..trajectory import check_trajectory, paper_motion
    from ..workspaces import OrientationSet, workspace

    m: dict = {
        "base_outer_radius": float(np.max(np.linalg.norm(mech.base_points[:, :2], axis=1))),
        "platform_outer_radius": float(np.max(np.linalg.norm(mech.platform_points[:, :2],
                                                             axis=1))),
        "stroke_length": float(mech.stroke[1] - mech.stroke[0]),
    }
    _ = mech.nominal_pose      # raises ParameterError if no level pose reaches mid-stroke
    if ev.get("workspace"):
        req = workspace_spec(ev["workspace"], prefix="evaluate.workspace.").build()
        res = workspace(mech, **req, refine=bool(ev["workspace"].get("refine", False)))
        m["workspace_volume"] = res.volume / 1e3
        m[f"{res.kind}_volume"] = res.volume / 1e3
        m["workspace_empty"] = float(res.empty)
        zr = res.metrics()["z_range_mm"]
        m["z_span"] = 0.0 if zr is None else zr[1] - zr[0]
        if ev.get("inscribed"):
            if res.empty:
                m.update(inscribed_box_volume=0.0, inscribed_box_edge=0.0,
                         inscribed_cylinder_radius=0.0, inscribed_cylinder_volume=0.0)
            else:
                box = res.inscribed_box(samples=2000, seed=seed)
                cyl = res.inscribed_cylinder(samples=2000, seed=seed)
                m.update(inscribed_box_volume=box.volume / 1e3,
                         inscribed_box_edge=float(box.size.min()),
                         inscribed_cylinder_radius=cyl.radius,
                         inscribed_cylinder_volume=cyl.volume / 1e3)
        if ev.get("orientation_capability"):
            m["orientation_capability"] = _capability(mech, req, workspace, OrientationSet)
        if ev.get("dexterity"):
            d = ev["dexterity"]
            L = d["characteristic_length"] or dx.characteristic_length(mech).length
            J0 = mech.jacobian(mech.nominal_pose)
            m["nominal_kappa"] = _finite(dx.condition_number(J0, L)[0])
            if res.empty:
                m.update(gci=0.0, gci_std_error=0.0, worst_kappa=None, min_force=0.0)
            else:
                g = dx.gci_monte_carlo(mech, res, L, samples=d["gci_samples"], seed=seed)
                m["gci"] = g.gci if g.ok else 0.0
                m["gci_std_error"] = _finite(g.std_error)
                m["worst_kappa"] = _finite(1.0 / g.lci_min) if g.ok and g.lci_min > 0 \
                    else None
                rng = np.random.default_rng(seed)
                p, R = dx.aggregate.sample_poses(res, d["gci_samples"], rng)
                valid = mech.inverse((p, R)).valid
                F = dx.max_force_all_directions(mech.jacobian((p[valid], R[valid])),
                                                d["force_limit"])
                m["min_force"] = float(np.nanmin(F)) if len(F) else 0.0
    if ev.get("trajectory"):
        tr = ev["trajectory"]
        t, X = paper_motion(mech, segment_time=tr["segment_time"])
        rep = check_trajectory(mech, t, X, payload_mass_kg=tr["payload"])
        m["paper_motion_fits"] = float(rep.fits)
        margins = np.concatenate([rep.margin_low, rep.margin_high])
        m["paper_motion_margin"] = _finite(np.min(margins)) if np.all(np.isfinite(margins)) \
            else None
    return m


def _capability(mech, req, workspace, OrientationSet) -> float:
    """Largest ±a (deg) of the simultaneous Euler box with a non-empty dexterous workspace."""
    samples = req["orientations"].samples if req["orientations"].kind == "box" else 7
    h = req["resolution"]

    def ok(a_deg: float) -> bool:
        o = OrientationSet.box(np.radians([a_deg] * 3), "simultaneous", samples)
        return not workspace(mech, "dexterous", o, h, req["constraints"]).empty

    if not ok(0.0):
        return 0.0
    lo, hi = 0.0, 60.0
    if ok(hi):
        return hi
    for _ in range(8):                              # to 60 / 2⁸ = 0.23°
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if ok(mid) else (lo, mid)
    return lo
