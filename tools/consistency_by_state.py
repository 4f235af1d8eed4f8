"""Filter consistency state by state on a flown approach: which of the 9 navigation errors the filter over- or
under-claims (the diagnosis behind tests/integration/test_nav_consistency_jsbsim.py's NEES finding).

    python tools/consistency_by_state.py PROFILE [--runs 60] [--seed 1] [--set KEY=VALUE ...]
        [--slow-tau-s TAU]

The profile is flown once on truth; RUNS seeded sensor realizations and open-loop navigation runs (the shared
covariance, as campaigns run) follow on that truth. Printed per state (dp N E D m, dv N E D m/s, psi N E D rad; clk
the receiver clock bias, m): the run-averaged e^2 / P over the approach after its first quarter (1 for a consistent
filter; below 1 the filter over-claims), the fraction of epochs whose run average is inside the two-sided 95 %
chi2(RUNS)/RUNS bounds, and the filter's mean sigma. --set changes a profile key for this run (dotted path, a TOML
value: --set sensors.gnss.multipath_model='"nrc1995"'). --slow-tau-s sets the truth's clock/ephemeris, iono and tropo
time constants to TAU (the filter keeps its own: it models the three as one Gauss-Markov state at the shortest,
nav/noise.py): with TAU = 1800 the truth drifts as fast as the filter assumes.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import tomllib
from pathlib import Path
from types import MappingProxyType

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402
from scipy.stats import chi2  # noqa: E402

STATES = ("dp_N", "dp_E", "dp_D", "dv_N", "dv_E", "dv_D", "psi_N", "psi_E", "psi_D")


def _set(data: dict, item: str) -> None:
    """Apply one KEY=VALUE (dotted key, TOML value) to the profile's data."""
    key, _, value = item.partition("=")
    *path, last = key.split(".")
    node = data
    for k in path:
        node = node.setdefault(k, {})
    node[last] = tomllib.loads(f"v = {value}")["v"]


def errors(profile: Path, runs: int, seed: int, sets: tuple[str, ...] = (), slow_tau_s: float | None = None,
           ideal_imu_axes: str = "", filter_turbulence: str | None = None
           ) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """The profile flown once (seed, run 0) on truth, RUNS sensor realizations and open-loop navigation runs (shared
    covariance) on it: (e (runs, epochs, s) the true errors, P (runs, epochs, s) the filter's variances, the state
    names) of the 9 navigation errors and, with GNSS, the receiver clock bias (m). The options: module docstring."""
    from approachsim.flight.run import Approach
    from approachsim.nav.system import NavSystem
    from approachsim.profile import parse_profile
    from approachsim.seeding import stream
    from approachsim.sensors.gnss import receiver
    from approachsim.sensors.states import measure_with_states
    from approachsim.sensors.suite import SensorSuite

    data = tomllib.loads(profile.read_text(encoding="utf-8"))
    for item in sets:
        _set(data, item)
    prof = parse_profile(data, source=profile.resolve())
    truth = Approach(prof).fly(seed=seed, run=0).truth
    suite = SensorSuite.from_profile(prof)
    if slow_tau_s is not None:  # the truth's slow range errors only; the filter is built from the profile below
        gnss = suite.sensors["gnss"]
        if not isinstance(gnss, receiver.GnssReceiver):
            raise SystemExit("--slow-tau-s needs a plain GNSS receiver (no fault on it)")
        budget = dataclasses.replace(gnss.budget, clock_ephemeris_tau_s=slow_tau_s, iono_tau_s=slow_tau_s,
                                     tropo_tau_s=slow_tau_s)
        suite = dataclasses.replace(suite, sensors=MappingProxyType(dict(suite.sensors) | {
            "gnss": dataclasses.replace(gnss, budget=budget)}))
    if ideal_imu_axes:  # the truth's IMU only; the filter is built from the profile's grade below
        imu = suite.sensors["imu"]
        zero = {"gyro": ("gyro_sf", "gyro_misalign_rad"), "accel": ("accel_sf", "accel_misalign_rad")}
        grade = dataclasses.replace(imu.grade, **{k: 0.0 for s in ideal_imu_axes.split(",") for k in zero[s]})
        suite = dataclasses.replace(suite, sensors=MappingProxyType(dict(suite.sensors) | {
            "imu": dataclasses.replace(imu, grade=grade)}))
    recs, st = measure_with_states(suite, truth, seed=seed, runs=list(range(runs)))
    nav = NavSystem.from_profile(prof)
    if filter_turbulence is not None:  # the filter's gyro axis noise at another level (none: no such noise)
        nav = dataclasses.replace(nav, turbulence=filter_turbulence)
    rs = nav.run(truth, recs, [stream(seed, r, "nav") for r in range(runs)], shared_covariance=True, states=st)
    e = np.stack([r.true_error_nav for r in rs])
    d = np.diagonal(np.stack([r.P_nav for r in rs]), axis1=2, axis2=3)
    lay = rs[0].layout
    if lay.has("clk") and "gnss" in recs:  # the receiver clock bias: the filter's clk state against the truth's
        g = recs["gnss"]
        t_g, cb = np.asarray(g.t_s), np.asarray(g.clock_bias_m).reshape(runs, -1)
        ic = lay.i("clk")
        idx = [np.clip(np.searchsorted(t_g, r.t_epoch_s + 1e-9, side="right") - 1, 0, t_g.size - 1) for r in rs]
        ec = np.stack([r.x[:, ic] - cb[i, j] for i, (r, j) in enumerate(zip(rs, idx, strict=True))])
        return (np.concatenate([e, ec[..., None]], axis=-1),
                np.concatenate([d, np.stack([r.P_diag[:, ic] for r in rs])[..., None]], axis=-1), STATES + ("clk",))
    return e, d, STATES


def summary(e: np.ndarray, d: np.ndarray) -> dict[str, np.ndarray]:
    """Per state over the approach after its first quarter: the run-averaged e^2 / P (mean over epochs), the
    fractions of epochs whose run average is inside / below / above the two-sided 95 % chi2(R)/R bounds (R runs),
    the filter's mean sigma and the run-mean error over the sigma's RMS (a deterministic error common to the runs
    on their one truth)."""
    runs = e.shape[0]
    z = (e**2 / d).mean(axis=0)
    later = slice(z.shape[0] // 4, z.shape[0])
    lo, hi = chi2.ppf([0.025, 0.975], runs) / runs
    zc = z[later]
    sig = np.sqrt(d[:, later])
    return {"ratio": zc.mean(axis=0), "inside": np.mean((zc >= lo) & (zc <= hi), axis=0),
            "below": np.mean(zc < lo, axis=0), "above": np.mean(zc > hi, axis=0), "sigma": sig.mean(axis=(0, 1)),
            "common": np.sqrt(np.mean((e[:, later].mean(axis=0) / sig.mean(axis=0)) ** 2, axis=0)),
            "bounds": np.array([lo, hi]), "epochs": np.array([z.shape[0], later.start])}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("profile", type=Path)
    ap.add_argument("--runs", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--slow-tau-s", type=float, default=None)
    ap.add_argument("--ideal-imu-axes", default="", choices=("", "gyro", "accel", "gyro,accel"),
                    help="the truth's IMU without scale-factor and misalignment errors (gyro, accel or both)")
    ap.add_argument("--filter-turbulence", default=None, choices=("none", "light", "moderate", "severe"),
                    help="the filter's gyro axis process noise at this turbulence level (default: the profile's)")
    a = ap.parse_args()
    e, d, names = errors(a.profile, a.runs, a.seed, tuple(a.set), a.slow_tau_s, a.ideal_imu_axes,
                         a.filter_turbulence)
    s = summary(e, d)
    lo, hi = s["bounds"]
    print(f"{a.profile}: {a.runs} runs, {s['epochs'][0]} epochs (from epoch {s['epochs'][1]}); 95 % bounds "
          f"[{lo:.2f}, {hi:.2f}]" + "".join(f"; {x}" for x in a.set)
          + (f"; truth slow taus {a.slow_tau_s:g} s" if a.slow_tau_s is not None else "")
          + (f"; truth {a.ideal_imu_axes} without scale factor / misalignment" if a.ideal_imu_axes else "")
          + (f"; filter turbulence {a.filter_turbulence}" if a.filter_turbulence else ""))
    print(f"  {'state':6s} {'e^2/P':>6s} {'inside':>7s} {'below':>6s} {'above':>6s} {'sigma':>10s} {'common':>7s}")
    for c, name in enumerate(names):
        print(f"  {name:6s} {s['ratio'][c]:6.2f} {s['inside'][c]:7.2f} {s['below'][c]:6.2f} {s['above'][c]:6.2f} "
              f"{s['sigma'][c]:10.3g} {s['common'][c]:7.2f}")

if __name__ == "__main__":
    main()
