"""Forward kinematics of the planar families in closed form: the 3-RPR sextic and the circle
intersection of a five-bar, batched over actuator vectors.

**3-RPR** (Gosselin, Sefrioui & Richard 1992; the same polynomial as Hunt's and Merlet's
derivations). The platform pose is ``(x, y, φ)``; leg ``i`` joins the base pivot ``a_i`` to
the platform pivot ``u_i`` (tool frame): ``|p + R(φ)·u_i - a_i|² = ρ_i²``. With
``e_i(φ) = R(φ)·u_i - a_i``, the differences of the equations of legs 2 and 3 from leg 1 are
linear in ``p``, ``M(φ)·p = r(φ)`` (entries trigonometric polynomials of degree 1), so ``p =
adj(M)·r / D`` with ``D = det M``; leg 1's equation multiplied by ``D²`` is

    F(φ) = |adj(M)·r|² + 2·D·(adj(M)·r)·e_1 + D²·(|e_1|² - ρ_1²) = 0,

a trigonometric polynomial of nominal degree 4 whose fourth harmonic cancels: degree 3,
so at most six real roots in φ (the sextic). Its Fourier coefficients are computed exactly
(up to rounding) by an FFT of 16 samples of F; with ``z = e^{iφ}``, ``z³·F`` is a polynomial of
degree 6 in ``z`` whose roots on the unit circle are the real assembly modes (companion-matrix
eigenvalues, batched). Each root is then polished by Newton on the three leg equations and kept
when its residual is below the tolerance; roots at which ``D`` vanishes (the linear system
loses rank) are solved by Newton from the least-squares ``p``. No start-point search.

**Five-bar**: given the two crank angles, the elbows ``C_1, C_2`` are known and the end point
lies on both circles of radius ``l2_i`` about them: zero, one or two points (two assembly
modes, on either side of the line C1C2).
"""

from __future__ import annotations

import numpy as np

#: samples of F(φ) for its Fourier coefficients (a trigonometric polynomial of degree ≤ 4 is
#: determined exactly by 9; 16 is a power of two above it)
_SAMPLES = 16
#: a root ``z`` of the sextic counts as a candidate real mode when ``| |z| - 1 | <`` this; the
#: candidates are then confirmed (or rejected) by their loop-closure residual after Newton
_ON_CIRCLE = 1e-3


def _legs_e(A, U, phi):
    """``e_i(φ) = R(φ)·u_i - a_i``: ``(..., 3, 2)`` for angles ``phi (...)``."""
    c, s = np.cos(phi)[..., None], np.sin(phi)[..., None]
    return np.stack([c * U[:, 0] - s * U[:, 1] - A[:, 0], s * U[:, 0] + c * U[:, 1] - A[:, 1]],
                    axis=-1)


def _linear_part(A, U, rho, phi):
    """``(N, K, ...)``: ``e``, ``|e|²``, ``M``, ``r``, ``D`` at angles ``phi (N, K)``, leg
    lengths ``rho (N, 3)``."""
    e = _legs_e(A, U, phi)                                       # (N, K, 3, 2)
    ee = np.sum(e * e, axis=-1)                                  # (N, K, 3)
    M = 2.0 * (e[..., 1:, :] - e[..., :1, :])                    # (N, K, 2, 2)
    r2 = rho * rho
    r = (r2[:, None, 1:] - r2[:, None, :1]) - ee[..., 1:] + ee[..., :1]   # (N, K, 2)
    D = M[..., 0, 0] * M[..., 1, 1] - M[..., 0, 1] * M[..., 1, 0]
    Nx = M[..., 1, 1] * r[..., 0] - M[..., 0, 1] * r[..., 1]
    Ny = -M[..., 1, 0] * r[..., 0] + M[..., 0, 0] * r[..., 1]
    return e, ee, M, r, D, Nx, Ny


def rpr3_polynomial(A, U, rho) -> np.ndarray:
    """Fourier coefficients ``(N, 9)`` of F(φ) for harmonics -4..4 (complex), ``A (3, 2)``
    base pivots, ``U (3, 2)`` platform pivots in the tool frame, ``rho (N, 3)`` leg lengths.
    The ±4 entries vanish up to rounding (the sextic): ``tests/test_rpr3.py`` checks it."""
    rho = np.atleast_2d(np.asarray(rho, dtype=float))
    phi = np.broadcast_to(2 * np.pi * np.arange(_SAMPLES) / _SAMPLES, (len(rho), _SAMPLES))
    e, ee, _, _, D, Nx, Ny = _linear_part(A, U, rho, phi)
    F = Nx * Nx + Ny * Ny + 2 * D * (Nx * e[..., 0, 0] + Ny * e[..., 0, 1]) \
        + D * D * (ee[..., 0] - rho[:, None, 0] ** 2)
    C = np.fft.fft(F, axis=-1) / _SAMPLES
    return C[:, [k % _SAMPLES for k in range(-4, 5)]]


def rpr3_candidates(A, U, rho) -> tuple[np.ndarray, np.ndarray]:
    """Candidate poses ``(N, 6, 3)`` (x, y, φ; NaN where a root is not near the unit circle)
    and the harmonic-4 residue ``(N,)`` (|c_±4| relative to the largest coefficient)."""
    rho = np.atleast_2d(np.asarray(rho, dtype=float))
    C = rpr3_polynomial(A, U, rho)
    big = np.max(np.abs(C), axis=1)
    big = np.where(big > 0, big, 1.0)
    residue = np.maximum(np.abs(C[:, 0]), np.abs(C[:, 8])) / big
    c = C[:, 1:8] / big[:, None]                    # harmonics -3..3 → z^0..z^6
    n = len(rho)
    lead = c[:, 6]
    # companion matrices of the monic degree-6 polynomials (batched eigenvalues)
    comp = np.zeros((n, 6, 6), dtype=complex)
    comp[:, 1:, :-1] = np.eye(5)
    with np.errstate(divide="ignore", invalid="ignore"):
        comp[:, :, -1] = -c[:, :6] / lead[:, None]
    ok = np.all(np.isfinite(comp), axis=(1, 2))
    z = np.full((n, 6), np.nan + 0j)
    if ok.any():
        z[ok] = np.linalg.eigvals(comp[ok])
    real = np.abs(np.abs(z) - 1.0) < _ON_CIRCLE
    phi = np.where(real, np.angle(z), np.nan)
    # positions from the linear system (least squares where D vanishes)
    e, ee, M, r, D, Nx, Ny = _linear_part(A, U, rho, np.nan_to_num(phi))
    with np.errstate(divide="ignore", invalid="ignore"):
        x, y = Nx / D, Ny / D
    small = ~(np.abs(D) > 1e-9 * np.max(np.abs(M), axis=(-2, -1)) ** 2)
    if small.any():
        ls = np.einsum("...ij,...j->...i", np.linalg.pinv(M[small]), r[small])
        x[small], y[small] = ls[:, 0], ls[:, 1]
    out = np.stack([x, y, phi], axis=-1)
    out[~real] = np.nan
    return out, residue


def circle_intersections(c1, c2, r1, r2) -> np.ndarray:
    """Points at distance ``r1`` from ``c1`` and ``r2`` from ``c2`` (2-D, batched ``(N, 2)``):
    ``(N, 2, 2)``, the point on the left of c1→c2 first, NaN where the circles do not meet."""
    d = c2 - c1
    L2 = np.sum(d * d, axis=-1)
    with np.errstate(divide="ignore", invalid="ignore"):
        a = (r1 * r1 - r2 * r2 + L2) / (2 * L2)
        h2 = r1 * r1 - a * a * L2
        h = np.sqrt(np.where(h2 >= 0, h2, np.nan) / L2)
    mid = c1 + a[..., None] * d
    perp = np.stack([-d[..., 1], d[..., 0]], axis=-1)
    return np.stack([mid + h[..., None] * perp, mid - h[..., None] * perp], axis=-2)
