"""The integrity bank's compiled reduced-state pass with GPS carrier phase (campaign/bankpass.py,
core/nav/copies.bank_epochs) against the path it replaces, NavSystem.run's batched copies on the full
state (run_bank(..., compiled=False): Navigator.compiled_pass, core/nav/epoch.shared_pass with the carrier states):
bit for bit, on the shipped carrier candidate (GBAS, all in view, two pseudolites) and with a channel's carrier
interrupted by an outage (a new arc: its float ambiguity reset in the copies that measure it, not in the copy that
leaves it out), and with the sensor fault modes. Why exact: the reduction drops the lone states (gse, gmp, gio, amb)
of channels never measured, whose rows and columns of P are exact zeros, and keeps every other sum's order (bankpass
module docstring); the ambiguity resets zero a kept row and column as on the full layout."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from approachsim import synthetic
from approachsim.campaign import bankpass
from approachsim.campaign.integrity_bank import run_bank
from approachsim.nav import reduced
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.gnss.constellation import Constellation
from approachsim.sensors.states import start_states
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
CARRIER = load_profile(PROFILES / "gbas-carrier-cat3-candidate.toml")
SEED = 4
FIELDS = ("t_s", "e0", "p0", "ek", "pk", "channels", "along_m", "height_m")


def _truth(prof):
    return synthetic.glidepath_descent(prof.runway.frame, rate_hz=20.0, start_distance_m=70.0 * 30.0,
                                       ground_speed_mps=70.0)


def _with_outage(prof, truth):
    """The profile with run 0's first measured channel's carrier (and code) out for 1.5 s mid-approach: a new arc
    when it returns. Returns (profile, channel index)."""
    suite = SensorSuite.from_profile(prof)
    rec = suite.apply(truth, suite.draw(truth.t_s, SEED, [0]))["gnss"]
    t_mid = 0.5 * (float(truth.t_s[0]) + float(truth.t_s[-1]))
    c = int(np.flatnonzero(np.all(np.asarray(rec.valid)[0], axis=0))[0])
    prn = int(Constellation.nominal(prof.sensors.gnss.epoch_utc).prn[c])
    f = FaultSpec(sensor="gnss", kind="outage", start_s=t_mid, end_s=t_mid + 1.5, channel=prn)
    return replace(prof, faults=(f,)), c


def _assert_banks_equal(new, old):
    for f in FIELDS:
        np.testing.assert_array_equal(getattr(new, f), getattr(old, f), err_msg=f)
    np.testing.assert_array_equal(new.identification(), old.identification(), err_msg="identification")


@pytest.mark.equality
@pytest.mark.parametrize("kind", ["candidate", "outage", "modes"])
def test_carrier_reduced_pass_equals_the_copies_pass(kind, monkeypatch):
    prof = CARRIER
    truth = _truth(prof)
    arc_channel = None
    if kind == "outage":
        prof, arc_channel = _with_outage(prof, truth)
    modes = kind == "modes"  # the baro, radar altimeter and pseudolites as fault modes too (no damping loop: the
    if modes:  # copies without the baro share the INS, so every mode is compiled)
        prof = replace(prof, nav=replace(prof.nav, baro_loop="none"))
    called, resets = [], []
    orig_pass, orig_arcs = bankpass.bank_pass, bankpass.stacked_new_arcs

    def spy(*a, **k):
        called.append(orig_pass(*a, **k))
        return called[-1]

    def spy_arcs(last, arc):
        out = orig_arcs(last, arc)
        resets.append(out[0])
        return out

    monkeypatch.setattr(bankpass, "bank_pass", spy)
    monkeypatch.setattr(bankpass, "stacked_new_arcs", spy_arcs)
    for run in (0, 1):
        new, main_new = run_bank(prof, truth, SEED, run, sensor_modes_on=modes)
        old, main_old = run_bank(prof, truth, SEED, run, sensor_modes_on=modes, compiled=False)
        assert len(called) == run + 1 and called[-1] is not None  # the compiled pass ran (no fallback)
        bp = called[-1]
        assert bp.layout.has("amb") and bp.layout.n_sv == bp.channels_kept.size  # carrier states, reduced
        assert new.ek.shape[1] >= 6 + (4 if modes else 0)  # + baro, radar altimeter, two pseudolites
        _assert_banks_equal(new, old)
        # the main filter's innovations and their variances: the same rows in the same order
        np.testing.assert_array_equal(main_new.status.variance, main_old.status.variance)
        new_arcs = resets[-1]  # (copies, epochs, kept channels): the first epoch opens every arc
        assert np.all(new_arcs[0, 0] == 1)
        if arc_channel is not None and run == 0:
            j = int(np.flatnonzero(bp.channels_kept == arc_channel)[0])
            k = int(np.flatnonzero(new.channels == arc_channel)[0])
            assert np.sum(new_arcs[0, 1:, j]) == 1  # the return from the outage: one reset after the first epoch
            assert np.sum(new_arcs[k + 1, :, j]) == 0  # the copy without the channel never opens its arc
            assert np.sum(new_arcs[0, 1:]) == 1  # and no other channel's


def test_carrier_group_pass_equals_the_runs_own():
    """The carrier bank from an open-loop flight group's pass (bankpass.bank_pass_group: the pipeline's path) against
    the run's own records, start and INS (bankpass.bank_pass): bit for bit, each run of a group of two."""
    prof = CARRIER
    truth = _truth(prof)
    nav = NavSystem.from_profile(prof)
    suite = SensorSuite.from_profile(prof)
    runs = [0, 1]
    errors = suite.draw(truth.t_s, SEED, runs)
    records = suite.apply(truth, errors)
    keep: dict = {}
    navs = nav.run(truth, records, [stream(SEED, i, "nav") for i in runs], shared_covariance=True,
                   states=start_states(suite, truth, errors), keep=keep)
    assert navs[0].layout.has("amb")
    g = bankpass.GroupInputs(records, keep)
    assert g.usable(nav) and bankpass.applicable(nav, g.records)
    for k, i in enumerate(runs):
        grp, _ = run_bank(prof, truth, SEED, i, group=(g, k))
        own, _ = run_bank(prof, truth, SEED, i)
        _assert_banks_equal(grp, own)


def test_carrier_start_has_no_arcs(monkeypatch):
    """bank_pass_group starts every copy's arcs empty (the group's pass keeps no arc ids): the converged start is
    code only (nav/initial.py), so the run's own start has none either."""
    prof = CARRIER
    truth = _truth(prof)
    seen = []
    orig = bankpass._core

    def spy(*a, **k):
        seen.append(a[12] if len(a) > 12 else k.get("arcs0"))
        return orig(*a, **k)

    monkeypatch.setattr(bankpass, "_core", spy)
    run_bank(prof, truth, SEED, 0)
    assert len(seen) == 1 and seen[0] is None


def test_carrier_channel_states_are_dropped_with_their_channel():
    """_kept_channels / _reduced with the carrier groups: a channel's gio and amb go with its gse and gmp, and a
    channel whose ambiguity is correlated with another state at the start is kept."""
    from approachsim.nav import errormodel as em

    lay = em.StateLayout(n_sv=6, clock=True, carrier=True)
    P0 = np.diag(np.arange(1.0, lay.n + 1.0))
    used = np.array([4, 1])
    np.testing.assert_array_equal(reduced.kept_channels(lay, used, P0), [1, 4])
    P0[lay.i("amb", 2), lay.i("dp", 0)] = P0[lay.i("dp", 0), lay.i("amb", 2)] = 1e-3
    np.testing.assert_array_equal(reduced.kept_channels(lay, used, P0), [1, 2, 4])
    red, idx = reduced.reduced_layout(lay, np.array([1, 2, 4]))
    assert red.n == lay.n - 12 and red.n_sv == 3 and red.has("gio") and red.has("amb")
    for g in ("gse", "gmp", "gio", "amb"):
        np.testing.assert_array_equal(idx[red.index[g]], lay.i(g) + np.array([1, 2, 4]))
    assert np.all(np.diff(idx) > 0)
