"""Integrity in a campaign: one run's integrity scalars from the solution-separation bank, and their campaign
statistics for details.json.

Per run (run_integrity): the bank (campaign.integrity_bank.run_bank, the main filter and one sub-filter per used GNSS
channel, open loop on the run's truth; in closed loop the flown truth) is scored per category at the filter
epochs from evaluation.timeavg_settle_s after the run start down to the category's decision height
(bank.score_category: H0 / H1 protection levels on the vertical and lateral approach axes with the category's
K factors, Annex 10 alert limits at the aircraft's distance and height, exclusion at the first detection).
Scalars, prefix `<cat key>_int_`: epochs, available epochs, available at the DH (the last epoch of the
window), misleading (MI: output error > PL) and hazardously misleading (HMI: error > AL while PL < AL) epochs,
HMI in the category's window before the DH (hmi_window_scalars: CAT II / III the last 15 s vertical / 30 s
lateral; CAT I the approach), the bank's fault-mode count,
Stanford region counts per axis, detection epochs and detection onsets (a false alert when no fault was
injected), the excluded channel, and for the first injected fault ([[faults]]) its onset, the delay from the
onset to the detection, the time to alert (detection minus the first epoch at which the unprotected main
solution's error exceeded its protection level: negative when detected before; inf when it exceeded and
nothing was detected, a missed detection) and whether the excluded channel is the faulted one. With the
online FDE on ([nav.fde]): its alert epochs, exclusions and delay (`fde_`). Per run also a (error, PL)
histogram per category and axis (`counts`, summed over runs into the Stanford diagrams) and, on the height
grid of score.HEIGHT_GRID_FT, the availability margin min(AL - PL) and the distance to the threshold.

Campaign (campaign_integrity): per category availability (fraction of epochs, and of runs at the DH) with
Clopper-Pearson one-sided bounds; MI, HMI and false alerts counted per approach (a run: its ~250 epochs are
strongly correlated and are not independent samples), each with Clopper-Pearson bounds of its per-approach
probability (HMI against the allocation per approach, false alerts against the continuity allocation over the
approach's scored time); the epoch counts and per-epoch rates of before are kept beside them for comparison
(optimistic by about the correlation length in epochs); time-to-alert statistics with missed detections, the
time to alert counted from error > PL (TTA_DEFINITION), and the missed-detection probability P_md the allocation
asks per fault mode (requirements.p_md with the bank's mode count), not a fixed 99 %.
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Mapping, Sequence
from typing import Any

import numpy as np
from scipy import stats as sps

from approachsim.campaign.integrity_bank import BankEpochs, CategoryIntegrity, run_bank, score_category
from approachsim.evaluate.dh import interp_on_height
from approachsim.integrity.requirements import REQUIREMENTS, describe
from approachsim.memo import TruthMemo
from approachsim.sensors.suite import SensorSuite

Array = np.ndarray

CATEGORY_KEYS = {"CAT I": "cat1", "CAT II": "cat2", "CAT III": "cat3"}
"""Column prefix of each category (as evaluate.score)."""

STANFORD_EDGES_M = np.logspace(-2.0, 3.0, 41)
"""Bin edges of the per-run (error, protection level) histograms, m (both axes; values outside are put in
the end bins, a PL of inf in the last)."""
NB = STANFORD_EDGES_M.size - 1

TTA_DEFINITION = ("detection time minus the first epoch at which the unprotected main solution's error exceeded its "
                  "protection level (error > PL); stricter than the standard's time to alert, which counts from "
                  "error > alert limit (ICAO Annex 10 / DO-245A), since PL < AL wherever the service is available")
"""What `time_to_alert` measures (details.json), in words a report can print."""

REGIONS = ("normal", "mi", "hmi", "unavailable")
"""Stanford regions counted per axis (standards.md 1.6): available PE <= PL; MI PL < PE <= AL; HMI PE > AL
while available; unavailable PL >= AL."""


def _bin(x: Array) -> Array:
    x = np.nan_to_num(np.asarray(x, float), nan=STANFORD_EDGES_M[-1], posinf=STANFORD_EDGES_M[-1])
    return np.clip(np.searchsorted(STANFORD_EDGES_M, x, side="right") - 1, 0, NB - 1)


def stanford_hist(err_m: Array, pl_m: Array) -> Array:
    """(NB * NB,) counts of epochs per (|error| bin, PL bin), row-major (error index first)."""
    i, j = _bin(np.abs(err_m)), _bin(pl_m)
    return np.bincount(i * NB + j, minlength=NB * NB).astype(float)


def stanford_counts(err_m: Array, pl_m: Array, al_m: Array) -> dict[str, int]:
    """Epochs in each Stanford region of one axis."""
    e, pl, al = np.abs(np.asarray(err_m, float)), np.asarray(pl_m, float), np.asarray(al_m, float)
    avail = pl < al
    return {"normal": int(np.sum(avail & (e <= pl))), "mi": int(np.sum(avail & (e > pl) & (e <= al))),
            "hmi": int(np.sum(avail & (e > al))), "unavailable": int(np.sum(~avail))}


def bank_profile(profile: Any) -> Any:
    """The profile the bank navigates with: the online FDE off (the bank's own separation test detects and
    excludes; an online exclusion inside copy 0 would hide the fault from the separation)."""
    fde = profile.nav.fde
    if not fde.enabled:
        return profile
    nav = dataclasses.replace(profile.nav, fde=dataclasses.replace(fde, enabled=False))
    return dataclasses.replace(profile, nav=nav)


def first_fault(profile: Any, channel_prn: Array | None = None) -> tuple[float, int]:
    """(onset s, faulted GNSS channel index or -1) of the profile's earliest declared fault; (nan, -1) when none."""
    faults = tuple(getattr(profile, "faults", ()) or ())
    if not faults:
        return math.nan, -1
    f = min(faults, key=lambda f: f.start_s)
    ch = -1
    if f.sensor == "gnss" and f.channel is not None and channel_prn is not None:
        hits = np.flatnonzero(np.asarray(channel_prn) == f.channel)
        ch = int(hits[0]) if hits.size else -1
    return float(f.start_s), ch


def hmi_window_scalars(s: CategoryIntegrity, t: Array, req: Any) -> dict[str, float]:
    """HMI in the category's window before the DH (issue 41): `hmi_window` 1 when an epoch within the last
    req.hmi_window_s() = (15, 30) s (vertical, lateral) before the last epoch above the DH had the output's error on
    that axis beyond its alert limit while the service was available (PL < AL on both axes), else 0;
    `hmi_window_epochs` the count of such epochs. CAT I (no window: per approach): any HMI epoch of the approach."""
    err = np.abs(s.err_m) if s.err_m is not None else np.zeros_like(s.al_m)
    haz = (err > s.al_m) & s.available[:, None]  # (e, 2) per axis
    w = req.hmi_window_s()
    if w is None:
        inside = np.ones_like(haz)
    else:
        age = t[-1] - t  # seconds before the last epoch above the DH
        inside = np.stack([age < w[0], age < w[1]], axis=1)
    n = int(np.sum(np.any(haz & inside, axis=1)))
    return {"hmi_window": float(n > 0), "hmi_window_epochs": float(n)}


def _fault_scalars(s: CategoryIntegrity, t: Array, onset_s: float, fault_ch: int) -> dict[str, float]:
    """Delay, time to alert, exceeded / missed and right exclusion of one category for the injected fault."""
    if not math.isfinite(onset_s):
        return {}
    after = s.result.detected & (t >= onset_s)
    delay = float(t[np.argmax(after)] - onset_s) if after.any() else math.nan
    exceeded = math.isfinite(s.time_to_alert_s) or s.time_to_alert_s == math.inf
    return {"onset_s": onset_s, "delay_s": delay, "tta_s": s.time_to_alert_s, "exceeded": float(exceeded),
            "missed": float(s.time_to_alert_s == math.inf),
            "right": float(fault_ch >= 0 and s.excluded_channel == fault_ch)}


def _fde_scalars(nav: Any, t_epoch_s: Array, t_nav_s: Array, onset_s: float, fault_ch: int) -> dict[str, float]:
    """Online FDE (NavSolution.alert / exclusions), when it ran."""
    if nav is None or getattr(nav, "alert", None) is None:
        return {}
    j = np.clip(np.searchsorted(t_nav_s, t_epoch_s), 0, len(t_nav_s) - 1)
    ex = tuple(nav.exclusions)
    out = {"fde_alert_epochs": float(np.sum(np.asarray(nav.alert)[j])), "fde_epochs": float(len(j)),
           "fde_exclusions": float(len(ex)),
           "fde_first_exclusion_s": float(ex[0].t_s) if ex else math.nan}
    if math.isfinite(onset_s):
        late = [e for e in ex if e.t_s >= onset_s]
        out["fde_delay_s"] = float(late[0].t_s - onset_s) if late else math.nan
        out["fde_right"] = float(bool(late) and fault_ch >= 0 and late[0].channel == fault_ch)
    return out


def run_integrity(ep: BankEpochs, cfg: Any, *, epoch_hz: float, t0_s: float, onset_s: float = math.nan,
                  fault_ch: int = -1, nav: Any = None, height_grid_m: Array | None = None
                  ) -> tuple[dict[str, float], dict[str, Array], dict[str, Array]]:
    """(scalars, counts, arrays) of one run (module docstring); cfg: the EvaluationConfig."""
    scalars: dict[str, float] = {}
    counts: dict[str, Array] = {}
    arrays: dict[str, Array] = {}
    settled = ep.t_s >= t0_s + cfg.timeavg_settle_s
    for cat, req in REQUIREMENTS.items():
        key = CATEGORY_KEYS[cat]
        win = settled & (ep.height_m >= cfg.dh_m(cat))
        if not win.any():
            raise ValueError(f"integrity: no filter epoch between the settle time and the {cat} decision height")
        s = score_category(ep, req, epoch_hz, win)
        t = ep.t_s[win]
        err = np.abs(ep.e0[win])
        if s.excluded_channel != -1:  # the output after the exclusion is the excluded sub-solution
            k = int(np.nonzero(ep.channels == s.excluded_channel)[0][0])
            i = int(np.argmax(s.result.detected))
            err[i:] = np.abs(ep.ek[win][i:, k])
        det = s.result.detected
        v = {"epochs": float(s.epochs), "avail_epochs": float(np.sum(s.available)),
             "avail_dh": float(s.available[-1]), "mi": float(np.sum(s.misleading)),
             "hmi": float(np.sum(s.hazardous)), "detect_epochs": float(np.sum(det)),
             "detect_events": float(np.sum(det & ~np.r_[False, det[:-1]])),
             "excluded_channel": float(s.excluded_channel), "t_detect_s": s.t_detect_s,
             "vpl_dh_m": float(s.pl_m[-1, 0]), "lpl_dh_m": float(s.pl_m[-1, 1]),
             "vert_dh_m": float(err[-1, 0]), "lat_dh_m": float(err[-1, 1]), "modes": float(ep.ek.shape[1])}
        for a, name in ((0, "v"), (1, "l")):
            for reg, c in stanford_counts(err[:, a], s.pl_m[:, a], s.al_m[:, a]).items():
                v[f"{name}_{reg}"] = float(c)
            counts[f"{key}_stanford_{name}"] = stanford_hist(err[:, a], s.pl_m[:, a])
        v.update(hmi_window_scalars(s, t, req))
        v.update(_fault_scalars(s, t, onset_s, fault_ch))
        scalars.update({f"{key}_int_{k}": x for k, x in v.items()})
        if height_grid_m is not None:
            margin = np.full(ep.t_s.shape, np.nan)
            margin[win] = np.min(s.al_m - s.pl_m, axis=1)
            arrays[f"{key}_int_margin_m"] = interp_on_height(ep.height_m, margin, height_grid_m)
    if height_grid_m is not None:
        arrays["int_distance_m"] = interp_on_height(ep.height_m, -ep.along_m, height_grid_m)
    if nav is not None:
        scalars.update(_fde_scalars(nav, ep.t_s, np.asarray(nav.t_s), onset_s, fault_ch))
    return scalars, counts, arrays


def score_with_bank(profile: Any, truth: Any, seed: int, run: int, nav: Any = None,
                    height_grid_m: Array | None = None, group: tuple[Any, int] | None = None,
                    memo: TruthMemo | None = None) -> tuple[dict[str, float], dict[str, Array], dict[str, Array]]:
    """Run the bank open loop on `truth` for run `run` of the campaign seeded `seed` and score it
    (run_integrity); nav: the run's own NavSolution (online FDE records), if any; group: what its open-loop
    flight group's pass left for it, memo: the truth's TruthMemo (run_bank)."""
    ep, main = run_bank(bank_profile(profile), truth, seed, run, group=group, memo=memo)
    prn = getattr(SensorSuite.from_profile(profile).sensors.get("gnss"), "constellation", None)
    onset, ch = first_fault(profile, None if prn is None else prn.prn)
    return run_integrity(ep, profile.evaluation, epoch_hz=profile.nav.aiding_rate_hz, t0_s=float(truth.t_s[0]),
                         onset_s=onset, fault_ch=ch, nav=nav, height_grid_m=height_grid_m)


# ---- campaign statistics -------------------------------------------------------------------------------------


def _cp(k: float, n: float, level: float) -> tuple[float, float]:
    """One-sided Clopper-Pearson (lower, upper) bounds, each at `level`, of a proportion k / n."""
    k, n = int(round(k)), int(round(n))
    if n <= 0:
        return 0.0, 1.0
    lo = 0.0 if k == 0 else float(sps.beta.ppf(1.0 - level, k, n - k + 1))
    hi = 1.0 if k >= n else float(sps.beta.ppf(level, k + 1, n - k))
    return lo, hi


def poisson_upper(k: float, level: float) -> float:
    """One-sided upper bound, at `level`, of a Poisson mean from k observed events: chi2.ppf(level, 2k+2) / 2."""
    return float(sps.chi2.ppf(level, 2 * int(round(k)) + 2) / 2.0)


def _num(x: Any) -> float | int | None:
    if x is None:
        return None
    x = float(x)
    if not math.isfinite(x):
        return None
    return int(x) if x.is_integer() and abs(x) < 1e15 else x


def _dist(x: Array) -> dict | None:
    x = np.asarray(x, float)
    x = x[np.isfinite(x)]
    if not x.size:
        return None
    return {"n": int(x.size), "median": _num(np.median(x)), "p95": _num(np.percentile(x, 95)),
            "min": _num(x.min()), "max": _num(x.max())}


def _sparse(h: Array) -> list[list[int]]:
    """[[error bin, PL bin, count], ...] of the nonzero cells."""
    h = np.asarray(h, float).reshape(NB, NB)
    i, j = np.nonzero(h)
    return [[int(a), int(b), int(h[a, b])] for a, b in zip(i, j, strict=True)]


def campaign_integrity(columns: Mapping[str, Array], counts: Mapping[str, Array], cfg: Any, *,
                       verdicts: Mapping[str, Any] | None = None, faulted: bool | None = None) -> dict:
    """details.json `integrity`: per category (module docstring); columns: per-run scalars of the completed
    runs; counts: the histograms summed over them; verdicts: category -> verdict.IntegrityVerdict (the
    categories in the verdict). faulted: faults injected (None: from the presence of onset columns)."""
    level = cfg.confidence
    epoch_hz = 1.0
    out: dict = {"categories_in_verdict": list(cfg.integrity), "confidence": level,
                 "protection_levels": "solution separation (H0 / H1), vertical and lateral, approach frame",
                 "stanford_edges_m": [float(x) for x in STANFORD_EDGES_M]}
    cats = {}
    for cat, req in REQUIREMENTS.items():
        key = CATEGORY_KEYS[cat]

        def col(name: str, key: str = key) -> Array:
            return np.asarray(columns.get(f"{key}_int_{name}", np.empty(0)), float)

        ep = col("epochs")
        if not ep.size:
            continue
        n_ep, n_av = float(np.nansum(ep)), float(np.nansum(col("avail_epochs")))
        dh = col("avail_dh")
        lo, hi = _cp(n_av, n_ep, level)
        dlo, dhi = _cp(np.nansum(dh), dh.size, level)
        is_faulted = (f"{key}_int_onset_s" in columns) if faulted is None else faulted
        allowed = req.hmi_rate_per_epoch(epoch_hz)
        n_runs = int(ep.size)
        modes = col("modes")
        modes = modes[np.isfinite(modes)]
        n_modes = max(1, int(np.median(modes))) if modes.size else 1  # the bank's fault modes (a typical run)
        entry: dict = {
            "in_verdict": cat in cfg.integrity,
            "requirement": {**{k: _num(v) for k, v in describe(req, n_modes=n_modes).items()},
                            "hmi_probability_allowed": req.hmi_probability_allowed,
                            "hmi_window_s": None if req.hmi_window_s() is None else list(req.hmi_window_s()),
                            "model": req.model, "source": req.source,
                            "availability_covers": req.availability_covers,
                            "integrity_risk": req.integrity_risk, "exposure_s": req.exposure_s,
                            "continuity_risk_per_15s": req.continuity_risk_per_15s,
                            "availability": req.availability, "hmi_rate_per_epoch_allowed": allowed},
            "runs": int(ep.size), "epochs": int(n_ep),
            "availability": {"fraction": _num(n_av / n_ep) if n_ep else None, "lower": _num(lo), "upper": _num(hi)},
            "availability_dh": {"runs": int(dh.size), "available": int(np.nansum(dh)),
                                "fraction": _num(np.nanmean(dh)), "lower": _num(dlo), "upper": _num(dhi)},
            "pl_at_dh_m": {"vertical": _dist(col("vpl_dh_m")), "lateral": _dist(col("lpl_dh_m"))},
        }
        entry["fault_modes"] = _dist(col("modes"))
        for name in ("mi", "hmi"):
            c = col(name)
            k = int(np.sum(c > 0))
            p_lo, p_hi = _cp(k, n_runs, level)
            entry[name] = {"count": int(np.nansum(c)), "runs_with": k,
                           "approaches": n_runs, "probability_per_approach_upper": _num(p_hi),
                           "probability_per_approach_lower": _num(p_lo),
                           "rate_per_epoch_upper": _num(_cp(np.nansum(c), n_ep, level)[1]),
                           "rate_per_epoch_lower": _num(_cp(np.nansum(c), n_ep, level)[0])}
        hw = col("hmi_window")
        if hw.size:
            kw = int(np.sum(hw > 0))
            w_lo, w_hi = _cp(kw, n_runs, level)
            entry["hmi"].update({"window_s": None if req.hmi_window_s() is None else list(req.hmi_window_s()),
                                 "window_runs_with": kw, "window_probability_per_approach_lower": _num(w_lo),
                                 "window_probability_per_approach_upper": _num(w_hi)})
        entry["hmi"]["rate_per_epoch_allowed"] = allowed
        entry["hmi"]["allowed_per_approach"] = req.hmi_probability_allowed
        entry["stanford"] = {
            axis: {reg: int(np.nansum(col(f"{a}_{reg}"))) for reg in REGIONS}
            for a, axis in (("v", "vertical"), ("l", "lateral"))
        }
        entry["stanford_hist"] = {axis: _sparse(counts.get(f"{key}_stanford_{a}", np.zeros(NB * NB)))
                                  for a, axis in (("v", "vertical"), ("l", "lateral"))}
        windows = n_ep / (15.0 * epoch_hz)
        ev = float(np.nansum(col("detect_events")))
        fa_runs = int(np.sum(col("detect_events") > 0))
        t_run = n_ep / (epoch_hz * n_runs) if n_runs else 0.0  # scored seconds per approach
        entry["false_alert"] = None if is_faulted else {
            "alerts": int(ev), "windows_15s": _num(windows),
            "rate_per_15s": _num(ev / windows) if windows else None,
            "rate_per_15s_upper": _num(poisson_upper(ev, level) / windows) if windows else None,
            "allocation_per_15s": req.continuity_risk_per_15s,
            "runs_with": fa_runs, "approaches": n_runs,
            "probability_per_approach_upper": _num(_cp(fa_runs, n_runs, level)[1]),
            "allocation_per_approach": _num(-math.expm1(t_run / 15.0 * math.log1p(-req.continuity_risk_per_15s))),
            "scored_s_per_approach": _num(t_run),
        }
        if is_faulted:
            tta = col("tta_s")
            exceeded = col("exceeded") > 0
            missed = col("missed") > 0
            within = exceeded & (tta <= req.time_to_alert_s)
            entry["time_to_alert"] = {
                "faulted_runs": int(ep.size), "detected": int(np.sum(np.isfinite(col("delay_s")))),
                "right_exclusions": int(np.nansum(col("right"))),
                "exceeded_pl": int(exceeded.sum()), "missed_detections": int(missed.sum()),
                "within_tta": int(within.sum()), "tta_required_s": req.time_to_alert_s,
                "fraction_within_tta": _num(within.sum() / exceeded.sum()) if exceeded.any() else None,
                "fraction_within_tta_lower": _num(_cp(within.sum(), exceeded.sum(), level)[0])
                if exceeded.any() else None,
                "delay_after_onset_s": _dist(col("delay_s")), "tta_s": _dist(tta[exceeded & ~missed]),
                "definition": TTA_DEFINITION,
                "late_or_missed_upper": _num(1.0 - _cp(within.sum(), exceeded.sum(), level)[0])
                if exceeded.any() else None,
                "p_md_allocated": req.p_md(n_modes),
            }
        v = (verdicts or {}).get(cat)
        if v is not None:
            entry["verdict"] = v.verdict
            entry["runs_needed"] = v.runs_needed
            entry["availability_verdict"] = v.availability_verdict
            entry["hmi_verdict"] = v.hmi_verdict
            entry["hmi_finding"] = v.hmi_finding
        cats[cat] = entry
    out["categories"] = cats
    fde = np.asarray(columns.get("fde_epochs", np.empty(0)), float)
    if fde.size:
        al = np.asarray(columns["fde_alert_epochs"], float)
        exn = np.asarray(columns["fde_exclusions"], float)
        out["online_fde"] = {"runs": int(fde.size), "alert_epochs": int(np.nansum(al)),
                             "alert_fraction": _num(np.nansum(al) / np.nansum(fde)),
                             "exclusions": int(np.nansum(exn)), "runs_with_exclusion": int(np.sum(exn > 0)),
                             "delay_after_onset_s": _dist(columns.get("fde_delay_s", np.empty(0))),
                             "right_exclusions": int(np.nansum(columns.get("fde_right", np.empty(0))))}
    return out


def sum_counts(results: Sequence[Any]) -> dict[str, Array]:
    """The per-run histograms summed over the completed runs."""
    out: dict[str, Array] = {}
    for r in results:
        if not r.ok:
            continue
        for k, v in getattr(r, "counts", {}).items():
            out[k] = out.get(k, 0.0) + np.asarray(v, float)
    return out
