"""Faults change exactly the intended samples, by the intended amount, with the right labels."""

from __future__ import annotations

import math

import numpy as np
import pytest

from approachsim.sensors.baro import Baro
from approachsim.sensors.faults import FAULT_CODES, Faulted, FaultSpec
from approachsim.sensors.gnss import GnssReceiver
from approachsim.sensors.imu import Imu
from approachsim.sensors.presets import PRESETS


def _pair(sensor, specs, truth, seed=4):
    clean = sensor.measure(truth, np.random.default_rng(seed))
    faulty = Faulted(sensor, tuple(specs)).measure(truth, np.random.default_rng(seed))
    return clean, faulty


def test_cbm_step_ramp_iam_on_baro(descent):
    b = Baro(rate_hz=1.0)
    specs = [
        FaultSpec("baro", "cbm", start_s=20.0, end_s=40.0, magnitude=30.0),
        FaultSpec("baro", "step", start_s=100.0, magnitude=-12.0),
        FaultSpec("baro", "ramp", start_s=60.0, end_s=80.0, rate=0.5),
        FaultSpec("baro", "iam", start_s=200.0, end_s=240.0, every=10, magnitude=50.0),
    ]
    clean, faulty = _pair(b, specs, descent)
    t = clean.t_s
    d = faulty.h_baro_m - clean.h_baro_m
    expect = np.zeros_like(t)
    lab = np.zeros(t.shape, dtype=np.int8)
    w = (t >= 20) & (t < 40)
    expect[w] += 30.0
    lab[w] = FAULT_CODES["cbm"]
    w = (t >= 60) & (t < 80)
    expect[w] += 0.5 * (t[w] - 60.0)
    lab[w] = FAULT_CODES["ramp"]
    w = t >= 100
    expect[w] += -12.0
    lab[w] = FAULT_CODES["step"]
    w = np.isin(t, [200.0, 210.0, 220.0, 230.0])  # every 10th sample of [200, 240)
    expect[w] += 50.0
    lab[w] = FAULT_CODES["iam"]
    assert np.allclose(d, expect, atol=1e-9)  # a difference of ~1000 m heights: floor(2, 1000, 1000) = 8.9e-13 m
    # bit-identical: same code path (an unfaulted sample adds an exact 0 to the same noise): exactly the intended
    assert np.array_equal(d != 0, expect != 0)
    assert np.array_equal(faulty.fault, lab)
    assert faulty.valid.all()


def test_seed_000_spikes_and_mni(descent):
    b = Baro(rate_hz=1.0, bias_sigma_m=0.0, noise_sigma_m=1.0)
    specs = [FaultSpec("baro", "spike", steps=(101, 201), k=100.0),
             FaultSpec("baro", "mni", start_s=10.0, end_s=20.0, factor=9.0)]
    clean, faulty = _pair(b, specs, descent)
    truth_h = b.measure(descent, np.random.default_rng(4), noise=False).h_baro_m
    n_clean = clean.h_baro_m - truth_h
    n_faulty = faulty.h_baro_m - truth_h
    # unchanged samples are bit-identical (same code path); 1e-12 m (above floor(2, 1000) = 4.4e-13 m of the
    # heights) only separates them from the changes (>= 1e-3 m)
    changed = np.flatnonzero(~np.isclose(n_clean, n_faulty, rtol=0, atol=1e-12))
    mni = np.flatnonzero((clean.t_s >= 10) & (clean.t_s < 20))
    assert np.array_equal(changed, np.sort(np.concatenate([mni, [101, 201]])))
    assert np.allclose(n_faulty[[101, 201]], 100.0 * n_clean[[101, 201]])
    assert np.allclose(n_faulty[mni], 3.0 * n_clean[mni])  # variance x 9
    assert np.all(faulty.fault[[101, 201]] == FAULT_CODES["spike"])
    assert np.all(faulty.fault[mni] == FAULT_CODES["mni"])
    assert np.count_nonzero(faulty.fault) == len(mni) + 2


def test_gnss_outage_and_single_prn_bias(descent):
    rx = GnssReceiver(selection="all")
    visible = rx.measure(descent, np.random.default_rng(0), noise=False).valid
    ic = int(np.flatnonzero(visible[150])[0])  # a channel in view at t = 150 s
    specs = [FaultSpec("gnss", "outage", start_s=50.0, end_s=110.0),
             FaultSpec("gnss", "cbm", start_s=150.0, end_s=160.0, channel=int(rx.constellation.prn[ic]),
                       magnitude=100.0)]
    clean, faulty = _pair(rx, specs, descent)
    t = clean.t_s
    out = (t >= 50) & (t < 110)
    assert not faulty.valid[out].any()
    assert np.all(np.isnan(faulty.pseudorange_m[out]))
    assert np.all(faulty.fault[out] == FAULT_CODES["outage"])
    assert np.array_equal(faulty.valid[~out], clean.valid[~out])
    w = (t >= 150) & (t < 160)
    d = faulty.pseudorange_m - clean.pseudorange_m
    ch = np.zeros(24, dtype=bool)
    ch[ic] = True
    expect_changed = w[:, None] & ch[None, :] & clean.valid
    assert expect_changed.any()
    assert np.allclose(d[expect_changed], 100.0)  # of 2e7 m ranges: floor(2, 2.7e7, 2.7e7) = 1.2e-8; 1e-3 (rtol)
    both = clean.valid & faulty.valid & ~expect_changed
    assert np.all(d[both] == 0.0)  # bit-identical: same code path (an exact 0 added)
    lab = np.where(out[:, None], FAULT_CODES["outage"], 0) + np.where(w[:, None] & ch[None, :], FAULT_CODES["cbm"], 0)
    assert np.array_equal(faulty.fault, lab.astype(np.int8))


def test_imu_axis_fault_and_batched_runs(descent):
    imu = Imu(PRESETS["nav-2.0"])
    spec = FaultSpec("imu", "step", start_s=5.0, target="dtheta", channel=2, magnitude=1e-4)
    rngs = [np.random.default_rng(s) for s in (1, 2)]
    clean = imu.measure(descent, [np.random.default_rng(s) for s in (1, 2)])
    faulty = Faulted(imu, (spec,)).measure(descent, rngs)
    w = clean.t_s >= 5.0
    d = faulty.dtheta_body - clean.dtheta_body
    # the step: allclose's 1e-8 rad is far above floor(2, 2e-4) = 9e-20; elsewhere bit-identical (same code path)
    assert np.allclose(d[:, w, 2], 1e-4) and np.all(d[:, ~w, :] == 0) and np.all(d[:, :, :2] == 0)
    assert np.array_equal(faulty.dv_body, clean.dv_body)
    assert faulty.fault.shape == (2, len(clean.t_s))
    assert np.all(faulty.fault[:, w] == FAULT_CODES["step"]) and not faulty.fault[:, ~w].any()


def test_stepwise_faulted_apply_equals_batch(descent):
    b = Faulted(Baro(rate_hz=1.0), (FaultSpec("baro", "iam", start_s=30.0, end_s=60.0, every=7, magnitude=5.0),
                                    FaultSpec("baro", "mni", start_s=40.0, end_s=50.0, factor=4.0)))
    e = b.draw(descent.t_s, np.random.default_rng(3))
    batch = b.apply(descent, e)
    for j in range(25, 65):
        one = b.apply(descent, e.take(slice(j, j + 1)))
        assert one.h_baro_m[0] == batch.h_baro_m[j] and one.fault[0] == batch.fault[j]


def test_bad_kind_is_rejected():
    with pytest.raises(ValueError, match="kind must be one of"):
        FaultSpec("baro", "glitch")
    assert math.isinf(FaultSpec("baro", "cbm").end_s)


def test_wrapper_exposes_the_sensor_and_pickles(descent):
    import pickle

    f = Faulted(Baro(rate_hz=2.0), (FaultSpec("baro", "cbm", start_s=1.0, magnitude=1.0),))
    assert f.rate_hz == 2.0 and f.name == "baro" and f.fault_targets == Baro.fault_targets
    g = pickle.loads(pickle.dumps(f))
    assert g == f
    with pytest.raises(AttributeError):
        _ = f.no_such_attribute
