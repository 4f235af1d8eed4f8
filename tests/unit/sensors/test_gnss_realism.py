"""Per-run GPS epochs, DO-253 airframe multipath and the selectable clock/ephemeris budget (issue 10, Deliver 4)."""

from __future__ import annotations

import math
import tomllib
from dataclasses import replace

import numpy as np
import pytest
from scipy import stats as sps

from approachsim.config import ProfileError, Section
from approachsim.nav.system import NavSystem
from approachsim.seeding import stream
from approachsim.sensors.config import SensorsConfig, parse_sensors
from approachsim.sensors.gnss.elevation import do253_multipath_sigma_m
from approachsim.sensors.gnss.receiver import (
    CLOCK_EPHEMERIS_M,
    SIDEREAL_DAY_S,
    GnssReceiver,
    draw_epoch_offsets,
    make_budget,
)
from approachsim.sensors.suite import EPOCH_STREAM, SensorSuite


def _sensors(text: str) -> SensorsConfig:
    return parse_sensors(Section(tomllib.loads(text), "sensors"))


def _suite(runway, gnss: str = "") -> SensorSuite:
    cfg = _sensors("[gnss]\n" + gnss)
    return SensorSuite.from_config(replace(cfg, baro=None, radalt=None), runway, 101325.0)


def test_per_run_epoch_offsets_are_uniform_over_the_sidereal_day():
    """2000 runs' offsets from their own "gnss_epoch" streams: KS against U[0, 23.934 h) (seeded: p is fixed;
    a draw clustered in one half of the window gives p ~ 0), and each run's offset is its stream's first draw."""
    runs = range(2000)
    off = draw_epoch_offsets(SIDEREAL_DAY_S, [stream(11, r, EPOCH_STREAM) for r in runs])
    assert off.shape == (2000,) and np.all((off >= 0.0) & (off < SIDEREAL_DAY_S))
    assert sps.kstest(off / SIDEREAL_DAY_S, "uniform").pvalue > 0.01
    assert off[7] == stream(11, 7, EPOCH_STREAM).uniform(0.0, SIDEREAL_DAY_S)  # bit-identical: the same seeded draw


def test_per_run_sky_is_bit_identical_whatever_the_batch(descent, runway):
    """Run 3 measured alone and in a batch of 5 sees the same sky and the same pseudoranges, bit for bit; its sky
    differs from run 0's; the other sensors and the GNSS error draws do not change with the epoch setting."""
    suite = _suite(runway)
    assert suite.epoch_window_s == pytest.approx(SIDEREAL_DAY_S)
    batch = suite.measure(descent, seed=5, runs=[0, 1, 2, 3, 4])["gnss"]
    alone = suite.measure(descent, seed=5, runs=[3])["gnss"]
    assert batch.per_run_sky and alone.per_run_sky
    a, b = alone.run(0), batch.run(3)
    for f in ("r_sv_ecef", "elevation_rad", "pseudorange_m", "valid", "pdop", "sigma_m"):  # bit-identical: same path
        np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)
    assert not np.array_equal(batch.run(0).visible, b.visible)  # a different sky (14 h apart for this seed)
    fixed = _suite(runway, 'epoch = "fixed"')
    assert fixed.epoch_window_s == 0.0
    e_fixed = fixed.draw(descent.t_s, 5, [3]).sensors["gnss"]
    e_run = suite.draw(descent.t_s, 5, [3]).sensors["gnss"]
    for k, v in e_fixed.series.items():  # bit-identical: the same draws
        np.testing.assert_array_equal(v, e_run.series[k], err_msg=k)
    assert "epoch_offset_s" not in e_fixed.constants
    off = e_run.constants["epoch_offset_s"]
    assert off[0] == stream(5, 3, EPOCH_STREAM).uniform(0.0, SIDEREAL_DAY_S)  # bit-identical: the same seeded draw
    # noise=False keeps the run's sky (the epoch is not an error)
    exact = suite.measure(descent, seed=5, runs=[3], noise=False)["gnss"]
    np.testing.assert_array_equal(exact.elevation_rad, alone.elevation_rad)  # bit-identical: same code path


def test_do253_multipath_sigma_measured_against_elevation(descent):
    """Every error zero but a white (tau 1 ms) do253 multipath: the residual pseudorange - range, binned by
    elevation, has the standard deviation 0.13 + 0.53 exp(-el / 10 deg) m within 5 standard errors
    (sigma / sqrt(2 N)); nrc1995 gives 1.8 m at every elevation."""
    zero = dict(clock_ephemeris_m=0.0, iono_zenith_m=0.0, tropo_zenith_m=0.0, code_noise_m=0.0)
    for model in ("do253", "nrc1995"):
        bud = replace(make_budget("P(Y)", model, multipath_tau_s=1e-3), **zero)
        rx = GnssReceiver(budget=bud, selection="all")
        rngs = [np.random.default_rng(i) for i in range(20)]
        rec = rx.measure(descent, rngs)
        exact = rx.measure(descent, np.random.default_rng(0), noise=False)
        res = rec.pseudorange_m - exact.pseudorange_m[None]
        el = np.broadcast_to(np.degrees(exact.elevation_rad)[None], res.shape)
        ok = np.isfinite(res)
        checked = 0
        for lo, hi in ((5, 10), (10, 20), (20, 40), (40, 90)):
            m = ok & (el >= lo) & (el < hi)
            if m.sum() < 500:
                continue
            expect = np.sqrt(np.mean(do253_multipath_sigma_m(np.radians(el[m])) ** 2)) if model == "do253" else 1.8
            got = np.sqrt(np.mean(res[m] ** 2))
            assert abs(got - expect) < 5.0 * expect / math.sqrt(2.0 * m.sum()), (model, lo, hi, got, expect)
            checked += 1
        assert checked >= 3
    assert do253_multipath_sigma_m(np.radians(90.0)) == pytest.approx(0.13 + 0.53 * math.exp(-9.0))
    assert do253_multipath_sigma_m(np.radians(5.0)) == pytest.approx(0.451, abs=5e-4)  # reference table


def test_budget_selection_and_the_filter_uses_the_same_sigmas(runway):
    """Defaults: do253 (100 s), current clock/ephemeris 2.4 m; nrc1995 restores 3.6 m / 1.8 m / 60 s; the
    filter's gmp states take sigma_mp at each channel's elevation and its gse the chosen clock/ephemeris."""
    d = _sensors("[gnss]\n").gnss
    assert (d.epoch, d.multipath_model, d.clock_ephemeris) == ("per-run", "do253", "current")
    b = d.budget()
    assert (b.clock_ephemeris_m, b.multipath_tau_s, b.multipath_model) == (2.4, 100.0, "do253")
    assert CLOCK_EPHEMERIS_M["nrc1995"] == 3.6
    old = _sensors('[gnss]\nepoch = "fixed"\nmultipath_model = "nrc1995"\nclock_ephemeris = "nrc1995"\n').gnss
    ob = old.budget()
    assert (ob.clock_ephemeris_m, ob.multipath_m, ob.multipath_tau_s) == (3.6, 1.8, 60.0)
    assert old.epoch_window() == 0.0
    el = np.radians(np.linspace(5.0, 85.0, 24))
    for cfg, gmp, ce in ((d, do253_multipath_sigma_m(el), 2.4), (old, np.full(24, 1.8), 3.6)):
        nz = NavSystem.build(sensors=SensorsConfig(gnss=cfg), runway=runway).noise(el)
        # the DO-253 curve 0.13 + 0.53 exp(-el / 10 deg), ~6 roundings (exp of <= 8.5): rtol 1e-12 is 300x that
        np.testing.assert_allclose(np.broadcast_to(nz.gmp_sigma_m, (24,)), gmp, rtol=1e-12)
        assert nz.gmp_tau_s == cfg.budget().multipath_tau_s
        assert np.all(np.asarray(nz.gse_sigma_m) > ce) and np.min(nz.gse_sigma_m) < ce + 0.5
    assert _sensors("[gnss]\nmultipath_tau_s = 5.0\nepoch_window_h = 2.0\n").gnss.budget().multipath_tau_s == 5.0


@pytest.mark.parametrize(("text", "needle"), [
    ('epoch = "daily"', "sensors.gnss.epoch"),
    ('multipath_model = "do229"', "sensors.gnss.multipath_model"),
    ('clock_ephemeris = "2020"', "sensors.gnss.clock_ephemeris"),
    ("multipath_tau_s = 0.0", "sensors.gnss.multipath_tau_s"),
    ("epoch_window_h = -1.0", "sensors.gnss.epoch_window_h"),
    ('epoch = "fixed"\nepoch_window_h = 2.0', "sensors.gnss.epoch_window_h"),
])
def test_bad_gnss_keys_name_the_field(text, needle):
    with pytest.raises(ProfileError, match=needle.replace(".", r"\.")):
        _sensors("[gnss]\n" + text + "\n")
