"""Measurement rows: each h is the derivative of the exact difference measurement g(x) (central differences),
and the linearized z reproduces the exact innovation z - g(x_hat); baro / loose rows by hand."""

from __future__ import annotations

import numpy as np
import pytest
from floors import floor

from approachsim import geo
from approachsim.nav import errormodel as em
from approachsim.nav import measurements as meas

LAY = em.StateLayout(baro_scale=True, clock=True, n_sv=4, n_pl=1, pl_clock=True)
LAT, LON, H = np.radians(37.6), np.radians(-122.36), 300.0
R_INS = geo.geodetic_to_ecef(LAT, LON, H)
C_EN = geo.c_ecef_to_ned(LAT, LON)


def _true_position(x):
    return R_INS - C_EN.T @ x[LAY.index["dp"]]


def _pr_exact(x, r_tx, sv=None, pl=None):
    """Exact |r_ins - r_tx| - rho for the error state x (rho built from the truth that x implies)."""
    rho = np.linalg.norm(_true_position(x) - r_tx) + x[LAY.i("clk")]
    if sv is not None:
        rho += x[LAY.i("gse", sv)] + x[LAY.i("gmp", sv)]
    if pl is not None:
        rng = np.linalg.norm(_true_position(x) - r_tx)
        rho += x[LAY.i("pmp", pl)] + x[LAY.i("ptr", pl)] * rng + x[LAY.i("pclk", 2 * pl)]
    return np.linalg.norm(R_INS - r_tx) - rho


@pytest.mark.parametrize("tx", ["satellite", "pseudolite"])
def test_pseudorange_row_is_the_jacobian_and_innovation_exact(tx):
    rng = np.random.default_rng(4)
    if tx == "satellite":
        r_tx = R_INS + 2.2e7 * np.array([0.3, -0.5, 0.81]) / np.linalg.norm([0.3, -0.5, 0.81])
        kw = {"sv": 2}
    else:
        r_tx = R_INS + C_EN.T @ np.array([900.0, -300.0, 290.0])  # 1 km away, below the aircraft
        kw = {"pl": 0}
    x_hat = rng.normal(size=LAY.n) * 1e-3
    x_hat[LAY.index["dp"]] = [40.0, -25.0, 10.0]  # large position error: the nonlinearity matters at 1 km
    x_true = x_hat + rng.normal(size=LAY.n) * 1e-2
    z = _pr_exact(x_true, r_tx, **kw)  # the measured difference (noise-free)
    rho = np.linalg.norm(R_INS - r_tx) - z
    m = meas.pseudorange(LAY, x_hat, R_INS, C_EN, r_tx, rho, 1.0, 0.0, "r", **kw)
    # both sides are differences of ~2.2e7 m ranges built from 6.4e6 / 2.6e7 m ECEF vectors: their floor
    # (tests/floors.py) 8 eps (|rho| + range + |r_ins| + |r_tx|) = 1.4e-7 m for the satellite, 1e-8 m for the pseudolite
    ops = (rho, np.linalg.norm(R_INS - r_tx), np.linalg.norm(R_INS), np.linalg.norm(r_tx))
    assert m.z - m.h @ x_hat == pytest.approx(z - _pr_exact(x_hat, r_tx, **kw), abs=float(floor(8, *ops)))
    eps = 1e-3
    num = np.array([(_pr_exact(x_hat + eps * e, r_tx, **kw) - _pr_exact(x_hat - eps * e, r_tx, **kw)) / (2 * eps)
                    for e in np.eye(LAY.n)])
    np.testing.assert_allclose(m.h, num, atol=1e-6)


def test_baro_row_and_value():
    x = np.zeros(LAY.n)
    x[LAY.i("dp", 2)], x[LAY.i("bb")], x[LAY.i("sb")] = -2.0, 1.5, 1e-3  # INS 2 m high, baro bias 1.5 m, SF 0.1 %
    h_true = H - 2.0
    h_baro = h_true * (1 + 1e-3) + 1.5
    m = meas.baro(LAY, H, h_baro, 1.0, 0.0)
    assert m.h @ x == pytest.approx(m.z, abs=2.5e-3)  # z = dh - bb - S h; S h at h_ins: S dh = 2 mm off
    assert m.r == 1.0


def test_baro_scale_factor_is_on_the_height_above_the_field():
    """A 5434 ft (1656 m) field, the aircraft 100 ft above it, a 12 % scale error (issue 39's uncorrected sigma):
    the truth's error S (h - H_ref) is 3.7 m; on the MSL height it would be 202 m. The row's sb column is
    -(h_ins - H_ref), so the filter's prediction matches the truth's error to S dh (the INS's 2 m error: 0.24 m)."""
    h_ref = 5434.0 * 0.3048
    h_ins = h_ref + 100.0 * 0.3048
    x = np.zeros(LAY.n)
    x[LAY.i("dp", 2)], x[LAY.i("sb")] = -2.0, 0.12  # INS 2 m high
    h_true = h_ins - 2.0
    h_baro = h_true + (h_true - h_ref) * 0.12  # sensors/baro.py with B = v = 0
    m = meas.baro(LAY, h_ins, h_baro, 1.0, 0.0, h_ref_m=h_ref)
    assert m.h[LAY.i("sb")] == pytest.approx(-100.0 * 0.3048, abs=1e-9)
    assert m.h @ x == pytest.approx(m.z, abs=0.12 * 2.0 + 1e-9)
    assert abs(h_baro - h_true) == pytest.approx(0.12 * 28.48, abs=0.01)


def test_radalt_row_with_sloping_terrain():
    rwy = geo.RunwayFrame(LAT, LON, 0.0, np.radians(90.0))  # runway x = east

    def terrain(r):
        return 0.02 * rwy.from_ecef(r)[..., 0]  # 2 % slope rising eastward

    x_hat = np.zeros(LAY.n)
    x_hat[LAY.index["dp"]] = [3.0, 50.0, -1.0]  # INS 50 m east, 1 m high
    r_true = _true_position(x_hat)
    h_agl = (H + x_hat[LAY.i("dp", 2)]) - float(terrain(r_true))
    m = meas.radalt(LAY, x_hat, LAT, LON, H, h_agl, 1.0, terrain, 0.0)
    assert m.z - m.h @ x_hat == pytest.approx(0.0, abs=1e-6)  # exact at the true error
    assert m.h[LAY.i("dp", 1)] == pytest.approx(-0.02, abs=1e-4)
    assert m.h[LAY.i("dp", 2)] == -1.0


def test_loose_position_rows():
    ms = meas.gps_position(LAY, np.array([1.0, 2.0, 3.0]), np.array([2.0, 2.0, 4.0]), 5.0)
    assert [m.name for m in ms] == ["gps_N", "gps_E", "gps_D"]
    assert [m.r for m in ms] == [4.0, 4.0, 16.0]
    assert all(m.h[LAY.i("dp", k)] == 1.0 and m.h.sum() == 1.0 for k, m in enumerate(ms))


LAY_RA = em.StateLayout(baro_scale=True, clock=True, n_sv=2, radalt_bias=True, radalt_markov=True, terrain_db=True)


def test_radalt_correlated_error_columns_are_the_jacobian_and_innovation_exact():
    """rab (altimeter + database bias), ram, tdb (unit Gauss-Markov scaled by the database sigma there): h is
    the central-difference derivative of the exact difference g(x), and z - h x_hat is z - g(x_hat)."""
    lay = LAY_RA
    rwy = geo.RunwayFrame(LAT, LON, 0.0, np.radians(90.0))
    s_db = 1.772  # the database's correlated 1-sigma at the aircraft, m

    def terrain(r):
        return 0.02 * rwy.from_ecef(r)[..., 0] - 0.01 * rwy.from_ecef(r)[..., 1]  # planar: the 10 m steps are exact

    def g(x):  # exact (h_ins - T(r_ins)) - h_R for error state x; the database error is in rab and tdb
        r_true = R_INS - C_EN.T @ x[lay.index["dp"]]
        h_true = H + x[lay.i("dp", 2)]
        h_r = h_true - float(terrain(r_true)) + x[lay.i("rab")] + x[lay.i("ram")] + s_db * x[lay.i("tdb")]
        return (H - float(terrain(R_INS))) - h_r

    rng = np.random.default_rng(11)
    x_true = np.zeros(lay.n)
    x_true[lay.index["dp"]] = [3.0, 20.0, -1.0]
    x_true[lay.i("rab")], x_true[lay.i("ram")], x_true[lay.i("tdb")] = 0.5, -0.2, 0.7
    # the world: the altimeter bias 0.3 m, the database bias 0.2 m (rab = 0.5) and error s u at the INS position
    db_err = 0.2 + s_db * 0.7
    r_true = R_INS - C_EN.T @ x_true[lay.index["dp"]]
    h_agl = (H + x_true[lay.i("dp", 2)]) - float(terrain(r_true)) + 0.3 - 0.2  # altimeter: truth + bias + Markov
    x_hat = x_true + rng.normal(size=lay.n) * 0.05
    m = meas.radalt(lay, x_hat, LAT, LON, H, h_agl, 1.0, terrain, 0.0, tdb_sigma_m=s_db, db_error_m=db_err)
    z = (H - float(terrain(R_INS)) - db_err) - h_agl
    assert z == pytest.approx(g(x_true), abs=1e-9)  # the model reproduces the world's measurement
    assert m.z - m.h @ x_hat == pytest.approx(z - g(x_hat), abs=1e-6)
    eps = 1e-3
    num = np.array([(g(x_hat + eps * e) - g(x_hat - eps * e)) / (2 * eps) for e in np.eye(lay.n)])
    np.testing.assert_allclose(m.h, num, atol=2e-5)
    assert m.h[lay.i("rab")] == -1.0 and m.h[lay.i("ram")] == -1.0 and m.h[lay.i("tdb")] == -s_db
