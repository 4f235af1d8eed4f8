"""Pseudolite: exact geometric range with noise=False, shared receiver clock, visibility, survey error."""

from __future__ import annotations

import numpy as np
import pytest

from approachsim.sensors.gnss import GnssReceiver
from approachsim.sensors.pseudolite import Pseudolite


def test_noise_false_is_geometric_range_to_the_published_position(descent, runway):
    pl = Pseudolite(runway, positions_rwy=((300.0, -150.0, 9.0), (-3000.0, 100.0, 3.0)), synchronized=False)
    rec = pl.measure(descent, np.random.default_rng(0), noise=False)
    rows = np.arange(0, len(descent), 20)
    rng = np.linalg.norm(rec.r_pl_ecef[None] - descent.r_ecef[rows][:, None], axis=-1)
    assert rec.valid.all()
    # ranges from 6.4e6 m ECEF positions: floor(3, 6.4e6, 6.4e6) = 8.5e-9 m; 1e-3 m is 1e5x (a model check)
    assert np.max(np.abs(rec.pseudorange_m - rng)) < 1e-3
    # published position: runway frame x, y and height above threshold
    back = runway.from_ecef(rec.r_pl_ecef)
    # (the local vertical tilts by d / R from the threshold one: a sub-millimetre shift of x, y at 3 km)
    assert back[:, :2] == pytest.approx(np.array([[300.0, -150.0], [-3000.0, 100.0]]), abs=2e-3)


def test_receiver_clock_is_shared_with_gnss(descent, runway):
    rx = GnssReceiver()
    clk = rx.draw_clock(descent.t_s, np.random.default_rng(8))
    pl = Pseudolite(runway, survey_sigma_m=0.0, tropo_ppm_sigma=0.0, multipath_m=0.0, code_noise_m=0.0,
                    sync_sigma_m=0.0)
    rec = pl.apply(descent, pl.draw(descent.t_s, np.random.default_rng(1)), clock=clk)
    g = rx.apply(descent, rx.draw(descent.t_s, np.random.default_rng(2)), clock=clk)
    assert np.array_equal(rec.clock_bias_m, g.clock_bias_m)  # bit-identical: the same clock array passed through
    rows = np.arange(0, len(descent), 20)
    rng = np.linalg.norm(rec.r_pl_ecef[None] - descent.r_ecef[rows][:, None], axis=-1)
    assert np.max(np.abs(rec.pseudorange_m - rec.clock_bias_m[:, None] - rng)) < 1e-3  # as above, 1e5x the floor


def test_visibility_range_and_mask(descent, runway):
    pl = Pseudolite(runway, positions_rwy=((0.0, 0.0, 0.0),), max_range_m=10e3)
    rec = pl.measure(descent, np.random.default_rng(0))
    rng = np.linalg.norm(rec.r_pl_ecef[None] - descent.r_ecef[::20][:, None], axis=-1)[:, 0]
    assert np.array_equal(rec.valid[:, 0], rng <= 10e3)
    high = Pseudolite(runway, positions_rwy=((0.0, 0.0, 2000.0),))  # transmitter above the aircraft: masked
    assert not high.measure(descent, np.random.default_rng(0)).valid.any()


def test_survey_error_is_a_constant_per_run(descent, runway):
    pl = Pseudolite(runway, survey_sigma_m=1.0, code_noise_m=0.0, multipath_m=0.0, tropo_ppm_sigma=0.0)
    e = pl.draw(descent.t_s, [np.random.default_rng(i) for i in range(3000)])
    assert e.constants["survey"].shape == (3000, 1, 3)
    assert e.constants["survey"].std() == pytest.approx(1.0, rel=0.05)


def test_synchronized_time_sync_error_is_gauss_markov(descent, runway):
    """A synchronized transmitter's time-sync error (issue 39): c x 3 ns = 0.899 m 1-sigma, tau 600 s, per
    transmitter, no drift. 2000 runs: the sample sigma within 5 % (its standard error is 1.6 %: 3 sigma), the
    1 s lag correlation exp(-1 / 600) = 0.9983 within 0.002 (its standard error over 2000 x 2 pairs ~ 4e-5 x
    the 0.03 scatter), the two transmitters independent (|r| < 0.08: 3.5 / sqrt(2000))."""
    sig = 3e-9 * 299792458.0
    pl = Pseudolite(runway, positions_rwy=((300.0, -150.0, 9.0), (-3000.0, 100.0, 3.0)), sync_sigma_m=sig,
                    sync_tau_s=600.0)
    e = pl.draw(descent.t_s, [np.random.default_rng(i) for i in range(2000)])
    clk = e.series["pl_clock"]  # (runs, m, p)
    assert clk.shape[-1] == 2
    assert np.all(e.series["pl_clock_drift"] == 0.0)
    assert clk[:, 0, :].std() == pytest.approx(sig, rel=0.05)
    assert clk[:, -1, :].std() == pytest.approx(sig, rel=0.05)  # stationary
    dt = float(e.t_s[1] - e.t_s[0])
    a = np.mean(clk[:, 1:, :] * clk[:, :-1, :]) / np.mean(clk[:, :-1, :] ** 2)
    assert a == pytest.approx(np.exp(-dt / 600.0), abs=2e-3)
    assert abs(np.corrcoef(clk[:, 0, 0], clk[:, 0, 1])[0, 1]) < 0.08


def test_time_sync_error_leaves_the_other_errors_unchanged(descent, runway):
    """The sync error draws on the columns the unsynchronized clock would use: multipath, noise, survey and
    troposphere are the same numbers with and without it (common random numbers), and sigma 0 is exactly zero."""
    on = Pseudolite(runway).draw(descent.t_s, np.random.default_rng(7))
    off = Pseudolite(runway, sync_sigma_m=0.0).draw(descent.t_s, np.random.default_rng(7))
    for k in ("multipath", "noise"):
        np.testing.assert_array_equal(on.series[k], off.series[k])
    for k in ("survey", "tropo_ppm"):
        np.testing.assert_array_equal(on.constants[k], off.constants[k])
    assert np.all(off.series["pl_clock"] == 0.0) and np.any(on.series["pl_clock"] != 0.0)
