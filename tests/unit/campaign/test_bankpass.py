"""The integrity bank's compiled reduced-state pass (campaign/bankpass.py, core/nav/copies.py) against the
path it replaces, NavSystem.run's batched copies on the full state (run_bank(..., compiled=False), core/nav/epoch.
shared_pass): the same main and sub-solution errors, variances and identification statistics, to the rounding
floors of tests/floors.py (measured equal to the last bit on this machine: the reduction drops exact zeros, module
docstring of bankpass), with per-run skies, pseudolites with their states, a baro outage that holds the damping
loop, GBAS corrections and the sensor fault modes; and the bank from an open-loop flight group's pass (what the
pipeline runs) equal bit for bit to the run's own, whatever the group (a run's numbers do not depend on its batch)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from floors import R_EARTH_M, R_GPS_MAX_M, assert_within, floor

from approachsim import synthetic
from approachsim.campaign import bankpass
from approachsim.campaign.integrity_bank import run_bank
from approachsim.nav import errormodel as em
from approachsim.nav import reduced
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.seeding import stream
from approachsim.sensors.config import PseudoliteConfig
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.gnss.gbas import GbasModel
from approachsim.sensors.states import start_states
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""
DEFAULT = load_profile(PY_DEFAULT)
SEED = 4


def _profile(kind: str):
    p = DEFAULT
    if kind == "pseudolite":
        pl = PseudoliteConfig(positions_rwy=((0.0, -150.0, 9.0), (-3000.0, 200.0, 30.0)), synchronized=False)
        p = replace(p, sensors=replace(p.sensors, pseudolite=pl))
    if kind == "baro-outage":  # the damping loop held over the outage: the held model at those epochs
        p = replace(p, faults=(FaultSpec(sensor="baro", kind="outage", start_s=10.0, end_s=16.0),))
    if kind == "gbas":
        p = replace(p, sensors=replace(p.sensors, gnss=replace(p.sensors.gnss, corrections="gbas", gbas=GbasModel(),
                                                               selection="all")))
    if kind == "sbas":  # SBAS L1, the nominal filter model: the zenith states (giz, gtz) kept whole in the reduction
        p = replace(p, sensors=replace(p.sensors, gnss=load_profile(PROFILES / "sbas-lpv200.toml").sensors.gnss))
    if kind == "modes":  # no damping loop: the copies without the baro share the INS, so every mode is compiled
        pl = PseudoliteConfig(positions_rwy=((0.0, -150.0, 9.0),), synchronized=True)
        p = replace(p, nav=replace(p.nav, baro_loop="none"), sensors=replace(p.sensors, pseudolite=pl))
    return p


def _truth(prof):
    return synthetic.glidepath_descent(prof.runway.frame, rate_hz=20.0, start_distance_m=70.0 * 30.0,
                                       ground_speed_mps=70.0)


@pytest.mark.equality
@pytest.mark.parametrize("kind", ["default", "pseudolite", "baro-outage", "gbas", "modes", "sbas"])
def test_reduced_pass_equals_the_copies_pass(kind, monkeypatch):
    prof = _profile(kind)
    truth = _truth(prof)
    modes = kind == "modes"
    called = []
    orig = bankpass.bank_pass

    def spy(*a, **k):
        called.append(orig(*a, **k))
        return called[-1]

    monkeypatch.setattr(bankpass, "bank_pass", spy)
    for run in (0, 1):
        new, _ = run_bank(prof, truth, SEED, run, sensor_modes_on=modes)
        old, main = run_bank(prof, truth, SEED, run, sensor_modes_on=modes, compiled=False)
        assert len(called) == run + 1 and called[-1] is not None  # the compiled pass ran (no fallback)
        assert np.array_equal(new.channels, old.channels) and new.ek.shape == old.ek.shape
        assert new.ek.shape[1] >= 4 + (2 if modes else 0)
        np.testing.assert_array_equal(new.t_s, old.t_s)
        # floors as tests/unit/nav/test_epoch_engine.py's: an innovation is known to K eps of its ECEF and range
        # operands; a state moves by K nu per update, |K_i| <= sqrt(P_ii / S); the copies' variances are the
        # Riccati recursion's, K n eps of the largest; the output error adds an ECEF difference
        nu = floor(8, R_EARTH_M, R_GPS_MAX_M, R_GPS_MAX_M)
        p_max = max(float(np.max(old.pk)), float(np.max(old.p0)))
        s_min = float(np.min(main.status.variance))
        e_floor = nu * np.sqrt(p_max / s_min) + floor(8, R_EARTH_M)
        cond = R_EARTH_M / 150.0 if prof.sensors.pseudolite is not None else 1.0  # a pseudolite 150 m off
        p_floor = floor(8 * main.layout.n * cond, p_max)
        assert_within(new.e0, old.e0, e_floor, "main error")
        assert_within(new.ek, old.ek, e_floor, "sub-solution errors")
        assert_within(new.p0, old.p0, p_floor, "main variances")
        assert_within(new.pk, old.pk, p_floor, "sub-solution variances")
        # the identification statistic d' (P_k - P_0)^+ d on the correlation scale: relative to its own size, the
        # separations' floor over their sigma (a pseudo-inverse's cut-off may drop a direction either way only at
        # its 1e-10 rcond, far above these floors)
        w_new, w_old = new.identification(), old.identification()
        sd = np.sqrt(np.maximum(np.max(old.pk - old.p0[:, None, :], axis=2), 1e-300))
        rel = 2.0 * e_floor / sd
        assert_within(w_new, w_old, 4.0 * rel * (np.abs(w_old) + 1.0) + floor(100, w_old), "identification")


def test_group_pass_equals_the_runs_own():
    """The bank from the flight group's pass (NavSystem.run(keep=...), bankpass.bank_pass_group: the pipeline's
    path) against the run's own records, start and INS (bankpass.bank_pass): the same code on the same numbers, so
    bit-identical, for each run of a group of three and of a group of one."""
    prof = _profile("default")
    truth = _truth(prof)
    nav = NavSystem.from_profile(prof)
    suite = SensorSuite.from_profile(prof)

    def group_banks(runs):
        errors = suite.draw(truth.t_s, SEED, runs)
        records = suite.apply(truth, errors)
        keep: dict = {}
        nav.run(truth, records, [stream(SEED, i, "nav") for i in runs], shared_covariance=True,
                states=start_states(suite, truth, errors), keep=keep)
        g = bankpass.GroupInputs(records, keep)
        assert g.usable(nav)
        assert all(bankpass.bank_pass_group(nav, truth, g, k, np.zeros(0, int)) is not None for k in range(len(runs)))
        return [run_bank(prof, truth, SEED, i, group=(g, k))[0] for k, i in enumerate(runs)]

    three = group_banks([0, 1, 2])
    one = group_banks([1])
    own = [run_bank(prof, truth, SEED, i)[0] for i in (0, 1, 2)]
    for a, b in [(three[0], own[0]), (three[1], own[1]), (three[2], own[2]), (one[0], own[1])]:
        for f in ("t_s", "e0", "p0", "ek", "pk", "channels", "along_m", "height_m"):
            np.testing.assert_array_equal(getattr(a, f), getattr(b, f), err_msg=f)
        np.testing.assert_array_equal(a.identification(), b.identification())


def test_only_decoupled_channel_states_are_dropped():
    """The reduction keeps the measured channels and any channel whose states are correlated with another state at
    the start (a dropped state must be exactly uncorrelated: bankpass module docstring), in channel order."""
    lay = em.StateLayout(n_sv=6, clock=True)
    P0 = np.diag(np.arange(1.0, lay.n + 1.0))
    used = np.array([4, 1])
    np.testing.assert_array_equal(reduced.kept_channels(lay, used, P0), [1, 4])
    P0[lay.i("gmp", 3), lay.i("dp", 0)] = P0[lay.i("dp", 0), lay.i("gmp", 3)] = 1e-3
    np.testing.assert_array_equal(reduced.kept_channels(lay, used, P0), [1, 3, 4])
    red, idx = reduced.reduced_layout(lay, np.array([1, 3, 4]))
    assert red.n == lay.n - 6 and red.n_sv == 3
    np.testing.assert_array_equal(idx[red.index["gse"]], lay.i("gse") + np.array([1, 3, 4]))
    np.testing.assert_array_equal(idx[red.index["gmp"]], lay.i("gmp") + np.array([1, 3, 4]))
    assert np.all(np.diff(idx) > 0)  # the kept states keep their order (the sums' order: same bits)
