"""Issue 26, the second look's cost in continuity under faults: the same faulted bank epochs scored with the
first-look identification (exclude the first detection's suspect for good), with the second look
(campaign.integrity_bank.second_level: not protected until a mode's exclusion is confirmed, and again when a later
detection names another mode) and with the second look `at_once` (a clear first detection excluded at once, only an
ambiguous one waits), per sample and category.

    PYTHONPATH=. python benchmarks/second_look_continuity.py [--profile P] [--mode sat-ramp] [--samples N]
        [--seed S] [--workers K] [--truths T] [--out FILE.json]

Samples are plain Monte Carlo over the mode's fault distribution (campaign.integrity_risk.fault_spec: onset uniform over
the approach window, log-uniform magnitude, the faulted satellite uniform over those in use), on flown truths
(risk.flight_truth) and the open-loop bank (risk.run_sample's path); both scorings read the same bank epochs, so
every difference is the rule's. An epoch is alerted when its protection level reaches the alert limit on either
axis (PL = inf while the second look has not confirmed). Per category: samples detected, samples where the second
look alerts at an epoch the first look had protected, the added alerted epochs, approaches with no alerted epoch
under the first look that the second look interrupts (the loss of continuity it causes), and the HMI samples of
both (the paired comparison of docs/integrity.md on fresh samples). The loss's probability times the mode's prior
(risk.modes_for) is its share of the continuity risk per approach.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import multiprocessing
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

from approachsim.campaign.integrity_risk import CATEGORY_KEYS, MODES, fault_mode, fault_spec, flight_truth, modes_for
from approachsim.integrity import rare
from approachsim.integrity.requirements import REQUIREMENTS
from approachsim.profile import load_profile


def sample(profile, seed: int, truths: int, mode_name: str, run: int, u: list[float]) -> dict:
    """One faulted sample scored both ways: per category (epochs, alerted epochs first / second look, alerted
    epochs the first look protected, hmi epochs first / second, detected)."""
    from approachsim.campaign.integrity_bank import run_bank, score_category
    from approachsim.campaign.integrity_campaign import bank_profile

    truth, t_lo, t_hi = flight_truth(profile, seed, run % truths)
    spec, params = fault_spec(fault_mode(mode_name), np.asarray(u), profile, truth, seed, run, (t_lo, t_hi))
    prof = dataclasses.replace(profile, faults=(*tuple(profile.faults or ()), spec))
    ep, _ = run_bank(bank_profile(prof), truth, seed, run)
    cfg, hz = profile.evaluation, profile.nav.aiding_rate_hz
    settled = ep.t_s >= float(truth.t_s[0]) + cfg.timeavg_settle_s
    out: dict = {"run": run, **params}
    for cat, req in REQUIREMENTS.items():
        win = settled & (ep.height_m >= cfg.dh_m(cat))
        s0 = score_category(ep, req, hz, win, confirm=False)
        row = [s0.epochs, int(np.sum(~s0.available)), int(np.sum(s0.hazardous)), int(np.any(s0.detected))]
        for at_once in (False, True):
            s1 = score_category(ep, req, hz, win, confirm=True, at_once=at_once)
            row += [int(np.sum(~s1.available)), int(np.sum(s0.available & ~s1.available)), int(np.sum(s1.hazardous))]
        out[CATEGORY_KEYS[cat]] = row
    return out


def _task(args: tuple) -> list[dict]:
    profile, seed, truths, mode_name, items = args
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1):
        return [sample(profile, seed, truths, mode_name, run, u) for run, u in items]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--profile", type=Path, default=Path(__file__).resolve().parents[1] / "profiles/default.toml")
    ap.add_argument("--mode", default="sat-ramp", choices=sorted(MODES))
    ap.add_argument("--samples", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--truths", type=int, default=4)
    ap.add_argument("--out", type=Path, default=None)
    a = ap.parse_args()
    profile = load_profile(a.profile)
    mode = fault_mode(a.mode)
    modes_for(profile, [a.mode])  # a ValueError naming the mode when the profile has not that sensor
    rng = np.random.default_rng(a.seed * 7919 + 17)
    u = rng.standard_normal((a.samples, mode.dim))
    items = [(7_000_000 + i, u[i].tolist()) for i in range(a.samples)]
    t = time.time()
    n = max(1, math.ceil(len(items) / (8 * a.workers)))
    chunks = [(profile, a.seed, a.truths, a.mode, items[i:i + n]) for i in range(0, len(items), n)]
    if a.workers > 1:
        from approachsim.campaign.runner import register_pickling

        register_pickling()
        with ProcessPoolExecutor(a.workers, mp_context=multiprocessing.get_context("fork")) as pool:
            rows = [r for part in pool.map(_task, chunks) for r in part]
    else:
        rows = [r for c in chunks for r in _task(c)]
    wall = time.time() - t
    # the mode's prior per approach, as campaign.integrity_risk takes it: per satellite (pseudolite unit) times the most
    # in use over the samples
    prior = mode.prior * (max(int(r["n_channels"]) for r in rows) if mode.has_channel else 1)
    res: dict = {"profile": profile.name, "mode": a.mode, "prior_per_approach": prior, "samples": a.samples,
                 "seed": a.seed, "wall_s": wall, "categories": {}}
    print(f"{profile.name}, {a.mode}: {a.samples} samples in {wall:.0f} s; prior {prior:.2g} per approach")
    print("  rule: second look (alert until confirmed) or at once (a clear first detection excluded at once)\n"
          "  category  rule      detected  alerts where the first look protected (samples, epochs: mean / max)  "
          "continuous approaches interrupted [one-sided 95 % bounds]  HMI samples first look / rule")
    for key in CATEGORY_KEYS.values():
        m = np.array([r[key] for r in rows])
        epochs, a0, h0, det = m[:, :4].T
        cont = a0 == 0
        nc = int(cont.sum())
        res["categories"][key] = {"epochs_per_sample_mean": float(epochs.mean()), "detected": int(det.sum()),
                                  "continuous_first_look": nc, "hmi_samples_first_look": int((h0 > 0).sum())}
        for j, rule in enumerate(("second_look", "at_once")):
            a1, added, h1 = m[:, 4 + 3 * j:7 + 3 * j].T
            k = int((cont & (a1 > 0)).sum())
            lo, hi = rare.clopper_pearson(k, max(nc, 1), 0.95)
            hit = added > 0
            c = {"samples_with_added_alerts": int(hit.sum()),
                 "added_alert_epochs_mean_where_added": float(added[hit].mean()) if hit.any() else 0.0,
                 "added_alert_epochs_max": int(added.max()), "interrupted": k,
                 "p_interrupted_given_fault": k / max(nc, 1), "p_interrupted_lower_95": lo,
                 "p_interrupted_upper_95": hi, "continuity_risk_per_approach_upper": hi * nc / a.samples * prior,
                 "hmi_samples": int((h1 > 0).sum())}
            res["categories"][key][rule] = c
            print(f"  {key:8s}  {rule:11s} {int(det.sum()):5d}     {c['samples_with_added_alerts']:5d}, "
                  f"{c['added_alert_epochs_mean_where_added']:.1f} / {c['added_alert_epochs_max']}"
                  f"{'':34s}{k} of {nc} = {k / max(nc, 1):.3g} [{lo:.2g}, {hi:.2g}]"
                  f"{'':10s}{int((h0 > 0).sum())} / {c['hmi_samples']}")
    if a.out is not None:
        a.out.write_text(json.dumps(res, indent=1) + "\n")


if __name__ == "__main__":
    main()
