"""Lower-mobility families (issue 24): the delta robots against the six-DOF families.

1. IK throughput per family on 10⁶ poses, as actuator values per second (poses/s × actuators),
   CPU time on one thread, against the six-DOF families' (psu6, ups6, rss6) in the same run:
   each delta and planar family must stay within 2× of their mean per-actuator rate.
2. The exact workspace (constant orientation, columns exact in z) against a plain NumPy brute
   force on the same grid (the engine's x-y columns, z at the same spacing h), in the same
   run; each delta must be >= 1000× faster, and every feasible voxel of the brute force must
   lie in the exact set.
3. The time to a 1 % guaranteed volume bracket (:mod:`pkmlab.workspaces.bracket.octree`) of
   the deltas, and to a 1 % area bracket of the planar families.

Run: .venv/bin/python benchmarks/bench_lowmob.py [ik|workspace|bracket|scaling[:h...] ...]
(``scaling``: the delta3 exact / brute-force ratio against h, brute force timed on the
middle x-slabs; docs/validation.md "Issue 24 follow-up").
"""

from __future__ import annotations

import math
import sys
import time
from pathlib import Path

import numba
import numpy as np
from _timing import timed

import pkmlab
from pkmlab.mechanisms.families.ldelta3 import LDelta3
from pkmlab.workspaces import Constraints, workspace
from pkmlab.workspaces.bracket.columns import volume_bracket
from pkmlab.workspaces.planar import planar_workspace

ROOT = Path(__file__).resolve().parents[1]
MECH = ROOT / "studies" / "mechanisms"
SIX = {"psu6": "hopkins-williams-6psu.yaml", "ups6": "gough-stewart-6ups.yaml",
       "rss6": "instructables-servo-6rss.yaml"}
DELTAS = {"delta3": "clavel-delta3.yaml", "ldelta3": "klipper-example-ldelta3.yaml"}
PLANAR = {"rpr3": "planar-3rpr.yaml", "fivebar": "fivebar-scara.yaml"}
N_IK = 1_000_000
CONNECTED_OFF = Constraints(connected=False)      # the brute force keeps every component


def _deltas():
    out = {k: pkmlab.load_mechanism(MECH / f) for k, f in DELTAS.items()}
    out["ldelta3 inclined"] = LDelta3.from_towers(tilt=math.radians(12),
                                                 rod_angle_limit=math.radians(60))
    return out


def _cpu(fn, repeats: int = 7) -> float:
    """Least CPU time (``time.process_time``, every thread of the process) of ``repeats`` calls
    after a warm-up: on a shared machine the least disturbed call."""
    fn()
    best = math.inf
    for _ in range(repeats):
        t = time.process_time()
        fn()
        best = min(best, time.process_time() - t)
    return best


def bench_ik() -> None:
    """Per-actuator IK rate, CPU time on one numba thread (a rate per core; the ratio to the
    six-DOF families does not depend on the thread count, and CPU time is what a loaded
    machine leaves comparable). A mechanism whose mobility is not spatial gets its poses in
    its free coordinates, as its users give them (``inverse`` then runs the free-coordinate
    driver, :mod:`pkmlab.mechanisms.kernels.ik_free`)."""
    rng = np.random.default_rng(0)
    rates = {}
    mechs = ({k: pkmlab.load_mechanism(MECH / f) for k, f in SIX.items()} | _deltas()
             | {k: pkmlab.load_mechanism(MECH / f) for k, f in PLANAR.items()})
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        for name, m in mechs.items():
            ang = 15.0 if m.mobility.rotations else 0.0
            X = m.nominal_pose + np.concatenate(
                [rng.uniform(-40, 40, (N_IK, 3)), np.radians(rng.uniform(-ang, ang, (N_IK, 3)))],
                axis=1)
            X = np.ascontiguousarray(m.mobility.free(X))
            t = _cpu(lambda: m.inverse(X))                    # noqa: B023
            ok = m.inverse(X[:100_000]).valid.mean()
            rates[name] = N_IK * m.n_actuators / t
            print(f"{name:17s} IK {N_IK / t / 1e6:6.1f} M poses/s  {rates[name] / 1e6:6.1f} M "
                  f"actuators/s per core ({m.n_actuators} actuators, input {X.shape[1]} "
                  f"coordinates, {ok:.0%} valid)", flush=True)
    finally:
        numba.set_num_threads(threads)
    six = np.mean([rates[k] for k in SIX])
    for name in rates:
        if name in SIX:
            continue
        ratio = six / rates[name]
        print(f"{name:17s} six-DOF mean ({six / 1e6:.1f} M/s) / this = {ratio:.2f} "
              f"({'ok' if ratio <= 2.0 else 'SLOWER THAN 2x'})")


def _brute(m, xs, ys, zs):
    """Plain NumPy: the IK validity of every voxel centre (x slab by x slab), written here
    from the families' formulas (vertical towers; rotary arms), not the kernels."""
    out = np.zeros((len(xs), len(ys), len(zs)), dtype=bool)
    Y, Z = np.meshgrid(ys, zs, indexing="ij")
    for i, x in enumerate(xs):
        p = np.stack([np.full(Y.shape, x), Y, Z], axis=-1)[..., None, :]      # (ny, nz, 1, 3)
        W = p + m.tool_points - m.base_points                              # (ny, nz, 3, 3)
        if m.family == "ldelta3":
            lo, hi = m.stroke
            h2 = m.rod_length ** 2 - W[..., 0] ** 2 - W[..., 1] ** 2
            with np.errstate(invalid="ignore"):
                q = W[..., 2] + np.sqrt(h2)
            ok = (h2 >= 0) & (q >= lo) & (q <= hi) \
                & (h2 >= (m.rod_length * math.cos(m.rod_angle_limit)) ** 2 - 1e-9)
        else:
            a, s, b = m.crank_length, m.rod_length, m.branch
            x_ = np.sum(W * m.zero_directions, axis=-1)
            y_ = np.sum(W * m.v_directions, axis=-1)
            E, F = 2 * a * x_, 2 * a * y_
            G = np.sum(W * W, axis=-1) + a * a - s * s
            h2 = E * E + F * F - G * G
            with np.errstate(invalid="ignore"):
                h = np.sqrt(h2)
                th = np.arctan2(F * G + b * E * h, E * G - b * F * h)
            cone = np.abs(np.sum(W * m.servo_axes, axis=-1)) <= s * math.sin(m.cone_limit)
            lo, hi = m.stroke
            ok = (h2 >= 0) & (E * E + F * F > 1e-24 * a ** 4) & (th >= lo) & (th <= hi) & cone
        out[i] = np.all(ok, axis=-1)
    return out


def _exact_cpu(m, h, repeats):
    """CPU time of the exact workspace call on one numba thread (the NumPy brute force runs on
    one core too)."""
    threads = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        return _cpu(lambda: workspace(m, "constant", resolution=h, constraints=CONNECTED_OFF),
                    repeats)
    finally:
        numba.set_num_threads(threads)


def bench_workspace(only=None) -> None:
    """Wall times (the engine on its threads, median of 3; the brute force once) and CPU
    times (the engine on one thread, least of 3; the brute force's process time)."""
    for name, m in _deltas().items():
        if name == "ldelta3 inclined" or (only and name not in only):
            continue
        for h in ((4.0, 2.0, 1.0) if name == "ldelta3" else (10.0, 5.0)):
            t_ex, w = timed(lambda: workspace(m, "constant", resolution=h,   # noqa: B023
                                              constraints=CONNECTED_OFF), repeats=3)
            c_ex = _exact_cpu(m, h, 3)
            t_col = w.timings["columns_s"]
            box = m.position_bounds(np.eye(3)[None])[0]
            zs = np.arange(math.ceil(box[0, 2] / h), math.floor(box[1, 2] / h) + 1) * h
            t, c = time.perf_counter(), time.process_time()
            occ = _brute(m, w.xs, w.ys, zs)
            t_bf, c_bf = time.perf_counter() - t, time.process_time() - c
            X, Y, Z = np.meshgrid(w.xs, w.ys, zs, indexing="ij")
            inside = np.zeros_like(occ)
            for k in range(w.lo.shape[-1]):
                inside |= (Z >= w.lo[..., k:k + 1] - 1e-9) & (Z <= w.hi[..., k:k + 1] + 1e-9)
            missed = int(np.sum(occ & ~inside))
            print(f"{name:8s} h = {h:4.1f} mm: {len(w.xs)} × {len(w.ys)} columns, "
                  f"{occ.size:,} voxels; exact {t_ex * 1e3:7.1f} ms wall (column kernel "
                  f"{t_col * 1e3:6.1f} ms), {c_ex * 1e3:7.1f} ms CPU on one thread; NumPy brute "
                  f"force {t_bf:6.2f} s wall, {c_bf:6.2f} s CPU: {t_bf / t_ex:6.0f}× wall "
                  f"(kernel {t_bf / t_col:6.0f}×), {c_bf / c_ex:6.0f}× CPU; volume exact "
                  f"{w.volume / 1e6:.4f} L, brute {occ.sum() * h ** 3 / 1e6:.4f} L; "
                  f"feasible voxels outside the exact set: {missed}", flush=True)


def bench_scaling(hs=(10.0, 5.0, 2.5, 1.0), slabs: int = 5) -> None:
    """delta3: how the exact / brute-force ratio grows as h shrinks (∝ 1/h: the exact cost is
    per column, the brute force's per voxel). The brute force is timed on the ``slabs``
    middle x-slabs and scaled by the slab count (its cost per voxel is uniform), so that fine
    grids (2·10⁹ voxels at 1 mm) take seconds, not an hour. Wall: the engine on its threads;
    CPU: the engine on one thread against the brute force's process time."""
    m = _deltas()["delta3"]
    for h in hs:
        t_ex, w = timed(lambda: workspace(m, "constant", resolution=h,   # noqa: B023
                                          constraints=CONNECTED_OFF), repeats=1 if h < 2 else 3)
        c_ex = _exact_cpu(m, h, 3 if h < 2 else 5)
        box = m.position_bounds(np.eye(3)[None])[0]
        zs = np.arange(math.ceil(box[0, 2] / h), math.floor(box[1, 2] / h) + 1) * h
        nx, ny = len(w.xs), len(w.ys)
        first = nx // 2 - slabs // 2
        t, c = time.perf_counter(), time.process_time()
        _brute(m, w.xs[first:first + slabs], w.ys, zs)
        t_s, c_s = time.perf_counter() - t, time.process_time() - c
        t_bf, c_bf = t_s * nx / slabs, c_s * nx / slabs
        print(f"delta3 h = {h:4.2f} mm: {nx * ny:,} columns, {nx * ny * len(zs):.3g} voxels; "
              f"exact {t_ex:.3f} s wall ({t_ex / (nx * ny) * 1e6:.2f} µs/column, kernel "
              f"{w.timings['columns_s'] / (nx * ny) * 1e6:.2f}), {c_ex:.3f} s CPU on one thread "
              f"({c_ex / (nx * ny) * 1e6:.2f} µs/column); brute force (from {slabs} middle "
              f"x-slabs) {t_bf:.1f} s wall, {c_bf:.1f} s CPU "
              f"({c_s / (slabs * ny * len(zs)) * 1e9:.0f} ns/voxel): {t_bf / t_ex:.0f}× wall, "
              f"{c_bf / c_ex:.0f}× CPU", flush=True)


def bench_bracket() -> None:
    """Time to a 1 % guaranteed bracket: the deltas' volume (octree), the planar families'
    constant-orientation area (:func:`pkmlab.workspaces.planar.planar_workspace`, 5 mm cells
    refined; its time includes the sampled estimate). The 3-PRS has no guaranteed bracket
    (its volume is a sampled estimate): said so, not timed."""
    for name, m in _deltas().items():
        b = volume_bracket(m, target=0.01, budget_s=300.0)
        print(f"{name:17s} 1 % bracket [{b.lower / 1e6:.4f}, {b.upper / 1e6:.4f}] L "
              f"({100 * b.relative_width:.2f} %), {b.stop_reason}, {b.seconds:.1f} s "
              f"(set-up {b.setup_seconds:.1f} s), final cube {b.resolution:.3g} mm", flush=True)
    for name, f in PLANAR.items():
        m = pkmlab.load_mechanism(MECH / f)
        planar_workspace(m, "constant", resolution=5.0, target=0.01)       # compile / load
        r = planar_workspace(m, "constant", resolution=5.0, target=0.01)
        width = (r.upper - r.lower) / r.lower
        print(f"{name:17s} 1 % area bracket [{r.lower / 100:.3f}, {r.upper / 100:.3f}] cm² "
              f"({100 * width:.2f} % of the lower bound{', met' if width <= 0.01 else ''}), "
              f"{r.seconds:.2f} s, depth {r.depth}", flush=True)
    print("prs3              no guaranteed volume bracket (sampled estimate only)")


def bench_tripod_bracket() -> None:
    """3-PRS (tripod-3prs): time to a guaranteed (z, θx, θy) volume bracket
    (:func:`pkmlab.workspaces.tripod.tripod_volume_bracket`): column form (vertical rails) to
    1 % and 0.1 %, and the box form (the same design with rails inclined 15°) to what its
    budget reaches."""
    from pkmlab.mechanisms.families.prs3 import Prs3, tripod_layout
    from pkmlab.workspaces.tripod import tripod_volume_bracket

    tp = pkmlab.load_mechanism(MECH / "tripod-3prs.yaml")
    a, d, n, b = tripod_layout(200.0, 100.0, math.radians(15.0))
    runs = [("vertical rails", tp, 0.01), ("vertical rails", tp, 0.001),
            ("rails at 15°", Prs3(a, b, d, n, [250.0] * 3, (0.0, 400.0)), 0.01)]
    for label, m, target in runs:
        c0 = time.process_time()
        br = tripod_volume_bracket(m, math.radians(30.0), target=target, max_level=60,
                                   budget_s=120.0)
        print(f"tripod {label:15s} ±30°, target {target:.1%}: [{br.lower:.3f}, "
              f"{br.upper:.3f}] mm·rad² ({br.relative_width:.3%}), {br.stop_reason}, "
              f"{br.seconds:.2f} s wall, {time.process_time() - c0:.2f} s CPU, "
              f"{br.history[-1].get('cells', br.history[-1].get('boxes'))} cells/boxes in "
              f"the last step", flush=True)


if __name__ == "__main__":
    print(f"numba threads: {numba.get_num_threads()}")
    which = sys.argv[1:] or ["ik", "workspace", "bracket"]
    for part in which:
        if part.startswith("workspace:"):            # workspace:ldelta3 runs one family
            bench_workspace(part.split(":")[1:])
            continue
        if part.startswith("scaling"):                # scaling:1.0:0.75 sets the grids
            bench_scaling(tuple(map(float, part.split(":")[1:])) or (10.0, 5.0, 2.5, 1.0))
            continue
        {"ik": bench_ik, "workspace": bench_workspace, "bracket": bench_bracket,
         "tripod": bench_tripod_bracket}[part]()
