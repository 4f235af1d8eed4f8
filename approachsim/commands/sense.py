"""`approachsim sense PROFILE --out DIR [--seed S] [--run I] [--synthetic] [--no-figures]`: sensor streams.

Flies the approach (JSBSim truth via approachsim.flight; --synthetic: the still-air synthetic test truth of
approachsim.synthetic instead), measures it with the profile's sensor suite and faults for run I of the
campaign seeded S, and writes

    DIR/truth.npz, DIR/truth.json     the truth record (flight/truthfile.py format)
    DIR/sensors/<name>.npz            every field of the sensor's record (see approachsim.records: ImuSamples,
                                      BaroSamples, RadaltSamples, GnssSamples, PseudoliteSamples), plus
                                      exact_<field> = the same record with noise=False (error = field - exact)
    DIR/sensors/<name>.csv            the same in long form (one row per sample, or per sample and channel)
    DIR/sensors.json                  schema: each file's arrays with shape, dtype and unit; seed, run, streams
    DIR/sensor_<name>.png             each sensor's error against time; DIR/gnss_sky.png the sky plot
"""

from __future__ import annotations

import argparse
import csv
import json
from dataclasses import fields
from pathlib import Path
from typing import Any

import numpy as np

from approachsim.commands._single_run import add_single_run_arguments, load_single_run

UNITS = {
    "t_s": "s", "dt_s": "s", "dtheta_body": "rad", "dv_body": "m/s", "valid": "bool", "fault": "code",
    "h_baro_m": "m", "sigma_m": "m", "h_agl_m": "m", "prn": "1", "r_sv_ecef": "m", "pseudorange_m": "m",
    "elevation_rad": "rad", "azimuth_rad": "rad", "visible": "bool", "pdop": "1", "clock_bias_m": "m",
    "clock_drift_mps": "m/s", "r_pl_ecef": "m",
}
VALUE_FIELDS = {"imu": ("dtheta_body", "dv_body"), "baro": ("h_baro_m",), "radalt": ("h_agl_m",),
                "gnss": ("pseudorange_m",), "pseudolite": ("pseudorange_m",)}


def register(sub: argparse._SubParsersAction) -> None:
    """Add the `sense` sub-command."""
    from approachsim.commands._help import command_parser

    p = command_parser(
        sub, "sense", help="fly one approach and write its sensor streams (with faults) and figures",
        description="Flies the approach (or, with --synthetic, uses a still-air synthetic truth), measures it with\n"
        "the profile's sensors and [[faults]], and writes DIR/sensors/<sensor>.npz and .csv (every record field and\n"
        "its noise-free value), DIR/sensors.json (schema with units), an error figure per sensor and the GPS\n"
        "sky plot.",
        examples=["approachsim sense profiles/default.toml --out out/sense",
                  "approachsim sense my-faults.toml --out out/faults --synthetic --no-figures"],
    )
    add_single_run_arguments(p)
    p.add_argument("--synthetic", action="store_true",
                   help="use the synthetic constant-velocity test truth instead of flying JSBSim")
    p.set_defaults(func=run)


def _record_arrays(rec: Any) -> dict[str, np.ndarray]:
    return {f.name: np.asarray(getattr(rec, f.name)) for f in fields(rec)}


def _write_csv(path: Path, name: str, rec: Any, exact: Any) -> None:
    """Long-form CSV: per sample (IMU, baro, radalt) or per sample and channel (GNSS, pseudolite)."""
    with path.open("w", newline="", encoding="utf-8") as fh:
        w = csv.writer(fh)
        if name == "imu":
            w.writerow(["t_s", "dtheta_x_rad", "dtheta_y_rad", "dtheta_z_rad", "dv_x_mps", "dv_y_mps", "dv_z_mps",
                        "err_dtheta_x_rad", "err_dtheta_y_rad", "err_dtheta_z_rad", "err_dv_x_mps", "err_dv_y_mps",
                        "err_dv_z_mps", "valid", "fault"])
            e1 = rec.dtheta_body - exact.dtheta_body
            e2 = rec.dv_body - exact.dv_body
            for j in range(rec.t_s.shape[0]):
                w.writerow([f"{rec.t_s[j]:.6f}", *(f"{v:.12e}" for v in rec.dtheta_body[j]),
                            *(f"{v:.12e}" for v in rec.dv_body[j]), *(f"{v:.6e}" for v in e1[j]),
                            *(f"{v:.6e}" for v in e2[j]), int(rec.valid[j]), int(rec.fault[j])])
        elif name in ("baro", "radalt"):
            fld = VALUE_FIELDS[name][0]
            w.writerow(["t_s", fld, f"exact_{fld}", "sigma_m", "valid", "fault"])
            v, x = getattr(rec, fld), getattr(exact, fld)
            for j in range(rec.t_s.shape[0]):
                w.writerow([f"{rec.t_s[j]:.6f}", f"{v[j]:.6f}", f"{x[j]:.6f}", f"{rec.sigma_m[j]:.4f}",
                            int(rec.valid[j]), int(rec.fault[j])])
        else:
            ids = rec.prn if name == "gnss" else np.arange(rec.pseudorange_m.shape[1])
            w.writerow(["t_s", "prn" if name == "gnss" else "unit", "pseudorange_m", "geometric_range_m",
                        "clock_bias_m", "sigma_m", "elevation_rad", "valid", "fault"])
            for j in range(rec.t_s.shape[0]):
                for c in range(ids.shape[0]):
                    if name == "gnss" and not rec.visible[j, c]:
                        continue
                    w.writerow([f"{rec.t_s[j]:.6f}", int(ids[c]), f"{rec.pseudorange_m[j, c]:.4f}",
                                f"{exact.pseudorange_m[j, c]:.4f}", f"{rec.clock_bias_m[j]:.4f}",
                                f"{rec.sigma_m[j, c]:.4f}", f"{rec.elevation_rad[j, c]:.6f}", int(rec.valid[j, c]),
                                int(rec.fault[j, c])])


def _day_sky(gnss: Any, profile: Any, path: Path) -> Path:
    """Sky plot of a whole day (every 10 min from the epoch) at the runway threshold, with the worst case
    of satellites in view and PDOP (all in view) in the title."""
    from approachsim import geo
    from approachsim.report.sensors import day_sky_plot
    from approachsim.sensors.gnss.constellation import dops, look_angles

    rx = getattr(gnss, "sensor", gnss)  # unwrap a Faulted receiver
    t = np.arange(0.0, 86400.0 + 1.0, 600.0)
    rw = profile.runway.frame
    r_rx = np.tile(rw.origin_ecef, (t.shape[0], 1))
    _, u, el, az = look_angles(r_rx, rx.constellation.positions_ecef(t))
    vis = el >= rx.mask_rad
    c = np.tile(geo.c_ecef_to_ned(rw.threshold_lat_rad, rw.threshold_lon_rad), (t.shape[0], 1, 1))
    _, pdop, _, _ = dops(u, vis, c)
    title = (f"{profile.name}: 24 h from the epoch, 10 min steps\nmin {int(vis.sum(axis=1).min())} SVs above "
             f"{np.degrees(rx.mask_rad):.0f} deg, max PDOP {pdop.max():.2f}")
    return day_sky_plot(az, el, rx.constellation.prn, rx.mask_rad, path, title)


def run(args: argparse.Namespace) -> int:
    """Fly (or build the synthetic truth), measure, write data, schema and figures; print a summary."""
    from approachsim.flight.truthfile import save_truth
    from approachsim.sensors.faults import FAULT_CODES
    from approachsim.sensors.suite import CLOCK_STREAM, SensorSuite

    profile, seed = load_single_run(args)
    if args.synthetic:
        from approachsim import synthetic

        truth = synthetic.profile_descent(profile)
        source = "synthetic test truth (approachsim.synthetic.profile_descent; not a flight)"
    else:
        from approachsim.flight.run import Approach

        truth = Approach(profile).fly(seed=seed, run=args.run).truth
        source = "JSBSim (approachsim.flight)"
    suite = SensorSuite.from_profile(profile)
    meas = suite.measure(truth, seed, args.run)
    exact = suite.measure(truth, seed, args.run, noise=False)
    args.out.mkdir(parents=True, exist_ok=True)
    sdir = args.out / "sensors"
    sdir.mkdir(exist_ok=True)
    save_truth(args.out / "truth.npz", truth, meta={"profile": profile.name, "seed": seed, "run": args.run,
                                                     "source": source})
    schema: dict[str, Any] = {
        "schema": "approachsim.sensors/1", "profile": profile.name, "seed": seed, "run": args.run,
        "truth": "truth.npz", "truth_source": source,
        "streams": {name: f"approachsim.seeding.stream({seed}, {args.run}, {name!r})" for name in meas}
        | ({CLOCK_STREAM: f"approachsim.seeding.stream({seed}, {args.run}, {CLOCK_STREAM!r})"}
           if suite.clock is not None else {}),
        "fault_codes": dict(FAULT_CODES), "faults": [vars(f) | {"end_s": str(f.end_s)} for f in profile.faults],
        "files": {},
    }
    for name, rec in meas.items():
        arrays = _record_arrays(rec)
        for fld in VALUE_FIELDS[name]:
            arrays[f"exact_{fld}"] = np.asarray(getattr(exact[name], fld))
        np.savez(sdir / f"{name}.npz", **arrays)
        _write_csv(sdir / f"{name}.csv", name, rec, exact[name])
        schema["files"][f"sensors/{name}.npz"] = {
            k: {"shape": list(v.shape), "dtype": str(v.dtype), "unit": UNITS.get(k.removeprefix("exact_"), "")}
            for k, v in arrays.items()
        }
        schema["files"][f"sensors/{name}.csv"] = "long form of the same (see approachsim/commands/sense.py)"
    (args.out / "sensors.json").write_text(json.dumps(schema, indent=2, default=str) + "\n", encoding="utf-8")
    figs = []
    if not args.no_figures:
        from approachsim.report.sensors import write_sensor_figures

        figs = write_sensor_figures(meas, exact, args.out, f"{profile.name} seed {seed} run {args.run}")
        if "gnss" in meas:
            figs.append(_day_sky(suite.sensors["gnss"], profile, args.out / "gnss_sky_day.png"))
    print(f"{profile.name}: seed {seed} run {args.run}: {len(truth)} truth samples ({source})")
    for name, rec in meas.items():
        n = rec.t_s.shape[0]
        nf = int(np.count_nonzero(np.asarray(rec.fault)))
        print(f"  {name:10s} {n:6d} samples, {int(np.count_nonzero(rec.valid))} valid values, {nf} fault-labelled")
    print(f"  wrote {sdir} (NPZ + CSV), sensors.json, truth.npz{f', {len(figs)} figures' if figs else ''}")
    return 0
