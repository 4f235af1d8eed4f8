"""Integrity risk per category by rare-event simulation: the total-probability split over fault modes, each mode's
P(HMI | fault) by importance sampling (integrity.rare, NAIS by default) over its parameters, the fault-free term
from a Gaussian tail with the covariance's overbound measured on simulated runs.

    P(HMI) = P(HMI, fault-free) + sum_k P_k P(HMI | fault k)

**What is simulated.** One sample of mode k is an open-loop navigation of a flown approach (one of `truths`
JSBSim flights of the profile, shared as the campaign's open loop shares them) with the run's own sensor and filter
noise (its own run index, so its own streams and, with per-run epochs, its own GPS sky), one fault from the mode
with the parameters u maps to, through the solution-separation bank (campaign.integrity_bank.run_bank: the main filter
and one sub-filter per used GPS channel, the exclusion at the first detection), scored per category as the campaign
does (campaign.integrity_bank.score_category: epochs from the settle time down to the category's DH, Annex 10 alert
limits at the aircraft's distance and height). The event is hazardously misleading information at any epoch: the output
error beyond the alert limit on either axis while the output's protection levels are inside both limits. Its
limit-state function (continuous, for the adaptive steps) is

    g = max over epochs of min( max_axis (|e| - AL), min_axis (AL - PL) )        HMI  <=>  g > 0

The importance sampling targets the union of the categories' events (g = max over categories); the last step's
weighted sample then estimates each category's own event (rare.reweight).

**The fault parameters** are standard normals u mapped through Phi: the onset uniform between the settle time
and the lowest decision height, the magnitude (step, m) or rate (ramp, m/s) log-uniform over the mode's range, the
channel (GPS: uniform over the channels the receiver used at the onset; pseudolite: over the units). Positive
magnitudes only: the filter and the bank are linear in the measurement errors and the noise is symmetric, so a
fault of -m gives the error of +m mirrored and the same probability of an event defined on |e|.

**The fault-free term is analytic.** HMI needs the output's PL inside the AL, and PL >= K_ff sigma, so a
fault-free HMI is an error beyond AL > K_ff sigma. Per run, N_es = exposure / TTA independent samples times
2 Q(r_v / s_v) + 2 Q(r_l / s_l), r the smallest AL / sigma over the run's available epochs (sigma the filter's
standard deviation on that axis) and s the upper confidence bound of the RMS of the simulated normalized errors
e / sigma on that axis (the covariance's overbound, measured on `fault_free_runs` runs, the runs counted as the
independent samples; at least 1); the term is the mean over the runs (`hmi_gaussian`), its upper figure the worst
run's. Simulating this tail directly would need the sensor noise as standard normals (the sensors draw from their
named streams); the filter is linear in that noise, so its error is Gaussian with the filter's covariance where the
models are: what is simulated is the check that the covariance bounds the error. The RMS checks the core, not the
tail: an error distribution with heavier tails than its RMS suggests is not caught (overbounding in the sense of
DeCleene, *Defining pseudorange integrity - overbounding*, is not tested). Same for false alerts: the allocation
scaled by Q(K_fa / s_ss) / Q(K_fa), s_ss the measured bound of the RMS of Delta / sigma_ss over the separations.

**Priors** (per approach; marks as in the reference notes: [S] a secondary source, [U] none found, [D] derived):
satellite fault P_sat = 1e-5 per satellite (ARAIM ISM default, integrity-envelope.md sec. 3a) [S], times the
satellites the receiver used at the onset (the most seen over the samples) [D], given in full to the ramp and to
the step (a satellite fault counted twice: conservative); baro, radar altimeter and each pseudolite 1e-5 [U]
(no source: the verdict on them is conditional on this number). A category's total is `shown` (the allocation
met) when its upper bound (the sum of the terms' upper bounds) is within the allocation, `exceeds` when its lower
bound is beyond, `not shown` otherwise. CAT II / III allocations are per 15 s; the simulated window is the whole
approach, so the per-approach probability compared with them is conservative.

**Specific risk.** Certification bounds the worst fault, not the average over an assumed magnitude law (the ARAIM
protection-level equation, the GBAS threat models' limit case, DO-253 / Annex 10 Attachment D): prior x max over
the magnitude of P(HMI | magnitude). Each mode's samples are binned by magnitude decade (from the range's low end;
the last bin ends at its high end: sat-ramp 0.01-0.1-1-5 m/s, sat-step 1-10-100 m) and by onset third of the
window, and P(HMI | bin) is bounded per category (`specific_risk`): from the first step, a sample of the fault's
own distribution (exact Clopper-Pearson, about samples / (3 x decades) per bin: 33 at 200 samples and two decades,
so a bin without an HMI sample is bounded by 0.087), or from the last NAIS step where its effective sample size
in the bin is larger (the likelihood-ratio-weighted conditional, Clopper-Pearson on Kish's effective counts:
approximate). The verdict uses prior x the worst bin's upper bound; the average (the estimator's P(HMI | fault))
is reported beside it as `..._average`. A bin is still an average over a decade and a third of the window: a
narrower worst case inside it is not resolved.
"""

from __future__ import annotations

import dataclasses
import functools
import math
import os
import time
from collections.abc import Callable, Mapping, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy import stats as sps

from approachsim.campaign import preapproach
from approachsim.campaign.bank_modes import BARO_MODE, PSEUDOLITE_MODE, RADALT_MODE
from approachsim.campaign.integrity_bank import run_bank, score_category
from approachsim.campaign.integrity_campaign import bank_profile
from approachsim.campaign.pipeline import approach_stop_height_m
from approachsim.campaign.runner import register_pickling
from approachsim.flight.run import Approach
from approachsim.integrity import rare
from approachsim.integrity.requirements import REQUIREMENTS
from approachsim.memo import TruthMemo
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.suite import SensorSuite

Array = np.ndarray

CATEGORY_KEYS = {"CAT I": "cat1", "CAT II": "cat2", "CAT III": "cat3"}
P_SAT = 1e-5
"""State probability of a fault of one satellite (ARAIM ISD: 1e-5 / h x 1 h mean fault duration, [S])."""
ONSET_BINS = 3
"""Onset bins of the specific risk inside the window: thirds of the onset window (early, middle, late)."""
PRE_BINS = 3
"""Onset bins before the window (a mode with an MFD): thirds of the MFD."""


@dataclass(frozen=True)
class FaultMode:
    """One fault mode: which sensor, which fault kind, the magnitude range and the prior."""

    name: str
    sensor: str
    """gnss | baro | radalt | pseudolite (sensors/faults.py)."""
    kind: str
    """step (magnitude, m) or ramp (rate, m/s)."""
    low: float
    high: float
    """Magnitude (m) or rate (m/s) range, log-uniform."""
    prior: float
    """Prior probability per approach (per satellite for GPS: times the satellites in use)."""
    prior_mark: str
    prior_source: str
    law: str = "log-uniform"
    """Magnitude law: log-uniform over [low, high], or half-normal (|N(0, high^2)|, low unused: the estimator
    validation's mode, whose tail is the fault's own)."""
    mfd_s: float = 0.0
    """Mean fault duration, s: `prior` is then the state probability (rate x MFD) and onsets are sampled over the
    MFD before the window as well as inside it ("Faults present before the approach"); 0: inside the window only,
    `prior` per approach."""
    mfd_mark: str = ""
    pre_fraction: float = 0.0
    """Share of the onset's uniform Phi(u_0) mapped before the window: MFD / (MFD + window length), set per study
    from its first truth (`with_window`); 0: every onset inside the window."""

    def with_window(self, window_s: float) -> FaultMode:
        """This mode for an onset window of `window_s` seconds: the pre-approach share MFD / (MFD + window)."""
        if self.mfd_s <= 0.0:
            return self
        return dataclasses.replace(self, pre_fraction=self.mfd_s / (self.mfd_s + float(window_s)))

    def prior_per_approach(self, window_s: float) -> float:
        """The probability that a fault of this mode (one satellite or unit) is present during the onset window:
        rate x (MFD + window) = state probability x (1 + window / MFD) (every fault lasting its MFD); without an
        MFD, `prior` itself."""
        return self.prior * (1.0 + float(window_s) / self.mfd_s) if self.mfd_s > 0.0 else self.prior

    def onset(self, f: float, window: tuple[float, float]) -> float:
        """The onset time (s) of the onset window's uniform f in [0, 1]: below `pre_fraction` an age uniform over
        the MFD before the window's start (the oldest at f = 0), above it uniform over the window."""
        lo, hi = window
        if f < self.pre_fraction:
            return lo - (1.0 - f / self.pre_fraction) * self.mfd_s
        g = (f - self.pre_fraction) / (1.0 - self.pre_fraction) if self.pre_fraction > 0.0 else f
        return lo + g * (hi - lo)

    def onset_edges(self) -> list[tuple[float, float, str]]:
        """The specific risk's onset bins as ranges of Phi(u_0) with labels: thirds of the MFD before the window
        (ages counted back from the window's start) when the mode has one, then thirds of the window."""
        out = []
        if self.pre_fraction > 0.0:
            a = self.pre_fraction
            for j in range(PRE_BINS):
                age = (self.mfd_s * (1 - (j + 1) / PRE_BINS), self.mfd_s * (1 - j / PRE_BINS))
                out.append((a * j / PRE_BINS, a * (j + 1) / PRE_BINS,
                            f"present {age[0]:.0f}-{age[1]:.0f} s before"))
        b = self.pre_fraction
        for j in range(ONSET_BINS):
            out.append((b + (1 - b) * j / ONSET_BINS, b + (1 - b) * (j + 1) / ONSET_BINS, f"window {j + 1}/3"))
        return out

    @property
    def has_channel(self) -> bool:
        """The mode picks a channel (GPS satellite, pseudolite unit)."""
        return self.sensor in ("gnss", "pseudolite")

    @property
    def dim(self) -> int:
        """Standard-normal inputs: onset, magnitude (and channel)."""
        return 3 if self.has_channel else 2

    def magnitude(self, u: float) -> float:
        """The magnitude from a standard normal (log-uniform, or half-normal: high |u|)."""
        if self.law == "half-normal":
            return float(self.high * abs(u))
        a, b = math.log(self.low), math.log(self.high)
        return float(math.exp(a + float(sps.norm.cdf(u)) * (b - a)))

    def magnitude_edges(self) -> list[float]:
        """The specific-risk magnitude bins' edges: decades from `low` (the last one ends at `high`, e.g. sat-ramp
        0.01, 0.1, 1, 5 m/s); half-normal: 0, 1, 2, inf times `high` (|u| below 1, 1 to 2, beyond 2)."""
        if self.law == "half-normal":
            return [0.0, self.high, 2.0 * self.high, math.inf]
        edges = [self.low]
        while edges[-1] * 10.0 < self.high * (1.0 - 1e-9):
            edges.append(edges[-1] * 10.0)
        return [*edges, self.high]

    def magnitude_fraction(self, lo: float, hi: float) -> float:
        """The magnitude law's probability of [lo, hi) (the bin's share of the fault's prior)."""
        if self.law == "half-normal":
            return float(2.0 * (sps.norm.cdf(hi / self.high) - sps.norm.cdf(lo / self.high)))
        return math.log(hi / lo) / math.log(self.high / self.low)


_ISM = ("ARAIM ISD: R_sat 1e-5 / h x mean fault duration 1 h = state probability 1e-5 per satellite (draft ICAO "
        "Annex 10 default ISD, standards.md 1.5; ARAIM-4DS, integrity-envelope.md 3a), not reduced for GBAS or SBAS "
        "ground monitoring")
_NONE = "none found: assumed; the term is not shown (prior_allowed: the prior it could carry)"
MFD_SAT_S = 3600.0
"""GPS satellite mean fault duration, s (ARAIM ISD, standards.md 1.5 [S])."""
MODES: Mapping[str, FaultMode] = {
    "sat-ramp": FaultMode("sat-ramp", "gnss", "ramp", 0.01, 5.0, P_SAT, "S", _ISM, mfd_s=MFD_SAT_S, mfd_mark="S"),
    "sat-step": FaultMode("sat-step", "gnss", "step", 1.0, 100.0, P_SAT, "S", _ISM, mfd_s=MFD_SAT_S, mfd_mark="S"),
    "baro-step": FaultMode("baro-step", "baro", "step", 1.0, 100.0, 1e-5, "U", _NONE, mfd_s=3600.0, mfd_mark="U"),
    "radalt-bias": FaultMode("radalt-bias", "radalt", "step", 0.3, 30.0, 1e-5, "U", _NONE, mfd_s=3600.0,
                             mfd_mark="U"),
    "pseudolite-step": FaultMode("pseudolite-step", "pseudolite", "step", 1.0, 100.0, 1e-5, "U", _NONE + ", per unit",
                                 mfd_s=3600.0, mfd_mark="U"),
}
"""Fault modes by name (module docstring)."""

VALIDATION_MODES: Mapping[str, FaultMode] = {
    "baro-step-halfnormal": FaultMode("baro-step-halfnormal", "baro", "step", 0.0, 5.0, 1e-5, "U",
                                      "estimator validation only", law="half-normal"),
}
"""Modes for validating the estimators against brute force (benchmarks/rare_event_validation.py): a fault whose
event tail is the fault parameter's own (a baro step of 5 m |u|: an error beyond C needs a large |u|)."""


def fault_mode(name: str) -> FaultMode:
    """A mode of MODES or VALIDATION_MODES by name."""
    return MODES[name] if name in MODES else VALIDATION_MODES[name]


def modes_for(profile: Any, names: Sequence[str] | None = None) -> list[FaultMode]:
    """The modes that apply to the profile's sensors (all of them unless `names`); ValueError naming a bad one."""
    have = {k for k in ("gnss", "baro", "radalt", "pseudolite") if getattr(profile.sensors, k, None) is not None}
    if names is None:
        return [m for m in MODES.values() if m.sensor in have]
    out = []
    for n in names:
        if n not in MODES:
            raise ValueError(f"unknown fault mode {n!r}; choose from {', '.join(MODES)}")
        if MODES[n].sensor not in have:
            raise ValueError(f"fault mode {n!r}: the profile has no {MODES[n].sensor} sensor")
        out.append(MODES[n])
    return out


# ---- one sample ----------------------------------------------------------------------------------------------

@dataclass(frozen=True, eq=False)
class FlownTruth:
    """One of the study's flown truths, its onset window and the memo of the work its samples share (the bank's
    reference, epoch models and converged starts: approachsim/memo.py)."""

    truth: Any
    t_lo_s: float
    """Start of the onset window: the settle time after the start, s."""
    t_hi_s: float
    """End of the onset window: where the truth passes the lowest decision height, s."""
    memo: TruthMemo


@functools.lru_cache(maxsize=16)
def flown_truth(profile: Any, seed: int, index: int) -> FlownTruth:
    """Truth `index` of the campaign seeded `seed` (the open-loop group index * flight_group's flight), flown once per
    process for the same (profile value, seed, index), and its onset window: from the settle time after the start
    to the lowest decision height, s."""
    flight = Approach(profile, stop_height_m=approach_stop_height_m(profile)).fly(
        seed=seed, run=index * profile.evaluation.flight_group)
    if not flight.ok:
        raise RuntimeError(f"truth {index}: the flight failed ({flight.termination})")
    truth = flight.truth
    z = np.asarray(truth.r_rwy)[:, 2]
    low = min(profile.evaluation.dh_m(c) for c in REQUIREMENTS)
    t_end = float(truth.t_s[int(np.argmax(z < low))]) if np.any(z < low) else float(truth.t_s[-1])
    return FlownTruth(truth, float(truth.t_s[0]) + profile.evaluation.timeavg_settle_s, t_end, TruthMemo(truth))


def flight_truth(profile: Any, seed: int, index: int) -> tuple[Any, float, float]:
    """(truth, onset window start s, end s) of `flown_truth`."""
    f = flown_truth(profile, int(seed), int(index))
    return f.truth, f.t_lo_s, f.t_hi_s


def fault_spec(mode: FaultMode, u: Array, profile: Any, truth: Any, seed: int, run: int,
               window: tuple[float, float]) -> tuple[Any, dict]:
    """The FaultSpec u maps to (module docstring) and its physical parameters: the onset by FaultMode.onset (before
    the window's start when the mode has an MFD and Phi(u_0) < its pre_fraction: `age_at_start_s` > 0 when that is
    before the run's first sample, which the pre-approach segment then carries: run_sample)."""
    u = np.asarray(u, float)
    onset = mode.onset(float(sps.norm.cdf(u[0])), window)
    mag = mode.magnitude(float(u[1]))
    channel, n_used, index = None, 1, -1
    if mode.sensor == "gnss":
        suite = SensorSuite.from_profile(profile)
        g = suite.without(*[s for s in suite.sensors if s != "gnss"]).measure(truth, seed=seed, runs=[run])["gnss"]
        j = int(np.clip(np.searchsorted(g.t_s, max(onset, float(g.t_s[0]))), 0, len(g.t_s) - 1))
        used = np.flatnonzero(np.asarray(g.valid)[0, j])
        n_used = int(used.size)
        index = int(used[min(int(sps.norm.cdf(u[2]) * n_used), n_used - 1)])
        channel = int(np.asarray(g.prn)[index])
    elif mode.sensor == "pseudolite":
        n_used = len(profile.sensors.pseudolite.positions_rwy)
        channel = index = min(int(sps.norm.cdf(u[2]) * n_used), n_used - 1)
    target = {"gnss": "pseudorange", "pseudolite": "pseudorange", "baro": "h", "radalt": "h"}[mode.sensor]
    spec = FaultSpec(sensor=mode.sensor, kind=mode.kind, start_s=onset, target=target, channel=channel,
                     magnitude=mag if mode.kind == "step" else 0.0, rate=mag if mode.kind == "ramp" else 0.0)
    t0 = float(truth.t_s[0]) if truth is not None else window[0]
    return spec, {"onset_s": onset, "magnitude": mag, "channel": -1 if channel is None else channel,
                  "n_channels": n_used, "channel_index": index, "age_at_start_s": max(0.0, t0 - onset),
                  "onset_before_window_s": max(0.0, window[0] - onset)}


def pre_fault(mode: FaultMode, params: Mapping[str, float]) -> Any:
    """The pre-approach segment's fault (campaign.preapproach.PreFault) of a sample whose onset is before the run
    start (fault_spec's params), else None."""
    if params["age_at_start_s"] <= 0.0:
        return None
    code = {"gnss": int(params["channel_index"]), "baro": BARO_MODE, "radalt": RADALT_MODE,
            "pseudolite": PSEUDOLITE_MODE - int(params["channel_index"])}[mode.sensor]
    return preapproach.PreFault(preapproach.row_name(code), mode.kind, float(params["magnitude"]),
                                float(params["age_at_start_s"]))


def limit_states(ep: Any, cfg: Any, epoch_hz: float, t0_s: float, confirm: bool = False) -> dict[str, float]:
    """Per category (prefix cat1_ ...): `hmi_g` (module docstring), `mi_g` (max over available epochs of
    max_axis (|e| - PL)), the largest output errors `vmax_m` / `lmax_m`, `hmi` / `mi` epoch counts, `available`
    epochs, `detected` (any detection) and the excluded channel; fault-free diagnostics: the normalized main errors
    and separations (`z2_v`, `z2_l`, `ss2`: sums of squares, `n_z`, `n_ss`: counts). confirm: the bank identifies
    with the second look (bank.second_level)."""
    out: dict[str, float] = {}
    settled = ep.t_s >= t0_s + cfg.timeavg_settle_s
    for cat, req in REQUIREMENTS.items():
        key = CATEGORY_KEYS[cat]
        win = settled & (ep.height_m >= cfg.dh_m(cat))
        s = score_category(ep, req, epoch_hz, win, confirm=confirm)
        err = s.err_m
        al, pl = s.al_m, s.pl_m
        with np.errstate(invalid="ignore"):
            h = np.minimum(np.max(err - al, axis=1), np.min(al - pl, axis=1))
            mi = np.where(s.available, np.max(err - pl, axis=1), -np.inf)
        sig = np.sqrt(np.maximum(ep.p0[win], 1e-18))
        ratio = np.where(s.available[:, None], al / sig, np.inf)  # AL / sigma where HMI is possible
        out.update({f"{key}_rmin_v": float(np.min(ratio[:, 0])) if ratio.size else math.inf,
                    f"{key}_rmin_l": float(np.min(ratio[:, 1])) if ratio.size else math.inf})
        out.update({f"{key}_hmi_g": float(np.clip(np.max(h), -1e3, 1e3)) if h.size else -1e3,
                    f"{key}_mi_g": float(np.clip(np.max(mi), -1e3, 1e3)) if mi.size else -1e3,
                    f"{key}_vmax_m": float(np.max(err[:, 0])), f"{key}_lmax_m": float(np.max(err[:, 1])),
                    f"{key}_hmi": float(np.sum(s.hazardous)), f"{key}_mi": float(np.sum(s.misleading)),
                    f"{key}_available": float(np.sum(s.available)), f"{key}_epochs": float(s.epochs),
                    f"{key}_detected": float(np.any(s.result.detected)),
                    f"{key}_detect_events": float(np.sum(s.result.detected & ~np.r_[False, s.result.detected[:-1]])),
                    f"{key}_excluded": float(s.excluded_channel)})
    win = settled & (ep.height_m >= min(cfg.dh_m(c) for c in REQUIREMENTS))
    z = ep.e0[win] / np.sqrt(np.maximum(ep.p0[win], 1e-18))
    out.update({"z2_v": float(np.sum(z[:, 0] ** 2)), "z2_l": float(np.sum(z[:, 1] ** 2)), "n_z": float(len(z)),
                "zmax": float(np.max(np.abs(z))) if z.size else 0.0})
    if ep.ek.shape[1]:
        d = (ep.ek[win] - ep.e0[win][:, None, :]) / np.sqrt(np.maximum(ep.pk[win] - ep.p0[win][:, None, :], 1e-18))
        out.update({"ss2": float(np.sum(d * d)), "n_ss": float(d.size)})
    else:
        out.update({"ss2": 0.0, "n_ss": 0.0})
    return out


def run_sample(profile: Any, seed: int, run: int, truths: int, mode_name: FaultMode | str | None, u: Sequence[float],
               sensor_modes: bool = False, confirm: bool = False) -> dict[str, float]:
    """One sample: the flown truth run % truths, the fault of `mode_name` (a FaultMode or its name) at u (None:
    fault-free; present before the run start: with its pre-approach segment, campaign/preapproach.py), the bank (with
    the baro, radar altimeter and pseudolites as fault modes too when `sensor_modes`), the limit states (and the
    fault's parameters); confirm: the second-level identification (bank.second_level). A sample that raises is
    returned with `failed` = 1 and every category's hmi_g = +1e3 (a failed navigation counts as the event:
    conservative)."""
    try:
        flown = flown_truth(profile, int(seed), int(run % truths))
        truth, t_lo, t_hi = flown.truth, flown.t_lo_s, flown.t_hi_s
        prof = profile
        params: dict = {}
        pre = None
        if mode_name is not None:
            mode = mode_name if isinstance(mode_name, FaultMode) else fault_mode(mode_name)
            spec, params = fault_spec(mode, np.asarray(u), profile, truth, seed, run, (t_lo, t_hi))
            prof = dataclasses.replace(profile, faults=(*tuple(profile.faults or ()), spec))
            pre = pre_fault(mode, params)
        ep, _ = run_bank(bank_profile(prof), truth, seed, run, sensor_modes_on=sensor_modes, memo=flown.memo,
                         pre=pre)
        out = limit_states(ep, profile.evaluation, profile.nav.aiding_rate_hz, float(truth.t_s[0]), confirm)
        return {**out, **{f"fault_{k}": float(v) for k, v in params.items()}, "failed": 0.0}
    except Exception as e:  # noqa: BLE001 - a failed sample is data (counted as the event), never dropped
        out = {f"{k}_hmi_g": 1e3 for k in CATEGORY_KEYS.values()}
        return {**out, "failed": 1.0, "error": f"{type(e).__name__}: {e}"}  # type: ignore[dict-item]


def _task(args: tuple) -> list[dict]:
    profile, seed, truths, mode_name, items, sensor_modes, confirm = args
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        return [run_sample(profile, seed, run, truths, mode_name, u, sensor_modes, confirm) for run, u in items]


class Simulator:
    """Batched evaluation of samples on a local process pool (fork; `workers` processes), in order."""

    def __init__(self, profile: Any, seed: int, truths: int = 4, workers: int = 1, sensor_modes: bool = False,
                 confirm: bool = False) -> None:
        if truths < 1 or workers < 1:
            raise ValueError("truths and workers must be >= 1")
        self.profile, self.seed, self.truths, self.workers = profile, int(seed), int(truths), int(workers)
        self.sensor_modes = bool(sensor_modes)
        self.confirm = bool(confirm)
        self._pool: ProcessPoolExecutor | None = None
        self.samples = 0
        self.wall_s = 0.0

    def __enter__(self) -> Simulator:
        if self.workers > 1:
            import multiprocessing

            register_pickling()
            self._pool = ProcessPoolExecutor(self.workers, mp_context=multiprocessing.get_context("fork"))
        return self

    def __exit__(self, *exc: object) -> None:
        if self._pool is not None:
            self._pool.shutdown(cancel_futures=True)
            self._pool = None

    def run(self, mode_name: FaultMode | str | None, runs: Sequence[int], u: Array) -> list[dict]:
        """The samples (runs[i], u[i]) of one mode, in order."""
        t = time.time()
        items = list(zip([int(r) for r in runs], np.asarray(u, float).tolist(), strict=True))
        if self._pool is None or len(items) < 2:
            out = _task((self.profile, self.seed, self.truths, mode_name, items, self.sensor_modes, self.confirm))
        else:
            n = max(1, math.ceil(len(items) / (4 * self.workers)))
            chunks = [items[i:i + n] for i in range(0, len(items), n)]
            out = [r for part in self._pool.map(
                _task, [(self.profile, self.seed, self.truths, mode_name, c, self.sensor_modes, self.confirm)
                        for c in chunks])
                for r in part]
        self.samples += len(items)
        self.wall_s += time.time() - t
        return out


def _columns(rows: Sequence[Mapping[str, Any]]) -> dict[str, Array]:
    keys = sorted({k for r in rows for k, v in r.items() if not isinstance(v, str)})
    return {k: np.array([float(r.get(k, math.nan)) for r in rows]) for k in keys}


# ---- one mode --------------------------------------------------------------------------------------------------



def sample_bins(mode: FaultMode, u: Array) -> tuple[Array, Array]:
    """(magnitude bin, onset bin) of each standard-normal sample u (N, dim): `FaultMode.magnitude_edges` and
    `FaultMode.onset_edges` over Phi(u_0) (thirds of the MFD before the window, when the mode has one, then
    `ONSET_BINS` thirds of the window)."""
    u = np.atleast_2d(np.asarray(u, float))
    edges = mode.magnitude_edges()
    mag = np.array([mode.magnitude(float(x)) for x in u[:, 1]]) if u.size else np.zeros(0)
    mb = np.clip(np.searchsorted(edges, mag, side="right") - 1, 0, len(edges) - 2)
    on = mode.onset_edges()
    cuts = np.array([e[1] for e in on[:-1]])
    ob = np.searchsorted(cuts, sps.norm.cdf(u[:, 0]), side="right") if u.size else mb
    return mb.astype(int), np.asarray(ob).astype(int)


def specific_risk(mode: FaultMode, first_u: Array, first_hit: Array, level: float, last_u: Array | None = None,
                  last_hit: Array | None = None, last_w: Array | None = None) -> dict:
    """P(HMI | magnitude bin, onset bin) of one mode and category, with one-sided Clopper-Pearson bounds at
    `level`, from the samples the estimator drew (module docstring, "Specific risk").

    The first step samples the fault's own distribution: per bin an unweighted count, exact Clopper-Pearson. The
    last adaptive step (NAIS; None for mc or a one-step run) samples a proposal concentrated on the failure region:
    per bin the likelihood-ratio-weighted conditional with Kish's effective sample size (rare.weighted_conditional,
    approximate bounds). A bin's figure is the one of the two with the larger (effective) sample size: a choice by
    size, not by outcome, so each bin keeps its level. The worst bin is the one with the largest upper bound; its
    upper bound is an upper bound of max over bins of P(HMI | bin) at `level` (the true worst bin's own bound is
    no larger). A bin with few samples has a wide bound (0 of n: 1 - (1 - level)^(1/n), 0.087 at n = 33)."""
    edges = mode.magnitude_edges()
    onsets = mode.onset_edges()
    fb = sample_bins(mode, first_u)
    first_hit = np.asarray(first_hit, bool)
    lb = sample_bins(mode, last_u) if last_u is not None else None
    bins = []
    for i in range(len(edges) - 1):
        for j, (f_lo, f_hi, label) in enumerate(onsets):
            sel = (fb[0] == i) & (fb[1] == j)
            k, n = int(np.sum(first_hit[sel])), int(np.sum(sel))
            lo, hi = rare.clopper_pearson(k, n, level)
            first = {"hits": k, "samples": n, "probability": k / n if n else None, "lower": lo, "upper": hi}
            last = None
            if lb is not None and last_hit is not None and last_w is not None:
                s2 = (lb[0] == i) & (lb[1] == j)
                last = rare.weighted_conditional(np.asarray(last_hit, bool)[s2], np.asarray(last_w, float)[s2],
                                                 level)
            use_last = last is not None and last["n_eff"] > n
            used = last if use_last else first
            third = j - (len(onsets) - ONSET_BINS) + 1
            bins.append({"magnitude": [edges[i], edges[i + 1]], "onset": label,
                         "onset_third": third if third >= 1 else None,
                         "onset_fraction": [f_lo, f_hi],
                         "bin_probability": mode.magnitude_fraction(edges[i], edges[i + 1]) * (f_hi - f_lo),
                         "probability": used["probability"], "lower": used["lower"], "upper": used["upper"],
                         "from": "last_step_weighted" if use_last else "first_step",
                         "first_step": first, "last_step": last})
    worst = max(range(len(bins)), key=lambda b: (bins[b]["upper"], bins[b]["probability"] or 0.0))
    ns = [b["first_step"]["samples"] for b in bins]
    return {"bins": bins, "worst_bin": worst, "worst_upper": bins[worst]["upper"],
            "worst_lower": max(b["lower"] for b in bins),
            "first_step_samples_per_bin": {"min": min(ns), "max": max(ns)}}


MODE_OFFSET = 1_000_000
"""Run indices of mode k's samples start at (k + 1) * MODE_OFFSET (fault-free: at 0), so no two samples of a
study share noise streams."""


def estimate_mode(sim: Simulator, mode: FaultMode, index: int, *, categories: Sequence[str], method: str,
                  samples: int, max_calls: int, level: float, seed: int,
                  event: Callable[[Mapping[str, Array]], Array] | None = None) -> dict:
    """P(HMI | fault of `mode`) per category: the estimator on the union of the categories' HMI events (or
    `event`, a function of the sample columns giving g), then each category reweighted on the last step."""
    counter = [0]
    store: list[dict] = []
    rows_of: dict[bytes, dict] = {}

    def g(u: Array) -> Array:
        runs = (index + 1) * MODE_OFFSET + counter[0] + np.arange(u.shape[0])
        counter[0] += u.shape[0]
        rows = sim.run(mode, runs, u)
        for x, r in zip(u, rows, strict=True):
            rows_of[np.asarray(x, float).tobytes()] = r
        store.extend(rows)
        cols = _columns(rows)
        if event is not None:
            return np.asarray(event(cols), float)
        return np.max(np.stack([cols[f"{CATEGORY_KEYS[c]}_hmi_g"] for c in categories]), axis=0)

    t = time.time()
    est, last = rare.estimate(g, mode.dim, method=method, samples=samples, seed=seed, level=level,
                              max_calls=max_calls)
    last_rows = [rows_of.get(np.asarray(x, float).tobytes(), {}) for x in last["u"]]
    first_rows = [rows_of.get(np.asarray(x, float).tobytes(), {}) for x in last["first_u"]]
    lc, fc = _columns(last_rows), _columns(first_rows)
    per_cat = {}
    for cat in REQUIREMENTS:
        key = CATEGORY_KEYS[cat]
        if f"{key}_hmi_g" not in lc:
            continue
        ind = lc[f"{key}_hmi_g"] > 0.0
        first = int(np.sum(fc[f"{key}_hmi_g"] > 0.0))
        mc_hi = rare.clopper_pearson(first, len(first_rows), level)[1]
        if est.shown or est.steps == 1:
            r = rare.reweight(ind, last["w"], level)
        else:
            r = {"probability": None, "sd": None, "cov": None, "hits": int(ind.sum()), "samples": int(ind.size),
                 "lower": 0.0, "upper": None, "shown": False}
        if not r["shown"]:  # the first step samples the fault distribution itself: its Clopper-Pearson bound
            r["upper"] = mc_hi
            r["bound"] = f"first step's Monte Carlo: {first} of {len(first_rows)}"
        else:
            r["bound"] = "importance sampling (normal interval)"
        r["mi_first_step"] = int(np.sum(fc.get(f"{key}_mi_g", np.zeros(1)) > 0.0))
        one_sample = est.steps == 1 or last["u"] is last["first_u"] or not np.all(np.isfinite(last["w"]))
        r["specific"] = specific_risk(
            mode, np.asarray(last["first_u"]), fc.get(f"{key}_hmi_g", np.full(len(first_rows), -1.0)) > 0.0, level,
            *((None, None, None) if one_sample else (np.asarray(last["u"]), ind, np.asarray(last["w"]))))
        per_cat[cat] = r
    allc = _columns(store)
    _, t_lo, t_hi = flight_truth(sim.profile, sim.seed, 0)
    dp = None
    if est.design_point_u is not None:
        u = np.asarray(est.design_point_u)
        dp = {"u": [float(x) for x in u], "onset_fraction": float(sps.norm.cdf(u[0])),
              "onset_s_before_lowest_dh": float(t_hi - mode.onset(float(sps.norm.cdf(u[0])), (t_lo, t_hi))),
              "magnitude": mode.magnitude(float(u[1])), "unit": "m/s" if mode.kind == "ramp" else "m"}
    n_ch = allc.get("fault_n_channels", np.array([1.0]))
    per_unit = mode.prior_per_approach(t_hi - t_lo)
    prior = per_unit * (float(np.nanmax(n_ch)) if mode.has_channel else 1.0)  # per satellite / unit
    age = allc.get("fault_age_at_start_s", np.zeros(1))
    return {"mode": mode.name, "sensor": mode.sensor, "kind": mode.kind,
            "range": [mode.low, mode.high], "unit": "m/s" if mode.kind == "ramp" else "m",
            "prior": prior, "prior_mark": mode.prior_mark, "prior_source": mode.prior_source,
            "prior_state": mode.prior, "mean_fault_duration_s": mode.mfd_s, "mfd_mark": mode.mfd_mark,
            "onset_window_s": t_hi - t_lo, "pre_fraction": mode.pre_fraction,
            "prior_per_unit_per_approach": per_unit,
            "present_at_start_fraction": float(np.mean(age > 0.0)) if age.size else 0.0,
            "estimator": est.as_dict(), "categories": per_cat, "worst_profile": dp,
            "samples": len(store), "failed_samples": int(np.nansum(allc.get("failed", np.zeros(1)))),
            "first_error": next((r["error"] for r in store if r.get("error")), None),
            "wall_s": time.time() - t,
            "detected_fraction_first_step": float(np.nanmean(fc.get("cat1_detected", np.full(1, np.nan))))}


def fault_free(sim: Simulator, runs: int, level: float) -> dict:
    """The fault-free term per category (module docstring) from `runs` simulated fault-free runs; also the
    plain Monte Carlo HMI / MI counts and the false-alert rate per 15 s with its Poisson bound."""
    t = time.time()
    rows = sim.run(None, np.arange(runs), np.zeros((runs, 1)))
    c = _columns(rows)
    ok = c.get("failed", np.zeros(runs)) == 0
    n_ok = int(ok.sum())
    s_v = rare.rms_scale_upper(c["z2_v"][ok], c["n_z"][ok], n_ok, level)
    s_l = rare.rms_scale_upper(c["z2_l"][ok], c["n_z"][ok], n_ok, level)
    s_ss = rare.rms_scale_upper(c["ss2"][ok], c["n_ss"][ok], n_ok, level) if np.nansum(c["n_ss"]) else math.nan
    out = {"runs": runs, "failed_runs": runs - n_ok, "wall_s": time.time() - t,
           "normalized_error_rms": {"vertical": _rms(c["z2_v"][ok], c["n_z"][ok]),
                                    "lateral": _rms(c["z2_l"][ok], c["n_z"][ok]),
                                    "separation": _rms(c["ss2"][ok], c["n_ss"][ok])},
           "normalized_error_rms_upper": {"vertical": s_v, "lateral": s_l, "separation": s_ss},
           "largest_normalized_error": float(np.nanmax(c["zmax"][ok])) if n_ok else None, "categories": {}}
    for cat, req in REQUIREMENTS.items():
        key = CATEGORY_KEYS[cat]
        k_ff = req.k_ff()
        # per run: N_es x (2 Q(r_v / s_v) + 2 Q(r_l / s_l)), r the smallest AL / sigma over its available epochs
        # (AL >= PL >= K_ff sigma there, so r >= K_ff); the mean over the runs estimates the per-approach risk
        s_vv, s_ll = max(s_v, 1.0), max(s_l, 1.0)
        per_run = np.minimum(1.0, req.n_es * 2.0 * (sps.norm.sf(c[f"{key}_rmin_v"][ok] / s_vv)
                                                    + sps.norm.sf(c[f"{key}_rmin_l"][ok] / s_ll)))
        p_hmi = float(np.mean(per_run)) if n_ok else 1.0
        p_hmi_max = float(np.max(per_run)) if n_ok else 1.0
        scale = max(s_vv, s_ll)
        ep = float(np.nansum(c[f"{key}_epochs"][ok]))
        windows = ep / 15.0
        ev = float(np.nansum(c[f"{key}_detect_events"][ok]))
        n_tests = 2 * max(1, int(round(np.nanmedian(c["n_ss"][ok] / np.maximum(c["n_z"][ok], 1) / 2)))) if n_ok else 2
        k_fa = req.k_fa(1.0, n_tests)
        fa = min(1.0, req.continuity_risk_per_15s * float(sps.norm.sf(k_fa / max(s_ss, 1.0)) / sps.norm.sf(k_fa)))
        out["categories"][cat] = {
            "hmi_gaussian": p_hmi, "hmi_gaussian_worst_run": p_hmi_max, "k_ff": k_ff, "n_es": req.n_es,
            "scale_used": {"vertical": s_vv, "lateral": s_ll},
            "hmi_gaussian_at_k_ff": min(1.0, req.n_es * 4.0 * float(sps.norm.sf(k_ff / scale))),
            "hmi_epochs_mc": int(np.nansum(c[f"{key}_hmi"][ok])), "mi_epochs_mc": int(np.nansum(c[f"{key}_mi"][ok])),
            "epochs_mc": int(ep),
            "false_alert": {"alerts": int(ev), "windows_15s": windows,
                            "rate_per_15s_upper_mc": float(sps.chi2.ppf(level, 2 * ev + 2) / 2.0 / windows)
                            if windows else None,
                            "rate_per_15s_gaussian": fa, "k_fa": k_fa, "tests_per_epoch": n_tests,
                            "allocation_per_15s": req.continuity_risk_per_15s}}
    return out


def _rms(s2: Array, n: Array) -> float | None:
    tot = float(np.nansum(n))
    return math.sqrt(float(np.nansum(s2)) / tot) if tot > 0 else None


def integrity_risk(profile: Any, *, modes: Sequence[str] | None = None, method: str = "nais", samples: int = 200,
                   max_calls: int | None = None, seed: int = 1, truths: int = 4, workers: int | None = None,
                   fault_free_runs: int = 100, level: float | None = None, sensor_modes: bool = False,
                   second_level: bool = False, log: Callable[[str], None] | None = None) -> dict:
    """The integrity-risk study of a profile (module docstring): the fault-free term, each mode's conditional
    estimate, the totals per category against the allocations. JSON-ready."""
    level = profile.evaluation.confidence if level is None else level
    ms = modes_for(profile, modes)
    cats = list(REQUIREMENTS)
    max_calls = max_calls if max_calls is not None else 8 * samples
    workers = workers or os.cpu_count() or 1
    say = log or (lambda s: None)
    t0 = time.time()
    out: dict = {"schema": "approachsim.integrity_risk/2", "profile": profile.name, "seed": seed,
                 "method": method, "samples_per_step": samples, "max_calls_per_mode": max_calls, "truths": truths,
                 "confidence": level, "bank_sensor_modes": bool(sensor_modes),
                 "bank_second_level": bool(second_level), "modes": {}}
    with Simulator(profile, seed, truths, workers, sensor_modes, second_level) as sim:
        say(f"fault-free: {fault_free_runs} runs")
        out["fault_free"] = fault_free(sim, fault_free_runs, level)
        _, t_lo, t_hi = flight_truth(profile, seed, 0)
        ms = [m.with_window(t_hi - t_lo) for m in ms]  # the pre-approach share of the onsets (FaultMode.onset)
        for m in ms:
            i = list(MODES).index(m.name)  # run indices and estimator seed by the mode, not its place in the list
            say(f"{m.name}: {method}, {samples} samples per step")
            r = estimate_mode(sim, m, i, categories=cats, method=method, samples=samples, max_calls=max_calls,
                              level=level, seed=seed * 7919 + i)
            out["modes"][m.name] = r
            say(f"{m.name}: " + ", ".join(
                f"{c} p={_fmt(v.get('probability'))} up={_fmt(v.get('upper'))}" for c, v in r["categories"].items())
                + f" ({r['samples']} samples, {r['wall_s']:.0f} s)")
        out["samples"] = sim.samples
    out["wall_s"] = time.time() - t0
    out["categories"] = totals(out, level)
    return out


def _fmt(x: Any) -> str:
    return "-" if x is None else f"{x:.2g}"


def totals(study: Mapping[str, Any], level: float) -> dict:
    """Per category: P(HMI) = fault-free + sum_k prior_k P(HMI | k), its bounds (sums of the terms' one-sided
    bounds: each term's bound at `level`, so the sum's coverage is at least 1 - sum of the misses: the union bound
    is stated, not a joint level), the allocation and the verdict (module docstring). The upper sum and `verdict`
    are the specific risk's (each mode's worst bin's upper bound x its prior, "Specific risk" in the module
    docstring); `p_hmi_average_upper` and `verdict_average` the same with the average over the magnitude law.
    `exceeds` comes from the average's lower bound in both (the average is at most the worst case, so it is a lower
    bound on the specific risk too)."""
    out = {}
    for cat, req in REQUIREMENTS.items():
        ff = study["fault_free"]["categories"][cat]
        p, lo, hi, complete = ff["hmi_gaussian"], 0.0, ff["hmi_gaussian_worst_run"], True
        hi_avg = hi
        hi_src, lo_src, unsourced = hi, 0.0, []
        terms = {"fault_free": {"probability": ff["hmi_gaussian"], "upper": ff["hmi_gaussian_worst_run"],
                                "how": "Gaussian tail with the measured overbound; upper: the worst run's"}}
        for name, m in study["modes"].items():
            c = m["categories"].get(cat)
            if c is None:
                continue
            prior = m["prior"]
            up = c.get("upper")
            pr = c.get("probability") if c.get("shown") else None
            sp = c.get("specific")
            # specific risk: the worst (magnitude, onset) bin's upper bound (without bins: the average's, or 1); never
            # below the average's upper bound (the worst case is at least the average)
            a_up = up if up is not None else 1.0
            w_up = max(sp["worst_upper"], a_up) if sp is not None else a_up
            terms[name] = {"prior": prior, "conditional": pr, "conditional_upper": up,
                           "probability": None if pr is None else prior * pr,
                           "upper": None if up is None else prior * up, "shown": bool(c.get("shown")),
                           "worst_bin_conditional_upper": w_up, "specific_upper": prior * w_up,
                           "specific_shown": prior * w_up <= req.integrity_risk}
            if sp is not None:
                wb = sp["bins"][sp["worst_bin"]]
                terms[name]["worst_bin"] = {k: wb[k] for k in ("magnitude", "onset", "onset_third", "probability",
                                                               "lower", "upper", "from")}
                terms[name]["worst_bin"]["samples"] = (wb["first_step"]["samples"] if wb["from"] == "first_step"
                                                       else wb["last_step"]["n_eff"])
                terms[name]["smallest_bin_probability"] = min(b["bin_probability"] for b in sp["bins"])
            hi_avg = hi_avg + (prior * up if up is not None else prior)
            hi = hi + prior * w_up
            lo = lo + (prior * c["lower"] if c.get("shown") else 0.0)
            terms[name]["prior_mark"] = m.get("prior_mark", "U")
            if terms[name]["prior_mark"] == "U":  # an assumed prior: the term is "not shown", whatever its bound
                unsourced.append(name)
                terms[name]["term_verdict"] = "not shown (prior assumed [U]: see prior_allowed)"
            else:
                hi_src += prior * w_up
                lo_src += prior * c["lower"] if c.get("shown") else 0.0
                terms[name]["term_verdict"] = "shown" if terms[name]["specific_shown"] else "not shown"
            p = p + (prior * pr if pr is not None else 0.0)
            complete = complete and c.get("shown", False)
        alloc = req.integrity_risk
        # a windowed category (CAT II / III: 15 s / 30 s before the DH) is simulated over the whole approach: its
        # lower bound is no lower bound on the windowed event, so it never `exceeds` (issue 41 item 1)
        can_exceed = req.hmi_window_s() is None
        verdict_assumed = "shown" if hi <= alloc else ("exceeds" if can_exceed and lo > alloc else "not shown")
        verdict_avg = "shown" if hi_avg <= alloc else ("exceeds" if can_exceed and lo > alloc else "not shown")
        # the verdict: on the sourced priors; a term whose prior is assumed [U] keeps the category at most "not shown"
        verdict_src = "shown" if hi_src <= alloc else ("exceeds" if can_exceed and lo_src > alloc else "not shown")
        verdict = "not shown" if verdict_src == "shown" and unsourced else verdict_src
        # a term bounded only by its first step's Monte Carlo: the first-step size that would bound it, with no HMI
        # sample, by an equal share of the allocation (Clopper-Pearson at 0 hits: 1 - (1 - level)^(1 / n))
        share = alloc / max(1, len(terms))
        for name, tm in terms.items():
            if name == "fault_free":
                continue
            # the largest prior at which this term's upper bound stays within its equal share: what the fault
            # rate of a source without a sourced prior must be shown to be for this term not to decide the verdict
            up = tm["conditional_upper"]
            tm["prior_allowed_average"] = share / up if up is not None and up > 0.0 else None
            w_up = tm["worst_bin_conditional_upper"]
            tm["prior_allowed"] = share / w_up if w_up > 0.0 else None
            if not tm["shown"] and tm["prior"] > share:
                tm["first_step_needed"] = math.ceil(math.log(1.0 - level) / math.log1p(-share / tm["prior"]))
            if not tm["specific_shown"] and tm["prior"] > share and "smallest_bin_probability" in tm:
                # specific risk: that many first-step runs in every bin, the smallest bin getting its share
                n_bin = math.ceil(math.log(1.0 - level) / math.log1p(-share / tm["prior"]))
                tm["first_step_needed_specific"] = math.ceil(n_bin / tm["smallest_bin_probability"])
        fa = study["fault_free"]["categories"][cat]["false_alert"]
        fa_up = max(fa["rate_per_15s_gaussian"], 0.0)
        out[cat] = {"p_hmi": p, "p_hmi_lower": lo, "p_hmi_upper": hi, "allocation": alloc,
                    "allocation_unit": "per approach" if req.exposure_s >= 150 else "per 15 s",
                    "verdict": verdict, "verdict_sourced": verdict_src, "p_hmi_upper_sourced": hi_src,
                    "p_hmi_lower_sourced": lo_src, "unsourced_terms": unsourced,
                    "verdict_assumed": verdict_assumed, "p_hmi_average_upper": hi_avg, "verdict_average": verdict_avg,
                    "every_term_estimated": complete, "terms": terms,
                    "p_false_alert_per_15s_gaussian": fa_up,
                    "p_false_alert_per_15s_upper_mc": fa["rate_per_15s_upper_mc"],
                    "false_alert_allocation_per_15s": fa["allocation_per_15s"],
                    "false_alert_verdict": "shown" if fa_up <= fa["allocation_per_15s"] else "not shown"}
    return out
