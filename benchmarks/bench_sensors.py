"""Benchmark: the sensor suite of a profile, numpy reference vs compiled kernels, batch and one row at a time.

    python benchmarks/bench_sensors.py [--runs 1000] [--chunk 25] [--repeat 3] [--pseudolite] [--jsbsim]
                                       [--profile profiles/default.toml]

Truth: the JSBSim approach of the profile (--jsbsim, flown once, run 0) or, by default, the synthetic
constant-velocity test truth of the same profile (approachsim.synthetic.profile_descent; same rates and about the
same length). --pseudolite adds one pseudolite unit near the threshold to the profile's suite. Prints, in one run:

1. draw + apply per run, for 1 run and for a chunk of runs sharing the truth (each its own GPS sky when the
   profile's epoch is per-run), "reference" (numpy: scipy lfilter Gauss-Markov recursions, the apply_reference of
   the GNSS receiver (best_pdop_four_reference), baro, radar altimeter, pseudolite) vs "compiled" (core/sensors/);
2. the best-PDOP selection alone on those skies: best_pdop_four_reference vs the kernel (and that they agree);
3. one truth row at a time: the closed loop's aiding epochs (baro + radalt + gnss [+ pseudolite]) and all its sensor
   calls over an approach (the epochs and every baro sample): the generic path with the numpy GNSS (before), the
   generic path compiled, and SensorSuite.prepare(...).one;
4. --runs N runs in chunks, compiled (throughput; 0 skips it).

Times are the minimum over --repeat repetitions (one warm-up call first: numba's cache load and compilation are not
counted; in part 1 the reference and compiled rounds alternate). The load average is printed before and after:
figures taken under load are slower and noisier, the ratios within one run are the figures to read. Not a test:
results go to benchmarks/RESULTS.md.
"""

from __future__ import annotations

import argparse
import os
import platform
import time
from contextlib import contextmanager, nullcontext
from dataclasses import replace
from pathlib import Path
from types import MappingProxyType

import numpy as np

from approachsim.profile import load_profile
from approachsim.sensors import base
from approachsim.sensors.baro import Baro
from approachsim.sensors.config import PseudoliteConfig
from approachsim.sensors.gnss.constellation import look_angles
from approachsim.sensors.gnss.receiver import GnssReceiver, best_pdop_four, best_pdop_four_reference
from approachsim.sensors.pseudolite import Pseudolite
from approachsim.sensors.radalt import RadarAltimeter
from approachsim.sensors.suite import SensorSuite, SuiteErrors

EPOCH_SENSORS = ("baro", "radalt", "gnss", "pseudolite")


@contextmanager
def numpy_reference():
    """The numpy versions in place of this work's kernels (the code before them): lfilter Gauss-Markov recursions,
    and the numpy apply of the GNSS receiver, baro, radar altimeter and pseudolite (the IMU kernel is older: kept)."""
    gm = base.gauss_markov
    applies = {cls: cls.apply for cls in (GnssReceiver, Baro, RadarAltimeter, Pseudolite)}
    base.gauss_markov = base.gauss_markov_reference
    for cls in applies:
        cls.apply = cls.apply_reference
    try:
        yield
    finally:
        base.gauss_markov = gm
        for cls, fn in applies.items():
            cls.apply = fn


def best_of(fn, repeat: int) -> float:
    """Minimum wall time (s) of fn() over `repeat` calls after one warm-up call."""
    fn()
    out = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return min(out)


def load() -> str:
    return "load average {:.2f} {:.2f} {:.2f}".format(*os.getloadavg())


def per_run_part(suite, truth, seed: int, runs: list[int], repeat: int) -> dict:
    """ms per run of draw and of each sensor's apply, reference and compiled: the minimum over `repeat` rounds that
    alternate the two (a first round is discarded as warm-up), so a change of load hits both alike."""
    modes = {"reference": numpy_reference, "compiled": nullcontext}
    best = {m: dict.fromkeys(["draw", *suite.sensors], np.inf) for m in modes}
    for rnd in range(repeat + 1):
        for mode, ctx in modes.items():
            with ctx():
                t0 = time.perf_counter()
                errors = suite.draw(truth.t_s, seed, runs)
                times = {"draw": time.perf_counter() - t0}
                for name in suite.sensors:
                    t0 = time.perf_counter()
                    suite.apply(truth, errors, names=[name])
                    times[name] = time.perf_counter() - t0
            if rnd > 0:
                best[mode] = {k: min(v, 1e3 * times[k] / len(runs)) for k, v in best[mode].items()}
    return best


def print_per_run(title: str, res: dict, names) -> None:
    print(f"\n{title} (ms per run; min of repeats)")
    cols = ["draw", *names]
    print(f"  {'':10s}" + "".join(f"{c:>11s}" for c in cols) + f"{'total':>11s}")
    for mode in ("reference", "compiled"):
        r = res[mode]
        print(f"  {mode:10s}" + "".join(f"{r[c]:11.2f}" for c in cols) + f"{sum(r[c] for c in cols):11.2f}")
    ratio = {c: res["reference"][c] / max(res["compiled"][c], 1e-12) for c in cols}
    tot = sum(res["reference"][c] for c in cols) / sum(res["compiled"][c] for c in cols)
    print(f"  {'ratio':10s}" + "".join(f"{ratio[c]:10.1f}x" for c in cols) + f"{tot:10.1f}x")


def selection_part(suite, truth, seed: int, runs: list[int], repeat: int) -> None:
    """The best-PDOP selection alone on the runs' skies (the numpy geometry's lines of sight)."""
    rx = suite.sensors["gnss"]
    e = suite.draw(truth.t_s, seed, runs).sensors["gnss"]
    offs = np.atleast_1d(e.constants.get("epoch_offset_s", np.zeros(1)))
    skies = []
    for o in offs:
        _, u, el, _ = look_angles(truth.r_ecef[e.rows], rx.geometry_constellation(float(o)).positions_ecef(e.t_s))
        skies.append((u, el >= rx.mask_rad))
    same = all(np.array_equal(best_pdop_four(u, v), best_pdop_four_reference(u, v)) for u, v in skies)
    t_ref = best_of(lambda: [best_pdop_four_reference(u, v) for u, v in skies], repeat)
    t_k = best_of(lambda: [best_pdop_four(u, v) for u, v in skies], repeat)
    n_vis = np.mean([v.sum(axis=1).mean() for _, v in skies])
    print(f"\nbest-PDOP four alone: {len(skies)} skies x {len(e)} epochs, {n_vis:.1f} satellites in view on average;"
          f" identical selections: {same}")
    print(f"  numpy {1e3 * t_ref / len(skies):.2f} ms per sky, compiled {1e3 * t_k / len(skies):.3f} ms per sky: "
          f"{t_ref / t_k:.0f}x")


def one_row_part(prof, suite, truth, seed: int, run: int, repeat: int) -> None:
    """One truth row at a time: us per aiding epoch (baro + radalt + gnss [+ pseudolite] at each GNSS epoch) and
    ms per approach of the closed loop's calls (loop/closed_loop.py: those at every aiding epoch and the baro at
    every baro sample for the damping loop), before (generic path, numpy GNSS), generic compiled, prepared."""
    errors = suite.draw(truth.t_s, seed, run)
    names = tuple(n for n in EPOCH_SENSORS if n in suite.sensors)
    ks = [int(k) for k in errors.sensors["gnss"].rows if k < len(truth)]
    at = {n: {int(r): j for j, r in enumerate(errors.sensors[n].rows)} for n in names}
    epoch_rows = max(1, int(round(prof.rates.imu_hz / prof.nav.aiding_rate_hz)))
    calls = []  # (sensor, row) in the closed loop's order; rows without a sample are skipped by its lookup
    for k in range(len(truth)):
        if k % epoch_rows == 0:
            calls += [(n, k) for n in names if k in at[n]]
        if k in at.get("baro", {}):
            calls.append(("baro", k))

    def generic(k: int, n: str) -> None:  # NavInTheLoop._apply: a one-sample view through SensorSuite.apply
        j = at[n][k]
        e = errors.sensors[n]
        one = replace(e, index=e.index[j:j + 1], rows=e.rows[j:j + 1], t_s=e.t_s[j:j + 1],
                      series={s: v[j:j + 1] for s, v in e.series.items()})
        suite.apply(truth, SuiteErrors(MappingProxyType({n: one}), errors.clock), names=[n])

    t_prep0 = time.perf_counter()
    prepared = suite.prepare(errors)
    t_prep = time.perf_counter() - t_prep0

    def prep(k: int, n: str) -> None:  # what NavInTheLoop._apply would call
        prepared.one(n, truth, k)

    res = {}
    for label, fn, ctx in (("generic path, numpy GNSS (before)", generic, numpy_reference),
                           ("generic path, compiled", generic, nullcontext), ("prepared (.one)", prep, nullcontext)):
        with ctx():
            epoch = best_of(lambda f=fn: [f(k, n) for k in ks for n in names if k in at[n]], repeat)
            approach = best_of(lambda f=fn: [f(k, n) for n, k in calls], repeat)
        res[label] = (epoch, approach)
    per = {n: best_of(lambda n=n: [prepared.one(n, truth, k) for k in ks if k in at[n]], repeat) for n in names}
    us = 1e6 / len(ks)
    base_e, base_a = res["generic path, numpy GNSS (before)"]
    print(f"\none truth row at a time (one run, {'per-run sky' if suite.epoch_window_s > 0 else 'fixed sky'}): "
          f"{' + '.join(names)} at each of {len(ks)} GNSS epochs; per approach the closed loop's {len(calls)} calls")
    for label, (e, a) in res.items():
        print(f"  {label:34s} {e * us:7.1f} us per epoch ({base_e / e:4.1f}x)   {1e3 * a:7.1f} ms per approach "
              f"({base_a / a:4.1f}x)")
    print("  prepared, per sensor: " + ", ".join(f"{n} {per[n] * us:.1f} us" for n in names)
          + f"; prepare once per run {1e3 * t_prep:.1f} ms")


def throughput_part(suite, truth, seed: int, n_runs: int, chunk: int) -> None:
    t0 = time.perf_counter()
    per = dict.fromkeys(["draw", *suite.sensors], 0.0)
    for r0 in range(0, n_runs, chunk):
        runs = list(range(r0, min(n_runs, r0 + chunk)))
        t1 = time.perf_counter()
        errors = suite.draw(truth.t_s, seed, runs)
        per["draw"] += time.perf_counter() - t1
        for name in suite.sensors:
            t1 = time.perf_counter()
            suite.apply(truth, errors, names=[name])
            per[name] += time.perf_counter() - t1
    total = time.perf_counter() - t0
    flight_s = float(truth.t_s[-1])
    print(f"\n{n_runs} runs in chunks of {chunk}, compiled: {total:.1f} s total, {1e3 * total / n_runs:.1f} ms per "
          f"run, {flight_s * n_runs / total:.0f}x real time; " + ", ".join(f"{k} {v:.2f} s" for k, v in per.items()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--profile", type=Path, default=Path(__file__).resolve().parents[1] / "profiles" / "default.toml")
    ap.add_argument("--runs", type=int, default=1000)
    ap.add_argument("--chunk", type=int, default=25)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--pseudolite", action="store_true", help="add a pseudolite unit near the threshold")
    ap.add_argument("--jsbsim", action="store_true", help="fly the JSBSim truth once instead of the synthetic one")
    args = ap.parse_args()
    print(f"start: {load()}")
    prof = load_profile(args.profile)
    t0 = time.perf_counter()
    if args.jsbsim:
        from approachsim.flight.run import Approach

        truth = Approach(prof).fly(seed=args.seed, run=0).truth
        kind = "JSBSim"
    else:
        from approachsim import synthetic

        truth = synthetic.profile_descent(prof)
        kind = "synthetic"
    t_truth = time.perf_counter() - t0
    cfg = prof.sensors
    if args.pseudolite:
        cfg = replace(cfg, pseudolite=PseudoliteConfig(positions_rwy=((0.0, -152.4, 9.1),)))
    suite = SensorSuite.from_config(cfg, prof.runway.frame, prof.environment.setting_pa, prof.faults)
    print(f"profile {prof.name}: {kind} truth, {len(truth)} samples at {prof.rates.imu_hz:g} Hz, "
          f"{float(truth.t_s[-1]):.0f} s of flight (truth built in {t_truth:.1f} s); "
          f"sensors {', '.join(suite.sensors)}")
    print(f"machine: {platform.processor() or platform.machine()}, {os.cpu_count()} CPUs visible, "
          f"numpy {np.__version__}")
    names = list(suite.sensors)
    print_per_run("draw + apply, 1 run", per_run_part(suite, truth, args.seed, [0], args.repeat), names)
    chunk = list(range(args.chunk))
    print_per_run(f"draw + apply, {args.chunk} runs sharing the truth",
                  per_run_part(suite, truth, args.seed, chunk, args.repeat), names)
    if "gnss" in suite.sensors:
        selection_part(suite, truth, args.seed, chunk, args.repeat)
        one_row_part(prof, suite, truth, args.seed, 0, args.repeat)
    if args.runs > 0:
        throughput_part(suite, truth, args.seed, args.runs, args.chunk)
    print(f"\nend: {load()}")


if __name__ == "__main__":
    main()
