"""The analyses behind the ``inspect``, ``ik`` and ``dexterity`` commands, as library functions.

The command-line interface only parses options, calls these, writes files and prints; every
number it shows comes from here. Results are JSON-ready dicts in the library's units (mm, rad,
N, N·mm; poses as ``(6,)`` lists ``[x, y, z, θx, θy, θz]``); the CLI converts angles to degrees
for display. Nothing here prints, plots or writes files.

Not imported by :mod:`pkmlab.dexterity` itself (it depends on :mod:`pkmlab.workspaces`, which
depends on :mod:`pkmlab.dexterity.metrics`): ``from pkmlab.dexterity.report import ...``.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..mechanisms import LEG_STATUS
from ..workspaces import workspace
from .aggregate import (
    gci_grid,
    gci_monte_carlo,
    kappa_grid,
    kappa_statistics,
    well_conditioned_volume,
)
from .budget import require_grid
from .force import max_force_all_directions, max_moment_all_directions
from .maps import METRICS, MetricMap, metric_map
from .metrics import (
    CharacteristicLength,
    condition_number,
    is_singular,
    manipulability,
    resolve_length,
    smallest_singular_value,
)
from .singularity import singularity_flags
from .stiffness import stiffness
from .worst import worst_case

log = logging.getLogger(__name__)

__all__ = ["pose_report", "DexterityReport", "dexterity_report"]


def _fin(v) -> float | None:
    v = float(v)
    return v if math.isfinite(v) else None


def pose_report(mech, pose, *, L: float | CharacteristicLength | None = None,
                force_limit=None, actuator_stiffness=None) -> dict:
    """Inverse kinematics and conditioning of one pose (``inspect``, ``ik``, ``dexterity``).

    Args:
        mech: a mechanism.
        pose: ``(6,)`` pose (mm, rad).
        L: characteristic length of κ; default :func:`pkmlab.dexterity.resolve_length`.
        force_limit: actuator force limit(s) in N: adds the all-direction force and moment.
        actuator_stiffness: N/mm: adds the weakest stiffnesses and manipulabilities.

    Returns:
        ``pose`` (list, mm and rad), ``actuators`` (``{name: mm}``; ``None`` where a leg has no
        solution), ``valid``, ``reason``, ``leg_status`` (``{name: text}``),
        ``characteristic_length`` (L, status, reason), ``kappa`` (``None`` when singular),
        ``lci``, ``sigma_min``, ``singular`` (pkmlab's one rule), ``singularity`` (the
        serial / parallel proximity class of :func:`pkmlab.dexterity.singularity_flags`),
        and with the optional arguments ``force_all_directions_N``,
        ``moment_all_directions_Nmm``, ``manipulability_translational`` / ``_rotational``,
        ``stiffness_translational_min_N_per_mm``, ``stiffness_rotational_min_Nmm_per_rad``.
    """
    X = np.asarray(pose, dtype=float).reshape(6)
    length = resolve_length(mech, L)
    ik = mech.inverse(X)
    J = mech.jacobian(X)
    names = mech.actuator_names
    out = {
        "pose": X.tolist(),
        "actuators": {n: _fin(v) for n, v in zip(names, ik.q[0])},
        "valid": bool(ik.valid[0]),
        "reason": str(ik.reason_text[0]),
        "leg_status": {n: LEG_STATUS[int(c)] for n, c in zip(names, ik.leg_status[0])},
        "characteristic_length": length.as_dict(),
        "kappa": _fin(condition_number(J, length)[0]),
        "lci": float(1.0 / condition_number(J, length)[0]),
        "sigma_min": _fin(smallest_singular_value(J, length)[0]),
        "singular": bool(is_singular(J, length)[0]),
        "singularity": str(singularity_flags(mech, X, L=length).kind[0]),
    }
    mob = mech.mobility
    if force_limit is not None:
        out["force_all_directions_N"] = _fin(max_force_all_directions(
            J, force_limit, length.length, mob)[0])
        # no free rotation: the platform carries no moment through the actuators (None)
        out["moment_all_directions_Nmm"] = _fin(max_moment_all_directions(
            J, force_limit, length.length, mob)[0]) if mob.rotations else None
    if actuator_stiffness is not None:
        wt, wr = manipulability(J, mob)
        st = stiffness(J, actuator_stiffness, mob)
        out.update({
            "manipulability_translational": _fin(wt[0]),
            "manipulability_rotational": _fin(wr[0]),
            "stiffness_translational_min_N_per_mm": _fin(st.translational_min[0]),
            "stiffness_rotational_min_Nmm_per_rad": _fin(st.rotational_min[0]),
        })
    return out


@dataclass(frozen=True)
class DexterityReport:
    """Result of :func:`dexterity_report`.

    Attributes:
        data: JSON-ready dict: ``mechanism``, ``workspace`` (its metrics), ``nominal``
            (:func:`pose_report` of the nominal pose), ``aggregates`` (over the workspace;
            ``{"empty": True, ...}`` without them), ``metric``, ``characteristic_length``.
        result: the :class:`~pkmlab.workspaces.WorkspaceResult` analysed.
        mechanism: its mechanism (with the request's stroke window, if one was given).
        map: the :class:`~pkmlab.dexterity.maps.MetricMap` of ``metric`` (``None`` when the
            workspace is empty), for plots and coloured meshes.
        length: the characteristic length used, with its status and reason.
    """

    data: dict
    result: object
    mechanism: object
    map: MetricMap | None
    length: CharacteristicLength


def _stats(values: np.ndarray) -> dict:
    v = np.asarray(values, dtype=float)
    if v.size == 0:       # a workspace thinner than a grid cell has no sample inside
        return dict.fromkeys(("min", "mean", "p5", "p50", "max"))
    return {"min": float(v.min()), "mean": float(v.mean()), "p5": float(np.percentile(v, 5)),
            "p50": float(np.percentile(v, 50)), "max": float(v.max())}


def dexterity_report(mech, request: dict, *, L: float | CharacteristicLength | None = None,
                     metric: str = "kappa", well_conditioned: float = 10.0,
                     force_limit=150.0, force_required: float = 100.0,
                     actuator_stiffness=1.0e4, gci_samples: int = 2000,
                     seed: int = 0) -> DexterityReport:
    """Conditioning, force and stiffness at the nominal pose and over a workspace.

    Args:
        mech: a mechanism.
        request: a workspace request, the keyword arguments of :func:`pkmlab.workspace`
            (``kind``, ``orientations``, ``resolution``, ``constraints``, ...).
        L: characteristic length of κ; default :func:`pkmlab.dexterity.resolve_length`.
        metric: the per-voxel map to return (a key of :data:`pkmlab.dexterity.maps.METRICS`).
        well_conditioned: κ bound of the well-conditioned sub-workspace (≥ 1).
        force_limit: actuator force limit(s) in N.
        force_required: force (N) the platform must hold in every direction: the volume
            where it can.
        actuator_stiffness: actuator stiffness(es) in N/mm.
        gci_samples: Monte-Carlo GCI samples.
        seed: Monte-Carlo seed.

    Returns:
        :class:`DexterityReport`. Aggregates: κ statistics and the grid GCI over every
        voxel × orientation sample, the Monte-Carlo GCI (a sampled estimate, with its
        standard error), :func:`pkmlab.dexterity.worst_case` (worst κ, smallest force,
        singular pose inside), the well-conditioned and force-capable volumes.
    """
    if metric not in METRICS:
        raise ParameterError("metric", f"one of {list(METRICS)}", metric)
    if not (math.isfinite(well_conditioned) and well_conditioned >= 1):
        raise ParameterError("well_conditioned", "a κ bound >= 1", well_conditioned)
    if not (math.isfinite(force_required) and force_required > 0):
        raise ParameterError("force_required", "a force > 0 N", force_required)
    log.info("dexterity: workspace")
    res = workspace(mech, **request)
    mech = res.mechanism                      # carries a stroke window override, if any
    length = resolve_length(mech, L)
    nominal = pose_report(mech, mech.nominal_pose, L=length, force_limit=force_limit,
                          actuator_stiffness=actuator_stiffness)
    agg: dict = {"workspace_volume_cm3": res.volume / 1e3, "empty": res.empty}
    mmap = None
    if not res.empty and res.mesh_problem is not None:    # no grid sample inside
        agg["no_samples"] = res.mesh_problem
    elif not res.empty:
        require_grid(res)
        log.info("dexterity: κ over %d voxels × %d orientations", int(res.occupancy.sum()),
                 len(res.orientations.rotations()))
        g = kappa_grid(mech, res, length)
        ks = kappa_statistics(g.kappa[g.valid])
        grid_gci = gci_grid(mech, res, grid=g)
        mc = gci_monte_carlo(mech, res, length, samples=gci_samples, seed=seed)
        wc_vol = well_conditioned_volume(mech, res, well_conditioned, grid=g)
        log.info("dexterity: worst case, then the %s map", metric)
        wc = worst_case(mech, res, length, force_limit)
        mmap = metric_map(mech, res, metric, length, force_limit, actuator_stiffness)
        fmap = mmap if metric == "force" else metric_map(mech, res, "force", length,
                                                         force_limit)
        agg.update({
            "gci_grid": _fin(grid_gci.gci), "gci_grid_singular_samples": grid_gci.singular,
            "gci_monte_carlo": _fin(mc.gci), "gci_monte_carlo_std_error": _fin(mc.std_error),
            "gci_samples": mc.samples, "gci_rejected": mc.rejected,
            "gci_monte_carlo_sampled_max_kappa": _fin(mc.sampled_max_kappa),
            "kappa": {"min": _fin(ks.min), "mean": _fin(ks.mean), "p5": _fin(ks.p5),
                      "p50": _fin(ks.p50), "p95": _fin(ks.p95), "max": _fin(ks.max),
                      "singular_samples": ks.non_finite},
            "worst_case": wc.as_dict(),
            "well_conditioned_kappa_max": well_conditioned,
            "well_conditioned_volume_cm3": wc_vol.volume / 1e3,
            "well_conditioned_fraction": wc_vol.fraction,
            "force_all_directions_N": _stats(fmap.values),
            "force_required_N": force_required,
            "force_capable_volume_cm3": (float(np.mean(fmap.values >= force_required))
                                         * res.volume / 1e3) if fmap.values.size else None,
        })
    data = {"mechanism": mech.name, "workspace": res.metrics(), "nominal": nominal,
            "aggregates": agg, "metric": metric, "characteristic_length": length.as_dict()}
    return DexterityReport(data=data, result=res, mechanism=mech, map=mmap, length=length)
