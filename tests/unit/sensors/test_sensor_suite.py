"""The suite: named streams make sensors independent; stepwise apply equals batch measure; profile config."""

from __future__ import annotations

import tomllib
from dataclasses import fields
from pathlib import Path

import numpy as np
import pytest

from approachsim import synthetic
from approachsim.config import ProfileError
from approachsim.profile import load_profile, parse_profile
from approachsim.sensors.config import PseudoliteConfig
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""


def _full_suite():
    p = load_profile(PY_DEFAULT)
    cfg = p.sensors
    from dataclasses import replace

    cfg = replace(cfg, pseudolite=PseudoliteConfig(positions_rwy=((300.0, -150.0, 9.0), (-2000.0, 200.0, 5.0)),
                                                   synchronized=False))
    return SensorSuite.from_config(cfg, p.runway.frame, p.environment.qnh_pa), p


def _same(a, b):
    """Bit-identical: same code path (a sensor left out or a run drawn alone does not move the others' values)."""
    for f in fields(a):
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray):
            assert np.array_equal(x, y, equal_nan=x.dtype.kind == "f"), f.name
        else:
            assert x == y, f.name


@pytest.fixture(scope="module")
def setup():
    suite, p = _full_suite()
    truth = synthetic.profile_descent(p, rate_hz=20.0)
    return suite, truth


def test_default_profile_suite_is_seed_002(setup):
    p = load_profile(PY_DEFAULT)
    s = SensorSuite.from_profile(p)
    assert set(s.sensors) == {"imu", "baro", "radalt", "gnss"}
    assert s.sensors["imu"].grade.name == "nav-2.0"
    assert s.sensors["gnss"].selection == "best4"
    gm = SensorSuite.from_profile(load_profile(PROFILES / "gray-maybeck.toml"))
    assert "pseudolite" in gm.sensors and gm.sensors["imu"].grade.name == "nav-0.4"


@pytest.mark.parametrize("removed", ["pseudolite", "radalt", "gnss", "baro"])
def test_removing_a_sensor_leaves_the_others_bit_identical(setup, removed):
    suite, truth = setup
    full = suite.measure(truth, seed=5, runs=[0, 3])
    part = suite.without(removed).measure(truth, seed=5, runs=[0, 3])
    assert removed not in part
    for name, rec in part.items():
        _same(rec, full[name])


def test_run_is_reproducible_alone(setup):
    suite, truth = setup
    many = suite.measure(truth, seed=5, runs=[0, 3])
    one = suite.measure(truth, seed=5, runs=3)  # bit-identical: same code path (a run alone and in a batch)
    for name in one:
        assert np.array_equal(one[name].t_s, many[name].t_s)
    assert np.array_equal(one["imu"].dv_body, many["imu"].dv_body[1])
    assert np.array_equal(one["gnss"].pseudorange_m, many["gnss"].pseudorange_m[1], equal_nan=True)
    assert np.array_equal(one["pseudolite"].pseudorange_m, many["pseudolite"].pseudorange_m[1], equal_nan=True)


def test_stepwise_apply_equals_batch_for_every_sensor(setup):
    """Closed-loop use: draw for a longer flight once, apply one sample at a time as truth rows appear."""
    suite, truth = setup
    longer = np.arange(len(truth) + 400) * (truth.t_s[1] - truth.t_s[0])
    errs = suite.draw(longer, seed=9, runs=2)
    batch = suite.measure(truth, seed=9, runs=2)
    for name, e in errs.sensors.items():
        m = len(batch[name].t_s)
        for j in (0, m // 3, m - 1):  # bit-identical: same code path (the kernels on a one-sample slice)
            rec = suite.apply(truth, SensorSuite.take(errs, name, slice(j, j + 1)), names=[name])[name]
            for f in fields(rec):
                x = getattr(rec, f.name)
                y = getattr(batch[name], f.name)
                if isinstance(x, np.ndarray) and x.ndim >= 1 and x.shape[0] == 1 and f.name not in ("prn",
                                                                                                 "r_pl_ecef"):
                    assert np.array_equal(x[0], y[j], equal_nan=x.dtype.kind == "f"), (name, f.name, j)
        assert e.index[0] == 0


def test_profile_without_sensors_loads_with_defaults_and_errors_name_fields():
    data = tomllib.loads((PY_DEFAULT).read_text())
    data.pop("sensors", None)
    p = parse_profile(data)
    assert p.sensors.imu.grade == "nav-2.0" and p.faults == ()
    bad = dict(data, sensors={"imu": {"grade": "ring-laser"}})
    with pytest.raises(ProfileError, match=r"sensors\.imu\.grade: must be one of"):
        parse_profile(bad)
    bad = dict(data, sensors={"gnss": {"mask_deg": 60}})
    with pytest.raises(ProfileError, match=r"sensors\.gnss\.mask_deg"):
        parse_profile(bad)
    bad = dict(data, faults=[{"sensor": "pseudolite", "kind": "outage"}])
    with pytest.raises(ProfileError, match=r"faults\[0\]\.sensor: 'pseudolite' is not fitted"):
        parse_profile(bad)
    bad = dict(data, faults=[{"sensor": "gnss", "kind": "outage", "start_s": 10.0, "end_s": 5.0}])
    with pytest.raises(ProfileError, match=r"faults\[0\]\.end_s"):
        parse_profile(bad)
    bad = dict(data, faults=[{"sensor": "baro", "kind": "cbm", "target": "dv"}])
    with pytest.raises(ProfileError, match=r"faults\[0\]\.target"):
        parse_profile(bad)
    ok = dict(data, faults=[{"sensor": "gnss", "kind": "outage", "start_s": 150.0, "end_s": 210.0}])
    p = parse_profile(ok)
    assert p.faults[0].kind == "outage" and p.faults[0].end_s == 210.0
    assert type(SensorSuite.from_profile(p).sensors["gnss"]).__name__ == "Faulted"
