"""SensorSuite.prepare: one truth row at a time (the closed loop's path) gives exactly, bit for bit, the records the
generic `apply` gives for that one sample, for every sensor (IMU, baro, radar altimeter, GNSS with per-run skies or
best4-fixed with Doppler, an unsynchronized two-unit pseudolite), with faults of every kind, for one run drawn alone
and for a batch, with errors drawn for a longer flight than the truth."""

from __future__ import annotations

from dataclasses import fields, replace
from pathlib import Path

import numpy as np
import pytest

from approachsim import synthetic
from approachsim.profile import load_profile
from approachsim.sensors.config import PseudoliteConfig
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.suite import SensorSuite

PROFILE = load_profile(Path(__file__).resolve().parents[3] / "tests" / "data" / "default-py.toml")

FAULTS = (
    FaultSpec("gnss", "outage", start_s=40.0, end_s=60.0),
    FaultSpec("gnss", "spike", start_s=10.0, end_s=200.0, channel=5, k=50.0, every=3),
    FaultSpec("gnss", "ramp", start_s=100.0, end_s=150.0, rate=0.5),
    FaultSpec("baro", "mni", start_s=20.0, end_s=80.0, factor=4.0),
    FaultSpec("baro", "ramp", start_s=50.0, end_s=120.0, rate=0.1),
    FaultSpec("radalt", "iam", steps=(5, 17, 40, 200, 230), magnitude=3.0),
    FaultSpec("radalt", "outage", start_s=210.0, end_s=215.0),
    FaultSpec("pseudolite", "step", start_s=30.0, channel=1, magnitude=2.0),
    FaultSpec("imu", "cbm", start_s=60.0, end_s=70.0, channel=2, magnitude=1e-4),
)


def _suite(gnss: dict, faults: tuple[FaultSpec, ...]) -> SensorSuite:
    cfg = replace(PROFILE.sensors, gnss=replace(PROFILE.sensors.gnss, **gnss),
                  pseudolite=PseudoliteConfig(positions_rwy=((300.0, -150.0, 9.0), (-2000.0, 200.0, 5.0)),
                                              synchronized=False))
    return SensorSuite.from_config(cfg, PROFILE.runway.frame, PROFILE.environment.setting_pa, faults)


@pytest.fixture(scope="module")
def truth():
    return synthetic.profile_descent(PROFILE, rate_hz=20.0)


def _identical(a, b, what):
    """Bit-identical: same code path (prepare().at runs the record's kernels on one sample's values)."""
    assert type(a) is type(b), what
    for f in fields(b):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(y, np.ndarray):
            assert isinstance(x, np.ndarray) and x.shape == y.shape and x.dtype == y.dtype, (what, f.name)
            assert np.array_equal(x, y, equal_nan=y.dtype.kind == "f"), (what, f.name)
        else:
            assert (x is None and y is None) or x == y, (what, f.name)


@pytest.mark.parametrize("gnss", [{}, {"selection": "best4-fixed", "doppler": True, "epoch": "fixed"}],
                         ids=["per-run-sky", "best4-fixed-doppler"])
@pytest.mark.parametrize("runs", [2, [0, 5]], ids=["one-run", "batch"])
@pytest.mark.parametrize("faulted", [False, True], ids=["clean", "faults"])
def test_prepared_rows_equal_the_generic_path_bit_for_bit(truth, gnss, runs, faulted):
    suite = _suite(gnss, FAULTS if faulted else ())
    longer = np.arange(len(truth) + 400) * (truth.t_s[1] - truth.t_s[0])
    errors = suite.draw(longer, seed=9, runs=runs)
    prepared = suite.prepare(errors)
    names = ("imu", "baro", "radalt", "gnss", "pseudolite")
    checked = dict.fromkeys(names, 0)
    faults_seen = dict.fromkeys(names, 0)
    for k in range(len(truth)):
        if k % 20 and k % 37:  # every GNSS row (20 Hz truth, 1 Hz receiver) and a spread of other rows
            continue
        got = prepared.at(truth, k, names)
        for name in names:
            e = errors.sensors[name]
            hit = np.flatnonzero(e.rows == k)
            if hit.size == 0:
                assert name not in got
                continue
            j = int(hit[0])
            ref = suite.apply(truth, SensorSuite.take(errors, name, slice(j, j + 1)), names=[name])[name]
            _identical(got[name], ref, (name, k))
            checked[name] += 1
            faults_seen[name] += int(np.any(ref.fault))
    assert min(checked.values()) >= 10 and checked["gnss"] >= 200
    if faulted:
        assert all(faults_seen[n] > 0 for n in names), faults_seen  # every faulted sensor hit in the rows checked
    if gnss.get("epoch") != "fixed":
        assert "epoch_offset_s" in errors.sensors["gnss"].constants


def test_prepared_suite_skips_absent_sensors_and_rows_without_samples(truth):
    suite = _suite({}, ()).without("pseudolite", "radalt")
    prepared = suite.prepare(suite.draw(truth.t_s, seed=1, runs=0))
    recs = prepared.at(truth, 20, ("baro", "radalt", "gnss", "pseudolite"))
    assert set(recs) == {"baro", "gnss"}
    assert set(prepared.at(truth, 21, ("baro", "gnss"))) == set()  # 20 Hz truth: baro every 2nd row, GNSS 20th
    assert set(prepared.at(truth, 22, ("baro", "gnss"))) == {"baro"}
    assert prepared.one("gnss", truth, 22) is None and prepared.one("radalt", truth, 20) is None
    _identical(prepared.one("baro", truth, 22), prepared.at(truth, 22, ("baro",))["baro"], "baro")
    assert prepared.sample("gnss", 40) == 2 and prepared.sample("gnss", 41) is None
    assert prepared.sample("gnss", 20 * 10_000) is None  # beyond the drawn samples
