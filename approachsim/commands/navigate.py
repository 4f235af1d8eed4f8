"""`approachsim navigate PROFILE --out DIR [--seed S] [--run I] [--mode closed|open]`: fly one approach and
navigate it with the profile's INS + filter; write the truth, the navigation solution, the filter status and
figures.

closed (default: the profile's run.mode): the autopilot flies on the navigation solution (nav in the loop);
open: JSBSim flies on truth, the navigation system then runs over the sensor records of that flight.
Writes DIR/truth.npz (+ truth.json), DIR/nav.npz (solution at the IMU rate, epoch history: x, P diag, P of the
navigation errors, true errors; status log: t, name, innovation, variance, test ratio, weight, accepted),
DIR/nav.json (summary), DIR/nav_*.png (errors with +-1 / +-3 sigma envelopes per state group, NIS).
"""

from __future__ import annotations

import argparse
import json
import sys

import numpy as np

from approachsim.commands._single_run import add_single_run_arguments, load_single_run


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `navigate` sub-command."""
    from approachsim.commands._help import command_parser
    from approachsim.nav.registry import FILTERS

    p = command_parser(
        sub, "navigate", help="fly one approach and navigate it (INS + filter): solution, status, figures",
        description="Flies one approach and runs the strapdown INS and the profile's filter over its sensors:\n"
        "closed loop (the autopilot flies on the navigation solution) or open loop (flown on truth, navigated\n"
        "afterwards). Writes DIR/nav.npz (solution, covariances, true errors, measurement status), DIR/nav.json\n"
        "(summary, SI units in the key names), DIR/truth.npz and the error figures with +-1 / +-3 sigma.\n\n"
        "filters (profile [nav] filter = NAME; tuning in [nav.filter_tuning], see docs/profiles.md):\n  "
        + ", ".join(FILTERS),
        examples=["approachsim navigate profiles/default.toml --out out/nav",
                  "approachsim navigate my-rkf.toml --out out/nav-open --mode open --seed 5"],
    )
    add_single_run_arguments(p)
    p.add_argument("--mode", choices=("closed", "open"), default=None, help="default: the profile's run.mode")
    p.set_defaults(func=run)


def _summary(nav, truth, profile, res) -> dict:
    from approachsim import geo, units
    from approachsim.loop.errors import approach_errors

    e = nav.true_error_nav
    nees = [float(x @ np.linalg.solve(P, x)) for x, P in zip(e, nav.P_nav, strict=True)]
    err = approach_errors(truth, res.guidance_r_rwy, profile.runway)
    # NSE from the navigation solution itself (in the open loop guidance flew on truth, so FTE + NSE != TSE)
    r_nav = profile.runway.frame.from_ecef(nav.solution.r_ecef)
    r_nav[:, 2] = geo.ecef_to_geodetic(nav.solution.r_ecef)[2] - profile.runway.elevation_m
    nse = approach_errors(truth, r_nav, profile.runway).nse_m
    out = {
        "epochs": int(len(nav.t_epoch_s)),
        "measurements": int(len(nav.status.t_s)),
        "rejected": int(np.sum(~nav.status.accepted)),
        "mean_nees_9dof": float(np.mean(nees)),
        "mean_nis": float(np.mean(nav.status.test_ratio)),
        "rms_position_error_ned_m": np.sqrt(np.mean(e[:, 0:3] ** 2, axis=0)).tolist(),
    }
    for h_ft in (200.0, 100.0, 50.0):
        z = truth.r_rwy[:, 2]
        if z.min() > h_ft * units.FT:
            continue
        k = int(np.argmax(z <= h_ft * units.FT))
        out[f"at_{int(h_ft)}_ft"] = {
            "fte_lateral_m": float(err.fte_m[k, 0]), "fte_vertical_m": float(err.fte_m[k, 1]),
            "nse_lateral_m": float(nse[k, 0]), "nse_vertical_m": float(nse[k, 1]),
            "tse_lateral_m": float(err.tse_m[k, 0]), "tse_vertical_m": float(err.tse_m[k, 1]),
        }
    return out


FAILED_APPROACH = 3
"""Exit status when the flight ended as a failed approach (outputs written; see commands/fly.py)."""


def run(args: argparse.Namespace) -> int:
    """Fly, navigate, write files and figures; print a summary."""
    from approachsim.flight.run import Approach
    from approachsim.flight.truthfile import save_truth
    from approachsim.loop.closed_loop import NavInTheLoop
    from approachsim.loop.errors import approach_errors
    from approachsim.nav.system import NavSystem
    from approachsim.seeding import stream
    from approachsim.sensors.states import start_states
    from approachsim.sensors.suite import SensorSuite

    profile, seed = load_single_run(args)
    mode = args.mode or profile.run.mode
    approach = Approach(profile)
    if mode == "closed":
        src = NavInTheLoop(profile, seed=seed, run=args.run)
        res = approach.fly(seed=seed, run=args.run, nav_source=src)
        nav = src.result(res.truth)
    else:
        res = approach.fly(seed=seed, run=args.run)
        suite = SensorSuite.from_profile(profile)
        errors = suite.draw(res.truth.t_s, seed, args.run)
        recs = suite.apply(res.truth, errors)
        nav = NavSystem.from_profile(profile).run(res.truth, recs, stream(seed, args.run, "nav"),
                                                  states=start_states(suite, res.truth, errors))
    truth = res.truth
    args.out.mkdir(parents=True, exist_ok=True)
    meta = {"profile": profile.name, "seed": seed, "run": args.run, "mode": mode}
    save_truth(args.out / "truth.npz", truth, meta=meta)
    sol, st = nav.solution, nav.status
    err = approach_errors(truth, res.guidance_r_rwy, profile.runway)
    np.savez_compressed(
        args.out / "nav.npz",
        t_s=sol.t_s, r_ecef=sol.r_ecef, v_ned=sol.v_ned, euler_rad=sol.euler_rad, P_pos_ned=sol.P_pos_ned,
        clock_bias_m=sol.clock_bias_m, clock_bias_sigma_m=sol.clock_bias_sigma_m,
        epoch_t_s=nav.t_epoch_s, epoch_x=nav.x, epoch_P_diag=nav.P_diag, epoch_P_nav=nav.P_nav,
        epoch_true_error_nav=nav.true_error_nav, state_names=np.array(_state_names(nav.layout)),
        status_t_s=st.t_s, status_name=st.name, status_innovation=st.innovation, status_variance=st.variance,
        status_test_ratio=st.test_ratio, status_weight=st.weight, status_accepted=st.accepted,
        fte_m=err.fte_m, nse_m=err.nse_m, tse_m=err.tse_m,
    )
    summary = {**meta, "filter": profile.nav.filter, "termination": res.termination, "ok": res.ok,
               "lowest_height_ft": res.lowest_height_ft, **_summary(nav, truth, profile, res)}
    (args.out / "nav.json").write_text(json.dumps(summary, indent=2) + "\n", encoding="utf-8")
    if not args.no_figures:
        from approachsim.report.nav import write_nav_figures

        write_nav_figures(nav, args.out, title=profile.name)
    print(f"{profile.name}: seed {seed} run {args.run} ({mode} loop, filter {profile.nav.filter}): "
          f"{res.termination}, lowest {res.lowest_height_ft:.0f} ft")
    print(f"  mean NEES (9 dof) {summary['mean_nees_9dof']:.2f}, mean NIS {summary['mean_nis']:.2f}, "
          f"{summary['rejected']} of {summary['measurements']} measurements rejected")
    if "at_200_ft" in summary:
        a = summary["at_200_ft"]
        print(f"  at 200 ft: NSE lat {a['nse_lateral_m']:+.2f} m vert {a['nse_vertical_m']:+.2f} m; "
              f"FTE lat {a['fte_lateral_m']:+.2f} m vert {a['fte_vertical_m']:+.2f} m")
    print(f"  wrote {args.out / 'nav.npz'}, nav.json, truth.npz{'' if args.no_figures else ', figures'}")
    if not res.ok:
        sys.stderr.write(f"approachsim navigate: failed approach: {res.termination}\n")
        return FAILED_APPROACH
    return 0


def _state_names(layout) -> list[str]:
    names = []
    for g, sl in layout.index.items():
        names += [f"{g}{i}" for i in range(sl.stop - sl.start)]
    return names
