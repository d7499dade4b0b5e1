"""``sweep_core`` and ``lu_force`` are functions the kernels call, not inline (issue 28, session
6, for compile time): called, ``sweep_core`` gives the same values bit for bit as the same code
inlined into a loop, which is how every kernel used it before, and ``lu_force`` gives its force
and ``det J``. Checked on random Jacobian-like
matrices, badly conditioned ones, singular ones (an exactly zero pivot) and ones with a NaN or
an infinite entry, compared by their bits (NaN included)."""

from __future__ import annotations

import numpy as np
from numba import njit

from pkmlab.dexterity import _linalg

_core_inlined = njit(inline="always", error_model="numpy")(_linalg.sweep_core.py_func)


def _loop(core, lu):
    def loop(Js, L, fmax, out, Bs):
        A, B, G, T = np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6)), np.empty((6, 6))
        piv = np.empty(6, np.int64)
        for m in range(Js.shape[0]):
            la, lb, f, d = core(Js[m], L, fmax, A, B, G, T, piv)
            out[m, 0], out[m, 1], out[m, 2], out[m, 3] = la, lb, f, d
            Bs[m] = B
            if lu is not None:
                ok, f2, d2 = lu(Js[m], fmax, A, B, piv)
                out[m, 4], out[m, 5], out[m, 6] = 1.0 if ok else 0.0, f2, d2
    return njit(error_model="numpy")(loop)


def _matrices(n: int = 3000) -> np.ndarray:
    rng = np.random.default_rng(28)
    J = rng.normal(size=(n, 6, 6))
    J[:, :, 3:] *= 150.0                                 # angular columns in mm, as a 6-PSU's
    J[::7] *= 10.0 ** rng.uniform(-6, 6, size=(len(J[::7]), 1, 1))
    J[1::11, 2] = J[1::11, 4] * 1e-9 + J[1::11, 2] * 1e-15   # nearly dependent rows
    J[2::13, :, 5] = 0.0                                 # a zero column: a zero pivot
    J[3::17, 4, 1] = np.nan
    J[4::19, 0, 0] = np.inf
    return np.ascontiguousarray(J)


def test_the_called_lu_and_gram_bounds_equal_the_inlined_ones_bit_for_bit():
    J = _matrices()
    fmax = np.array([900.0, 800.0, 1000.0, 700.0, 950.0, 850.0])
    res = {}
    for name, core, lu in (("inlined", _core_inlined, None),
                           ("called", _linalg.sweep_core, _linalg.lu_force)):
        out, Bs = np.zeros((len(J), 7)), np.empty_like(J)
        _loop(core, lu)(J, 173.0, fmax, out, Bs)
        res[name] = out, Bs
    (a, Ba), (b, Bb) = res["inlined"], res["called"]
    bits = np.int64
    assert np.array_equal(a[:, :4].view(bits), b[:, :4].view(bits))
    ok = b[:, 4] == 1.0                                  # B is written only where the LU is
    assert np.array_equal(Ba[ok].view(bits), Bb[ok].view(bits))
    # lu_force (the same LU, inlined into its own function): sweep_core's force and det
    assert np.array_equal(b[:, 5:7].view(bits), b[:, 2:4].view(bits))
    # the cases are there: singular, non-finite and regular matrices
    assert (~ok).sum() >= 300 and np.isnan(b[:, 2]).sum() >= 300
    assert (b[:, 3] == 0.0).sum() >= 150 and (ok & (b[:, 0] > 0)).sum() >= 2000
