"""chi^2 / F-ratio monitors (Chernodarov sec. 2) and their scoring against fault labels."""

from __future__ import annotations

import numpy as np
import pytest
from scipy import stats

from approachsim.nav import monitors as mon


def test_tolerances_are_the_chi2_quantiles() -> None:
    cfg = mon.MonitorConfig(p_chi2=1e-3, p_f=1e-4, window=21)
    assert stats.chi2.sf(cfg.gamma2, 1) == pytest.approx(1e-3)
    assert stats.chi2.sf(cfg.eta2 * 20, 20) == pytest.approx(1e-4)
    with pytest.raises(ValueError, match="window"):
        mon.MonitorConfig(window=2)
    with pytest.raises(ValueError, match="p_chi2"):
        mon.MonitorConfig(p_chi2=1.5)


def _clean(rng: np.random.Generator, runs: int, n: int) -> tuple[np.ndarray, np.ndarray]:
    S = np.exp(rng.uniform(-2, 2, (runs, n)))  # predicted variances that change from epoch to epoch
    return rng.standard_normal((runs, n)) * np.sqrt(S), S


def test_false_alarm_rate_of_clean_residuals_matches_the_design() -> None:
    rng = np.random.default_rng(42)
    cfg = mon.MonitorConfig(p_chi2=1e-3, p_f=1e-4, window=30)
    v, S = _clean(rng, 50, 4000)
    res = mon.monitor(v, S, cfg)
    n = v.size
    rate_chi2 = np.mean(res.beta2 > cfg.gamma2)
    # binomial 5-sigma band around the design probability
    assert abs(rate_chi2 - 1e-3) < 5 * np.sqrt(1e-3 / n)
    assert np.mean(res.decision == mon.FAILURE) < 1e-3  # F alarms are correlated over a window: loose bound
    assert np.nanmean(res.f_ratio) == pytest.approx(1.0, abs=0.02)  # E[F] = 1 under no fault


def test_outliers_are_outliers_and_a_variance_ramp_is_a_failure() -> None:
    rng = np.random.default_rng(3)
    n = 600
    v, S = _clean(rng, 1, n)
    v, S = v[0], S[0]
    spikes = np.array([100, 130, 135, 200, 260])
    v[spikes] = 12.0 * np.sqrt(S[spikes]) * np.array([1, -1, 1, 1, -1])
    onset = 400
    growth = 1.0 + 0.03 * np.clip(np.arange(n) - onset, 0, None)
    v = v * growth
    res = mon.monitor(v, S, mon.MonitorConfig())
    assert np.all(res.decision[spikes] == mon.OUTLIER)
    assert not np.any(res.decision[:onset] == mon.FAILURE)
    first_fail = np.flatnonzero(res.decision == mon.FAILURE)[0]
    assert onset < first_fail < onset + 100


def test_streaming_monitor_equals_the_batch_monitor() -> None:
    rng = np.random.default_rng(9)
    cfg = mon.MonitorConfig(window=10)
    v, S = _clean(rng, 3, 80)
    v[:, 40] = 30.0
    batch = mon.monitor(v, S, cfg)
    w = mon.init_window((3,), cfg)
    for k in range(80):
        w, dec, beta2, f = mon.monitor_step(w, v[:, k], S[:, k], cfg)
        np.testing.assert_array_equal(dec, batch.decision[:, k])
        np.testing.assert_allclose(beta2, batch.beta2[:, k])
        np.testing.assert_allclose(f, batch.f_ratio[:, k], equal_nan=True)
    w = mon.reset_window(w, np.array([True, False, False]))
    assert w.count.tolist() == [0, 80, 80]


def test_score_counts_detections_false_alarms_and_time_to_detect() -> None:
    N, O, F = mon.NONE, mon.OUTLIER, mon.FAILURE
    t = np.arange(8.0)
    labels = np.array([[N, O, N, N, F, F, F, F], [N, N, O, N, N, N, N, N]])
    decision = np.array([[N, O, O, N, N, N, F, F], [N, N, F, N, O, N, N, N]])
    sc = mon.score(decision, labels, t)
    assert sc.outlier_detection_rate == pytest.approx(0.5)  # 1 of 2 outliers decided OUTLIER
    assert sc.misclassified_outliers == pytest.approx(0.5)  # the other was called a failure
    assert sc.false_alarm_rate == pytest.approx(2 / 10)  # clean epochs 3 + 7, one alarm in each row
    assert sc.failure_detection_rate == 1.0
    np.testing.assert_allclose(sc.time_to_detect_s, [2.0])
    events = mon.failure_events(decision[0], t, "gyro-y")
    assert events == [mon.MonitorEvent("gyro-y", 6, 6.0, "failure")]


def test_centered_f_misses_a_bias_that_the_mean_square_f_sees() -> None:
    """The paper's F removes the window mean, so a constant bias of 1.5 sigma is invisible to it; the mean-square
    variant (centered=False) flags it."""
    rng = np.random.default_rng(5)
    n = 400
    S = np.ones(n)
    v = rng.standard_normal(n) + np.where(np.arange(n) >= 200, 1.5, 0.0)
    paper = mon.monitor(v, S, mon.MonitorConfig(centered=True))
    square = mon.monitor(v, S, mon.MonitorConfig(centered=False))
    assert not np.any(paper.decision[260:] == mon.FAILURE)
    assert np.all(square.decision[260:] == mon.FAILURE)
    assert not np.any(square.decision[:200] == mon.FAILURE)


def test_labels_from_the_sensor_fault_codes() -> None:
    from approachsim.sensors.faults import FAULT_CODES

    codes = np.array([FAULT_CODES[k] for k in ("none", "spike", "iam", "ramp", "mni", "outage", "step", "cbm")])
    labels = mon.labels_from_fault_codes(codes, FAULT_CODES)
    N, O, F = mon.NONE, mon.OUTLIER, mon.FAILURE
    np.testing.assert_array_equal(labels, [N, O, O, F, F, N, F, F])
    with pytest.raises(ValueError, match="99"):
        mon.labels_from_fault_codes(np.array([99]), FAULT_CODES)


def test_redundancy_monitor_sees_a_slow_bias_between_two_channels() -> None:
    rng = np.random.default_rng(8)
    n = 600
    truth = np.cumsum(rng.standard_normal(n))  # any common signal cancels in the difference
    ramp = 0.03 * np.clip(np.arange(n) - 300.0, 0, None)  # sigma units per epoch
    a = truth + rng.standard_normal(n) + ramp
    b = truth + rng.standard_normal(n)
    res = mon.redundancy_monitor(a, b, 1.0, 1.0)
    assert not np.any(res.decision[:300] == mon.FAILURE)
    first = np.flatnonzero(res.decision == mon.FAILURE)[0]
    assert 300 < first < 450
