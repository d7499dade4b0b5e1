"""numba's disk cache of the family kernels: no aliasing across processes, and invalidation.

Kernels compiled by different processes into one ``NUMBA_CACHE_DIR`` and then loaded together
by a third process must each run their own code (see ``pkmlab.runtime.jit``), and editing a family's
source must recompile its kernels. The references are plain NumPy formulas, computed here.
"""

from __future__ import annotations

import json
import os
import re
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor
from pathlib import Path

import numpy as np
import pytest

import pkmlab
from pkmlab.poses import euler_to_matrix  # plain NumPy

SRC = Path(pkmlab.__file__).resolve().parents[1]
MECH_DIR = Path(__file__).resolve().parents[2] / "studies" / "mechanisms"
# psu6 and ups6 pass geometry tuples of the same length, so their kernels have the same argument
# types and, before pkmlab.runtime.jit, could get the same symbols (luzi3's could not: 28 floats).
FILES = {"psu6": "hopkins-williams-6psu.yaml", "ups6": "gough-stewart-6ups.yaml"}
# Poses (mm, rad) around each family's nominal pose, a few of them outside the workspace.
_rng = np.random.default_rng(7)
CENTRES = {"psu6": [0, 0, 295.0, 0, 0, 0], "ups6": [0, 0, 568.27, 0, 0, 0]}
POSES = {f: (np.array(c) + np.concatenate([_rng.uniform(-40, 40, (64, 3)),
                                           np.radians(_rng.uniform(-12, 12, (64, 3)))], axis=1))
         for f, c in CENTRES.items()}
BOX_DEG, SAMPLES = 4.0, 3     # the small dexterous workspace: ±4°, 27 orientations, grid H mm
H = {"psu6": 4.0, "ups6": 25.0}

# One script for every process: each argument is a task, run in order.
SCRIPT = '''
import json, sys
import numpy as np
import pkmlab
from pkmlab.mechanisms.kernels import columns as column_kernels, ik as _kernels
from pkmlab.poses import euler_to_matrix

from numba.extending import register_jitable

args = json.loads(sys.argv[1])
files, poses, out = args["files"], args["poses"], {}
mechs = {}


@register_jitable(inline="always")
def dummy_one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, j):
    for i in range(6):
        q[i * _kernels.ROW + j] = pz + g[i]
        st[i * _kernels.ROW + j] = 0


class Dummy(pkmlab.mechanisms.UPS6):
    """A trivial family whose kernels compile the drivers' shared helpers."""
    _ik_one = dummy_one


def mech(f):
    if f not in mechs:
        mechs[f] = pkmlab.load_mechanism(files[f])
    return mechs[f]


for task in args["tasks"]:
    kind, f = task.split(":")
    if kind == "warm":
        m = Dummy.from_circles()
        X = np.array([[0.0, 0.0, 500.0, 0.0, 0.0, 0.0]])
        m.inverse(X), m.inverse((X[:, :3].copy(), np.eye(3)[None]))
        continue
    m = mech(f)
    if kind == "ik":
        X = np.array(poses[f])
        R = euler_to_matrix(X[:, 3:]).reshape(-1, 3, 3)
        out[task] = {"euler": m.inverse(X).q.tolist(),
                     "frames": m.inverse((X[:, :3].copy(), R)).q.tolist(),
                     "base": m.base_points.tolist(), "tool": m.tool_points.tolist(),
                     "length": m.link_length.tolist() if f == "psu6" else None}
    elif kind == "jac":
        X = np.array(poses[f])
        R = euler_to_matrix(X[:, 3:]).reshape(-1, 3, 3)
        ik, J = m.inverse_and_jacobian((X[:, :3].copy(), R))
        from pkmlab.dexterity._fused import fused_sweep
        sw = fused_sweep(m, X[:8, :3], R[:8], np.ones((8, 8), bool), 80.0, np.full(6, 150.0))
        out[task] = {"fused": ik.q.tolist(), "fused_jac": J.tolist(),
                     "sweep": [a.tolist() for a in sw]}
    elif kind == "ws":
        deg = args["box_deg"]
        oset = pkmlab.OrientationSet.box(np.radians([deg, deg, deg]), samples=args["samples"])
        ws = pkmlab.workspace(m, "dexterous", oset, resolution=args["h"][f])
        R = oset.rotations()
        xs = np.arange(-12, 13) * args["h"][f]
        lo, hi, _ = m.column_intervals(xs, xs, R, "all")
        alo, ahi, _ = m.column_intervals(xs, xs, R, "any")
        W = m.leg_offsets(R)
        Wk = W.reshape(-1, 3)
        Pk = np.tile(m.column_params(), (len(R), 1))
        x = np.linspace(-60, 60, len(Wk))
        a, b, ok = column_kernels.make_leg_eval(type(m).column_leg)(x, x[::-1], Wk, Pk)
        fin = lambda v: np.where(np.isfinite(v), v, np.nan).tolist()
        out[task] = {"volume": ws.volume, "xs": xs.tolist(), "W": W.tolist(),
                     "P": m.column_params().tolist(), "all": [fin(lo), fin(hi)],
                     "any_length": np.where(alo <= ahi, ahi - alo, 0.0).sum(axis=2).tolist(),
                     "leg": [x.tolist(), fin(a), fin(b), ok.tolist()]}
print("RESULT " + json.dumps(out))
'''


def _run(cache: Path, script: Path, tasks, extra_env=None) -> tuple[dict, str]:
    args = {"tasks": tasks, "files": {f: str(MECH_DIR / n) for f, n in FILES.items()},
            "poses": {f: X.tolist() for f, X in POSES.items()}, "box_deg": BOX_DEG,
            "samples": SAMPLES, "h": H}
    env = {**os.environ, "NUMBA_CACHE_DIR": str(cache), "PYTHONPATH": str(SRC),
           **(extra_env or {})}
    proc = subprocess.run([sys.executable, str(script), json.dumps(args)], env=env,
                          capture_output=True, text=True, timeout=600)
    assert proc.returncode == 0, proc.stderr[-3000:]
    line = next(s for s in proc.stdout.splitlines() if s.startswith("RESULT "))
    return json.loads(line[7:]), proc.stdout


# ---- NumPy references -------------------------------------------------------------------------
def ik_reference(family, X, base, tool, length):
    p, R = X[:, :3], euler_to_matrix(X[:, 3:]).reshape(-1, 3, 3)
    B, U = np.array(base), np.array(tool)
    Wj = p[:, None, :] + np.einsum("nij,kj->nki", R, U)                 # platform joints
    if family == "psu6":
        a = Wj - B
        h2 = np.array(length) ** 2 - a[..., 0] ** 2 - a[..., 1] ** 2
        with np.errstate(invalid="ignore"):
            return np.where(h2 >= 0, a[..., 2] - np.sqrt(h2), np.nan)
    return np.linalg.norm(Wj - B, axis=-1)                              # ups6


def jacobian_reference(family, X, base, tool, length):
    """Rows ``[a, r × a] / a_z`` (psu6, ``a`` the link) or ``[n, r × n]`` (ups6)."""
    p, R = X[:, :3], euler_to_matrix(X[:, 3:]).reshape(-1, 3, 3)
    r = np.einsum("nij,kj->nki", R, np.array(tool))
    a = p[:, None, :] + r - np.array(base)
    if family == "psu6":
        with np.errstate(invalid="ignore"):
            a[..., 2] = np.sqrt(np.array(length) ** 2 - a[..., 0] ** 2 - a[..., 1] ** 2)
        return np.concatenate([a, np.cross(r, a)], axis=-1) / a[..., 2:3]
    n = a / np.linalg.norm(a, axis=-1)[..., None]
    return np.concatenate([n, np.cross(r, n)], axis=-1)


def leg_reference(family, x, y, W, P):
    """Each leg's stroke interval on the column (x, y), as in the family docstrings."""
    wx, wy, wz = W[..., 0], W[..., 1], W[..., 2]
    d2 = (x + wx) ** 2 + (y + wy) ** 2
    if family == "psu6":                         # q = z + w_z - sqrt(l² - d²)
        l2, qmin, qmax = P[..., 0], P[..., 1], P[..., 2]
        s = np.sqrt(np.maximum(l2 - d2, 0.0))
        return qmin - wz + s, qmax - wz + s, l2 - d2 >= 0
    side, qmin2, qmax2 = P[..., 0], P[..., 1], P[..., 2]   # q² = d² + (z + w_z)²
    ro, ri = np.sqrt(np.maximum(qmax2 - d2, 0.0)), np.sqrt(np.maximum(qmin2 - d2, 0.0))
    a = np.where(side > 0, -wz + ri, -wz - ro)
    b = np.where(side > 0, -wz + ro, -wz - ri)
    return a, b, qmax2 - d2 >= 0


def column_reference(family, xs, W, P):
    """``(lo, hi)`` of every column for each orientation: intersection over the legs."""
    x, y = np.meshgrid(xs, xs, indexing="ij")
    a, b, ok = leg_reference(family, x[..., None, None], y[..., None, None], W[None, None],
                             P[None, None, None])                    # (nx, ny, M, 6)
    a = np.where(ok, a, np.inf)
    return a.max(axis=-1), np.where(ok, b, -np.inf).min(axis=-1)     # (nx, ny, M)


def dexterous_length(family, xs, W, P):
    """Length of every column's z interval common to all orientations (and legs)."""
    x, y = np.meshgrid(xs, xs, indexing="ij")
    lo, hi = np.full(x.shape, -np.inf), np.full(x.shape, np.inf)
    for Wm in W:
        a, b, ok = leg_reference(family, x[..., None], y[..., None], Wm, P)   # (nx, ny, 6)
        lo = np.maximum(lo, np.where(ok, a, np.inf).max(axis=-1))
        hi = np.minimum(hi, np.where(ok, b, -np.inf).min(axis=-1))
    return np.maximum(hi - lo, 0.0)


def union_length(lo, hi):
    total = 0.0
    end = -np.inf
    for a, b in sorted(zip(lo[lo <= hi], hi[lo <= hi], strict=True)):
        total += max(0.0, b - max(a, end))
        end = max(end, b)
    return total


def check_ik(family, r):
    X = POSES[family]
    ref = ik_reference(family, X, r["base"], r["tool"], r["length"])
    for path in ("euler", "frames"):
        q = np.array(r[path], dtype=float)
        np.testing.assert_allclose(q, ref, rtol=1e-11, atol=1e-9,
                                   err_msg=f"{family} IK, {path} path")


def check_jac(family, r, ik):
    """The fused IK + Jacobian driver against the NumPy references."""
    X = POSES[family]
    ref = ik_reference(family, X, ik["base"], ik["tool"], ik["length"])
    np.testing.assert_allclose(np.array(r["fused"], dtype=float), ref, rtol=1e-11, atol=1e-9,
                               err_msg=f"{family} IK, fused path")
    Jref = jacobian_reference(family, X, ik["base"], ik["tool"], ik["length"])
    np.testing.assert_allclose(np.array(r["fused_jac"], dtype=float), Jref, rtol=1e-11,
                               atol=1e-11, err_msg=f"{family} Jacobian, fused path")
    # the worst case's fused Jacobian + bounds kernel: the NumPy Jacobians of the 8 × 8
    # (position, orientation) grid through the unfused bounds pass
    from pkmlab.dexterity._linalg import sweep_bounds

    G = np.concatenate([np.tile(X[:8, :3], (8, 1)), np.repeat(X[:8, 3:], 8, axis=0)], axis=1)
    Jg = jacobian_reference(family, G, ik["base"], ik["tool"], ik["length"])
    ref = [np.empty(64) for _ in range(3)]
    sweep_bounds(np.ascontiguousarray(Jg), 80.0, np.full(6, 150.0), *ref)
    for got, want in zip(r["sweep"], ref):
        np.testing.assert_allclose(np.array(got, dtype=float), want.reshape(8, 8).T,
                                   rtol=1e-9, err_msg=f"{family} fused worst-case sweep")


def check_columns(family, r):
    xs, W, P = np.array(r["xs"]), np.array(r["W"]), np.array(r["P"])
    lo_m, hi_m = column_reference(family, xs, W, P)
    lo, hi = lo_m.max(axis=-1), hi_m.min(axis=-1)
    alive = lo <= hi
    got_lo, got_hi = (np.array(v, dtype=float)[..., 0] for v in r["all"])
    assert np.array_equal(alive, np.isfinite(got_lo)), f"{family}: columns alive ('all')"
    assert alive.sum() > 20, f"{family}: the test grid should cut the workspace"
    np.testing.assert_allclose(got_lo[alive], lo[alive], atol=1e-9, err_msg=f"{family} 'all'")
    np.testing.assert_allclose(got_hi[alive], hi[alive], atol=1e-9, err_msg=f"{family} 'all'")
    ref_any = [[union_length(lo_m[i, j], hi_m[i, j]) for j in range(len(xs))]
               for i in range(len(xs))]
    np.testing.assert_allclose(r["any_length"], ref_any, atol=1e-9, err_msg=f"{family} 'any'")
    x, a, b, ok = (np.array(v, dtype=float) for v in r["leg"])
    ra, rb, rok = leg_reference(family, x, x[::-1], W.reshape(-1, 3),
                                np.tile(P, (len(W), 1)))
    assert np.array_equal(ok.astype(bool), rok), f"{family}: leg_eval reach"
    np.testing.assert_allclose(a[rok], ra[rok], atol=1e-9, err_msg=f"{family} leg_eval")
    np.testing.assert_allclose(b[rok], rb[rok], atol=1e-9, err_msg=f"{family} leg_eval")


def test_parallel_and_family_kernels_are_built_safely():
    """Every ``parallel=True`` kernel and every closure compiled by numba goes through
    ``pkmlab.runtime.jit`` (whose naming makes cached kernels unique), none is declared directly."""
    bad = []
    for path in SRC.joinpath("pkmlab").rglob("*.py"):
        text = path.read_text()
        for m in re.finditer(r"\b(?:njit|jit)\(([^()]|\([^()]*\))*parallel\s*=\s*True", text):
            bad.append(f"{path.name}: {m.group(0)[:60]}")
        for line in text.splitlines():
            if re.match(r"\s+@(?:njit|jit|register_jitable|numba\.)", line):
                bad.append(f"{path.name}: nested {line.strip()}")
    assert not bad, bad


def test_uid_namespace_of_a_kernel():
    """Functions numba creates while a kernel compiles get uids from the kernel's own range,
    far above the ordinary ones, which carry on afterwards as if nothing happened."""
    from numba.core.bytecode import FunctionIdentity

    from pkmlab.runtime import jit as _jit

    assert _jit.CACHE_SAFE            # else this numba's internals changed: kernels uncached

    def f():
        pass

    before = FunctionIdentity.from_function(f).unique_id
    ident = "0123456789abcdef" * 4
    base = ((1 << 63) | 0x0123456789ABCDEF) << 32
    with _jit._uid_namespace(ident):
        inside = [FunctionIdentity.from_function(f).unique_id for _ in range(3)]
    with _jit._uid_namespace(ident):
        inside.append(FunctionIdentity.from_function(f).unique_id)
    after = FunctionIdentity.from_function(f).unique_id
    assert inside == [base, base + 1, base + 2, base + 3]
    assert before < after < 1 << 32


def test_identity_tells_functions_apart():
    """Two per-pose functions of one module, or one reached through another function, give
    different identities; the same function gives the same one every time."""
    from pkmlab.mechanisms.families import luzi3, psu6, ups6
    from pkmlab.runtime import jit as _jit

    ids = [_jit.identity(f) for f in (psu6._psu_one, psu6._psu_column_leg, ups6._ups_one,
                                      luzi3._luzi_one, luzi3._luzi_chain)]
    assert len(set(ids)) == len(ids)
    assert _jit.identity(psu6._psu_one) == ids[0]
    assert _jit.identity(psu6._psu_one, extra=(1,)) != ids[0]


def test_kernels_compiled_by_different_processes_do_not_alias(tmp_path):
    """Two processes compile the families' kernels into one fresh cache at the same time, in
    different orders, from the same start (the drivers' shared helpers compiled by a first
    process), so that numba's counters agree between them; a third process loads everything
    and must reproduce NumPy."""
    script = tmp_path / "run.py"
    script.write_text(SCRIPT)
    cache = tmp_path / "cache"
    _run(cache, script, ["warm:dummy"])
    with ThreadPoolExecutor(2) as pool:
        list(pool.map(lambda tasks: _run(cache, script, tasks),
                      [["ik:psu6", "ws:ups6", "jac:ups6"], ["ik:ups6", "ws:psu6", "jac:psu6"]]))
    res, log = _run(cache, script, ["ik:psu6", "ws:ups6", "ik:ups6", "ws:psu6", "jac:psu6",
                                    "jac:ups6"], {"NUMBA_DEBUG_CACHE": "1"})
    for family in ("psu6", "ups6"):
        check_ik(family, res[f"ik:{family}"])
        check_jac(family, res[f"jac:{family}"], res[f"ik:{family}"])
    for family in ("psu6", "ups6"):
        check_columns(family, res[f"ws:{family}"])
    # the small dexterous workspace: the engine's volume from the NumPy columns
    for family in ("psu6", "ups6"):
        r = res[f"ws:{family}"]
        h = H[family]
        length = dexterous_length(family, np.arange(-100, 101) * h, np.array(r["W"]),
                                  np.array(r["P"]))
        assert length[0].sum() == length[-1].sum() == 0    # the grid holds the workspace
        assert r["volume"] == pytest.approx(h * h * length.sum(), rel=1e-9), family
    # everything came from the cache: nothing compiled and saved in the third process
    assert "data saved" not in log, [s for s in log.splitlines() if "data saved" in s][:5]
    for name in ("drive_euler", "drive_frames", "columns_all", "columns_any", "leg_eval",
                 "drive_kinematics", "fused_sweep_loop"):
        assert re.search(rf"data loaded from .*{name}", log), f"{name} not loaded from cache"


FAMILY = '''
from numba import njit
from numba.extending import register_jitable

from famx_helpers import offset
from pkmlab.mechanisms.kernels import ik as _kernels

SCALE = 1.0


@register_jitable(inline="always")
def one(px, py, pz, r00, r01, r02, r10, r11, r12, r20, r21, r22, g, qmin, qmax, q, st, j):
    for i in range(6):
        v = SCALE * pz + g[i] + offset()
        k = i * _kernels.ROW + j
        q[k] = v
        st[k] = _kernels.stroke_status(v, qmin, qmax)


@njit(inline="always")
def leg(x, y, wx, wy, wz, p0, p1, p2):
    return x + wx + p0, x + wx + p0 + 1.0, True
'''
HELPERS = '''
from numba.extending import register_jitable


@register_jitable(inline="always")
def offset():
    return 0.0
'''
FAMILY_SCRIPT = '''
import json
import numpy as np
import famx
from pkmlab.mechanisms.kernels import columns as column_kernels, ik as _kernels

X = np.array([[0.0, 0.0, 10.0, 0.0, 0.0, 0.0]])
q, st, reason = np.empty((1, 6)), np.empty((1, 6), np.int8), np.empty(1, np.int8)
_kernels.make_driver(famx.one, 6, "euler")(X, (1., 2., 3., 4., 5., 6.), -1e9, 1e9, q, st, reason)
a, _, _ = column_kernels.make_leg_eval(famx.leg)(np.ones(1), np.ones(1), np.zeros((1, 3)),
                                           np.full((1, 3), 2.0))
lo, hi = np.empty((1, 1, 1)), np.empty((1, 1, 1))
column_kernels.make_column_kernel(famx.leg, "all")(np.ones(1), np.ones(1), np.zeros((1, 6, 3)),
                                            np.full((6, 3), 2.0), lo, hi)
print("RESULT " + json.dumps([q[0].tolist(), float(a[0]), float(lo[0, 0, 0])]))
'''


def test_editing_a_family_recompiles_its_kernels(tmp_path):
    """A cached kernel is recompiled when its family's module or a module that the family
    function calls is edited, and loaded from the cache when nothing changed."""
    (tmp_path / "famx.py").write_text(FAMILY)
    (tmp_path / "famx_helpers.py").write_text(HELPERS)
    (tmp_path / "script.py").write_text(FAMILY_SCRIPT)
    env = {**os.environ, "NUMBA_CACHE_DIR": str(tmp_path / "cache"),
           "PYTHONPATH": os.pathsep.join([str(tmp_path), str(SRC)]), "NUMBA_DEBUG_CACHE": "1"}

    def run():
        """``(results, kernels compiled and saved)``."""
        proc = subprocess.run([sys.executable, str(tmp_path / "script.py")], env=env,
                              capture_output=True, text=True, timeout=600)
        assert proc.returncode == 0, proc.stderr[-3000:]
        line = next(s for s in proc.stdout.splitlines() if s.startswith("RESULT "))
        saved = set(re.findall(r"data saved to .*(drive_euler|leg_eval|columns_all)",
                               proc.stdout))
        return json.loads(line[7:]), saved

    kernels = {"drive_euler", "leg_eval", "columns_all"}
    assert run() == ([[11.0, 12.0, 13.0, 14.0, 15.0, 16.0], 3.0, 3.0], kernels)
    assert run() == ([[11.0, 12.0, 13.0, 14.0, 15.0, 16.0], 3.0, 3.0], set())   # all cached
    # the per-pose function (through a module constant) and the leg interval
    edited = FAMILY.replace("SCALE = 1.0", "SCALE = 2.0").replace("x + wx + p0,", "x + wx,")
    (tmp_path / "famx.py").write_text(edited)
    assert run() == ([[21.0, 22.0, 23.0, 24.0, 25.0, 26.0], 1.0, 1.0], kernels)
    # a helper in another module that only the per-pose function calls
    (tmp_path / "famx_helpers.py").write_text(HELPERS.replace("return 0.0", "return 0.5"))
    assert run() == ([[21.5, 22.5, 23.5, 24.5, 25.5, 26.5], 1.0, 1.0], {"drive_euler"})


def test_compiling_a_kernel_shows_no_numba_ir_warning(monkeypatch):
    """numba's NumbaIRAssumptionWarning ("internal pedantic check", a page of text per
    kernel) was printed on every first compile of the continuous-search kernels; compiling
    through cached_kernel keeps it out of the user's terminal, and lets other warnings pass."""
    import warnings

    from numba import types as nt
    from numba.core.errors import NumbaIRAssumptionWarning

    from pkmlab.runtime import jit as _jit

    real = _jit.njit

    def noisy(*a, **k):
        warnings.warn("variable 'x.1' is not in scope", NumbaIRAssumptionWarning, stacklevel=2)
        warnings.warn("a warning the user should see", RuntimeWarning, stacklevel=2)
        return real(*a, **k)

    monkeypatch.setattr(_jit, "njit", noisy)

    def add_one(x):
        return x + 1.0

    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        k = _jit.cached_kernel(add_one, nt.float64(nt.float64))
    assert k(1.0) == 2.0
    assert [w.category for w in seen] == [RuntimeWarning]


_RELOAD = """
from pkmlab.mechanisms.families import psu6, ups6
from pkmlab.mechanisms.kernels import columns as column_kernels, ik as _kernels
from pkmlab.mechanisms.kernels import search as _search, tiles as _tiles

missed = []
for fam in (psu6.PSU6, ups6.UPS6):
    leg = fam.column_leg
    for k in (_search.make_capability(leg), _search.make_branch_bound(leg),
              _search.make_certify(leg), _tiles.make_tiled_all(leg),
              column_kernels.make_column_kernel(leg, "all"),
              column_kernels.make_column_kernel(leg, "any")):
        if sum(k.stats.cache_misses.values()) or not sum(k.stats.cache_hits.values()):
            missed.append(k.py_func.__name__)
print(len(missed), " ".join(missed))
"""


def test_search_and_tile_kernels_load_from_the_cache_in_a_fresh_process():
    """numba keys its on-disk cache by the kernel's pickled closure; a closure (or a jitable in
    it, pickled by value with its globals) that reaches an ``njit`` dispatcher pickles
    differently in every process, so the cache never hits. That happened to the continuous
    search (a shared tile-distance helper written as ``njit``): every fresh study worker spent
    14 s recompiling the capability kernel. After one process has compiled them, a second
    must load every kernel from the cache."""
    for _ in range(2):          # the first may compile (a cold cache); the second must not
        r = subprocess.run([sys.executable, "-c", _RELOAD], capture_output=True, text=True,
                           check=True)
    assert r.stdout.split()[0] == "0", r.stdout
