"""Workspaces of planar mechanisms (issue 24): areas in the plane of motion, per orientation φ.

A planar mechanism (mobility :data:`~pkmlab.mechanisms.mobility.PLANAR`, ``x, y, theta_z``, or
a point mechanism such as the five-bar, ``x, y``) has its own pose grid: positions ``(x, y)``
on a square grid of spacing ``h`` (cell centres at multiples of ``h``), for each orientation φ.
The 3-D engine (:mod:`.engine`) does not apply (z is not free); this module is its planar
counterpart and only reads the protocol plus three family hooks:

* ``position_box(phi_lo, phi_hi)`` → ``(xlo, xhi, ylo, yhi)`` mm, a box holding every
  stroke-feasible position for φ in the range;
* ``planar_cell_margins(xy (N, 2), phi (N,), delta (N,), alpha (N,))`` → ``(m, eps)``, both
  ``(N, K)``: ``m`` the margins of the K feasibility conditions at the cell centre (feasible
  iff every ``m >= 0``) and ``eps`` a bound on their change over every position within
  ``delta`` mm and every orientation within ``alpha`` rad of it (``m > eps`` everywhere in the
  cell proves the condition, ``m < -eps`` disproves it);
* optionally ``annuli(phi)`` → ``(centres (K, 2), r_in (K,), r_out (K,))`` when the
  constant-orientation set is an intersection of annuli (3-RPR; a five-bar without motor
  limits): its area is then computed exactly (:func:`annuli_area`, Green's theorem on the
  boundary arcs).

Kinds, over an orientation range ``[φ_lo, φ_hi]``: ``constant`` (one φ), ``reachable`` (some
φ of the range), ``dexterous`` (every φ of the range). Every result carries

* ``estimate``: the grid count of feasible cell centres (reachable / dexterous: at
  ``samples`` orientations of the range) × h² — **an estimate**, never the value;
* ``bracket``: a **guaranteed** ``[lower, upper]`` on the area of the continuous set: cells
  (and orientation intervals) proved in or out by the margins, undecided cells split in four
  (and their orientation intervals in two) until the width is within ``target`` of the lower
  bound or ``max_depth`` levels;
* ``exact``: the exact area where the family gives ``annuli`` and the kind is ``constant``.

The whole stroke-feasible set is measured (every connected component).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..errors import ParameterError

__all__ = ["PlanarWorkspace", "planar_workspace", "area_per_phi", "annuli_area",
           "KINDS", "plot_planar", "resolution_map", "areas_per_working_mode"]

KINDS = ("constant", "reachable", "dexterous")
#: largest (cells × orientation intervals) evaluated per refinement level of the bracket
_MAX_ITEMS = 4_000_000
#: a singularity field (dimensionless) whose largest magnitude on a slice is below this is zero
#: everywhere there (a 3-RPR whose platform is homothetic to its base at that φ: every pose of
#: the slice is a parallel singularity); the picture says so instead of drawing noise
_EVERYWHERE = 1e-9


@dataclass(frozen=True)
class PlanarWorkspace:
    """A planar workspace (module docstring). Areas in mm², angles in rad."""

    kind: str
    phi: tuple[float, float]
    resolution: float
    xs: np.ndarray
    ys: np.ndarray
    occupancy: np.ndarray              # (nx, ny) feasible cell centres (the estimate's grid)
    estimate: float
    lower: float
    upper: float
    exact: float | None
    samples: int
    depth: int
    seconds: float
    notes: tuple[str, ...] = field(default=())

    @property
    def bracket(self) -> tuple[float, float]:
        return (self.lower, self.upper)

    @property
    def empty(self) -> bool:
        return self.upper == 0.0

    def metrics(self) -> dict:
        """Plain-dict summary (mm², deg)."""
        return {"kind": self.kind, "phi_deg": [math.degrees(a) for a in self.phi],
                "resolution_mm": self.resolution,
                "area_estimate_mm2": self.estimate,
                "area_bracket_mm2": [self.lower, self.upper],
                "area_exact_mm2": self.exact,
                "method": ("exact: Green's theorem on the annuli's boundary arcs; "
                           if self.exact is not None else "")
                + f"guaranteed bracket: cell margins, {self.depth} refinement levels; "
                  f"estimate: grid count of cell centres"
                  + ("" if self.kind == "constant" else f" at {self.samples} orientations"),
                "seconds": self.seconds, "notes": list(self.notes)}


def _phi_range(mech, kind, phi) -> tuple[float, float]:
    nom = float(mech.nominal_pose[5])
    if phi is None:
        return (nom, nom)
    arr = np.atleast_1d(np.asarray(phi, dtype=float))
    if arr.size == 1:
        lo = hi = float(arr[0])
    elif arr.size == 2 and arr[0] <= arr[1]:
        lo, hi = float(arr[0]), float(arr[1])
    else:
        raise ParameterError("phi", "an angle or [min, max] (rad)", phi)
    if kind == "constant" and lo != hi:
        raise ParameterError("phi", "one angle for kind 'constant'", phi)
    if "theta_z" not in mech.mobility.coordinates and (lo != nom or hi != nom):
        raise ParameterError("phi", f"the nominal orientation (family {mech.family!r} has no "
                             "free rotation)", phi)
    return lo, hi


def _check(mech, kind, resolution):
    mob = mech.mobility.coordinates
    if mob[:2] != ("x", "y") or not set(mob) <= {"x", "y", "theta_z"}:
        raise ParameterError("mechanism", "a planar mechanism (free coordinates x, y and "
                             "optionally theta_z)", f"{mech.family!r} ({', '.join(mob)})")
    if kind not in KINDS:
        raise ParameterError("kind", f"one of {list(KINDS)}", kind)
    if not (math.isfinite(resolution) and resolution > 0):
        raise ParameterError("resolution", "a grid spacing > 0 mm", resolution)


def _poses(mech, x, y, phi) -> np.ndarray:
    X = np.repeat(mech.nominal_pose[None], len(x), axis=0)
    X[:, 0], X[:, 1], X[:, 5] = x, y, phi
    return X


def _grid(box, h):
    xs = np.arange(math.floor(box[0] / h), math.ceil(box[1] / h) + 1) * h
    ys = np.arange(math.floor(box[2] / h), math.ceil(box[3] / h) + 1) * h
    return xs, ys


def planar_workspace(mech, kind: str = "constant", phi=None, resolution: float = 5.0, *,
                     samples: int = 9, target: float = 0.01, max_depth: int = 6,
                     exact: bool = True) -> PlanarWorkspace:
    """Workspace of a planar mechanism (module docstring).

    Args:
        mech: a mechanism with planar mobility and the hooks of the module docstring.
        kind: ``"constant"``, ``"reachable"`` or ``"dexterous"``.
        phi: the orientation (rad) for ``constant``, ``[min, max]`` for the others; default
            the nominal orientation.
        resolution: grid spacing h (mm).
        samples: orientations of the range for the estimate (reachable / dexterous), and
            initial orientation intervals of the bracket.
        target: stop refining when ``upper - lower <= target · lower``.
        max_depth: refinement levels at most (each splits undecided cells in four).
        exact: compute the exact area when the family gives ``annuli`` (constant kind).
    """
    t0 = time.perf_counter()
    _check(mech, kind, float(resolution))
    lo, hi = _phi_range(mech, kind, phi)
    h = float(resolution)
    xs, ys = _grid(mech.position_box(lo, hi), h)
    nx, ny = len(xs), len(ys)
    if nx * ny > 4_000_000:
        raise ParameterError("resolution", "a grid of at most 4,000,000 cells",
                             f"{h:g} mm ({nx} × {ny})")
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    phis = np.array([lo]) if kind == "constant" or hi == lo else np.linspace(lo, hi, samples)
    occ = np.ones(nx * ny, bool) if kind != "reachable" else np.zeros(nx * ny, bool)
    for a in phis:
        ok = mech.inverse(_poses(mech, X.ravel(), Y.ravel(), a)).valid
        occ = occ | ok if kind == "reachable" else occ & ok
    occ = occ.reshape(nx, ny)
    estimate = float(occ.sum()) * h * h
    lower, upper, depth, notes = _bracket(mech, kind, lo, hi, X.ravel(), Y.ravel(), h,
                                          max(1, samples - 1) if hi > lo else 1, target,
                                          max_depth)
    ex = None
    if exact and kind == "constant" and hasattr(mech, "annuli"):
        ann = mech.annuli(lo)
        if ann is not None:
            ex = annuli_area(*ann)
    return PlanarWorkspace(kind, (lo, hi), h, xs, ys, occ, estimate, lower, upper, ex,
                           len(phis), depth, time.perf_counter() - t0, tuple(notes))


def _classify(mech, kind, cx, cy, half, plo, phw, nphi):
    """Per cell: proved in, proved out (orientation intervals ``plo + (k + ½)·2·phw``)."""
    n = len(cx)
    k = np.arange(nphi)
    mid = plo[:, None] + (2 * k[None, :] + 1) * phw[:, None]                 # (n, nphi)
    xy = np.repeat(np.stack([cx, cy], axis=1), nphi, axis=0)
    delta = np.repeat(half * math.sqrt(2.0), nphi)
    m, eps = mech.planar_cell_margins(xy, mid.ravel(), delta, np.repeat(phw, nphi))
    with np.errstate(invalid="ignore"):
        cin = np.all(m > eps, axis=1).reshape(n, nphi)
        cout = np.any(m < -eps, axis=1).reshape(n, nphi)
    if kind == "reachable":
        return cin.any(axis=1), cout.all(axis=1)
    return cin.all(axis=1), cout.any(axis=1)


def _bracket(mech, kind, lo, hi, cx, cy, h, nphi, target, max_depth):
    notes = []
    half = np.full(len(cx), 0.5 * h)
    plo = np.full(len(cx), lo)
    phw = np.full(len(cx), 0.5 * (hi - lo) / nphi)
    lower, depth = 0.0, 0
    while True:
        cin, cout = _classify(mech, kind, cx, cy, half, plo, phw, nphi)
        area = (2 * half) ** 2
        lower += float(area[cin].sum())
        und = ~cin & ~cout
        width = float(area[und].sum())
        if width <= target * lower or depth >= max_depth or not und.any():
            break
        n_next = 4 * int(und.sum()) * (2 * nphi if hi > lo else 1)
        if n_next > _MAX_ITEMS:
            notes.append(f"bracket refinement stopped at level {depth}: the next level "
                         f"would evaluate {n_next:,} cell-orientation items")
            break
        cx, cy, half, plo, phw = cx[und], cy[und], half[und], plo[und], phw[und]
        q = 0.5 * half
        cx = np.concatenate([cx - q, cx + q, cx - q, cx + q])
        cy = np.concatenate([cy - q, cy - q, cy + q, cy + q])
        half = np.tile(q, 4)
        plo, phw = np.tile(plo, 4), np.tile(phw, 4)
        if hi > lo:
            nphi *= 2
            phw = 0.5 * phw
        depth += 1
    return lower, lower + width, depth, notes


def area_per_phi(mech, phis, resolution: float = 5.0, **kw) -> list[PlanarWorkspace]:
    """Constant-orientation workspaces at each orientation of ``phis`` (rad)."""
    return [planar_workspace(mech, "constant", float(a), resolution, **kw) for a in phis]


def areas_per_working_mode(mech, resolution: float = 5.0, **kw) -> dict:
    """Constant-orientation workspaces of every working mode of a family that has several
    (``working_modes()``, ``with_working_mode(mode)``: the five-bar): ``{mode: result}``."""
    modes = mech.working_modes()
    return {mode: planar_workspace(mech if mode == getattr(mech, "working_mode", None)
                                   else mech.with_working_mode(mode), "constant", None,
                                   resolution, **kw) for mode in modes}


# ---- exact area of an intersection of annuli ---------------------------------------------------
def annuli_area(centres, r_in, r_out) -> float:
    """Exact area (mm²) of ``∩_k {p : r_in[k] <= |p - c_k| <= r_out[k]}``, by Green's theorem
    on the boundary: every circle is cut at its intersections with the others, and each arc
    whose midpoint lies in every other annulus is on the boundary (outer circles counted
    counter-clockwise, inner ones clockwise). Exact up to rounding; tangencies (measure zero)
    aside."""
    C = np.asarray(centres, dtype=float).reshape(-1, 2)
    rin, rout = np.asarray(r_in, dtype=float), np.asarray(r_out, dtype=float)
    circles = [(C[k], rout[k], +1.0, k) for k in range(len(C))]
    circles += [(C[k], rin[k], -1.0, k) for k in range(len(C)) if rin[k] > 0]
    total = 0.0
    for c, r, sign, own in circles:
        cuts = [0.0, 2 * math.pi]
        for c2, r2, _, _ in circles:
            d = float(np.hypot(*(c2 - c)))
            if d == 0.0 or d > r + r2 or d < abs(r - r2):
                continue
            base = math.atan2(c2[1] - c[1], c2[0] - c[0])
            w = math.acos(max(-1.0, min(1.0, (r * r + d * d - r2 * r2) / (2 * r * d))))
            cuts += [(base + w) % (2 * math.pi), (base - w) % (2 * math.pi)]
        cuts = np.unique(cuts)
        for t0, t1 in zip(cuts[:-1], cuts[1:]):
            tm = 0.5 * (t0 + t1)
            pm = c + r * np.array([math.cos(tm), math.sin(tm)])
            dist = np.hypot(*(pm - C).T)
            inside = np.ones(len(C), bool)
            others = np.arange(len(C)) != own
            inside[others] = (dist[others] >= rin[others]) & (dist[others] <= rout[others])
            if not inside.all():
                continue
            total += sign * 0.5 * (r * c[0] * (math.sin(t1) - math.sin(t0))
                                   - r * c[1] * (math.cos(t1) - math.cos(t0))
                                   + r * r * (t1 - t0))
    return float(total)


# ---- resolution ---------------------------------------------------------------------------------
def resolution_map(mech, res: PlanarWorkspace, step: float) -> dict:
    """Positioning resolution over a workspace's feasible cells (at the middle of its φ
    range): for actuator errors within ``±step`` each (mm or rad, the actuator unit), the
    largest tool displacement ``max_s |J⁻¹_xy·s|·step`` over the corners ``s ∈ {±1}^L`` of
    the error box (the largest of a convex function over a box is at a corner: exact), and
    the largest per axis, ``step·Σ_j |J⁻¹_kj|``. Returns ``worst``, ``x``, ``y`` arrays
    ``(nx, ny)`` in mm (NaN outside the workspace, inf at a singular pose)."""
    if mech.n_actuators != mech.mobility.width:
        raise ParameterError("mechanism", "as many actuators as free coordinates (a square "
                             "Jacobian)", f"{mech.n_actuators} and {mech.mobility.width}")
    idx = np.argwhere(res.occupancy)
    at = 0.5 * (res.phi[0] + res.phi[1])
    out = {k: np.full(res.occupancy.shape, np.nan) for k in ("worst", "x", "y")}
    if not len(idx):
        return out
    J = mech.jacobian(_poses(mech, res.xs[idx[:, 0]], res.ys[idx[:, 1]], at))
    L = J.shape[-1]
    with np.errstate(all="ignore"):
        det_ok = np.abs(np.linalg.det(J)) > 0
        Jinv = np.full_like(J, np.inf)
        Jinv[det_ok] = np.linalg.inv(J[det_ok])
    S = np.array(np.meshgrid(*[[-1.0, 1.0]] * L, indexing="ij")).reshape(L, -1)   # (L, 2^L)
    d = np.einsum("nkj,js->nks", Jinv[:, :2, :], S)
    worst = step * np.sqrt(np.max(np.sum(d * d, axis=1), axis=1))
    axis = step * np.sum(np.abs(Jinv[:, :2, :]), axis=2)
    out["worst"][idx[:, 0], idx[:, 1]] = np.where(det_ok, worst, np.inf)
    out["x"][idx[:, 0], idx[:, 1]] = np.where(det_ok, axis[:, 0], np.inf)
    out["y"][idx[:, 0], idx[:, 1]] = np.where(det_ok, axis[:, 1], np.inf)
    return out


# ---- pictures -----------------------------------------------------------------------------------
def plot_planar(mech, results, path, *, fields=None, points=None, title=None, ncols=3,
                field_grid=None, values=None, value_label=""):
    """Slice plots of planar workspaces (one panel per result): feasible cells, the
    singularity loci drawn in (``fields(X) -> {label: values}`` whose zero level is the locus,
    default the family's ``singular_fields``; ``points(phi) -> {label: (K, 2)}`` point loci,
    default ``singular_points``), the area estimate and bracket in each title; ``values``, one
    ``(nx, ny)`` array per result, colours the cells instead (a resolution map, labelled
    ``value_label``, log scale). Writes ``path`` (PNG); returns it."""
    from matplotlib.figure import Figure

    fields = fields or getattr(mech, "singular_fields", None)
    points = points or getattr(mech, "singular_points", None)
    n = len(results)
    nc = min(ncols, n)
    nr = (n + nc - 1) // nc
    fig = Figure(figsize=(4.2 * nc, 4.0 * nr))
    axes = np.asarray(fig.subplots(nr, nc, squeeze=False))
    styles = ("-", "--", ":", "-.")
    colours = ("crimson", "royalblue", "darkorange", "seagreen")
    for ax, res in zip(axes.ravel(), results):
        h = res.resolution
        ext = (res.xs[0] - h / 2, res.xs[-1] + h / 2, res.ys[0] - h / 2, res.ys[-1] + h / 2)
        if values is None:
            ax.imshow(res.occupancy.T, origin="lower", extent=ext, cmap="Greys", vmin=0,
                      vmax=2.2, interpolation="nearest")
        else:
            from matplotlib.colors import LogNorm

            v = np.asarray(values[results.index(res)], dtype=float)
            fin = v[np.isfinite(v)]
            norm = LogNorm(vmin=fin.min(), vmax=np.percentile(fin, 99)) if fin.size else None
            im = ax.imshow(np.where(np.isfinite(v), v, np.nan).T, origin="lower", extent=ext,
                           cmap="viridis", norm=norm, interpolation="nearest")
            fig.colorbar(im, ax=ax, shrink=0.8, label=value_label)
        if fields is not None:
            xs = np.linspace(ext[0], ext[1], field_grid or 2 * len(res.xs))
            ys = np.linspace(ext[2], ext[3], field_grid or 2 * len(res.ys))
            X, Y = np.meshgrid(xs, ys, indexing="ij")
            at = 0.5 * (res.phi[0] + res.phi[1])
            F = fields(_poses(mech, X.ravel(), Y.ravel(), at))
            if res.phi[0] != res.phi[1]:
                F = {f"{k} at φ = {math.degrees(at):.1f}°": v for k, v in F.items()}
            for k, (label, v) in enumerate(F.items()):
                v = np.asarray(v, dtype=float).reshape(X.shape)
                if not np.nanmax(np.abs(v)) > _EVERYWHERE:
                    ax.text(0.5, 0.04, f"{label}: everywhere at this φ", color=colours[k % 4],
                            transform=ax.transAxes, ha="center", fontsize=8)
                elif np.nanmin(v) < 0 < np.nanmax(v):
                    ax.contour(X, Y, v, levels=[0.0], colors=colours[k % 4],
                               linestyles=styles[k % 4], linewidths=1.2)
                    ax.plot([], [], color=colours[k % 4], ls=styles[k % 4], label=label)
        if points is not None:
            for k, (label, P) in enumerate(points(0.5 * (res.phi[0] + res.phi[1])).items()):
                P = np.asarray(P).reshape(-1, 2)
                ax.plot(P[:, 0], P[:, 1], "x", color=colours[(k + 2) % 4], label=label)
        ax.plot(*mech.base_points[:, :2].T, "k^", ms=6, label="base joints")
        ax.set_aspect("equal")
        ax.set_xlim(ext[0], ext[1])
        ax.set_ylim(ext[2], ext[3])
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        lo_d, hi_d = (math.degrees(a) for a in res.phi)
        phi = f"φ = {lo_d:.1f}°" if res.kind == "constant" else f"φ ∈ [{lo_d:.1f}°, {hi_d:.1f}°]"
        ax.set_title(f"{res.kind}, {phi}\nestimate {res.estimate / 100:.1f} cm², bracket "
                     f"[{res.lower / 100:.1f}, {res.upper / 100:.1f}]", fontsize=9)
        ax.legend(fontsize=6, loc="upper right")
    for ax in axes.ravel()[n:]:
        ax.axis("off")
    if title:
        fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    return path
