"""A published rotary (Clavel) delta reproduced (issue 24, validation): the inverse position
kinematics examples of R. L. Williams II, "The Delta Parallel Robot: Kinematics Solutions"
(Internet publication, Ohio University, www.ohio.edu/people/williar4/html/pdf/DeltaKin.pdf,
2015/2016), revolute-input examples on the ABB FlexPicker IRB 360-1/1600 dimensions.

Published numbers (the document's example section, as transcribed with the dimensions in
public test code, see docs/validation.md, "Issue 24: a published Clavel delta"):

* dimensions: base triangle side s_B = 0.567 m, platform triangle side s_P = 0.076 m, upper
  arm L = 0.524 m, parallelogram forearm l = 1.244 m (its width h = 0.131 m does not enter the
  3-DOF position kinematics);
* P = (0, 0, -0.9) m → θ = (-20.5, -20.5, -20.5)°;
* P = (0.3, 0.5, -1.1) m → θ = (47.5, -11.6, 21.4)°.

Reading of the paper (the document's frame, mapped onto ``delta3``): the motor pivots B_i are
the mid-points of the base triangle's sides, at w_B = s_B/(2√3) from the centre; the platform
joints are the platform triangle's vertices, at u_P = s_P/√3, in the same radial direction as
their leg; leg 1 points along -y, legs 2 and 3 at +30° and +150° (so ``angles`` = 270°, 30°,
150°); θ is measured from the horizontal, positive down (``delta3``'s convention). The
published angles have one decimal: the tolerance is half of it, 0.05°.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from pkmlab.mechanisms.families.delta3 import Delta3

S_B, S_P, L, ELL = 567.0, 76.0, 524.0, 1244.0            # mm
W_B, U_P = S_B / (2 * math.sqrt(3)), S_P / math.sqrt(3)
LEGS_DEG = (270.0, 30.0, 150.0)
PUBLISHED = [((0.0, 0.0, -900.0), (-20.5, -20.5, -20.5)),
             ((300.0, 500.0, -1100.0), (47.5, -11.6, 21.4))]
TOL_DEG = 0.05


@pytest.fixture(scope="module")
def williams():
    return Delta3.from_radii(base_radius=W_B, platform_radius=U_P, upper_arm=L, forearm=ELL,
                             stroke=(-math.radians(90), math.radians(90)),
                             angles=np.radians(LEGS_DEG))


def _poses(points):
    X = np.zeros((len(points), 6))
    X[:, :3] = points
    return X


def _second_formulation(p):
    """Each leg on its own, in the half-angle form: the elbow ``B + L(cos θ u - sin θ ẑ)``
    at distance l from the platform joint gives ``E cos θ + F sin θ + G = 0`` with ``E =
    2L·D·u``, ``F = -2L·D_z``, ``G = |D|² + L² - l²`` (``D = B - P - p_i``); with ``t =
    tan(θ/2)``: ``(G - E) t² + 2F t + (G + E) = 0``. Both roots; the one of smaller |θ|
    (the elbow out, the assembly of the examples)."""
    out = []
    for a in np.radians(LEGS_DEG):
        u = np.array([math.cos(a), math.sin(a), 0.0])
        D = W_B * u - (np.asarray(p) + U_P * u)
        E, F, G = 2 * L * D @ u, -2 * L * D[2], D @ D + L * L - ELL * ELL
        t = np.roots([G - E, 2 * F, G + E])
        th = np.degrees(2 * np.arctan(t[np.isreal(t)].real))
        out.append(th[np.argmin(np.abs(th))])
    return np.array(out)


def test_williams_inverse_kinematics_examples(williams):
    pts = np.array([p for p, _ in PUBLISHED])
    ik = williams.inverse(_poses(pts))
    assert ik.valid.all()
    mine = np.degrees(ik.q)
    for got, (p, pub) in zip(mine, PUBLISHED):
        np.testing.assert_allclose(got, pub, atol=TOL_DEG + 1e-12)
        np.testing.assert_allclose(got, _second_formulation(p), atol=1e-9)


def test_williams_examples_forward_round_trip(williams):
    """FK of the computed angles returns the published positions (1e-6 mm); FK of the
    published, rounded angles lands within the position change that ±0.05° of rounding can
    cause (Σ_j |J⁻¹_kj|·0.05°: 0.80 and 1.07 mm; measured 0.32 and 0.49 mm)."""
    pts = np.array([p for p, _ in PUBLISHED], dtype=float)
    q = williams.inverse(_poses(pts)).q
    fk = williams.forward(q)
    np.testing.assert_allclose(fk.pose[:, :3], pts, atol=1e-6)
    pub = np.radians([t for _, t in PUBLISHED])
    fk_pub = williams.forward(pub)
    J = williams.jacobian(_poses(pts))                      # q̇ = J ṗ (rad per mm)
    bound = np.abs(np.linalg.inv(J)).sum(axis=2).max(axis=1) * math.radians(TOL_DEG)
    err = np.linalg.norm(fk_pub.pose[:, :3] - pts, axis=1)
    assert np.all(err <= bound) and bound.max() < 1.5


def test_a_wrong_reading_is_refused(williams):
    """The test can fail: the platform joints at the platform triangle's side mid-points
    (s_P/(2√3)) instead of its vertices move the first example by more than the tolerance."""
    wrong = Delta3.from_radii(base_radius=W_B, platform_radius=S_P / (2 * math.sqrt(3)),
                              upper_arm=L, forearm=ELL,
                              stroke=(-math.radians(90), math.radians(90)),
                              angles=np.radians(LEGS_DEG))
    got = np.degrees(wrong.inverse(_poses([PUBLISHED[1][0]])).q[0])
    assert np.abs(got - PUBLISHED[1][1]).max() > TOL_DEG
