"""Workspace-wide dexterity: global conditioning index, κ statistics, well-conditioned volume.

All aggregates work on a :class:`pkmlab.workspaces.WorkspaceResult`: its occupied voxels
(centres ``(xs[i], ys[j], zs[k])``, edge ``h = result.resolution``) and its orientation set
``result.orientations`` (already centred on the mechanism's nominal orientation).

Global conditioning index (Gosselin & Angeles 1991): ``GCI = ∫ LCI dW / ∫ dW`` with
``LCI = 1/κ(J_h)``. Here the measure is the product of

* volume over the occupied voxels, and
* the orientation set's *own parameter measure*: uniform in the Z-Y-X Euler-angle box for
  ``box`` sets (not the Haar measure of SO(3)), uniform along the swept angles for
  ``single-axis`` boxes (each axis weighted by its range), uniform azimuth, area-uniform tilt
  (density ∝ sin θ) and uniform torsion for ``tilt-torsion`` sets, and the one orientation of a
  ``fixed`` set.

One estimator family, two members: :func:`gci_grid` evaluates it on voxel centres × the set's
sample orientations with equal weights (a quadrature of that integral); :func:`gci_monte_carlo`
estimates it by sampling. In both, a singular pose (:func:`pkmlab.dexterity.is_singular`,
κ = inf) counts with ``LCI = 0`` and is counted in ``GCIResult.singular``; poses whose inverse
kinematics is invalid (outside the stroke, no real solution) are not part of the workspace:
they are excluded and counted in ``rejected``, never averaged as zero.

The extremes the estimators meet (``GCIResult.sampled_max_kappa``) are sample statistics; the
worst case over the whole workspace grid is :func:`pkmlab.dexterity.worst_case`.
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from . import _fused_exact
from .metrics import CharacteristicLength, condition_number, lci, resolve_length

log = logging.getLogger(__name__)

__all__ = ["GCIResult", "KappaGrid", "KappaStatistics", "WellConditionedVolume", "kappa_grid",
           "gci_grid", "gci_monte_carlo", "sample_orientations", "kappa_statistics",
           "well_conditioned_volume"]

_CHUNK = 100_000


def _voxels(result) -> tuple[np.ndarray, np.ndarray]:
    """Occupied voxel indices ``(V, 3)`` and centres ``(V, 3)`` in mm."""
    idx = np.argwhere(result.occupancy)
    centres = np.stack([result.xs[idx[:, 0]], result.ys[idx[:, 1]], result.zs[idx[:, 2]]],
                       axis=1) if len(idx) else np.empty((0, 3))
    return idx, centres


def orientation_batches(pos: np.ndarray, R: np.ndarray):
    """Yield ``(m0, n, p, Rr)``: positions ``(V, 3)`` × orientations ``R[m0:m0+n]`` flattened
    orientation-major into ``p (n·V, 3)``, ``Rr (n·V, 3, 3)``, about ``_CHUNK`` poses each."""
    V = len(pos)
    step = max(1, _CHUNK // max(V, 1))
    for m0 in range(0, len(R), step):
        Rm = R[m0:m0 + step]
        n = len(Rm)
        yield m0, n, np.tile(pos, (n, 1)), np.repeat(Rm, V, axis=0)


def _units(mech, idx, pos):
    """Evaluation units of the voxels ``idx`` (lexicographic, as from :func:`_voxels` or a
    subset of it in the same order): the voxels, or their (x, y) columns for families whose
    Jacobian does not depend on z (``column_invariant``).

    Returns ``(unit_pos (U, 3), voxel_unit (V,), shared)``.
    """
    if mech.column_invariant and len(idx):
        # idx comes from np.argwhere (aggregate._voxels), in lexicographic (i, j, k) order: a
        # column is a run of equal (i, j), so no sort is needed
        new = np.empty(len(idx), dtype=bool)
        new[0] = True
        np.any(idx[1:, :2] != idx[:-1, :2], axis=1, out=new[1:])
        return pos[np.flatnonzero(new)], np.cumsum(new) - 1, True
    return pos, np.arange(len(idx)), False


def _ik_valid(mech, p: np.ndarray, R: np.ndarray) -> np.ndarray:
    ik = mech.inverse((np.ascontiguousarray(p), R))
    return ik.valid


# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class KappaGrid:
    """κ of every occupied voxel × orientation of a workspace.

    Attributes:
        kappa: ``(V, M)`` homogenised condition number; ``inf`` where ``valid`` is False or
            the Jacobian is singular.
        valid: ``(V, M)`` the pose's inverse kinematics is valid (within the stroke).
        positions: ``(V, 3)`` voxel centres in mm.
        index: ``(V, 3)`` voxel indices into ``result.occupancy``.
        rotations: ``(M, 3, 3)`` the orientation set's sample.
        L: characteristic length used (mm).
        length: ``L`` with its status and reason (:func:`pkmlab.dexterity.resolve_length`).
    """

    kappa: np.ndarray
    valid: np.ndarray
    positions: np.ndarray
    index: np.ndarray
    rotations: np.ndarray
    L: float
    length: CharacteristicLength | None = None


def kappa_grid(mech, result, L: float | CharacteristicLength | None = None) -> KappaGrid:
    """κ(J_h) at every occupied voxel centre and every sample orientation of ``result``.

    For column-invariant families (the 6-PSU: the Jacobian does not depend on z at fixed x, y
    and orientation) κ is computed once per (x, y) column and shared along it; the inverse
    kinematics (stroke) is still checked per voxel.

    Args:
        mech: the mechanism of ``result``.
        result: a :class:`pkmlab.workspaces.WorkspaceResult`.
        L: characteristic length in mm; default :func:`pkmlab.dexterity.resolve_length`
            (Angeles').

    Returns:
        :class:`KappaGrid` (V occupied voxels × M orientations).
    """
    length = resolve_length(mech, L)
    L = length.length
    idx, pos = _voxels(result)
    Rs = result.orientations.rotations()
    V, M = len(pos), len(Rs)
    kap = np.full((V, M), np.inf)
    valid = np.zeros((V, M), dtype=bool)
    if V == 0:
        return KappaGrid(kap, valid, pos, idx, Rs, L, length)
    if mech.column_invariant:
        cols, inv = np.unique(idx[:, :2], axis=0, return_inverse=True)
        inv = inv.ravel()
        first = np.zeros(len(cols), dtype=np.int64)
        first[inv[::-1]] = np.arange(V)[::-1]          # first voxel of each column
        eval_pos = pos[first]
    else:
        inv = np.arange(V)
        eval_pos = pos
    kap_e = _kappa_units(mech, eval_pos, Rs, L, V)
    for m0, k, pv, Rv in orientation_batches(pos, Rs):
        valid[:, m0:m0 + k] = _ik_valid(mech, pv, Rv).reshape(k, V).T
    kap = np.where(valid, kap_e[inv], np.inf)
    return KappaGrid(kap, valid, pos, idx, Rs, L, length)


def _kappa_units(mech, eval_pos, Rs, L, V: int) -> np.ndarray:
    """``(Ve, M)`` exact κ at every position × rotation: the Jacobian fused with κ in one
    numba loop where the family has one (:mod:`._fused_exact`, the same values bit for bit),
    else NumPy Jacobians in chunks of about ``_CHUNK`` poses (``V`` the voxels per rotation)."""
    if _fused_exact.serves(mech):
        return _fused_exact.fused_kappa_grid(mech, eval_pos, Rs, L)
    Ve, M = len(eval_pos), len(Rs)
    kap_e = np.empty((Ve, M))
    step = max(1, _CHUNK // V)                         # V >= Ve poses per orientation
    for m0 in range(0, M, step):
        k = len(Rs[m0:m0 + step])
        J = mech.jacobian((np.tile(eval_pos, (k, 1)), np.repeat(Rs[m0:m0 + step], Ve, axis=0)))
        kap_e[:, m0:m0 + k] = condition_number(J, L).reshape(k, Ve).T
    return kap_e


def _lci(mech, p, R, L) -> np.ndarray:
    """``1/κ`` at the poses ``(p, R)`` (in pairs): fused where the family allows
    (:func:`._fused_exact.fused_kappa`, bit for bit), else :func:`.lci` of NumPy Jacobians."""
    if _fused_exact.serves(mech):
        return 1.0 / _fused_exact.fused_kappa(mech, p, R, L)
    return lci(mech.jacobian((p, R)), L)


@dataclass(frozen=True)
class GCIResult:
    """A global conditioning index estimate.

    Attributes:
        gci: mean LCI over the accepted samples, singular ones counting 0 (NaN only when
            ``ok`` is False; ``reason`` then says why).
        std_error: standard error of the mean (Monte Carlo: sample std / √n); 0.0 for the
            deterministic grid quadrature (its error is discretisation, not sampling).
        lci_std: standard deviation of LCI over the accepted samples.
        samples: number of poses averaged (singular ones included).
        rejected: poses excluded because their inverse kinematics is invalid (not in the
            workspace).
        method: ``'grid'`` or ``'monte-carlo'``.
        L: characteristic length used (mm).
        ok: at least one pose was accepted.
        sampled_min_lci: smallest LCI among the samples (0 if one is singular), NaN if none.
            A sample statistic: the worst case over the workspace is
            :func:`pkmlab.dexterity.worst_case`.
        singular: samples that are singular (κ = inf), counted with LCI 0.
        length: ``L`` with its status and reason.
        reason: why ``ok`` is False ("" otherwise).
    """

    gci: float
    std_error: float
    lci_std: float
    samples: int
    rejected: int
    method: str
    L: float
    ok: bool
    sampled_min_lci: float = float("nan")
    singular: int = 0
    length: CharacteristicLength | None = None
    reason: str = ""

    @property
    def sampled_max_kappa(self) -> float:
        """Largest κ among the samples (``inf`` if one is singular, NaN if none): a sample
        statistic, ≤ the worst case over the workspace (:func:`pkmlab.dexterity.worst_case`)."""
        m = self.sampled_min_lci
        return float("nan") if not math.isfinite(m) else (math.inf if m == 0 else 1.0 / m)


def _summarise(values: np.ndarray, rejected: int, method: str,
               length: CharacteristicLength) -> GCIResult:
    """``values``: the LCI of every accepted sample, 0 for singular ones."""
    n = int(values.size)
    L = length.length
    if n == 0:
        reason = (f"no pose of the workspace to average: all {rejected} samples have invalid "
                  "inverse kinematics" if rejected else "the workspace is empty")
        log.warning("GCI (%s): %s", method, reason)
        return GCIResult(float("nan"), float("nan"), float("nan"), 0, rejected, method, L,
                         False, length=length, reason=reason)
    std = float(values.std(ddof=1)) if n > 1 else 0.0
    se = 0.0 if method == "grid" else (std / math.sqrt(n) if n > 1 else float("inf"))
    return GCIResult(float(values.mean()), se, std, n, rejected, method, L, True,
                     float(values.min()), int(np.sum(values == 0.0)), length)


def gci_grid(mech, result, L: float | CharacteristicLength | None = None, *,
             grid: KappaGrid | None = None) -> GCIResult:
    """GCI by equal-weight quadrature over occupied voxel centres × sample orientations.

    ``GCI = mean of 1/κ`` over every (voxel, orientation) pair of :func:`kappa_grid` whose
    inverse kinematics is valid (in a dexterous workspace all are; in a reachable one, only the
    orientations reachable at the voxel count); singular pairs count with ``1/κ = 0``. Equal
    weights: every voxel has volume h³ and every sample orientation stands for an equal share
    of the set.

    Args:
        mech: the mechanism of ``result``.
        result: a :class:`pkmlab.workspaces.WorkspaceResult`.
        L: characteristic length in mm; default :func:`pkmlab.dexterity.resolve_length`.
        grid: the :func:`kappa_grid` of ``result`` if already computed (then ``L`` is its).

    Returns:
        :class:`GCIResult` with ``method='grid'`` and ``std_error=0``.
    """
    g = kappa_grid(mech, result, L) if grid is None else grid
    vals = 1.0 / g.kappa[g.valid]                  # κ = inf (singular) → LCI 0, counted
    length = g.length or resolve_length(mech, g.L)
    return _summarise(vals, int(np.sum(~g.valid)), "grid", length)


def sample_orientations(oset, n: int, rng: np.random.Generator) -> np.ndarray:
    """``n`` rotations ``(n, 3, 3)`` drawn from an orientation set's parameter measure.

    ``fixed``: the one orientation. ``box`` (simultaneous): Z-Y-X Euler offsets uniform in
    ``oset.bounds()``. ``box`` (single-axis): an axis chosen with probability ∝ its half-range,
    then its angle uniform in ``[-a, a]``, the others at the centre. ``tilt-torsion``: azimuth
    φ uniform in [0, 2π), tilt θ with density ∝ sin θ on [0, β] (area-uniform on the cone of
    symmetry axes: ``cos θ`` uniform in ``[cos β, 1]``), torsion σ uniform in [-γ, γ].
    All relative to ``oset.centre``.
    """
    if oset.kind == "fixed":
        return np.broadcast_to(oset.rotations()[0], (n, 3, 3)).copy()
    b = oset.bounds()
    if oset.kind == "box":
        if oset.semantics == "simultaneous":
            P = rng.uniform(b[:, 0], b[:, 1], size=(n, 3))
        else:
            h = b[:, 1]
            P = np.zeros((n, 3))
            if h.sum() > 0:
                axis = rng.choice(3, size=n, p=h / h.sum())
                P[np.arange(n), axis] = rng.uniform(-1.0, 1.0, n) * h[axis]
        return oset.rotations_at(P)
    beta, gamma = oset.tilt, oset.torsion
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    theta = np.arccos(1.0 - rng.uniform(0.0, 1.0, n) * (1.0 - math.cos(beta)))
    sigma = rng.uniform(-gamma, gamma, n) if gamma > 0 else np.zeros(n)
    return oset.rotations_at(np.stack([phi, theta, sigma], axis=1))


def sample_poses(result, samples: int, rng: np.random.Generator):
    """``samples`` poses ``(p (n, 3), R (n, 3, 3))`` uniform over a workspace × its set.

    Positions: an occupied voxel chosen uniformly, then a point uniform within it;
    orientations: :func:`sample_orientations`.
    """
    occ = np.flatnonzero(result.occupancy)
    pick = occ[rng.integers(0, len(occ), samples)]
    i, j, k = np.unravel_index(pick, result.occupancy.shape)
    h = result.resolution
    p = np.stack([result.xs[i], result.ys[j], result.zs[k]], axis=1)
    p += rng.uniform(-0.5 * h, 0.5 * h, size=(samples, 3))
    return p, sample_orientations(result.orientations, samples, rng)


def gci_monte_carlo(mech, result, L: float | CharacteristicLength | None = None,
                    samples: int = 2000, seed: int | None = 0, *,
                    poses: tuple[np.ndarray, np.ndarray] | None = None) -> GCIResult:
    """GCI by Monte Carlo over the workspace volume × orientation set.

    Positions: an occupied voxel chosen uniformly (all have volume h³), then a point uniform
    within it. Orientations: :func:`sample_orientations`. Samples whose inverse kinematics is
    invalid (a boundary voxel only partly inside, or an orientation between the set's samples
    that the dexterous check did not cover) are not in the workspace: they are rejected and
    counted in ``rejected``. Every other sample counts, a singular one (κ = inf, including a
    Jacobian that is not finite at a serial singularity) with LCI 0; the estimate is the mean.

    Args:
        mech: the mechanism of ``result``.
        result: a :class:`pkmlab.workspaces.WorkspaceResult`.
        L: characteristic length in mm; default :func:`pkmlab.dexterity.resolve_length`.
        samples: number of poses drawn (≥ 1).
        seed: seed of ``numpy.random.default_rng``.
        poses: the sample ``(p (n, 3), R (n, 3, 3))`` to use instead of drawing one (from
            :func:`sample_poses`), so that several Monte-Carlo statistics share one sample.

    Returns:
        :class:`GCIResult` with ``method='monte-carlo'``.
    """
    length = resolve_length(mech, L)
    if poses is not None:
        p, R = poses
        valid = _ik_valid(mech, p, R)
        vals = _lci(mech, p[valid], R[valid], length.length)
        return _summarise(vals, len(p) - len(vals), "monte-carlo", length)
    samples = int(samples)
    if samples < 1:
        raise ParameterError("samples", "an integer >= 1", samples)
    rng = np.random.default_rng(seed)
    if not result.occupancy.any():
        return _summarise(np.empty(0), 0, "monte-carlo", length)
    p, R = sample_poses(result, samples, rng)
    valid = _ik_valid(mech, p, R)
    vals = _lci(mech, p[valid], R[valid], length.length)
    return _summarise(vals, samples - len(vals), "monte-carlo", length)


# ---------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class KappaStatistics:
    """Summary of κ values (over the finite ones).

    Attributes:
        min, mean, p5, p50, p95, max: statistics of the finite values (NaN if there are none).
        count: number of finite values.
        non_finite: number of inf / NaN values (singular or undefined poses), excluded above.
    """

    min: float
    mean: float
    p5: float
    p50: float
    p95: float
    max: float
    count: int
    non_finite: int

    def as_dict(self) -> dict:
        return dict(self.__dict__)


def kappa_statistics(values) -> KappaStatistics:
    """Min, mean, 5/50/95th percentiles (linear interpolation) and max of κ values.

    Args:
        values: array of any shape (e.g. ``kappa_grid(...).kappa[valid]``).

    Returns:
        :class:`KappaStatistics`; non-finite values are counted, not included.
    """
    v = np.asarray(values, dtype=float).ravel()
    fin = v[np.isfinite(v)]
    bad = int(v.size - fin.size)
    if fin.size == 0:
        nan = float("nan")
        return KappaStatistics(nan, nan, nan, nan, nan, nan, 0, bad)
    p5, p50, p95 = np.percentile(fin, [5, 50, 95])
    return KappaStatistics(float(fin.min()), float(fin.mean()), float(p5), float(p50),
                           float(p95), float(fin.max()), int(fin.size), bad)


@dataclass(frozen=True)
class WellConditionedVolume:
    """Part of a workspace where κ stays below a bound over the whole orientation set.

    Attributes:
        volume: ``fraction × result.volume`` in mm³.
        fraction: share of occupied voxels whose worst κ over the set is ≤ ``kappa_max``.
        voxels: occupied voxels evaluated; ``well_conditioned``: those that pass.
        worst_kappa: ``(V,)`` worst κ per occupied voxel (inf where an orientation of the set is
            not reachable there or is singular).
        kappa_max, L: the bound and the characteristic length (mm) used.
        length: ``L`` with its status and reason.
    """

    volume: float
    fraction: float
    voxels: int
    well_conditioned: int
    worst_kappa: np.ndarray
    kappa_max: float
    L: float
    length: CharacteristicLength | None = None


def well_conditioned_volume(mech, result, kappa_max: float,
                            L: float | CharacteristicLength | None = None, *,
                            grid: KappaGrid | None = None) -> WellConditionedVolume:
    """Volume (mm³) of the occupied voxels whose worst κ over the orientation set ≤ κ_max.

    A voxel passes when *every* sample orientation is reachable there (valid inverse
    kinematics at the voxel centre) with ``κ ≤ kappa_max``. The volume is the passing share of
    occupied voxels times ``result.volume`` (exact in z for column results), so its resolution
    is that of the voxel grid.

    Args:
        mech: the mechanism of ``result``.
        result: a :class:`pkmlab.workspaces.WorkspaceResult`.
        kappa_max: bound on κ (≥ 1).
        L: characteristic length in mm; default :func:`pkmlab.dexterity.resolve_length`.
        grid: the :func:`kappa_grid` of ``result`` if already computed (then ``L`` is its).
    """
    km = float(kappa_max)
    if not (km >= 1):
        raise ParameterError("kappa_max", "a number >= 1", kappa_max)
    g = kappa_grid(mech, result, L) if grid is None else grid
    worst = g.kappa.max(axis=1) if g.kappa.shape[1] else np.full(len(g.kappa), np.inf)
    V = len(worst)
    n_ok = int(np.sum(worst <= km))
    frac = n_ok / V if V else 0.0
    return WellConditionedVolume(volume=frac * float(result.volume), fraction=frac, voxels=V,
                                 well_conditioned=n_ok, worst_kappa=worst, kappa_max=km,
                                 L=g.L, length=g.length)
