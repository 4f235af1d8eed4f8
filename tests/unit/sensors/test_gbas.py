"""GBAS-corrected pseudoranges (sensors/gnss/gbas.py, receiver corrections = "gbas").

The residual's statistics term by term (mean 0, 1-sigma at each channel's elevation and the aircraft's distance and
height from the reference point, correlation time), seeded, with tolerances from the sampling error; the budget
monotone where the physics says so; the compiled path equal to its numpy oracle; "none" unchanged and drawn from the
same normals (common random numbers); the realized channel states adding up to the pseudorange error; the profile
keys and their errors."""

from __future__ import annotations

import copy
import math
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from floors import assert_within, floor
from gnss_floors import assert_fields_within, record_floors

from approachsim import synthetic
from approachsim.config import ProfileError
from approachsim.core.sensors import gnss as gk
from approachsim.profile import load_profile, parse_profile
from approachsim.seeding import stream
from approachsim.sensors.gnss import gbas as gb
from approachsim.sensors.gnss.receiver import (
    SIDEREAL_DAY_S,
    draw_epoch_offsets,
    draw_receiver_clock,
    make_budget,
)
from approachsim.sensors.states import start_states
from approachsim.sensors.suite import SensorSuite, SuiteErrors

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""
DEFAULT = PY_DEFAULT
SCALED = ("ground", "iono", "tropo", "multipath", "noise")
"""The unit Gauss-Markov series the kernel scales."""
TERMS = (*SCALED, "white")
"""Every error series of a GBAS receiver (the white carrier-phase noise in m)."""
DEG = math.pi / 180.0


def _profile(**gnss):
    """The default profile with [sensors.gnss] keys changed (a `gbas` dict becomes the sub-table)."""
    d = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    d["sensors"]["gnss"].update(copy.deepcopy(gnss))
    return parse_profile(d, source=DEFAULT)


def _receiver(selection="all", **gbas):
    p = _profile(corrections="gbas", selection=selection, **({"gbas": gbas} if gbas else {}))
    return p, SensorSuite.from_profile(p).sensors["gnss"]


# --- the model's terms against the tables and formulas of the standards (module docstring) -------------------------

def _gad_c(theta_deg, m):
    """GAD-C of Annex 10 App. B Table B-74, written out: the row above 35 deg, the flat 5-35 deg row."""
    a = 0.15 + 0.84 * math.exp(-theta_deg / 15.5) if theta_deg > 35.0 else 0.24
    return math.sqrt(a * a / m + 0.04**2)


@pytest.mark.parametrize("theta_deg", [5.0, 20.0, 35.0, 36.0, 60.0, 90.0])
@pytest.mark.parametrize("m", [2, 3, 4])
def test_ground_curve_is_table_b74_over_the_reference_receivers(theta_deg, m):
    model = gb.GbasModel(gad="C", reference_receivers=m)
    # the model against the table's formula written here (deg -> rad -> deg, exp of <= 6.3, a sqrt): ~15 eps
    # relative; rel 1e-13 (450 eps) is 30x that, here and in the formula tests below
    assert float(model.ground_sigma_m(np.radians(theta_deg))) == pytest.approx(_gad_c(theta_deg, m), rel=1e-13)
    a = gb.GbasModel(gad="A", reference_receivers=m).ground_sigma_m(np.radians(theta_deg))
    expect_a = math.sqrt((0.5 + 1.65 * math.exp(-theta_deg / 14.3)) ** 2 / m + 0.08**2)
    assert float(a) == pytest.approx(expect_a, rel=1e-13)


def test_gad_c_rows_meet_at_35_deg_and_the_designators_are_ordered():
    """The two GAD-C rows differ by under 2.5 mm at 35 deg (module docstring); at every elevation A > B > C, and
    more reference receivers average the ground noise down."""
    lo, hi = _gad_c(35.0, 1), math.sqrt((0.15 + 0.84 * math.exp(-35.0 / 15.5)) ** 2 + 0.04**2)
    assert abs(lo - hi) < 2.5e-3
    el = np.radians(np.linspace(5.0, 90.0, 200))
    a, b, c = (gb.GbasModel(gad=x).ground_sigma_m(el) for x in "ABC")
    assert np.all(a > b) and np.all(b > c)
    m2, m4 = (gb.GbasModel(reference_receivers=m).ground_sigma_m(el) for m in (2, 4))
    assert np.all(m4 < m2)


def test_airborne_designators_are_the_aad_curves():
    for aad, (a0, a1, t0) in {"A": (0.15, 0.43, 6.9), "B": (0.11, 0.13, 4.0)}.items():
        model = gb.GbasModel(aad=aad)
        for th in (5.0, 10.0, 45.0, 90.0):
            assert float(model.airborne_noise_sigma_m(np.radians(th))) == pytest.approx(a0 + a1 * math.exp(-th / t0),
                                                                                       rel=1e-13)
    # integrity-envelope.md section 8 sample values, 3 decimals: AAD-A 0.358 / 0.251 / 0.174 / 0.151 / 0.150 m
    got = gb.GbasModel(aad="A").airborne_noise_sigma_m(np.radians([5.0, 10.0, 20.0, 45.0, 90.0]))
    np.testing.assert_allclose(got, [0.358, 0.251, 0.174, 0.151, 0.150], atol=6e-4)


def test_iono_and_tropo_residuals_are_the_gbas_forms():
    """sigma_iono = F sigma_vig (x + 2 tau v); sigma_tropo = sigma_n h0 1e-6 / sqrt(0.002 + sin^2) (1 - e^(-dh/h0))."""
    model = gb.GbasModel(sigma_vig_per_m=4e-6, refractivity_sigma=30.0, scale_height_m=7350.0)
    el = np.radians(30.0)
    f = 1.0 / math.sqrt(1.0 - (6378137.0 * math.cos(el) / (6378137.0 + 350e3)) ** 2)
    assert float(model.iono_sigma_m(el, 5000.0, 70.0)) == pytest.approx(f * 4e-6 * (5000.0 + 2 * 100.0 * 70.0),
                                                                        rel=1e-13)
    t = 30.0 * 7350.0 * 1e-6 / math.sqrt(0.002 + math.sin(el) ** 2) * (1.0 - math.exp(-300.0 / 7350.0))
    assert float(model.tropo_sigma_m(el, 300.0)) == pytest.approx(t, rel=1e-13)
    assert float(model.tropo_sigma_m(el, -300.0)) == pytest.approx(30.0 * 7350e-6 / math.sqrt(
        0.002 + math.sin(el) ** 2) * (math.exp(300.0 / 7350.0) - 1.0), rel=1e-13)  # below the station: |.|
    # below the CAT I decision height (61 m above the reference point) the tropo term is under 2 cm above 5 deg
    assert float(model.tropo_sigma_m(np.radians(5.0), 61.0)) < 0.02


def test_budget_is_monotone_where_the_physics_says():
    """Every term and the total fall with elevation (at a fixed geometry; GAD-C's ground curve is flat from 5 to
    35 deg, Table B-74); the iono term grows with the distance from the station and the speed, the tropo term with
    the height above it; the total grows with the distance."""
    model = gb.GbasModel()
    el = np.radians(np.linspace(5.0, 90.0, 86))
    s = model.scales(el, 10e3, 500.0, 70.0)
    for name in (*SCALED, "sigma"):
        d = np.diff(s[name])
        assert np.all(d <= 0.0) and np.all(d[30:] < 0.0) if name == "ground" else np.all(d < 0.0), name
    for gad in "AB":
        assert np.all(np.diff(gb.GbasModel(gad=gad).ground_sigma_m(el)) < 0.0)
    x = np.linspace(0.0, 40e3, 81)
    for e in np.radians([5.0, 30.0, 80.0]):
        assert np.all(np.diff(model.iono_sigma_m(e, x, 70.0)) > 0.0)
        assert np.all(np.diff(model.sigma_m(e, x, 500.0, 70.0)) > 0.0)
        assert np.all(np.diff(model.iono_sigma_m(e, 5e3, np.linspace(0.0, 100.0, 11))) > 0.0)
        assert np.all(np.diff(model.tropo_sigma_m(e, np.linspace(0.0, 3000.0, 31))) > 0.0)


def test_corrected_sigma_is_an_order_below_stand_alone_ranging():
    """GAD-C / AAD-B near the threshold: a few decimetres at 10-90 deg, where stand-alone P(Y) is 2.4 m or more."""
    _, rx = _receiver()
    el = np.radians(np.linspace(10.0, 90.0, 9))
    corr = rx.sigma_m(el, 2000.0, 100.0, 70.0)
    stand_alone = replace(rx, budget=make_budget("P(Y)", "do253", "current"), station_ecef=None).sigma_m(el)
    assert np.all(corr < 0.5) and np.all(corr > 0.15) and np.all(stand_alone > 2.4)
    assert rx.budget.code_noise_m == gb.CARRIER_NOISE_M == 0.002 and rx.budget.corrections == "gbas"


# --- the drawn residual's statistics -------------------------------------------------------------------------------

RUNS = 6000


@pytest.fixture(scope="module")
def drawn():
    """One sky, two 10 s stretches of the approach (10 nmi out and near the threshold), RUNS runs of the GBAS
    receiver's errors, the records of each term alone (the others zeroed), and the geometry."""
    p, rx = _receiver()
    out = {}
    for where, (start, end) in {"far": (18520.0, 17820.0), "near": (1200.0, 500.0)}.items():
        truth = synthetic.glidepath_descent(p.runway.frame, rate_hz=1.0, start_distance_m=start, end_distance_m=end,
                                            ground_speed_mps=70.0)
        e = rx.draw(truth.t_s, [stream(11, r, "gnss") for r in range(RUNS)])
        exact = rx.apply(truth, e.zeroed())
        alone = {}
        for term in TERMS:
            one = replace(e, series={k: (v if k == term else np.zeros_like(v)) for k, v in e.series.items()})
            alone[term] = rx.apply(truth, one).pseudorange_m - exact.pseudorange_m
        x, dh, v = rx.station_geometry(truth, e.rows)
        out[where] = dict(truth=truth, e=e, alone=alone, el=exact.elevation_rad, x=x, dh=dh, v=v,
                          total=rx.apply(truth, e).pseudorange_m - exact.pseudorange_m, sigma=exact.sigma_m)
    return rx, out


def _expected(term, el, x, dh, v):
    """The documented 1-sigma of one term, written out from the standards' tables and forms (module docstring)."""
    th = math.degrees(el)
    if term == "ground":
        return _gad_c(th, 4)
    if term == "iono":
        f = 1.0 / math.sqrt(1.0 - (6378137.0 * math.cos(el) / (6378137.0 + 350e3)) ** 2)
        return f * 4e-6 * (x + 200.0 * v)
    if term == "tropo":
        return 30.0 * 7350.0 * 1e-6 / math.sqrt(0.002 + math.sin(el) ** 2) * abs(1.0 - math.exp(-dh / 7350.0))
    if term == "multipath":
        return 0.13 + 0.53 * math.exp(-th / 10.0)
    if term == "white":
        return 0.002
    return 0.11 + 0.13 * math.exp(-th / 4.0)


@pytest.mark.parametrize("where", ["far", "near"])
@pytest.mark.parametrize("term", TERMS)
def test_each_term_has_zero_mean_and_its_documented_sigma(drawn, where, term):
    """At the first and last sample of each stretch and every channel in view (5-90 deg): the mean over RUNS runs
    within 5 standard errors of 0 and the standard deviation within 5 standard errors (sigma / sqrt(2 RUNS)) of the
    term's documented 1-sigma at that elevation, distance, height and speed."""
    _, out = drawn
    d = out[where]
    checked = 0
    for i in (0, len(d["x"]) - 1):
        el = d["el"][i]
        for j in np.flatnonzero(np.isfinite(d["alone"][term][0, i])):
            err = d["alone"][term][:, i, j]
            want = _expected(term, float(el[j]), float(d["x"][i]), float(d["dh"][i]), float(d["v"][i]))
            assert abs(err.mean()) < 5.0 * want / math.sqrt(RUNS), (term, where, j)
            assert err.std() == pytest.approx(want, rel=5.0 / math.sqrt(2 * RUNS)), (term, where, j, el[j])
            checked += 1
    assert checked >= 12  # 6+ satellites in view at both samples


def test_the_distance_terms_shrink_toward_the_threshold(drawn):
    """The iono residual 10 nmi out is more than twice the one 1 km out (x + 2 tau v: 32.5 km against 15 km); the
    tropo residual from 980 m above the station dwarfs the one from 60 m."""
    _, out = drawn
    far, near = out["far"], out["near"]
    both = np.isfinite(far["alone"]["iono"][0, 0]) & np.isfinite(near["alone"]["iono"][0, -1])
    assert both.sum() >= 4
    # the same sky (both stretches start at t = 0): the elevations differ by the turn of the local vertical over
    # 18 km (0.16 deg), the parallax (0.05 deg) and 10 s of satellite motion (< 0.1 deg)
    assert np.max(np.abs(far["el"][0][both] - near["el"][-1][both])) < np.radians(0.3)
    for term, ratio in (("iono", 2.0), ("tropo", 10.0)):
        f = far["alone"][term][:, 0][:, both].std(axis=0)
        n = near["alone"][term][:, -1][:, both].std(axis=0)
        assert np.all(f > ratio * n), term


@pytest.mark.parametrize("term, tau_s", [("ground", 300.0), ("iono", 1800.0), ("tropo", 3600.0),
                                         ("multipath", 100.0), ("noise", gb.SMOOTHING_TAU_S)])
def test_each_term_decorrelates_over_its_time(drawn, term, tau_s):
    """The unit series' correlation between samples 10 s apart is exp(-10 / tau) within 5 standard errors
    ((1 - rho^2) / sqrt(RUNS)): ground 300 s, iono 30 min, tropo 1 h, multipath and smoothed noise 100 s."""
    _, out = drawn
    z = out["near"]["e"].series[term]
    a, b = z[:, 0].ravel(), z[:, 10].ravel()
    rho = np.corrcoef(a, b)[0, 1]
    want = math.exp(-10.0 / tau_s)
    n = z.shape[0] * z.shape[2]
    assert abs(rho - want) < 5.0 * (1.0 - want**2) / math.sqrt(n)
    assert z.std() == pytest.approx(1.0, rel=0.02)
    w = out["near"]["e"].series["white"]  # the carrier-phase noise: white, 2 mm
    assert abs(np.corrcoef(w[:, 0].ravel(), w[:, 1].ravel())[0, 1]) < 5.0 / math.sqrt(n)


def test_total_error_is_the_sum_of_the_terms_with_the_records_sigma(drawn):
    """The terms are independent: the corrected pseudorange error is their sum exactly, and its spread over the runs
    is the record's nominal sigma (the Annex's sigma_i) within 5 standard errors."""
    _, out = drawn
    for d in out.values():
        total = sum(d["alone"][t] for t in TERMS)
        # errors are differences of 2e7 m pseudoranges: floor(4, 2.7e7, 2.7e7) = 4.8e-8 m; 1e-6 m is 20x that
        np.testing.assert_allclose(d["total"], total, rtol=0, atol=1e-6, equal_nan=True)
        i = 0
        for j in np.flatnonzero(np.isfinite(d["total"][0, i])):
            assert d["total"][:, i, j].std() == pytest.approx(d["sigma"][i, j], rel=5.0 / math.sqrt(2 * RUNS))


# --- the compiled path, the stand-alone path, the channel states ---------------------------------------------------

def test_gbas_scales_kernel_equals_numpy():
    """gbas_scales against gbas.station_geometry and GbasModel.scales on random elevations (-10..90 deg) and aircraft
    positions around the runway (heights below and above the reference point), every designator, M = 2..4: to 1e-12
    relative of the elevation functions, plus the floors of the geometry they are scaled by: x_air = |r - station|
    a difference of two 6.4e6 m ECEF positions, dh = h - station_h a difference of heights."""
    p = load_profile(DEFAULT)
    rng = np.random.default_rng(3)
    el = np.radians(rng.uniform(-10.0, 90.0, (2, 30, 24)))
    rwy = np.stack([rng.uniform(-40e3, 3e3, 30), rng.uniform(-2e3, 2e3, 30), rng.uniform(-300.0, 3000.0, 30)], -1)
    r_rx = p.runway.frame.to_ecef(rwy)
    h = np.array([float(p.runway.frame.threshold_h_m) + z for z in rwy[:, 2]])
    v_ned = rng.uniform(-120.0, 120.0, (30, 3))
    for gad in gb.GADS:
        for aad in gb.AADS:
            for m in (2, 3, 4):
                model = gb.GbasModel(gad=gad, aad=aad, reference_receivers=m, sigma_vig_per_m=6e-6,
                                     station_rwy_m=(300.0, -150.0, 5.0))
                st = np.asarray(model.station_ecef(p.runway.frame))
                st_h = float(p.runway.frame.threshold_h_m) + 5.0
                got = gk.gbas_scales(el, r_rx, h, v_ned, st, st_h, model.gad_params(), float(m), model.aad_params(),
                                     model.sigma_vig_per_m, gb.SMOOTHING_TAU_S, model.refractivity_sigma,
                                     model.scale_height_m, 350e3, gb.CARRIER_NOISE_M**2)
                x, dh, v = gb.station_geometry(r_rx, h, v_ned, st, st_h)
                ref = model.scales(el, x[:, None], dh[:, None], v[:, None])
                # the elevation functions (exp of up to 25, a division by M, a sqrt): ~(25 + 10) eps; 1e-12 relative
                # is 130x that. iono scales x_air + 2 tau v, tropo |expm1(-dh / h0)|: the relative floors of their
                # operands (1e-12 of a 500 m x_air, 5e-10 m, was below one ulp of the positions it is formed from)
                rel = {"iono": floor(1, np.linalg.norm(r_rx, axis=-1), np.linalg.norm(st))
                       / (x + 2.0 * gb.SMOOTHING_TAU_S * v),
                       "tropo": floor(1, h, st_h) / np.abs(dh)}
                tol = {k: 1e-12 * np.abs(ref[k]) + np.abs(ref[k]) * rel.get(k, 0.0)[:, None] if k in rel
                       else 1e-12 * np.abs(ref[k]) for k in SCALED}
                tol["sigma"] = sum(np.abs(ref[k]) * tol[k] for k in SCALED) / ref["sigma"] + 1e-12 * ref["sigma"]
                for name, a in zip((*SCALED, "sigma"), got, strict=True):
                    assert_within(a, ref[name], tol[name], f"{gad} {aad} {m} {name}")


@pytest.mark.parametrize("selection", ["best4", "best4-fixed", "all"])
def test_apply_equals_the_numpy_reference(selection):
    """Records of 6 runs on their own skies, 3 runs on one sky and one run: every float field to its floor
    (gnss_floors.py), the pseudorange errors (pseudorange minus range) to the pseudoranges' floor, masks identical.

    The errors are a difference of two 2e7 m values: they are known to the ranges' floor (~5e-7 m, gnss_floors.py),
    not to 1e-12 of their own metre (the tolerance they had, 1e5x below it); the error model's own precision is
    checked where it is formed (test_gbas_scales_kernel_equals_numpy, 1e-12 relative)."""
    p, rx = _receiver(selection=selection)
    rx = replace(rx, doppler=True)
    truth = synthetic.profile_descent(p, rate_hz=10.0)
    runs = list(range(6))
    e = rx.draw(truth.t_s, [stream(5, r, "gnss") for r in runs])
    off = draw_epoch_offsets(SIDEREAL_DAY_S, [stream(5, r, "gnss_epoch") for r in runs])
    clock = draw_receiver_clock(rx.clock, truth.t_s, rx.rate_hz, [stream(5, r, "receiver_clock") for r in runs])
    per_run = replace(e, constants={**e.constants, "epoch_offset_s": off})
    one_sky = replace(e, series={k: v[:3] for k, v in e.series.items()})
    single = rx.draw(truth.t_s, stream(5, 3, "gnss"))
    for errs, clk in ((per_run, clock), (one_sky, None), (single, None)):
        a, b = rx.apply(truth, errs, clk), rx.apply_reference(truth, errs, clk)
        rng_m = np.linalg.norm(b.r_sv_ecef - truth.r_ecef[errs.rows][..., :, None, :], axis=-1)
        clk_b = 0.0 if clk is None else b.clock_bias_m[..., None]
        ea, eb = a.pseudorange_m - rng_m - clk_b, b.pseudorange_m - rng_m - clk_b
        fl = record_floors(rx, truth, errs.rows, b)
        assert_within(ea, eb, fl["pseudorange_m"] + floor(2, b.pseudorange_m, rng_m), "pseudorange error")
        assert_fields_within(a, b, fl)
        assert a.valid.any()


def test_none_is_the_stand_alone_receiver_and_gbas_draws_the_same_normals():
    """corrections = "none" (and the key absent) builds exactly the stand-alone receiver: the same budget, the same
    records bit for bit. GBAS draws its unit series from the same normals in the same columns: scaled by the
    stand-alone sigmas they are the stand-alone series (common random numbers between the two)."""
    base = load_profile(DEFAULT)
    none = _profile(corrections="none")
    rx0, rx1 = (SensorSuite.from_profile(p).sensors["gnss"] for p in (base, none))
    assert rx0.budget == rx1.budget == make_budget("P(Y)", "do253", "current") and rx0.budget.gbas is None
    assert rx0.station_ecef is None and rx1.station_ecef is None
    truth = synthetic.profile_descent(base, rate_hz=10.0)
    e0 = rx0.draw(truth.t_s, [stream(8, r, "gnss") for r in range(3)])
    e1 = rx1.draw(truth.t_s, [stream(8, r, "gnss") for r in range(3)])
    for k in e0.series:  # bit-identical: same code path (the same receiver built twice, the same seeds)
        np.testing.assert_array_equal(e0.series[k], e1.series[k])
    np.testing.assert_array_equal(rx0.apply(truth, e0).pseudorange_m, rx1.apply(truth, e1).pseudorange_m)
    _, rx_g = _receiver()
    eg = rx_g.draw(truth.t_s, [stream(8, r, "gnss") for r in range(3)])
    b = rx0.budget
    for sa, gname, sig in (("iono_zenith", "iono", b.iono_zenith_m), ("tropo_zenith", "tropo", b.tropo_zenith_m),
                           ("multipath", "multipath", 1.0)):
        # sigma GM(z; 1) against GM(z; sigma): the recursion x_k = a x_(k-1) + d_k rounds once a step relative to
        # the series' size and carries the error on with a < 1: over m steps floor(2 m, max |x|) per column (the
        # 1e-15 absolute it had was below one rounding of a value near a zero crossing)
        y = e0.series[sa]
        assert_within(sig * eg.series[gname], y, floor(2 * y.shape[1], np.max(np.abs(y), axis=1, keepdims=True)),
                      gname)
    # the ground series is the clock/ephemeris normals at the ground's correlation time: the first samples agree
    # (x_0 = sigma z_0 against sigma (1 z_0): one rounding each)
    y0 = e0.series["clock_ephemeris"][:, 0]
    assert_within(b.clock_ephemeris_m * eg.series["ground"][:, 0], y0, floor(1, y0), "ground x_0")


def test_realized_channel_states_add_up_to_the_pseudorange_error():
    """sensors/states.py under GBAS: gse + gmp + the receiver clock + the white carrier-phase noise is the pseudorange
    error at the start row."""
    p = _profile(corrections="gbas", selection="all")
    suite = SensorSuite.from_profile(p)
    truth = synthetic.glidepath_descent(p.runway.frame, rate_hz=10.0, start_distance_m=3000.0,
                                        ground_speed_mps=70.0)
    errors = suite.draw(truth.t_s, 4, [0, 1, 2])
    zero = SuiteErrors({k: v.zeroed() for k, v in errors.sensors.items()}, errors.clock.zeroed())
    rec, exact = suite.apply(truth, errors)["gnss"], suite.apply(truth, zero)["gnss"]
    st = start_states(suite, truth, errors, 0)
    ok = rec.valid[:, 0]
    assert ok.sum() >= 18
    err = rec.pseudorange_m[:, 0] - exact.pseudorange_m[:, 0]
    white = errors.sensors["gnss"].series["white"][:, 0]
    assert np.std(white[ok]) < 0.005
    # err is a difference of two 2e7 m pseudoranges (floor(2, 2.7e7) = 1.2e-8 m), the states a sum of terms of a few m:
    # 1e-6 m is 80x the floor
    np.testing.assert_allclose(err[ok], (st.gse + st.gmp + st.clk[:, :1] + white)[ok], atol=1e-6)
    assert np.all(np.abs(st.gse[ok]) < 3.0) and np.all(np.abs(st.gmp[ok]) < 3.0)


# --- the profile -----------------------------------------------------------------------------------------------------

def test_profile_keys_parse_into_the_model():
    p = _profile(corrections="gbas", gbas={"gad": "A", "aad": "A", "reference_receivers": 3,
                                           "sigma_vig_mm_per_km": 6.0, "refractivity_sigma": 10.0,
                                           "scale_height_m": 8000.0, "ground_tau_s": 120.0,
                                           "station_along_ft": 3000.0, "station_cross_ft": -400.0,
                                           "station_height_ft": 10.0})
    g = p.sensors.gnss
    assert g.corrections == "gbas"
    m = g.gbas
    assert (m.gad, m.aad, m.reference_receivers, m.refractivity_sigma, m.scale_height_m, m.ground_tau_s) == (
        "A", "A", 3, 10.0, 8000.0, 120.0)
    assert m.sigma_vig_per_m == pytest.approx(6e-6, rel=1e-12)  # unit conversions, 2-3 roundings: 4500 eps is ample
    assert m.station_rwy_m == pytest.approx((914.4, -121.92, 3.048), rel=1e-12)
    assert g.budget().gbas is g.gbas and g.budget().slow_tau_s == 120.0
    st = np.asarray(SensorSuite.from_profile(p).sensors["gnss"].station_ecef)
    along, cross, up = p.runway.frame.from_ecef(st)
    # on the ellipsoid height above the tangent point: the local vertical there tilts by 1 km / 6371 km (0.4 mm)
    assert (along, cross) == (pytest.approx(914.4, abs=1e-3), pytest.approx(-121.92, abs=1e-3))
    assert up == pytest.approx(3.048, abs=0.2)  # the tangent plane vs the ellipsoid: 0.07 m at 1 km
    assert _profile().sensors.gnss.corrections == "none" and _profile().sensors.gnss.gbas is None
    assert _profile(corrections="gbas").sensors.gnss.gbas == gb.GbasModel()


@pytest.mark.parametrize("gnss, field", [
    ({"corrections": "dgps"}, "sensors.gnss.corrections"),
    ({"corrections": "gbas", "gbas": {"gad": "D"}}, "sensors.gnss.gbas.gad"),
    ({"corrections": "gbas", "gbas": {"aad": "C"}}, "sensors.gnss.gbas.aad"),
    ({"corrections": "gbas", "gbas": {"reference_receivers": 5}}, "sensors.gnss.gbas.reference_receivers"),
    ({"corrections": "gbas", "gbas": {"sigma_vig_mm_per_km": -1.0}}, "sensors.gnss.gbas.sigma_vig_mm_per_km"),
    ({"corrections": "gbas", "gbas": {"ground_tau_s": 0.0}}, "sensors.gnss.gbas.ground_tau_s"),
    ({"corrections": "gbas", "gbas": {"station_x_ft": 0.0}}, "sensors.gnss.gbas.station_x_ft"),
    ({"gbas": {"gad": "C"}}, "sensors.gnss.gbas"),
    ({"corrections": "gbas", "multipath_model": "nrc1995"}, "sensors.gnss.multipath_model"),
])
def test_a_bad_value_names_the_field(gnss, field):
    with pytest.raises(ProfileError) as e:
        _profile(**gnss)
    assert str(e.value).startswith(field + ":"), str(e.value)


def test_the_candidate_profile_is_gbas_all_in_view():
    p = load_profile(PROFILES / "gbas-cat3-candidate.toml")
    g = p.sensors.gnss
    assert (g.corrections, g.selection, g.gbas.gad, g.gbas.aad) == ("gbas", "all", "C", "B")
    assert p.sensors.imu.grade == "nav-0.4" and len(p.sensors.pseudolite.positions_rwy) == 2
