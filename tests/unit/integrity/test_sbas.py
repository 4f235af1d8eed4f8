"""SBAS protection levels (integrity/sbas.py) of a fixed 8-satellite geometry against an independent computation:
the projection-matrix form of the WLS (MAAST's S = (G' W G)^-1 G' W, d_V^2 = sum_i S_ui^2 sigma_i^2) built here in
north-east-down axes with numpy.linalg.lstsq, and the horizontal ellipse's semi-major axis from the 2x2 block's
largest eigenvalue."""

from __future__ import annotations

import numpy as np

from approachsim.integrity.sbas import K_H_PA, K_V_PA, lpv200_available, protection_levels

EL_DEG = np.array([85.0, 50.0, 42.0, 30.0, 22.0, 15.0, 10.0, 6.0])
AZ_DEG = np.array([10.0, 70.0, 160.0, 230.0, 300.0, 20.0, 120.0, 200.0])
SIGMA_M = np.array([1.31, 1.45, 1.55, 1.86, 2.10, 2.45, 2.81, 3.10])
"""A fixed sky: eight satellites, broadcast sigmas of the SBAS L1 order at their elevations."""
COND_FLOOR = 1e-12
"""Relative floor: the two forms share no code and invert a 4x4 normal matrix of condition ~1e2 (this geometry);
their rounding differs by ~cond x eps ~ 1e-14 relative, 1e-12 leaves two orders for the eigen / sqrt paths."""


def _independent(el: np.ndarray, az: np.ndarray, sig: np.ndarray) -> tuple[float, float]:
    # line of sight in north-east-down; H = [-u, 1]; S = pinv(W^1/2 H) W^1/2 via lstsq on the whitened system
    u = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=1)
    h = np.hstack([-u, np.ones((el.size, 1))])
    wh = h / sig[:, None]
    s = np.linalg.lstsq(wh, np.diag(1.0 / sig), rcond=None)[0]  # (4, k): x = S rho
    cov = s @ np.diag(sig**2) @ s.T
    d_v = np.sqrt(cov[2, 2])
    d_major = np.sqrt(np.linalg.eigvalsh(cov[:2, :2]).max())
    return K_V_PA * d_v, K_H_PA * d_major


def test_pl_fixed_geometry() -> None:
    el, az = np.radians(EL_DEG), np.radians(AZ_DEG)
    vpl, hpl = protection_levels(el, az, np.ones(8, bool), SIGMA_M)
    v_ref, h_ref = _independent(el, az, SIGMA_M)
    np.testing.assert_allclose([vpl, hpl], [v_ref, h_ref], rtol=COND_FLOOR)
    assert 5.0 < float(vpl) < 35.0 and 3.0 < float(hpl) < 40.0  # an LPV-200 sky


def test_unused_channels_and_too_few() -> None:
    el, az = np.radians(EL_DEG), np.radians(AZ_DEG)
    used = np.array([True, True, True, True, True, False, False, True])
    vpl, hpl = protection_levels(el, az, used, SIGMA_M)
    v_ref, h_ref = _independent(el[used], az[used], SIGMA_M[used])
    np.testing.assert_allclose([vpl, hpl], [v_ref, h_ref], rtol=COND_FLOOR)
    used3 = np.zeros(8, bool)
    used3[:3] = True
    vpl3, hpl3 = protection_levels(el, az, used3, SIGMA_M)
    assert np.isinf(vpl3) and np.isinf(hpl3) and not lpv200_available(vpl3, hpl3)


def test_batched_epochs_and_scaling() -> None:
    """Epoch axes broadcast; scaling every sigma by c scales both PLs by c (W is homogeneous)."""
    el, az = np.radians(EL_DEG), np.radians(AZ_DEG)
    e2, a2 = np.stack([el, el]), np.stack([az, az])
    s2 = np.stack([SIGMA_M, 2.0 * SIGMA_M])
    vpl, hpl = protection_levels(e2, a2, np.ones((2, 8), bool), s2)
    np.testing.assert_allclose(vpl[1], 2.0 * vpl[0], rtol=COND_FLOOR)
    np.testing.assert_allclose(hpl[1], 2.0 * hpl[0], rtol=COND_FLOOR)


def test_snapshot_error_is_the_wls_of_the_range_errors() -> None:
    """A range error that is a pure position offset dx (e = G dx) comes back as dx (the clock column absorbs a
    common error; the fix is exact on a consistent system), and equals the independent lstsq fix otherwise."""
    from approachsim.integrity.sbas import geometry_enu, snapshot_error_enu

    el, az = np.radians(EL_DEG), np.radians(AZ_DEG)
    g = geometry_enu(el, az)
    dx = np.array([1.5, -2.0, 3.0, 7.0])
    got = snapshot_error_enu(el, az, np.ones(8, bool), SIGMA_M, g @ dx)
    np.testing.assert_allclose(got, dx[:3], rtol=0, atol=COND_FLOOR * 10.0)
    e = np.random.default_rng(3).standard_normal(8) * SIGMA_M
    ref = np.linalg.lstsq(g / SIGMA_M[:, None], e / SIGMA_M, rcond=None)[0][:3]
    np.testing.assert_allclose(snapshot_error_enu(el, az, np.ones(8, bool), SIGMA_M, e), ref, rtol=0,
                               atol=COND_FLOOR * 10.0)
