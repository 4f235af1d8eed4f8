"""Integrity monitors of a measurement channel (Chernodarov sec. 2): outliers vs gradual failures.

Two statistics of the filter residual v_j with predicted variance S_j (= alpha_j^2):
    chi^2 test of the current residual   beta_j^2 = v_j^2 / S_j  > gamma^2   -> outlier (or failure)
    F-ratio over a moving window of N     F_j = alpha^_j^2 / alpha_j^2  > eta^2 -> gradual failure
with alpha^_j^2 = sum_k (v_k - v_bar_N)^2 / (N - 1) the actual (sample) variance of the last N residuals and
alpha_j^2 the predicted one. The paper divides by one scaling parameter alpha_j^2; a filter's predicted
variance S_k changes along the window (fast while it converges), so each residual is normalized by its own
S_k first: F_j = sum_k (b_k - b_bar)^2 / (N - 1), b_k = v_k / sqrt(S_k) (identical when S is constant; with
the ratio of window means instead, the converging filter raised false failure alarms at the window's first
fill). Under no fault beta^2 ~ chi^2(1) and (N - 1) F ~ chi^2(N - 1), so
the tolerances follow from per-epoch false-alarm probabilities: gamma^2 = chi2.isf(p_chi2, 1) and
eta^2 = chi2.isf(p_f, n - 1) / (n - 1). Residuals already flagged as outliers are left out of the F window
(n = N minus those), so isolated outliers do not read as a failure: the combined chi^2 / F test tells them
apart. (Clipping them to the gamma boundary instead still raised false failure alarms in our runs.)

Decision (per epoch): no discrepancy -> process normally; F out of tolerance -> failure: exclude the channel
(switch to its redundant twin), logged with its detection time; else beta^2 out of tolerance -> outlier:
process robustly (influence function psi). `score` compares decisions with ground-truth fault labels.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from scipy import stats

Array = np.ndarray

NONE, OUTLIER, FAILURE = 0, 1, 2
"""Decision / label codes per epoch."""

FAULT_CLASS: dict[str, int] = {
    "none": NONE, "outage": NONE,  # an outage gives no measurement: nothing to monitor
    "spike": OUTLIER, "iam": OUTLIER,  # isolated abnormal samples
    "cbm": FAILURE, "mni": FAILURE, "step": FAILURE, "ramp": FAILURE,  # persistent or gradual failures
}
"""What the monitors should decide for each sensor fault kind (sensors/faults.py kinds)."""


def labels_from_fault_codes(codes: Array, fault_codes: Mapping[str, int]) -> Array:
    """Ground-truth labels (NONE / OUTLIER / FAILURE) from a sensor record's `fault` codes, given the
    kind -> code table of the sensor fault injector (sensors.faults.FAULT_CODES). Unknown codes: ValueError."""
    codes = np.asarray(codes)
    out = np.full(codes.shape, -1, dtype=int)
    for kind, code in fault_codes.items():
        if kind not in FAULT_CLASS:
            raise ValueError(f"fault kind {kind!r}: no monitor class (known: {', '.join(FAULT_CLASS)})")
        out[codes == code] = FAULT_CLASS[kind]
    if np.any(out < 0):
        raise ValueError(f"fault codes {sorted(set(codes[out < 0].tolist()))}: not in the fault table")
    return out


@dataclass(frozen=True)
class MonitorConfig:
    """Tolerances of the combined chi^2 / F test.

    p_chi2: per-epoch false-alarm probability of the chi^2(1) test of one residual; p_f: per-epoch
    false-alarm probability of the F test; window: N residuals of the moving window (>= 3).
    """

    p_chi2: float = 1e-4
    p_f: float = 1e-5
    window: int = 50
    centered: bool = True
    """True: the paper's sample variance about the window mean (sees variance growth); False: the mean square
    of the normalized residuals, sum b_k^2 / n ~ chi^2(n) / n (also sees a slowly growing bias)."""

    def __post_init__(self) -> None:
        for name in ("p_chi2", "p_f"):
            p = getattr(self, name)
            if not 0.0 < p < 1.0:
                raise ValueError(f"{name}: must be a probability in (0, 1); got {p!r}")
        if int(self.window) != self.window or self.window < 3:
            raise ValueError(f"window: must be an integer >= 3; got {self.window!r}")

    @property
    def gamma2(self) -> float:
        """Tolerance gamma^2 of beta^2 (chi^2(1) quantile)."""
        return float(stats.chi2.isf(self.p_chi2, 1))

    @property
    def eta2(self) -> float:
        """Tolerance eta^2 of F over a full window (chi^2(N-1)/(N-1) quantile; chi^2(N)/N when not centered)."""
        n = self.window - (1 if self.centered else 0)
        return float(stats.chi2.isf(self.p_f, n) / n)

    def eta2_for(self, n_valid: Array) -> Array:
        """eta^2 for windows holding n_valid residuals (outliers left out): chi^2(n-1)/(n-1) quantiles
        (chi^2(n)/n when not centered)."""
        dof = np.maximum(np.asarray(n_valid) - (1 if self.centered else 0), 1)
        return stats.chi2.isf(self.p_f, dof) / dof


def _f_ratio(win: Array, config: MonitorConfig) -> tuple[Array, Array]:
    """F (sample variance of the normalized residuals in each window, nan = left out) and its tolerance."""
    n_valid = np.sum(np.isfinite(win), axis=-1)
    with np.errstate(invalid="ignore", divide="ignore"):
        if config.centered:
            mean = np.nansum(win, axis=-1) / n_valid
            ss = np.nansum((win - mean[..., None]) ** 2, axis=-1)
            f = np.where(n_valid >= 3, ss / np.maximum(n_valid - 1, 1), np.nan)  # F = sum (b_k - b_bar)^2 / (n-1)
        else:
            f = np.where(n_valid >= 3, np.nansum(win**2, axis=-1) / n_valid, np.nan)  # F = sum b_k^2 / n
    return f, config.eta2_for(n_valid)


@dataclass(frozen=True)
class MonitorResult:
    """Per-epoch statistics and decisions; arrays over the trailing axis `time` (any leading axes = runs).

    beta2: v^2 / S; f_ratio: F (nan until the window is full); decision: NONE / OUTLIER / FAILURE.
    """

    beta2: Array
    f_ratio: Array
    decision: Array


def monitor(v: Array, S: Array, config: MonitorConfig = MonitorConfig()) -> MonitorResult:
    """Run the combined chi^2 / F test over residuals v and their predicted variances S, shape (..., time)."""
    v = np.asarray(v, dtype=float)
    S = np.asarray(S, dtype=float)
    beta2 = v * v / S  # beta_j^2 = v_j^2 / alpha_j^2
    outlier = beta2 > config.gamma2
    b_w = np.where(outlier, np.nan, v / np.sqrt(S))  # flagged residuals are left out of the F window
    N = config.window
    f_ratio = np.full(v.shape, np.nan)
    eta2 = np.full(v.shape, np.inf)
    if v.shape[-1] >= N:
        win = np.lib.stride_tricks.sliding_window_view(b_w, N, axis=-1)
        f_ratio[..., N - 1:], eta2[..., N - 1:] = _f_ratio(win, config)
    failure = f_ratio > eta2
    decision = np.where(failure, FAILURE, np.where(outlier, OUTLIER, NONE))
    return MonitorResult(beta2, f_ratio, decision)


def redundancy_monitor(z_a: Array, z_b: Array, var_a: float | Array, var_b: float | Array,
                       config: MonitorConfig = MonitorConfig()) -> MonitorResult:
    """The combined test on the difference of two redundant channels measuring the same quantity, d = z_a - z_b
    with variance var_a + var_b (hardware redundancy, Chernodarov sec. 1-2). It does not depend on any filter, so
    a slow bias that a filter would absorb into a state still shows; the F-ratio is the mean square (a bias is
    what it must see). With two channels it says that one has failed, not which."""
    d = np.asarray(z_a, dtype=float) - np.asarray(z_b, dtype=float)
    S = np.broadcast_to(np.asarray(var_a, dtype=float) + np.asarray(var_b, dtype=float), d.shape)
    cfg = MonitorConfig(config.p_chi2, config.p_f, config.window, centered=False)
    return monitor(d, S, cfg)


@dataclass(frozen=True)
class MonitorWindow:
    """Streaming state of `monitor_step`: the last N (clipped) residuals and predicted variances, shape
    (..., N), oldest first, and how many epochs each has seen, shape (...)."""

    v: Array
    S: Array
    count: Array


def init_window(shape: tuple[int, ...], config: MonitorConfig = MonitorConfig()) -> MonitorWindow:
    """An empty window for residual arrays of `shape` (e.g. (runs,))."""
    return MonitorWindow(np.zeros((*shape, config.window)), np.ones((*shape, config.window)),
                         np.zeros(shape, dtype=int))


def reset_window(w: MonitorWindow, mask: Array) -> MonitorWindow:
    """Empty the windows where mask is True (e.g. after switching those runs to the redundant channel)."""
    m = np.asarray(mask, dtype=bool)
    return MonitorWindow(np.where(m[..., None], 0.0, w.v), np.where(m[..., None], 1.0, w.S),
                         np.where(m, 0, w.count))


def monitor_step(
    w: MonitorWindow, v: Array, S: Array, config: MonitorConfig = MonitorConfig()
) -> tuple[MonitorWindow, Array, Array, Array]:
    """One epoch of `monitor` for online use (decisions feed back into the filter).

    Returns (window, decision, beta2, f_ratio) for residuals v and predicted variances S of one epoch;
    identical to the batch `monitor` on the same series.
    """
    v = np.asarray(v, dtype=float)
    S = np.asarray(S, dtype=float)
    beta2 = v * v / S
    outlier = beta2 > config.gamma2
    b_w = np.where(outlier, np.nan, v / np.sqrt(S))
    wv = np.concatenate([w.v[..., 1:], b_w[..., None]], axis=-1)
    wS = np.concatenate([w.S[..., 1:], S[..., None]], axis=-1)
    count = w.count + 1
    f_full, eta2 = _f_ratio(wv, config)
    f_ratio = np.where(count >= config.window, f_full, np.nan)
    failure = f_ratio > eta2
    decision = np.where(failure, FAILURE, np.where(outlier, OUTLIER, NONE))
    return MonitorWindow(wv, wS, count), decision, beta2, f_ratio


@dataclass(frozen=True)
class MonitorEvent:
    """A logged decision: channel, epoch index, time (s) and kind ('failure' or 'outlier')."""

    channel: str
    index: int
    t_s: float
    kind: str


def failure_events(decision: Array, t_s: Array, channel: str) -> list[MonitorEvent]:
    """The first FAILURE epoch of one run's decision series (the channel is then excluded), as an event list."""
    idx = np.flatnonzero(np.asarray(decision) == FAILURE)
    return [] if idx.size == 0 else [MonitorEvent(channel, int(idx[0]), float(t_s[idx[0]]), "failure")]


@dataclass(frozen=True)
class MonitorScore:
    """Scores against ground-truth labels (all runs pooled).

    outlier_detection_rate: fraction of labelled outlier epochs decided OUTLIER;
    failure_detection_rate: fraction of runs with a failure in which FAILURE is decided during the failure;
    false_alarm_rate: fraction of clean epochs (label NONE, before any failure) with any alarm;
    misclassified_outliers: fraction of labelled outlier epochs decided FAILURE;
    time_to_detect_s: per failed run, first FAILURE decision minus failure onset (nan if missed).
    """

    outlier_detection_rate: float
    failure_detection_rate: float
    false_alarm_rate: float
    misclassified_outliers: float
    time_to_detect_s: Array


def score(decision: Array, labels: Array, t_s: Array) -> MonitorScore:
    """Score decisions (runs, time) against labels (runs, time) of NONE / OUTLIER / FAILURE; t_s (time,)."""
    decision = np.atleast_2d(decision)
    labels = np.atleast_2d(labels)
    is_out = labels == OUTLIER
    in_fail = labels == FAILURE
    after_fail = np.cumsum(in_fail, axis=-1) > 0
    clean = (labels == NONE) & ~after_fail
    n_out = int(is_out.sum())
    ttd = []
    for dec, fail in zip(decision, in_fail, strict=True):
        if not fail.any():
            continue
        onset = int(np.argmax(fail))
        hits = np.flatnonzero((dec == FAILURE) & (np.arange(dec.size) >= onset))
        ttd.append(t_s[hits[0]] - t_s[onset] if hits.size else np.nan)
    ttd_arr = np.array(ttd)
    return MonitorScore(
        outlier_detection_rate=float((decision[is_out] == OUTLIER).sum() / n_out) if n_out else float("nan"),
        failure_detection_rate=float(np.mean(np.isfinite(ttd_arr))) if ttd_arr.size else float("nan"),
        false_alarm_rate=float((decision[clean] != NONE).mean()) if clean.any() else float("nan"),
        misclassified_outliers=float((decision[is_out] == FAILURE).sum() / n_out) if n_out else float("nan"),
        time_to_detect_s=ttd_arr,
    )
