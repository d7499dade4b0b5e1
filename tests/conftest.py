"""Shared fixtures: one instance of every registered family (the contract suite runs on each)."""

from __future__ import annotations

import math
from contextlib import contextmanager
from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import minimize

import pkmlab
from pkmlab.mechanisms import NO_STROKE, REGISTRY, Luzi3, register_family
from pkmlab.poses import euler_to_matrix
from pkmlab.testing import random_valid_poses  # noqa: F401 (used by the test modules)

ROOT = Path(__file__).resolve().parents[1]
MECH_DIR = ROOT / "studies" / "mechanisms"

# Every shipped mechanism file, plus the Luzi geometry with the upper link (200 mm) that the
# paper's Table 1 ψ columns were computed with (rows 1-2; docs/validation.md).
SHIPPED = sorted(MECH_DIR.glob("*.yaml"))


def _instances() -> dict[str, pkmlab.Mechanism]:
    mechs = {f.stem: pkmlab.load_mechanism(f) for f in SHIPPED}
    mechs["luzi-3chain-l200"] = Luzi3.from_paper(upper_link=200.0, stroke=(750.0, 1150.0))
    return mechs


MECHANISMS = _instances()
# The contract must cover every registered family.
assert {m.family for m in MECHANISMS.values()} == set(REGISTRY), "a family has no test instance"


@pytest.fixture(params=sorted(MECHANISMS), ids=sorted(MECHANISMS))
def mech(request):
    return MECHANISMS[request.param]


# ---- one tiny study run through the CLI, shared by the report tests ---------------------------

TINY_STUDY = {
    "study": "tiny-report",
    "description": "A tiny study for the report tests.",
    "mechanism": {"file": str(MECH_DIR / "hopkins-williams-6psu.yaml")},
    "design": {"base_outer_radius": {"low": "120 mm", "high": "165 mm"},
               "platform_outer_radius": {"low": "55 mm", "high": "90 mm"},
               "link_length": {"low": "200 mm", "high": "260 mm"}},
    "evaluate": {"workspace": {"kind": "dexterous", "box": ["8 deg"] * 3, "samples": 2,
                               "resolution": "8 mm"}},
    "objectives": [{"maximize": "dexterous_volume"}, {"minimize": "base_outer_radius"},
                   {"maximize": "z_span"}],
    "constraints": [{"base_outer_radius": {"max": 160}}],
    "optimizer": {"method": "sobol", "samples": 8},
    "seed": 5,          # 5 Pareto designs, 3 exported, 2 infeasible candidates
    "top": 3,
}


@pytest.fixture(scope="session")
def tiny_report(tmp_path_factory):
    """``(out, run)``: the tiny study's results folder after ``pkmlab run`` (no terminal), and
    the CLI result (its stderr holds the progress lines)."""
    import yaml
    from typer.testing import CliRunner

    from pkmlab.cli import app

    d = tmp_path_factory.mktemp("tiny-report")
    path = d / "study.yaml"
    path.write_text(yaml.safe_dump({**TINY_STUDY, "output": str(d / "out")}))
    r = CliRunner().invoke(app, ["run", str(path), "--json"])
    assert r.exit_code == 0, r.output
    return d / "out", r


def point_margin(mech, p, euler) -> np.ndarray:
    """Smallest stroke margin (mm) of ``mech``'s legs at position ``p`` and each Euler
    orientation of ``euler (n, 3)``, by the inverse kinematics; -1e9 where unreachable."""
    R = euler_to_matrix(np.atleast_2d(euler))
    ik = mech.inverse((np.tile(p, (len(R), 1)), R), stroke=NO_STROKE)
    lo, hi = mech.stroke
    m = np.min(np.minimum(ik.q - lo, hi - ik.q), axis=1)
    return np.where(np.isfinite(m), m, -1e9)


def assert_point_holds(mech, p, th, rng, minima=3) -> None:
    """A point certified for the continuous ±``th`` (rad) Euler box keeps every leg in stroke
    at 20,000 random orientations of ``rng``, at the box's corners, and at the local minima of
    its margin (L-BFGS-B) started from the ``minima`` worst of them."""
    E = np.vstack([rng.uniform(-th, th, (20_000, 3)),
                   np.array(np.meshgrid(*[[-th, th]] * 3)).reshape(3, -1).T])
    m = point_margin(mech, p, E)
    assert m.min() >= -1e-9
    for e in E[np.argsort(m)[:minima]]:
        r = minimize(lambda v: point_margin(mech, p, v)[0], e, method="L-BFGS-B",
                     bounds=[(-th, th)] * 3)
        assert r.fun >= -1e-9


def same_result(a, b) -> bool:
    """Equal nested results (dicts, lists, tuples, arrays, numbers), NaN equal to NaN: the
    bit-for-bit comparisons of the worst-case passes and of the fused kernels' callers."""
    if isinstance(a, dict):
        return a.keys() == b.keys() and all(same_result(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple):
        return len(a) == len(b) and all(same_result(x, y) for x, y in zip(a, b))
    if isinstance(a, np.ndarray):
        return isinstance(b, np.ndarray) and np.array_equal(a, b, equal_nan=a.dtype.kind in "fc")
    if isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b):
        return True
    return a == b


@contextmanager
def family_registered(cls):
    """``cls`` registered for the block, and the registry as it was afterwards (another test
    module of the same process may have registered it too: it stays registered then)."""
    before = REGISTRY.get(cls.family)
    register_family(cls)
    try:
        yield cls
    finally:
        if before is None:
            REGISTRY.pop(cls.family, None)
        else:
            REGISTRY[cls.family] = before


def sampled_designs(study, seed: int, n: int = 16):
    """``(mech, result)`` for each valid design of ``n`` scrambled Sobol points of
    ``study``'s space (seed ``seed``) whose workspace (the study's request) is not empty."""
    import warnings

    from scipy.stats import qmc

    from pkmlab.errors import ParameterError
    from pkmlab.study.evaluators import EVALUATORS
    from pkmlab.study.evaluators.registry import Context

    space = study.space
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", UserWarning)
        u = qmc.Sobol(d=len(space.variables), scramble=True, seed=seed).random(n)
    for r in u:
        try:
            mech = space.decode(space.from_unit(r))
            _ = mech.nominal_pose
        except ParameterError:
            continue
        ctx = Context(study.evaluation, 1, choices={})
        EVALUATORS["workspace"](mech, ctx)
        if not ctx.result.empty:
            yield mech, ctx.result
