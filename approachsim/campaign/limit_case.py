"""The limit-case sweep (issue 41 item 6): over a grid of faults the bank does not detect, the largest ratio of the
output's error to its protection level, per category and fault mode. A protection level bounds the error of every
fault it does not alarm on (the limit case of the GBAS and ARAIM threat models: the largest undetected fault,
DO-253 / ICAO Annex 10 Attachment D; Blanch et al., "Advanced RAIM user algorithm description"), so max |e| / PL
must stay below 1; where it does not, the fault named is the one the PL fails to bound.

One grid point is one deterministic fault of a mode (campaign.integrity_risk.fault_spec at a chosen u: magnitude or
ramp slope, onset and channel), flown as one sample of the integrity-risk study (the flown truth run % truths, the
run's own noise, a fault present before the approach through campaign/preapproach.py), through the bank and scored
per category over the epochs from the settle time to the DH (integrity_bank.score_category). Counted: the epochs
before the bank's first detection (the fault undetected), on both axes, |e| / PL of the main solution; the ratio of
a sample is its largest such epoch. The nominal noise is in every sample, so a fault-free run gives the floor the
faults add to (reported beside: `fault_free`).

Grid (`grid`): the onset as the mode's onset fraction (campaign.integrity_risk FaultMode.onset: ages before the
window start and fractions of the window), the magnitude or ramp slope on a log grid over the mode's range, the
channel (GPS: each of the satellites in use, by its rank among them; pseudolite: each unit).
"""

from __future__ import annotations

import dataclasses
import math
from collections.abc import Callable, Sequence
from typing import Any

import numpy as np
from scipy import stats as sps

from approachsim.campaign import integrity_risk as risk
from approachsim.campaign.integrity_bank import run_bank, score_category
from approachsim.campaign.integrity_campaign import bank_profile
from approachsim.integrity.requirements import REQUIREMENTS

Array = np.ndarray

ONSETS = (0.0, 0.5, 0.9, 0.99, 1.0)
"""Onset points on the window's uniform (FaultMode.onset with the study's pre-approach share), as named by
`onset_points`: ages of one MFD, half of it, 10 % and 1 % of it before the window start, and then the window's
start, middle and last tenth."""


def onset_points(mode: risk.FaultMode) -> list[tuple[float, str]]:
    """(Phi(u_0), label) of the sweep's onsets: before the window (a mode with an MFD) and inside it."""
    out = []
    a = mode.pre_fraction
    if a > 0.0:
        for age in (1.0, 0.5, 0.1, 0.01):
            out.append((a * (1.0 - age), f"{age * mode.mfd_s:.0f} s before the window"))
    for g, name in ((0.0, "window start"), (0.5, "window middle"), (0.9, "window 90 %")):
        out.append((a + (1.0 - a) * g, name))
    return out


def magnitudes(mode: risk.FaultMode, per_decade: int) -> Array:
    """Log grid over the mode's range, `per_decade` points a decade, both ends included."""
    n = max(2, int(math.ceil(per_decade * math.log10(mode.high / mode.low))) + 1)
    return np.geomspace(mode.low, mode.high, n)


def grid(mode: risk.FaultMode, per_decade: int, channels: int) -> list[tuple[Array, dict]]:
    """(u, what it is) for every grid point of a mode: u's onset, magnitude and channel inputs inverted from the
    chosen values (FaultMode.magnitude's log-uniform map, the channel's rank among `channels`)."""
    lo, hi = math.log(mode.low), math.log(mode.high)
    out = []
    for f, label in onset_points(mode):
        for m in magnitudes(mode, per_decade):
            q = float(np.clip((math.log(m) - lo) / (hi - lo), 1e-12, 1 - 1e-12))
            u = [float(sps.norm.ppf(np.clip(f, 1e-12, 1 - 1e-12))), float(sps.norm.ppf(q))]
            chans = range(channels) if mode.has_channel else [None]
            for c in chans:
                uu = u + ([float(sps.norm.ppf((c + 0.5) / channels))] if c is not None else [])
                out.append((np.array(uu), {"onset": label, "magnitude": float(m), "rank": c}))
    return out


def ratios(profile: Any, seed: int, run: int, truths: int, mode: risk.FaultMode | None, u: Array) -> dict:
    """Per category: the largest |e| / PL of the main solution over the epochs before the first detection (vertical,
    lateral), whether the bank detected the fault at all, and the fault's parameters (module docstring)."""
    flown = risk.flown_truth(profile, int(seed), int(run % truths))
    truth = flown.truth
    prof, params, pre = profile, {}, None
    if mode is not None:
        spec, params = risk.fault_spec(mode, u, profile, truth, seed, run, (flown.t_lo_s, flown.t_hi_s))
        prof = dataclasses.replace(profile, faults=(*tuple(profile.faults or ()), spec))
        pre = risk.pre_fault(mode, params)
    ep, _ = run_bank(bank_profile(prof), truth, seed, run, memo=flown.memo, pre=pre)
    cfg = profile.evaluation
    settled = ep.t_s >= float(truth.t_s[0]) + cfg.timeavg_settle_s
    out: dict = {"fault": params}
    for cat, req in REQUIREMENTS.items():
        win = settled & (ep.height_m >= cfg.dh_m(cat))
        s = score_category(ep, req, profile.nav.aiding_rate_hz, win)
        undetected = np.cumsum(np.asarray(s.result.detected, bool)) == 0
        e = np.abs(np.asarray(s.err_m, float))[undetected]  # before a detection the output is the main solution
        pl = np.asarray(s.pl_m, float)[undetected]
        with np.errstate(divide="ignore", invalid="ignore"):
            r = np.where(np.isfinite(pl) & (pl > 0), e / pl, 0.0)
        out[cat] = {"vertical": float(r[:, 0].max()) if r.size else 0.0,
                    "lateral": float(r[:, 1].max()) if r.size else 0.0,
                    "undetected_epochs": int(undetected.sum()), "epochs": int(undetected.size),
                    "detected": bool(np.any(s.result.detected))}
    return out


def sweep(profile: Any, modes: Sequence[str] | None = None, *, per_decade: int = 3, seed: int = 1, truths: int = 4,
          fault_free_runs: int = 8, log: Callable[[str], None] | None = None) -> dict:
    """The sweep of a profile (module docstring): per mode and category the largest ratio, its fault, and every grid
    point's figures; the fault-free runs' largest ratio beside it. JSON-ready."""
    say = log or (lambda s: None)
    _, t_lo, t_hi = risk.flight_truth(profile, seed, 0)
    ms = [m.with_window(t_hi - t_lo) for m in risk.modes_for(profile, modes)]
    out: dict = {"schema": "approachsim.limit_case/1", "profile": profile.name, "seed": seed, "truths": truths,
                 "per_decade": per_decade, "modes": {}}
    ff = [ratios(profile, seed, r, truths, None, np.zeros(0)) for r in range(fault_free_runs)]
    out["fault_free"] = {cat: {"runs": fault_free_runs,
                               "max_ratio": max(max(x[cat]["vertical"], x[cat]["lateral"]) for x in ff)}
                         for cat in REQUIREMENTS}
    for m in ms:
        n_ch = 1
        if m.has_channel:  # the satellites in use (at truth 0's window middle) or the pseudolite units
            _, p = risk.fault_spec(m, np.zeros(3), profile, risk.flight_truth(profile, seed, 0)[0], seed, 0,
                                   (t_lo, t_hi))
            n_ch = int(p["n_channels"])
        pts = grid(m, per_decade, n_ch)
        say(f"{m.name}: {len(pts)} grid points")
        rows = []
        base = (list(risk.MODES).index(m.name) + 1) * risk.MODE_OFFSET + 500_000
        for i, (u, what) in enumerate(pts):
            r = ratios(profile, seed, base + i, truths, m, u)
            rows.append({**what, **{cat: r[cat] for cat in REQUIREMENTS},
                         "channel": r["fault"].get("channel"), "age_at_start_s": r["fault"].get("age_at_start_s")})
        per_cat = {}
        for cat in REQUIREMENTS:
            j = int(np.argmax([max(x[cat]["vertical"], x[cat]["lateral"]) for x in rows]))
            w = rows[j]
            axis = "vertical" if w[cat]["vertical"] >= w[cat]["lateral"] else "lateral"
            per_cat[cat] = {"max_ratio": w[cat][axis], "axis": axis,
                            "worst_fault": {"magnitude": w["magnitude"], "unit": "m/s" if m.kind == "ramp" else "m",
                                            "onset": w["onset"], "channel": w["channel"],
                                            "detected_later": w[cat]["detected"]},
                            "points_at_or_above_1": int(sum(max(x[cat]["vertical"], x[cat]["lateral"]) >= 1.0
                                                            for x in rows))}
        out["modes"][m.name] = {"kind": m.kind, "range": [m.low, m.high], "points": len(rows),
                                "categories": per_cat, "grid": rows}
        say(f"{m.name}: " + ", ".join(f"{c} {v['max_ratio']:.2f}" for c, v in per_cat.items()))
    return out
