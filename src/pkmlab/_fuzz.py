"""Random mechanism geometries for property tests and the fuzz benchmark (no test framework
needed): :func:`random_mapping` draws a mechanism file mapping of the psu6, ups6 or luzi3
family and :func:`check_mapping` runs it through loading, the nominal pose, inverse
kinematics, the nominal pose report and a coarse workspace. The only exceptions allowed are
the declared ones (:class:`~pkmlab.errors.ParameterError`, :class:`~pkmlab.errors.NumericalError`);
a NaN reported as a valid number is a failure too."""

from __future__ import annotations

import math

import numpy as np

from .errors import NumericalError, ParameterError

__all__ = ["random_mapping", "check_mapping", "DECLARED"]

DECLARED = (ParameterError, NumericalError)


def random_mapping(rng: np.random.Generator) -> dict:
    """A random (often absurd) mechanism mapping."""
    fam = rng.choice(["psu6", "ups6", "luzi3"])

    def length(lo=-50.0, hi=1500.0):
        x = rng.uniform(lo, hi)
        return float(x) if rng.random() > 0.02 else float(rng.choice([0.0, -1.0, 1e7, 1e-9]))

    a, b = sorted([length(0, 1500), length(0, 1500)])
    stroke = [a, b] if rng.random() > 0.05 else [b, a]
    if fam == "psu6":
        r1, r2 = sorted([length(1, 300), length(1, 300)])
        p1, p2 = sorted([length(1, 200), length(1, 200)])
        return {"family": "psu6", "generator": {
            "base_radii": [r1, r2], "platform_radii": [p1, p2],
            "base_pair_angle": "auto" if rng.random() < 0.5 else f"{rng.uniform(0, 180)} deg",
            "platform_rotation": f"{rng.uniform(-90, 90)} deg",
            "pairing": str(rng.choice(["same", "crossed"]))},
            "link_length": length(1, 600), "stroke": [min(stroke), min(stroke) + abs(
                stroke[1] - stroke[0]) % 300] if rng.random() < 0.9 else stroke,
            "tool_offset": [0.0, 0.0, length(-100, 100)]}
    if fam == "ups6":
        ang = np.sort(rng.uniform(0, 2 * np.pi, 6))
        angp = np.sort(rng.uniform(0, 2 * np.pi, 6))
        rb, rp = length(1, 800), length(1, 400)
        base = [[rb * math.cos(t), rb * math.sin(t), 0.0] for t in ang]
        plat = [[rp * math.cos(t), rp * math.sin(t), 0.0] for t in angp]
        return {"family": "ups6", "base_points": base, "platform_points": plat,
                "stroke": stroke, "tool_offset": [0.0, 0.0, 0.0]}
    return {"family": "luzi3", "generator": {
        "base_diameter": length(10, 1500), "phi": f"{rng.uniform(0, 60)} deg",
        "platform_diameter": length(10, 600)},
        "upper_link": length(1, 300), "stroke": stroke, "tool_offset": "centroid"}


def _finite_or_none(x) -> bool:
    return x is None or (isinstance(x, float) and math.isfinite(x))


def check_mapping(data: dict, resolution: float = 40.0) -> str:
    """Run one mapping; returns ``"ok"`` or the declared error's class name. Raises anything
    else (or AssertionError for a NaN reported as valid)."""
    from .config import load_mechanism
    from .dexterity.report import pose_report
    from .workspaces import workspace

    try:
        mech = load_mechanism(data)
        X = mech.nominal_pose
        ik = mech.inverse(X)
        if ik.valid[0]:
            assert np.all(np.isfinite(ik.q[0])), "valid IK with a non-finite actuator value"
        rep = pose_report(mech, X)
        for key in ("kappa", "sigma_min"):
            assert _finite_or_none(rep[key]), f"{key} = {rep[key]!r}"
        res = workspace(mech, "constant", resolution=resolution)
        m = res.metrics()
        assert math.isfinite(m["volume_mm3"]) and m["volume_mm3"] >= 0, m["volume_mm3"]
        if not res.empty:
            assert all(math.isfinite(c) for c in m["centroid_mm"]), m["centroid_mm"]
    except DECLARED as exc:
        return type(exc).__name__
    return "ok"
