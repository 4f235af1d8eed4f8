"""GPS: constellation geometry at the default airport, exact pseudoranges, clock, selection, error budget."""

from __future__ import annotations

import itertools
import math
from dataclasses import replace

import numpy as np
import pytest

from approachsim import geo, synthetic
from approachsim.sensors.gnss import CODE_PRESETS, ClockModel, Constellation, GnssReceiver
from approachsim.sensors.gnss.constellation import MU_GPS, dops, look_angles
from approachsim.sensors.gnss.receiver import best_pdop_four


def test_orbits_are_circular_kepler_with_the_right_period():
    c = Constellation.nominal("2026-01-01T00:00:00Z")
    period = 2 * math.pi * math.sqrt(c.a_m**3 / MU_GPS)
    assert period == pytest.approx(43077.0, abs=5.0)  # standards.md 2.1: 11.966 h
    r = c.positions_ecef(np.array([0.0, period]))
    # 1e-3 m: 2000x the orbit's floor(6, 4 pi a) + floor(5, a) = 4.7e-7 m (gnss_floors.py)
    assert np.allclose(np.linalg.norm(r, axis=-1), 26559800.0, atol=1e-3)
    # after one period the inertial position repeats: ECEF rotates by OMEGA_E * period about z
    a = geo.OMEGA_E * period
    rz = np.array([[math.cos(a), math.sin(a), 0], [-math.sin(a), math.cos(a), 0], [0, 0, 1]])
    assert np.allclose(r[1], r[0] @ rz.T, atol=1e-3)  # as above, the angle w_E T ~ 3 rad adding floor(3, 3 a)
    # inclination 55 deg: maximum |z| / a = sin 55
    t = np.linspace(0, period, 400)
    z = c.positions_ecef(t)[..., 2]
    assert np.max(np.abs(z)) / c.a_m == pytest.approx(math.sin(math.radians(55.0)), rel=1e-4)


def test_geometry_at_the_default_airport_over_a_day(runway):
    """>= 5 SVs above the 5 deg mask and PDOP < 6 (all in view) every 10 minutes for 24 h (sky plot: sense)."""
    c = Constellation.nominal("2026-01-01T12:00:00Z")
    t = np.arange(0, 86400 + 1, 600.0)
    r_rx = np.tile(runway.origin_ecef, (t.shape[0], 1))
    _, u, el, _ = look_angles(r_rx, c.positions_ecef(t))
    vis = el >= math.radians(5.0)
    lat, lon, _ = geo.ecef_to_geodetic(r_rx)
    _, pdop, hdop, vdop = dops(u, vis, geo.c_ecef_to_ned(lat, lon))
    assert vis.sum(axis=1).min() >= 5
    assert pdop.max() < 6.0
    assert np.allclose(pdop**2, hdop**2 + vdop**2)  # rtol 1e-5: far above the traces' floor(16, pdop^2)

def _pdop_from_angles(el: np.ndarray, az: np.ndarray) -> float:
    """PDOP of SVs at elevations el and azimuths az (rad): G rows [-u_NED, 1], PDOP^2 = trace of the position
    block of (G' G)^-1 (Kaplan & Hegarty, eq. 7.67)."""
    u = np.stack([np.cos(el) * np.cos(az), np.cos(el) * np.sin(az), -np.sin(el)], axis=-1)
    g = np.concatenate([-u, np.ones((len(el), 1))], axis=1)
    q = np.linalg.inv(g.T @ g)
    return float(np.sqrt(q[0, 0] + q[1, 1] + q[2, 2]))


def test_best_four_is_the_minimum_pdop_combination(runway):
    c = Constellation.nominal("2026-01-01T12:00:00Z")
    r_rx = runway.origin_ecef[None, :]
    _, u, el, _ = look_angles(r_rx, c.positions_ecef(np.array([0.0])))
    vis = el >= math.radians(5.0)
    sel = best_pdop_four(u, vis)
    c_ned = geo.c_ecef_to_ned(runway.threshold_lat_rad, runway.threshold_lon_rad)[None]
    _, p_sel, _, _ = dops(u, sel, c_ned)
    # brute force with the PDOP written here from the elevations and azimuths (not the package's dops())
    _, _, el, az = look_angles(r_rx, c.positions_ecef(np.array([0.0])))
    pdops = {combo: _pdop_from_angles(el[0, list(combo)], az[0, list(combo)])
             for combo in itertools.combinations(np.flatnonzero(vis[0]), 4)}
    best = min(pdops, key=pdops.get)
    assert sel.sum() == 4 and set(np.flatnonzero(sel[0])) == set(best)
    # two formulas of a pdop ~ 2: relative floor 96 pdop^2 16 eps = 1.4e-12 (gnss_floors.py); rel 1e-9 is 700x
    assert p_sel[0] == pytest.approx(pdops[best], rel=1e-9)


def test_noise_false_pseudorange_is_geometric_range(descent):
    rx = GnssReceiver(selection="all")
    rec = rx.measure(descent, np.random.default_rng(0), noise=False)
    rows = np.arange(0, len(descent), 20)
    rng = np.linalg.norm(rec.r_sv_ecef - descent.r_ecef[rows][:, None, :], axis=-1)
    ok = rec.valid
    assert ok.sum(axis=1).min() >= 5
    assert np.max(np.abs(rec.pseudorange_m[ok] - rng[ok])) < 1e-3  # 2000x the range floor ~5e-7 m (gnss_floors)
    assert np.all(np.isnan(rec.pseudorange_m[~ok]))


def test_pseudorange_minus_clock_bias_is_geometric_range(descent):
    zero = replace(CODE_PRESETS["C/A"], clock_ephemeris_m=0.0, iono_zenith_m=0.0, tropo_zenith_m=0.0,
                   multipath_m=0.0, code_noise_m=0.0)
    rx = GnssReceiver(budget=zero, clock=ClockModel.named("tcxo", 1e5, 50.0))
    rec = rx.measure(descent, np.random.default_rng(0), clock_rng=np.random.default_rng(1))
    rows = np.arange(0, len(descent), 20)
    rng = np.linalg.norm(rec.r_sv_ecef - descent.r_ecef[rows][:, None, :], axis=-1)
    assert np.ptp(rec.clock_bias_m) > 1000.0  # a real, drifting clock
    resid = rec.pseudorange_m - rec.clock_bias_m[:, None] - rng
    assert np.nanmax(np.abs(resid)) < 1e-3  # 2000x the range floor ~5e-7 m (gnss_floors.py)

def test_pseudorange_error_matches_the_budget(runway):
    """Per-SV errors at 1 Hz over 2000 runs: RSS matches sigma(el) within 5 % (P(Y) and C/A)."""
    tr = synthetic.stationary(runway.threshold_lat_rad, runway.threshold_lon_rad, runway.threshold_h_m, 2.0, 1.0)
    for code, uere_30deg in (("P(Y)", 4.1), ("C/A", 8.0)):
        rx = GnssReceiver(budget=CODE_PRESETS[code], selection="all")
        rec = rx.measure(tr, [np.random.default_rng(i) for i in range(2000)])
        exact = rx.measure(tr, np.random.default_rng(0), noise=False)
        err = rec.pseudorange_m - exact.pseudorange_m
        ok = exact.valid
        assert err[:, ok].std(axis=0) == pytest.approx(rec.sigma_m[ok], rel=0.05)
        assert abs(np.nanmean(err[:, ok])) < 0.05 * rec.sigma_m[ok].min()
        # the NRC 1995 UERE the preset is built from, at 30 deg elevation
        assert rx.sigma_m(np.array(math.radians(30.0))) == pytest.approx(uere_30deg, rel=0.03)


def test_pseudorange_rate_is_the_range_derivative_plus_clock_drift(descent):
    rx = GnssReceiver(selection="all", doppler=True)
    exact = rx.measure(descent, np.random.default_rng(0), noise=False)
    rows = np.arange(0, len(descent), 20)
    # central difference of the geometric range between neighbouring 20 Hz truth rows (independent check)
    dt = descent.t_s[1] - descent.t_s[0]
    mid = rows[1:-1]
    c = rx.constellation
    r_p = np.linalg.norm(c.positions_ecef(descent.t_s[mid + 1]) - descent.r_ecef[mid + 1][:, None], axis=-1)
    r_m = np.linalg.norm(c.positions_ecef(descent.t_s[mid - 1]) - descent.r_ecef[mid - 1][:, None], axis=-1)
    fd = (r_p - r_m) / (2 * dt)
    ok = exact.valid[1:-1]
    # the central difference of 2e7 m ranges over 0.1 s: floor(6, 2.7e7, 6.4e6) / 0.1 s = 4.5e-7 m/s; 2000x
    assert np.max(np.abs(exact.pseudorange_rate_mps[1:-1][ok] - fd[ok])) < 1e-3
    noisy = rx.measure(descent, [np.random.default_rng(i) for i in range(200)],
                       clock_rng=[np.random.default_rng(1000 + i) for i in range(200)])
    resid = noisy.pseudorange_rate_mps - exact.pseudorange_rate_mps - noisy.clock_drift_mps[..., None]
    assert np.nanstd(resid) == pytest.approx(0.05, rel=0.05)
    assert GnssReceiver().measure(descent, np.random.default_rng(0)).pseudorange_rate_mps is None


def test_best4_fixed_keeps_the_start_set_and_is_stateless(descent):
    fixed = GnssReceiver(selection="best4-fixed")
    e = fixed.draw(descent.t_s, np.random.default_rng(0))
    rec = fixed.apply(descent, e)
    every = GnssReceiver(selection="best4").measure(descent, np.random.default_rng(0), noise=False)
    assert np.all(rec.valid.sum(axis=1) == 4)
    assert np.all(rec.valid == rec.valid[0])  # one planned set for the whole approach
    assert np.all(rec.elevation_rad[0][rec.valid[0]] >= fixed.mask_rad)
    # re-selecting every epoch switches sets (here PRN 14 sets through the 5 deg mask at t = 115 s)
    assert not np.all(every.valid == every.valid[0])
    # the planned set is the minimum-PDOP four at the start among the SVs above the mask for the whole approach
    # (brute force here with the PDOP written above), and its PDOP at every epoch is the one of those four SVs'
    # geometry (computed here from the record's angles); where re-selection switches, it costs PDOP
    stays = np.flatnonzero(np.all(every.visible, axis=0))
    el0, az0 = every.elevation_rad[0], every.azimuth_rad[0]
    best = min(itertools.combinations(stays, 4), key=lambda c: _pdop_from_angles(el0[list(c)], az0[list(c)]))
    assert set(np.flatnonzero(rec.valid[0])) == set(best)
    for j in (0, len(e) // 2, len(e) - 1):
        m = rec.valid[j]
        # two formulas of pdop (the los vs the angles): 700x the relative floor 96 pdop^2 16 eps, as above
        assert rec.pdop[j] == pytest.approx(_pdop_from_angles(rec.elevation_rad[j][m], rec.azimuth_rad[j][m]),
                                            rel=1e-9)
    switched = ~np.all(every.valid == rec.valid, axis=1)
    assert np.all(rec.pdop[switched] > every.pdop[switched] - 1e-9)  # 1e-9: 100x the pdops' floor ~1e-11
    for j in (0, 100, len(e) - 1):  # bit-identical: same code path (the kernels on a one-sample slice)
        one = fixed.apply(descent, e.take(slice(j, j + 1)))
        assert np.array_equal(one.pseudorange_m[0], rec.pseudorange_m[j], equal_nan=True)
