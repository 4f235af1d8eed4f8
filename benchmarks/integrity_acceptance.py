"""Issue 11 acceptance, faulted part: a pseudorange ramp (0.1, 0.5, 2 m/s) or step (10-100 m) on one used GPS
satellite, starting at a random time on final, scored by the solution-separation bank (campaign.integrity_campaign).

    PYTHONPATH=. python benchmarks/integrity_acceptance.py KIND RUNS [--seed S] [--out FILE.json] [--closed]

KIND: ramp0.1 | ramp0.5 | ramp2 | step. Open loop on the default profile (flown truth shared by groups of
evaluation.flight_group runs, as the campaign does); per run the onset is uniform between 30 s after the
start and 60 s before the CAT I decision height, the satellite uniform among the channels the receiver used
at the onset, the step magnitude uniform in 10-100 m, all from the run's own stream "acceptance_fault".
Prints and writes the details.json-style `integrity` block (time to alert, missed detections, MI / HMI) and
the per-run table. --closed: each run flies closed loop on the navigation with the online FDE ([nav.fde] enabled,
the profile's category allocation) and the fault, the bank scores the flown truth; the per-run flight result (failed
approaches with their reason, the FTE at the decision heights, the FDE's exclusion delay) is added: the aircraft
keeps flying on the protected solution. (The fault-free figures come from the campaign itself: approachsim evaluate
profiles/default.toml --mode open --runs N.)
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import time
from pathlib import Path

import numpy as np

from approachsim import units
from approachsim.campaign.integrity_campaign import campaign_integrity, score_with_bank
from approachsim.campaign.pipeline import _approach, closed_loop_group
from approachsim.campaign.result import RunResult
from approachsim.profile import load_profile
from approachsim.report.integrity import fig_integrity_tta
from approachsim.seeding import stream
from approachsim.sensors.faults import FaultSpec
from approachsim.sensors.suite import SensorSuite

KINDS = {"ramp0.1": ("ramp", 0.1), "ramp0.5": ("ramp", 0.5), "ramp2": ("ramp", 2.0), "step": ("step", None)}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("kind", choices=sorted(KINDS))
    ap.add_argument("runs", type=int)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None)
    ap.add_argument("--profile", type=Path, default=Path(__file__).resolve().parents[1] / "profiles/default.toml")
    ap.add_argument("--closed", action="store_true", help="fly closed loop with the online FDE on")
    a = ap.parse_args()
    base = load_profile(a.profile)
    kind, rate = KINDS[a.kind]
    size = base.evaluation.flight_group
    truths: dict[int, object] = {}
    rows, cols, results = [], {}, []
    failed: list[dict] = []
    flights: list[dict] = []
    t_start = time.time()
    for i in range(a.runs):
        first = (i // size) * size
        if first not in truths:
            truths.clear()
            truths[first] = _approach(base).fly(seed=a.seed, run=first).truth
        truth = truths[first]
        rng = stream(a.seed, i, "acceptance_fault")
        t_dh = _t_at_height(truth, 200.0 * units.FT)
        onset = float(rng.uniform(30.0, max(31.0, t_dh - 60.0)))
        g = SensorSuite.from_profile(base).measure(truth, seed=a.seed, runs=[i])["gnss"]
        j = int(np.clip(np.searchsorted(g.t_s, onset), 0, len(g.t_s) - 1))
        used = np.flatnonzero(np.asarray(g.valid)[0, j])
        ch = int(rng.choice(used))
        prn = int(np.asarray(g.prn)[ch])
        mag = float(rng.uniform(10.0, 100.0)) if kind == "step" else 0.0
        spec = FaultSpec(sensor="gnss", kind=kind, start_s=onset, target="pseudorange", channel=prn,
                         magnitude=mag, rate=rate or 0.0)
        prof = dataclasses.replace(base, faults=(spec,))
        if a.closed:  # the aircraft flies on the navigation with the online FDE; the bank scores its flown truth
            prof = dataclasses.replace(prof, nav=dataclasses.replace(
                prof.nav, fde=dataclasses.replace(prof.nav.fde, enabled=True)))
            r = closed_loop_group(prof, a.seed, [i])[0]
            if not r.ok:
                failed.append({"run": i, "error": r.error})
                print(f"run {i}: FAILED {r.error}", flush=True)
                continue
            s = dict(r.scalars)
            flights.append({k: s[k] for k in s if "fte" in k or k.startswith("fde_")})
        else:
            s, _, _ = score_with_bank(prof, truth, a.seed, i)
        for k, v in s.items():
            cols.setdefault(k, []).append(v)
        results.append(RunResult(run=i, ok=True, scalars=s))
        rows.append({"run": i, "onset_s": onset, "prn": prn, "channel": ch, "step_m": mag,
                     **{k: (s[k] if math.isfinite(s[k]) else str(s[k])) for k in s
                        if k.startswith("cat2_int_") and k[9:11] not in ("v_", "l_")}})
        print(f"run {i}: onset {onset:.0f} s PRN {prn} delay {s['cat2_int_delay_s']:.1f} s "
              f"tta {s['cat2_int_tta_s']:.1f} s excluded {s['cat2_int_excluded_channel']:.0f} ({ch}) "
              f"mi {s['cat2_int_mi']:.0f} [{time.time() - t_start:.0f} s]", flush=True)
    cols = {k: np.asarray(v, float) for k, v in cols.items()}
    out = campaign_integrity(cols, {}, base.evaluation, faulted=True)
    for c in out["categories"].values():
        c.pop("stanford_hist", None)
    res = {"kind": a.kind, "runs": a.runs, "seed": a.seed, "closed_loop": a.closed, "integrity": out,
           "per_run": rows, "wall_s": time.time() - t_start}
    if a.closed:
        fte = {k: float(np.sqrt(np.nanmean(np.square([f[k] for f in flights])))) for k in (flights[0] if flights
                                                                                            else {}) if "fte" in k}
        res["flight"] = {"failed_runs": failed, "completed": len(flights), "fte_rms_m": fte,
                         "fde_delay_s": [f.get("fde_delay_s") for f in flights]}
        print("closed loop:", len(flights), "completed,", len(failed), "failed approaches; FTE RMS (m):",
              json.dumps({k: round(v, 3) for k, v in fte.items()}))
    text = json.dumps(res, indent=1, allow_nan=False)
    if a.out is not None:
        a.out.write_text(text + "\n")
        fig = fig_integrity_tta(results, {"integrity": out})
        if fig is not None:
            fig.suptitle(f"Time to alert, {a.kind}, {a.runs} runs (open loop, default profile)", fontsize=11)
            fig.savefig(a.out.with_suffix(".png"), dpi=100)
    for cat, c in out["categories"].items():
        print(cat, json.dumps(c.get("time_to_alert")), "MI", c["mi"]["count"], "HMI", c["hmi"]["count"])


def _t_at_height(truth, height_m: float) -> float:
    """First time the truth is below `height_m` above the threshold (runway-frame z)."""
    z = np.asarray(truth.r_rwy)[:, 2]
    k = int(np.argmax(z < height_m))
    return float(truth.t_s[k])


if __name__ == "__main__":
    main()
