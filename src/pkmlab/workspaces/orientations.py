"""Orientation sets for workspace definitions, sampled as rotation matrices.

Three kinds, all taken relative to a centre orientation ``R_c`` (default: the mechanism's
nominal orientation):

* ``fixed`` — one orientation given as Z-Y-X Euler angles ``(θx, θy, θz)``;
* ``box`` — Z-Y-X Euler angles in ``centre ± (a, b, c)``. ``simultaneous`` semantics sample
  the whole box (``n³`` orientations, all three angles at once, as Hopkins & Williams require);
  ``single-axis`` semantics sweep each angle alone with the others at the centre
  (``3n - 2`` orientations);
* ``tilt-torsion`` — Bonev & Ryu's convention ``R = R_c · Rz(φ) · Ry(θ) · Rz(σ - φ)`` with
  azimuth φ ∈ [0, 2π), tilt θ ∈ [0, β] and torsion σ ∈ [-γ, γ]. Tilt rings ``θ_j = β·j/(n-1)``
  carry ``4·j`` azimuths each (one at θ = 0), torsion takes ``n`` values.

``parameters()`` returns the sample in the set's own coordinates, which
:func:`rotations_from_parameters` maps back to matrices; the adaptive refinement of the
workspace engine searches these coordinates inside :meth:`OrientationSet.bounds`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..errors import ParameterError
from ..poses import euler_to_matrix

__all__ = ["OrientationSet", "rotations_from_parameters"]

KINDS = ("fixed", "box", "tilt-torsion")
SEMANTICS = ("simultaneous", "single-axis")


def _rz(a: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(np.shape(a) + (3, 3))
    R[..., 0, 0], R[..., 0, 1], R[..., 1, 0], R[..., 1, 1] = c, -s, s, c
    R[..., 2, 2] = 1.0
    return R


def _ry(a: np.ndarray) -> np.ndarray:
    c, s = np.cos(a), np.sin(a)
    R = np.zeros(np.shape(a) + (3, 3))
    R[..., 0, 0], R[..., 0, 2], R[..., 2, 0], R[..., 2, 2] = c, s, -s, c
    R[..., 1, 1] = 1.0
    return R


@dataclass(frozen=True)
class OrientationSet:
    """A set of platform orientations (angles in rad).

    Attributes:
        kind: ``"fixed"``, ``"box"`` or ``"tilt-torsion"``.
        angles: for ``fixed``, the Z-Y-X Euler angles ``(θx, θy, θz)`` *added to the centre's*;
            for ``box``, the half-ranges ``(a, b, c)``.
        semantics: ``"simultaneous"`` or ``"single-axis"`` (box only).
        tilt: β, the largest tilt (tilt-torsion only).
        torsion: γ, the largest torsion magnitude (tilt-torsion only).
        samples: n, samples per angle (see the module docstring); ignored for ``fixed``.
        centre: Z-Y-X Euler angles of the centre orientation ``R_c``; ``None`` = use the
            mechanism's nominal orientation (resolved by :meth:`centred`).
    """

    kind: str = "fixed"
    angles: tuple[float, float, float] = (0.0, 0.0, 0.0)
    semantics: str = "simultaneous"
    tilt: float = 0.0
    torsion: float = 0.0
    samples: int = 7
    centre: tuple[float, float, float] | None = None

    def __post_init__(self):
        if self.kind not in KINDS:
            raise ParameterError("orientations.kind", f"one of {list(KINDS)}", self.kind)
        if self.semantics not in SEMANTICS:
            raise ParameterError("orientations.semantics", f"one of {list(SEMANTICS)}",
                                 self.semantics)
        ang = tuple(float(a) for a in np.asarray(self.angles, dtype=float).ravel())
        if len(ang) != 3 or not all(math.isfinite(a) for a in ang):
            raise ParameterError("orientations.angles", "three finite angles", self.angles)
        object.__setattr__(self, "angles", ang)
        if self.kind == "box" and any(a < 0 or a > math.pi for a in ang):
            raise ParameterError("orientations.box", "half-ranges in [0, 180] deg",
                                 [round(math.degrees(a), 6) for a in ang])
        if self.kind == "tilt-torsion":
            if not (0 <= self.tilt <= math.pi / 2):
                raise ParameterError("orientations.tilt", "an angle in [0, 90] deg",
                                     math.degrees(self.tilt))
            if not (0 <= self.torsion <= math.pi):
                raise ParameterError("orientations.torsion", "an angle in [0, 180] deg",
                                     math.degrees(self.torsion))
        if not (isinstance(self.samples, int | np.integer) and 1 <= self.samples <= 101):
            raise ParameterError("orientations.samples", "an integer in [1, 101]", self.samples)
        if self.centre is not None:
            c = tuple(float(a) for a in np.asarray(self.centre, dtype=float).ravel())
            if len(c) != 3 or not all(math.isfinite(a) for a in c):
                raise ParameterError("orientations.centre", "three finite angles", self.centre)
            object.__setattr__(self, "centre", c)

    # ---- constructors ------------------------------------------------------------------------
    @classmethod
    def fixed(cls, angles=(0.0, 0.0, 0.0), **kw) -> OrientationSet:
        return cls("fixed", angles=tuple(angles), **kw)

    @classmethod
    def box(cls, half_ranges, semantics: str = "simultaneous", samples: int = 7,
            **kw) -> OrientationSet:
        return cls("box", angles=tuple(half_ranges), semantics=semantics, samples=samples, **kw)

    @classmethod
    def tilt_torsion(cls, tilt: float, torsion: float = 0.0, samples: int = 7,
                     **kw) -> OrientationSet:
        return cls("tilt-torsion", tilt=tilt, torsion=torsion, samples=samples, **kw)

    def centred(self, centre) -> OrientationSet:
        """This set with its centre set to ``centre`` (Z-Y-X Euler angles) if it has none."""
        return self if self.centre is not None else replace(self, centre=tuple(centre))

    def with_samples(self, n: int) -> OrientationSet:
        return replace(self, samples=int(n))

    # ---- sampling ----------------------------------------------------------------------------
    def parameters(self) -> np.ndarray:
        """``(M, 3)`` sample in the set's own coordinates (see :meth:`bounds`)."""
        n = self.samples
        if self.kind == "fixed":
            return np.array([self.angles])
        if self.kind == "box":
            axes = [np.linspace(-h, h, n) if (n > 1 and h > 0) else np.zeros(1)
                    for h in self.angles]
            if self.semantics == "simultaneous":
                g = np.meshgrid(*axes, indexing="ij")
                return np.stack([a.ravel() for a in g], axis=1)
            rows = [np.zeros(3)]
            for k, ax in enumerate(axes):
                for v in ax:
                    if v != 0.0:
                        r = np.zeros(3)
                        r[k] = v
                        rows.append(r)
            return np.array(rows)
        # tilt-torsion: (azimuth φ, tilt θ, torsion σ)
        sig = np.linspace(-self.torsion, self.torsion, n) if (n > 1 and self.torsion > 0) \
            else np.zeros(1)
        rows = []
        rings = n if self.tilt > 0 else 1
        for j in range(rings):
            theta = self.tilt * j / max(rings - 1, 1)
            count = 1 if j == 0 else 4 * j
            for phi in 2 * np.pi * np.arange(count) / count:
                for s in sig:
                    rows.append((phi, theta, s))
        return np.array(rows)

    def bounds(self) -> np.ndarray:
        """``(3, 2)`` box of the parameters: Euler offsets for ``box``, (φ, θ, σ) otherwise."""
        if self.kind == "fixed":
            return np.stack([self.angles, self.angles], axis=1)
        if self.kind == "box":
            h = np.array(self.angles)
            if self.semantics == "single-axis":
                return np.stack([-h, h], axis=1)   # caller keeps one coordinate non-zero
            return np.stack([-h, h], axis=1)
        return np.array([[-np.inf, np.inf], [0.0, self.tilt], [-self.torsion, self.torsion]])

    def rotations(self) -> np.ndarray:
        """``(M, 3, 3)`` rotation matrices of the sample."""
        return rotations_from_parameters(self, self.parameters())

    def rotations_at(self, params: np.ndarray) -> np.ndarray:
        """``(M, 3, 3)`` rotation matrices of set coordinates ``params (M, 3)``
        (:func:`rotations_from_parameters`)."""
        return rotations_from_parameters(self, params)

    def describe(self) -> dict:
        d: dict = {"kind": self.kind, "samples": self.samples,
                   "count": int(self.parameters().shape[0])}
        if self.kind == "fixed":
            d["angles_deg"] = [math.degrees(a) for a in self.angles]
        elif self.kind == "box":
            d.update(half_ranges_deg=[math.degrees(a) for a in self.angles],
                     semantics=self.semantics)
        else:
            d.update(tilt_deg=math.degrees(self.tilt), torsion_deg=math.degrees(self.torsion))
        if self.centre is not None:
            d["centre_deg"] = [math.degrees(a) for a in self.centre]
        return d


def rotations_from_parameters(oset: OrientationSet, params: np.ndarray) -> np.ndarray:
    """Map set coordinates ``(M, 3)`` to rotation matrices ``(M, 3, 3)``."""
    P = np.asarray(params, dtype=float).reshape(-1, 3)
    centre = np.zeros(3) if oset.centre is None else np.asarray(oset.centre)
    if oset.kind in ("fixed", "box"):
        return euler_to_matrix(centre + P)
    phi, theta, sigma = P[:, 0], P[:, 1], P[:, 2]
    local = _rz(phi) @ _ry(theta) @ _rz(sigma - phi)
    return euler_to_matrix(centre) @ local
