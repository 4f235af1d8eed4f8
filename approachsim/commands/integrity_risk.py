"""`approachsim integrity-risk PROFILE [--modes M,...] [--method nais|ce|mc] [--samples N] [--max-calls N]
[--fault-free-runs N] [--truths T] [--seed S] [--workers K] [--sensor-modes] [--second-level] [--out DIR]
[--require CAT]`: the
probability of hazardously misleading information per category by rare-event simulation (campaign/integrity_risk.py,
docs/integrity.md "Integrity risk"), against the Annex 10 allocations.

Writes DIR/integrity_risk.json (docs/contract.md) and prints one line per category (the verdict on the specific
risk: each mode's worst magnitude-decade x onset-third bin's upper bound x its prior; the average over the
magnitude law beside it) and one line per mode and category with its worst bin. Exit status: 0 the study ran;
1 the --require'd category's P(HMI) is not shown within its allocation; 2 bad input (one line naming the option);
3 no sample completed.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path

from approachsim.config import ProfileError


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `integrity-risk` sub-command."""
    from approachsim.commands._help import command_parser

    p = command_parser(
        sub, "integrity-risk", help="P(HMI) per category by importance sampling over the fault modes",
        description="Estimates the integrity risk of a profile per category: P(HMI) = fault-free term + sum over\n"
        "the fault modes (GPS satellite ramp and step, baro step, radar-altimeter bias, pseudolite step) of\n"
        "prior x P(HMI | fault), each conditional probability by non-parametric adaptive importance sampling\n"
        "(OpenTURNS NAIS) over the fault's onset, magnitude and channel, with its confidence bounds and the\n"
        "number of navigation runs spent; compares the upper bound with the Annex 10 allocation\n"
        "(docs/integrity.md). Writes DIR/integrity_risk.json.",
        examples=["approachsim integrity-risk profiles/default.toml --samples 200 --out out/risk",
                  "approachsim integrity-risk profiles/default.toml --modes sat-ramp --method mc --samples 2000",
                  "approachsim integrity-risk profiles/gbas-cat3-candidate.toml --require \"CAT I\""],
    )
    p.add_argument("profile", type=Path, help="approach profile (TOML)")
    p.add_argument("--modes", default=None,
                   help="comma-separated fault modes (default: every mode the profile's sensors have): "
                        "sat-ramp, sat-step, baro-step, radalt-bias, pseudolite-step")
    p.add_argument("--method", default="nais", choices=("nais", "ce", "mc"),
                   help="nais (default; checked on the simulation from 8.5e-3 to 4e-5 against brute force and a "
                        "stratified reference: docs/integrity.md), ce (cross-entropy IS, biased low in our checks) "
                        "or mc")
    p.add_argument("--samples", type=int, default=200, help="samples per adaptive step (mc: in all); default 200")
    p.add_argument("--max-calls", type=int, default=None, help="navigation runs per mode at most (default 8 x samples)")
    p.add_argument("--fault-free-runs", type=int, default=100, help="fault-free runs for the overbound (default 100)")
    p.add_argument("--truths", type=int, default=4, help="flown approaches the samples share (default 4)")
    p.add_argument("--seed", type=int, default=None, help="study seed (default: the profile's run.seed)")
    p.add_argument("--workers", type=int, default=None, help="local worker processes (default: all cores)")
    p.add_argument("--out", type=Path, default=None, help="output directory (default: integrity-risk-<profile>)")
    p.add_argument("--sensor-modes", action="store_true",
                   help="the bank also leaves out the baro, the radar altimeter and each pseudolite (default: GPS "
                        "satellites only, as evaluate's bank)")
    p.add_argument("--second-level", action="store_true",
                   help="the bank confirms an identification before excluding (a second look: docs/integrity.md; "
                        "default: the first detection's suspect, as evaluate's bank)")
    p.add_argument("--require", default=None, metavar="CAT",
                   help="exit 1 unless this category's P(HMI) upper bound is within its allocation")
    p.set_defaults(func=run)


def check_options(args: argparse.Namespace, profile: object) -> dict:
    """Validate the options (ProfileError naming the option); the keyword arguments of integrity_risk."""
    from approachsim.api import check_risk

    return check_risk(profile,  # type: ignore[arg-type]
                      modes=None if args.modes is None else args.modes.split(","), method=args.method,
                      samples=args.samples, max_calls=args.max_calls, fault_free_runs=args.fault_free_runs,
                      truths=args.truths, seed=args.seed, workers=args.workers,
                      sensor_modes=bool(getattr(args, "sensor_modes", False)),
                      second_level=bool(getattr(args, "second_level", False)), prefix="--")


def _fmt(x: float | None) -> str:
    return "-" if x is None or not math.isfinite(x) else f"{x:.2g}"


def run(args: argparse.Namespace) -> int:
    """Run the study (api.integrity_risk), write integrity_risk.json, print the table."""
    from approachsim import api
    from approachsim.commands.evaluate import parse_require

    spec = api.ProfileSpec.from_file(args.profile)
    profile = spec.profile
    kw = check_options(args, profile)
    require = parse_require(args.require)
    out = args.out if args.out is not None else Path(f"integrity-risk-{profile.name}")
    if out.exists() and not out.is_dir():
        raise ProfileError(f"--out: {str(out)!r} exists and is not a directory")
    res = api.integrity_risk(spec, out=out, log=lambda s: print(s, file=sys.stderr, flush=True), **kw)
    print("specific risk: each mode's worst (magnitude decade, onset) bin's upper bound x prior; verdict on the "
          "sourced priors ([U] terms: not shown, see prior_allowed); average: over the magnitude law "
          "(docs/integrity.md)")
    print(f"{'category':9} {'P(HMI)':>9} {'upper':>9} {'sourced':>9} {'allocation':>12}  verdict     "
          f"{'assumed':>9}  {'avg upper':>9}  P(FA)/15s upper  (allocation)")
    for cat, c in res["categories"].items():
        print(f"{cat:9} {_fmt(c['p_hmi']):>9} {_fmt(c['p_hmi_upper']):>9} {_fmt(c['p_hmi_upper_sourced']):>9} "
              f"{_fmt(c['allocation']):>7} {c['allocation_unit'][4:]:>4}  {c['verdict']:10}  "
              f"{c['verdict_assumed']:>9}  {_fmt(c['p_hmi_average_upper']):>9}  "
              f"{_fmt(c['p_false_alert_per_15s_gaussian']):>9}"
              f"        ({_fmt(c['false_alert_allocation_per_15s'])}) {c['false_alert_verdict']}")
    print(f"{'mode':16} {'category':9} {'worst bin':>18} {'onset':>26} {'P(HMI|bin)':>10} {'upper':>7} {'n':>6} "
          f"{'x prior':>8} {'prior':>6} {'shown':>5}  {'average up':>10} {'x prior':>8}")
    for cat, c in res["categories"].items():
        for name, t in c["terms"].items():
            wb = t.get("worst_bin")
            if wb is None:
                continue
            m = res["modes"][name]
            band = f"{wb['magnitude'][0]:g}-{wb['magnitude'][1]:g} {m['unit']}"
            onset = wb.get("onset") or f"window {wb['onset_third']}/3"
            shown = "no [U]" if t.get("prior_mark") == "U" else ("yes" if t["specific_shown"] else "no")
            print(f"{name:16} {cat:9} {band:>18} {onset:>26} {_fmt(wb['probability']):>10} "
                  f"{_fmt(wb['upper']):>7} {wb['samples']:>6.0f} {_fmt(t['specific_upper']):>8} "
                  f"{'[' + t.get('prior_mark', 'U') + ']':>6} {shown:>5}  {_fmt(t['conditional_upper']):>10} "
                  f"{_fmt(t['upper']):>8}")
    print(f"{res['samples']} navigation runs, {res['wall_s']:.0f} s; wrote {out / 'integrity_risk.json'}")
    for name, m in res["modes"].items():
        if m["failed_samples"]:
            sys.stderr.write(f"approachsim integrity-risk: {name}: {m['failed_samples']} of {m['samples']} samples "
                             f"failed (counted as HMI); first: {m['first_error']}\n")
    ran = res["fault_free"]["runs"] - res["fault_free"]["failed_runs"] + sum(
        m["samples"] - m["failed_samples"] for m in res["modes"].values())
    if ran == 0:
        sys.stderr.write("approachsim integrity-risk: no sample completed\n")
        return 3
    if require is not None and res["categories"][require]["verdict"] != "shown":
        c = res["categories"][require]
        sys.stderr.write(f"approachsim integrity-risk: --require {require}: P(HMI) {c['verdict']} within "
                         f"{c['allocation']:g} ({c['allocation_unit']})\n")
        return 1
    return 0
