"""`approachsim fly PROFILE --out DIR [--seed S] [--run I] [--land]`: fly one approach, write truth and figures.

Writes DIR/truth.npz + DIR/truth.json (the truth record and its schema, see docs/truth.md and
approachsim.flight.truthfile), DIR/flight.json (termination, duration, truth_samples = the rows of truth.npz,
tracking statistics of the 1000-200 ft window with its tracking_window_samples) and the figures
DIR/vertical.png, DIR/lateral.png, DIR/airspeed.png, DIR/attitude.png; prints a short summary.
"""

from __future__ import annotations

import argparse
import json
import math
import sys

from approachsim.commands._single_run import add_single_run_arguments, load_single_run

FAILED_APPROACH = 3
"""Exit status of a flight that ended as a failed approach (unstabilized, ground contact, diverged, timeout):
the outputs are written, the run did not complete (as `evaluate`'s 3: no run completed)."""


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `fly` sub-command."""
    from approachsim.commands._help import command_parser

    p = command_parser(
        sub, "fly", help="fly one closed-loop approach (truth navigation) and write the truth record",
        description="JSBSim flies the profile's approach on the autopilot, guided by the true position, from the\n"
        "start distance to 50 ft (or to touchdown with --land). Writes DIR/truth.npz + truth.json (docs/truth.md),\n"
        "DIR/flight.json (termination, tracking statistics) and the figures vertical.png, lateral.png,\n"
        "airspeed.png, attitude.png.",
        examples=["approachsim fly profiles/default.toml --out out/fly",
                  "approachsim fly ~/approaches/default.toml --out out/land --land --seed 3"],
    )
    add_single_run_arguments(p)
    p.add_argument("--land", action="store_true", help="fly on through the flare to touchdown (default: stop 50 ft)")
    p.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Fly, write the truth, the figures and flight.json; print a summary."""
    from approachsim.flight.run import Approach, tracking_stats
    from approachsim.flight.truthfile import save_truth

    profile, seed = load_single_run(args)
    result = Approach(profile, land=args.land).fly(seed=seed, run=args.run)
    args.out.mkdir(parents=True, exist_ok=True)
    save_truth(args.out / "truth.npz", result.truth, meta={"profile": profile.name, "seed": seed, "run": args.run})
    stats = tracking_stats(result, profile)
    # flight.json: "samples" of tracking_stats counts the 1000-200 ft window only; name it so, and give the
    # truth record's own length beside it (the same number as truth.json's "samples")
    window = stats.pop("samples")
    stats["tracking_window_samples"] = window
    summary = {
        "profile": profile.name,
        "seed": seed,
        "run": args.run,
        "termination": result.termination,
        "ok": result.ok,
        "duration_s": float(result.truth.t_s[-1]),
        "truth_samples": len(result.truth),
        "lowest_height_ft": result.lowest_height_ft,
        "touchdown_past_threshold_ft": result.touchdown_x_m / 0.3048 if args.land else None,
        "touchdown_sink_fps": result.touchdown_sink_mps / 0.3048 if args.land else None,
        "touchdown_right_of_centreline_ft": result.touchdown_y_m / 0.3048 if args.land else None,
        "touchdown_drift_deg": math.degrees(result.touchdown_drift_rad) if args.land else None,
        "touchdown_crab_deg": math.degrees(result.touchdown_crab_rad) if args.land else None,
        **stats,
    }
    (args.out / "flight.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    if not args.no_figures:
        from approachsim.report.flight import write_flight_figures

        write_flight_figures(result, profile, args.out)
    print(
        f"{profile.name}: seed {seed} run {args.run}: {result.termination} after {summary['duration_s']:.1f} s, "
        f"lowest {result.lowest_height_ft:.0f} ft above threshold"
    )
    print(
        f"  1000-200 ft: vertical RMS {stats['vertical_rms_ft']:.2f} ft, lateral RMS {stats['lateral_rms_ft']:.2f} ft, "
        f"CAS {stats['cas_min_kt']:.1f}-{stats['cas_max_kt']:.1f} kt"
    )
    if args.land:
        print(f"  touchdown (main gear) {summary['touchdown_past_threshold_ft']:.0f} ft past the threshold, "
              f"sink {summary['touchdown_sink_fps']:.1f} ft/s, drift {summary['touchdown_drift_deg']:.1f} deg")
    extra = "" if args.no_figures else ", figures"
    print(f"  wrote {args.out / 'truth.npz'} (+ truth.json schema, flight.json{extra})")
    if not result.ok:
        sys.stderr.write(f"approachsim fly: failed approach: {result.termination}\n")
        return FAILED_APPROACH
    return 0
