"""Strapdown INS mechanization: exact trajectories flown with noiseless increments stay within 1 cm / 1 mm/s.

The trajectories are built here from their defining ODEs (solved to 1e-13 relative tolerance), and the
IMU increments from the exact body rate and specific force at the samples (trapezoid over each interval).
"""

from __future__ import annotations

import numpy as np
import pytest
from scipy.integrate import solve_ivp

from approachsim import geo
from approachsim.nav import ins

LAT0 = np.radians(37.6)
LON0 = np.radians(-122.36)


def constant_velocity_track(v_ned, euler, h0, duration_s, rate_hz):
    """Exact samples of a constant-NED-velocity, constant-attitude flight and its ideal IMU increments."""

    def rhs(t, y):
        lat, lon, h = y
        r_n, r_e = geo.radii(lat)
        return [v_ned[0] / (r_n + h), v_ned[1] / ((r_e + h) * np.cos(lat)), -v_ned[2]]

    n = int(round(duration_s * rate_hz)) + 1
    t = np.arange(n) / rate_hz
    sol = solve_ivp(rhs, (0.0, t[-1]), [LAT0, LON0, h0], t_eval=t, method="DOP853", rtol=1e-13, atol=1e-14)
    lat, lon, h = sol.y
    v = np.broadcast_to(np.asarray(v_ned, float), (n, 3))
    c_bn = ins.cbn_from_euler(np.asarray(euler, float))
    w_in = ins.earth_rate_ned(lat) + ins.transport_rate_ned(lat, h, v)
    w_ie = ins.earth_rate_ned(lat)
    # v' = 0: f_n = (2 w_ie + w_en) x v - g ; attitude fixed in NED: w_ib = C_nb w_in
    f_n = np.cross(2.0 * w_ie + ins.transport_rate_ned(lat, h, v), v) - ins.gravity_ned(lat, h)
    f_b = f_n @ c_bn  # rows: C_nb f_n = (f_n' C_bn)'
    w_b = w_in @ c_bn
    dtheta = 0.5 * (w_b[1:] + w_b[:-1]) / rate_hz
    dv = 0.5 * (f_b[1:] + f_b[:-1]) / rate_hz
    return t, lat, lon, h, v, c_bn, dtheta, dv


def fly(lat, lon, h, v, c_bn, dtheta, dv, dt):
    """Fly the INS over increments (runs, n, 3) from the true initial states; returns (runs, n + 1, ...) arrays."""
    s = ins.init_state(lat[:, 0], lon[:, 0], h[:, 0], v[:, 0], c_bn)
    out = [s]
    for k in range(dtheta.shape[1]):
        s = ins.step(s, dtheta[:, k], dv[:, k], dt)
        out.append(s)
    return tuple(np.stack([getattr(o, f) for o in out], axis=1) for f in ("lat_rad", "lon_rad", "h_m", "v_ned", "c_bn"))


def tracks(cases, duration_s, rate_hz):
    """Several exact tracks stacked on a leading run axis."""
    parts = [constant_velocity_track(v, np.radians(e), h0, duration_s, rate_hz) for v, e, h0 in cases]
    return [np.stack([p[i] for p in parts]) for i in range(len(parts[0]))]


CASES = [((0.0, 0.0, 0.0), (1.0, 2.0, 30.0), 100.0), ((-32.0, 60.0, 3.6), (-1.0, 2.5, 118.0), 1000.0)]
"""Stationary, and a 3 deg glidepath descent at 132 kt."""


def _check_within_1cm(lat, lon, h, v, c_bn, lat_i, lon_i, h_i, v_i, c_i):
    dp = ins.position_error_ned(lat_i, lon_i, h_i, lat, lon, h)
    assert np.max(np.linalg.norm(dp, axis=-1)) < 0.01
    assert np.max(np.linalg.norm(v_i - v, axis=-1)) < 0.001
    assert np.max(np.abs(ins.attitude_error(c_i, c_bn[:, None]))) < 1e-6


@pytest.mark.slow
def test_noiseless_approach_stays_within_1cm_at_120hz():
    """600 s at 120 Hz through one `propagate` call per run (the path of the system and the closed loop):
    |dp| < 1 cm, |dv| < 1 mm/s."""
    t, lat, lon, h, v, c_bn, dth, dv = tracks(CASES, 600.0, 120.0)
    for i in range(len(CASES)):
        s = ins.init_state(lat[i, 0], lon[i, 0], h[i, 0], v[i, 0], c_bn[i])
        rows = np.empty((1, dth.shape[1] + 1, 16))
        rows[:, 0] = ins.pack(s)
        ins.propagate(ins.pack(s), dth[i:i + 1], dv[i:i + 1], 1.0 / 120.0, out=rows)
        o = ins.unpack(rows)
        got = [o.lat_rad, o.lon_rad, o.h_m, o.v_ned, o.c_bn]
        _check_within_1cm(lat[i:i + 1], lon[i:i + 1], h[i:i + 1], v[i:i + 1], c_bn[i:i + 1], *got)


def test_noiseless_approach_stays_within_1cm_batched_path():
    """The same two tracks stepped together (run axis) at 20 Hz over 600 s: |dp| < 1 cm, |dv| < 1 mm/s."""
    t, lat, lon, h, v, c_bn, dth, dv = tracks(CASES, 600.0, 20.0)
    _check_within_1cm(lat, lon, h, v, c_bn, *fly(lat, lon, h, v, c_bn, dth, dv, 1.0 / 20.0))


def test_error_falls_as_dt_squared():
    """Second-order integration: halving a coarse step (1 s -> 0.5 s) divides the 600 s error by about 4."""
    errs = []
    for rate in (1.0, 2.0):
        t, lat, lon, h, v, c_bn, dth, dv = tracks([((-60.0, 40.0, 4.0), (0.0, 3.0, 115.0), 1000.0)], 600.0, rate)
        lat_i, lon_i, h_i, v_i, c_i = fly(lat, lon, h, v, c_bn, dth, dv, 1.0 / rate)
        errs.append(np.linalg.norm(ins.position_error_ned(lat_i, lon_i, h_i, lat, lon, h)[0, -1]))
    assert errs[0] < 0.01  # even at 1 Hz the mechanization holds a steady descent to a centimetre
    assert 3.5 < errs[0] / errs[1] < 4.5


def test_rotation_exp_is_orthonormal_and_inverts():
    rng = np.random.default_rng(3)
    phi = rng.normal(size=(50, 3))
    r = ins.rotation_exp(phi)
    np.testing.assert_allclose(r @ np.swapaxes(r, -1, -2), np.broadcast_to(np.eye(3), r.shape), atol=1e-14)
    np.testing.assert_allclose(ins.rotation_exp(-phi) @ r, np.broadcast_to(np.eye(3), r.shape), atol=1e-14)
    np.testing.assert_allclose(r @ phi[..., None], phi[..., None], atol=1e-13)  # the axis is fixed


def test_euler_round_trip_and_quaternion_agree():
    e = np.array([0.1, -0.2, 5.5])
    np.testing.assert_allclose(ins.euler_from_cbn(ins.cbn_from_euler(e)), e, atol=1e-14)
    # quaternion of a pure heading rotation psi: (cos psi/2, 0, 0, sin psi/2)
    q = np.array([np.cos(0.3), 0.0, 0.0, np.sin(0.3)])
    np.testing.assert_allclose(ins.cbn_from_quaternion(q), ins.cbn_from_euler([0.0, 0.0, 0.6]), atol=1e-15)


def test_perturb_and_error_functions_invert():
    s = ins.init_state(LAT0, LON0, 500.0, [10.0, -3.0, 1.0], ins.cbn_from_euler([0.1, 0.02, 1.0]))
    dp, dvv, psi = np.array([[3.0, -4.0, 2.0]]), np.array([[0.1, 0.2, -0.3]]), np.array([[1e-4, -2e-4, 3e-4]])
    p = ins.perturb(s, dp, dvv, psi)
    np.testing.assert_allclose(
        ins.position_error_ned(p.lat_rad, p.lon_rad, p.h_m, s.lat_rad, s.lon_rad, s.h_m), dp, atol=1e-6)
    np.testing.assert_allclose(ins.attitude_error(p.c_bn, s.c_bn), psi, atol=1e-10)


def test_held_baro_is_the_latest_sample_and_its_age():
    """The damping loop's hold (ins.held_baro): at each IMU interval start the latest baro sample at or before it
    (a sample at the same instant counts, to 1e-9 s), nan where that sample is invalid, and its age
    t_start - t_sample, which the INS uses to take its height back to the sample's time."""
    t_baro = np.array([0.0, 0.1, 0.2, 0.3])
    h = np.array([[100.0, 99.5, 99.0, 98.5], [200.0, 199.0, 198.0, 197.0]])
    valid = np.array([[True, True, False, True], [True, True, True, True]])
    t_start = np.arange(0.0, 0.35, 1.0 / 40.0)  # 14 starts, 4 per sample interval
    hb, age = ins.held_baro(valid, h, t_baro, t_start)
    idx = np.array([0] * 4 + [1] * 4 + [2] * 4 + [3] * 2)
    np.testing.assert_array_equal(hb[1], h[1, idx])
    np.testing.assert_array_equal(np.isnan(hb[0]), idx == 2)  # run 0's third sample is invalid: the loop holds
    np.testing.assert_allclose(age, t_start - t_baro[idx], rtol=0, atol=0)
    assert age.min() >= -1e-15 and age.max() < 0.1  # a start on a sample: age 0 to the rounding of t_start
    one_h, one_age = ins.held_baro(valid[1], h[1], t_baro, t_start)  # a single run's records: one row
    np.testing.assert_array_equal(one_h, hb[1:2])
    np.testing.assert_array_equal(one_age, age)
