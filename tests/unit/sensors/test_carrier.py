"""GPS carrier phase with float ambiguities (sensors/gnss/carrier.py, receiver carrier_phase = true).

The carrier minus the true range, the receiver clock and the slow errors it shares with the code (and plus the
ionospheric term, which it has with the opposite sign) is the arc's ambiguity plus the carrier's multipath and
noise: the ambiguity constant over each arc, a whole number of L1 wavelengths of the configured spread, the fast
errors of the configured sigma and correlation; arcs begin where a channel becomes valid (rising satellite, end of an
outage); the closed loop's sample-at-a-time path equals the batch; receivers without carrier phase keep their draws
and records bit for bit."""

from __future__ import annotations

import copy
import math
import tomllib
from pathlib import Path

import numpy as np
import pytest
from floors import assert_within
from gnss_floors import record_floors

from approachsim import synthetic
from approachsim.config import ProfileError
from approachsim.profile import load_profile, parse_profile
from approachsim.seeding import stream
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.gnss.carrier import L1_WAVELENGTH_M, CarrierModel, carrier_arcs
from approachsim.sensors.gnss.elevation import iono_obliquity, tropo_mapping
from approachsim.sensors.gnss.receiver import draw_receiver_clock
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""
DEFAULT = PY_DEFAULT


def _profile(**gnss):
    d = tomllib.loads(DEFAULT.read_text(encoding="utf-8"))
    d["sensors"]["gnss"].update(copy.deepcopy(gnss))
    return parse_profile(d, source=DEFAULT)


def _rx(faults=(), **gnss):
    p = _profile(**gnss)
    suite = SensorSuite.from_config(p.sensors, p.runway.frame, p.environment.setting_pa, faults)
    return p, suite.sensors["gnss"]


def _slow_and_iono(rx, truth, e, el):
    """The carrier's slow errors (the code's sign) and the code's ionospheric term, from the drawn series."""
    s = e.series
    if rx.budget.gbas is None:
        return (s["clock_ephemeris"] + tropo_mapping(el) * s["tropo_zenith"], iono_obliquity(el) * s["iono_zenith"])
    geom = tuple(a[:, None] for a in rx.station_geometry(truth, e.rows))
    sc = rx.budget.gbas.scales(el, *geom)
    return sc["ground"] * s["ground"] + sc["tropo"] * s["tropo"], sc["iono"] * s["iono"]


RUNS = 400


@pytest.fixture(scope="module", params=["none", "gbas"])
def drawn(request):
    """RUNS runs of an all-in-view receiver with carrier phase (stand-alone or GBAS) on one sky along the default
    approach at 1 Hz, with a receiver clock."""
    p, rx = _rx(carrier_phase=True, selection="all", epoch="fixed", corrections=request.param)
    truth = synthetic.profile_descent(p, rate_hz=1.0)
    gens = [stream(21, r, "gnss") for r in range(RUNS)]
    e = rx.draw(truth.t_s, gens)
    clock = draw_receiver_clock(rx.clock, truth.t_s, rx.rate_hz, [stream(21, r, "receiver_clock") for r in range(RUNS)])
    rec = rx.apply(truth, e, clock)
    rng_m = np.linalg.norm(rec.r_sv_ecef - truth.r_ecef[e.rows][:, None, :], axis=-1)
    slow, iono = _slow_and_iono(rx, truth, e, rec.elevation_rad)
    # carrier - range - clock - slow + iono = lambda N + c + w
    resid = rec.carrier_phase_m - rng_m - rec.clock_bias_m[..., None] - slow + iono
    return rx, truth, e, rec, resid, rng_m, slow, iono


def test_carrier_is_range_clock_slow_minus_iono_plus_the_arcs_ambiguity(drawn):
    """Subtracting the fast errors leaves the ambiguity: constant over every arc, a whole number of L1 cycles, equal
    to the pool entry of the arc's first sample; the fast errors have the configured sigmas (5-sigma sampling
    tolerance) and the multipath its correlation exp(-dt / tau)."""
    rx, _, e, rec, resid, *_ = drawn
    c = rx.carrier
    amb = resid - e.series["carrier_multipath"] - e.series["carrier_noise"]
    v = rec.valid
    assert v.sum() > 1000 and np.all(np.isnan(rec.carrier_phase_m[~v])) and np.all(rec.carrier_arc[~v] == -1)
    arcs = rec.carrier_arc
    r, j, k = np.nonzero(v)
    start = e.series["ambiguity"][r, arcs[r, j, k], k]
    # the arc's ambiguity, to the range's rounding: amb is carrier - range - ... of 2e7 m values, ~4 roundings each
    # (floor(4, 2.7e7, 2.7e7) = 4.8e-8 m); 1e-6 m is 20x that
    np.testing.assert_allclose(amb[r, j, k], start, rtol=0, atol=1e-6)
    cycles = start / L1_WAVELENGTH_M
    # the pool is whole cycles times lambda: cycles ~ 300 carry ~2 roundings, floor(2, 300) = 1.3e-13; 1e-9 is 7e3x
    np.testing.assert_allclose(cycles, np.round(cycles), atol=1e-9)
    a0 = e.series["ambiguity"][:, 0]  # one draw per run and channel
    assert np.std(a0) == pytest.approx(c.ambiguity_sigma_m, rel=5.0 / math.sqrt(2.0 * a0.size))
    f = resid[r, j, k] - start  # c + w at every valid sample
    assert abs(np.mean(f)) < 5.0 * c.sigma_m / math.sqrt(RUNS)
    assert np.std(f) == pytest.approx(c.sigma_m, rel=0.05)
    mp = e.series["carrier_multipath"]
    assert np.std(mp) == pytest.approx(c.multipath_m, rel=0.05)
    assert np.std(e.series["carrier_noise"]) == pytest.approx(c.noise_m, rel=0.02)
    lag1 = np.mean(mp[:, 1:] * mp[:, :-1]) / np.mean(mp * mp)
    assert lag1 == pytest.approx(math.exp(-1.0 / c.multipath_tau_s), abs=0.02)


def test_code_minus_carrier_is_twice_the_iono_less_the_ambiguity(drawn):
    """The ionospheric term enters the code and the carrier with opposite signs: code - carrier = 2 I + (code's own
    multipath and noise) - ambiguity - (carrier's fast errors), the slow common errors and the clock cancelling."""
    rx, truth, e, rec, resid, rng_m, slow, iono = drawn
    v = rec.valid
    code_err = rec.pseudorange_m - rng_m - rec.clock_bias_m[..., None] - slow - iono  # the code's fast errors
    amb = resid - e.series["carrier_multipath"] - e.series["carrier_noise"]
    cmc = rec.pseudorange_m - rec.carrier_phase_m
    expect = 2.0 * iono + code_err - amb - e.series["carrier_multipath"] - e.series["carrier_noise"]
    # differences of 2e7 m pseudoranges, carriers and ranges, ~8 of them: floor(8, 2.7e7, 2.7e7) = 9.6e-8 m; 1e-6 is 10x
    np.testing.assert_allclose(cmc[v], expect[v], rtol=0, atol=1e-6)
    assert np.std(iono[v]) > 1e-3  # the iono term is not negligible (the check above can fail on its sign)


def test_arc_ids_start_where_a_channel_becomes_valid():
    """carrier_arcs on a written-out validity pattern: a channel valid from the start, one rising, one with an
    outage (a new arc after it), one never valid."""
    v = np.array([[1, 0, 1, 0], [1, 0, 1, 0], [1, 1, 0, 0], [1, 1, 0, 0], [1, 1, 1, 0], [1, 1, 1, 0]], dtype=bool)
    arc = carrier_arcs(v[None])[0]
    expect = np.array([[0, -1, 0, -1], [0, -1, 0, -1], [0, 2, -1, -1], [0, 2, -1, -1], [0, 2, 4, -1],
                       [0, 2, 4, -1]])
    np.testing.assert_array_equal(arc, expect)
    # continued from a previous sample: the same ids as the whole pattern's
    tail = carrier_arcs(v[None, 3:], 3, v[None, 2], arc[None, 2])[0]
    np.testing.assert_array_equal(tail, expect[3:])


def test_an_outage_ends_the_arcs_and_reacquisition_draws_a_new_ambiguity():
    """An all-channel outage of 20 s: every channel valid before and after has a new arc id at the outage's end and
    its ambiguity changes to the pool entry of that sample (the carrier jumps by the difference); rising satellites
    begin arcs on their own. The closed loop's sample-at-a-time path (prepare().at, samples in order) gives the batch
    record bit for bit."""
    fault = FaultSpec("gnss", "outage", start_s=40.0, end_s=60.0)
    p, rx = _rx((fault,), carrier_phase=True, selection="all", epoch="fixed")
    truth = synthetic.profile_descent(p, rate_hz=1.0)
    e = rx.draw(truth.t_s, [stream(3, r, "gnss") for r in range(2)])
    rec = rx.apply(truth, e)
    t = rec.t_s
    before, after = np.flatnonzero(t < 40.0)[-1], np.flatnonzero(t >= 60.0)[0]
    both = rec.valid[:, before] & rec.valid[:, after]
    assert both.sum() >= 10
    assert np.all(rec.carrier_arc[:, after][both] == after)
    assert np.all(rec.carrier_arc[:, before][both] == 0)
    r, k = np.nonzero(both)
    jump = e.series["ambiguity"][r, after, k] - e.series["ambiguity"][r, 0, k]
    assert np.mean(np.abs(jump)) > 1.0  # a new ambiguity of the 10 m spread, not the old one
    clean = SensorSuite.from_config(p.sensors, p.runway.frame, p.environment.setting_pa).sensors["gnss"].apply(truth, e)
    dphi = rec.carrier_phase_m[:, after] - clean.carrier_phase_m[:, after]
    # a difference of two 2e7 m carriers against a difference of two ~10 m pool entries: floor(2, 2.7e7, 2.7e7) =
    # 2.4e-8 m; 1e-6 m is 40x that
    np.testing.assert_allclose(dphi[both], jump, rtol=0, atol=1e-6)
    assert np.all(np.isnan(rec.carrier_phase_m[:, (t >= 40.0) & (t < 60.0)]))
    prepared = rx.prepare(e)  # bit-identical: same code path (the record's kernels on one sample's slice)
    for j in range(len(t)):
        one = prepared.at(truth, j)
        np.testing.assert_array_equal(one.carrier_phase_m[:, 0], rec.carrier_phase_m[:, j])
        np.testing.assert_array_equal(one.carrier_arc[:, 0], rec.carrier_arc[:, j])
        np.testing.assert_array_equal(one.pseudorange_m[:, 0], rec.pseudorange_m[:, j])
    skipping = rx.prepare(e)  # a caller that asks for every third sample only: the skipped ones decide the arcs too
    for j in range(0, len(t), 3):
        one = skipping.at(truth, j)
        np.testing.assert_array_equal(one.carrier_phase_m[:, 0], rec.carrier_phase_m[:, j])
        np.testing.assert_array_equal(one.carrier_arc[:, 0], rec.carrier_arc[:, j])
    with pytest.raises(ValueError, match="increasing order"):
        skipping.at(truth, 3)


@pytest.mark.parametrize("gnss", [{}, {"corrections": "gbas", "selection": "all"}, {"doppler": True}])
def test_without_carrier_phase_draws_and_records_are_unchanged(gnss):
    """carrier_phase = false (and the key absent) builds the receiver without a carrier model; switching carrier
    phase on adds its series after every other draw: every other series and the pseudoranges stay bit for bit."""
    _, off = _rx(**gnss)
    _, off2 = _rx(carrier_phase=False, **gnss)
    p, on = _rx(carrier_phase=True, **gnss)
    assert off.carrier is None and off2.carrier is None and on.carrier == CarrierModel()
    truth = synthetic.profile_descent(p, rate_hz=5.0)
    eo = off.draw(truth.t_s, [stream(8, r, "gnss") for r in range(3)])
    en = on.draw(truth.t_s, [stream(8, r, "gnss") for r in range(3)])
    assert set(en.series) - set(eo.series) == {"carrier_multipath", "carrier_noise", "ambiguity"}
    for k in eo.series:  # bit-identical: same code path (the same draws; the carrier's come from a child stream)
        np.testing.assert_array_equal(eo.series[k], en.series[k], err_msg=k)
    a, b = off.apply(truth, eo), on.apply(truth, en)  # bit-identical: the code path does not touch the carrier
    np.testing.assert_array_equal(a.pseudorange_m, b.pseudorange_m)
    assert a.carrier_phase_m is None and a.carrier_arc is None and a.carrier_sigma_m is None
    assert b.carrier_sigma_m == pytest.approx(math.hypot(0.01, 0.002))


def test_apply_equals_the_numpy_reference_with_carrier():
    """apply (kernels + the carrier's numpy) against apply_reference on per-run skies with GBAS."""
    p, rx = _rx(carrier_phase=True, corrections="gbas", selection="all")
    truth = synthetic.profile_descent(p, rate_hz=5.0)
    e = rx.draw(truth.t_s, [stream(4, r, "gnss") for r in range(3)])
    a, b = rx.apply(truth, e), rx.apply_reference(truth, e)
    np.testing.assert_array_equal(a.carrier_arc, b.carrier_arc)
    # two computations of a 2e7 m carrier: the floor of the range it is built on (orbit phases and ECEF operands,
    # ~5e-7 m, gnss_floors.py) plus the sums onto it
    assert_within(a.carrier_phase_m, b.carrier_phase_m, record_floors(rx, truth, e.rows, b)["carrier_phase_m"],
                  "carrier phase")


def test_profile_keys_and_their_errors():
    p = _profile(carrier_phase=True, carrier_multipath_m=0.02, carrier_multipath_tau_s=2.0, carrier_noise_m=0.003,
                 carrier_ambiguity_sigma_m=50.0)
    assert p.sensors.gnss.carrier == CarrierModel(0.02, 2.0, 0.003, 50.0)
    assert load_profile(DEFAULT).sensors.gnss.carrier is None
    with pytest.raises(ProfileError, match="carrier_noise_m"):
        _profile(carrier_noise_m=0.003)
    with pytest.raises(ProfileError, match="carrier_multipath_m"):
        _profile(carrier_phase=True, carrier_multipath_m=0.06)  # above lambda / 4
