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


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("profile", type=Path)
    ap.add_argument("--runs", type=int, default=60)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--set", action="append", default=[], metavar="KEY=VALUE")
    ap.add_argument("--slow-tau-s", type=float, default=None)
    a = ap.parse_args()

    from approachsim.flight.run import Approach
    from approachsim.nav.system import NavSystem
    from approachsim.profile import parse_profile
    from approachsim.seeding import stream
    from approachsim.sensors.gnss import receiver
    from approachsim.sensors.states import measure_with_states
    from approachsim.sensors.suite import SensorSuite

    data = tomllib.loads(a.profile.read_text(encoding="utf-8"))
    for item in a.set:
        _set(data, item)
    prof = parse_profile(data, source=a.profile.resolve())
    truth = Approach(prof).fly(seed=a.seed, run=0).truth
    suite = SensorSuite.from_profile(prof)
    if a.slow_tau_s is not None:  # the truth's slow range errors only; the filter is built from the profile below
        gnss = suite.sensors["gnss"]
        if not isinstance(gnss, receiver.GnssReceiver):
            raise SystemExit("--slow-tau-s needs a plain GNSS receiver (no fault on it)")
        budget = dataclasses.replace(gnss.budget, clock_ephemeris_tau_s=a.slow_tau_s, iono_tau_s=a.slow_tau_s,
                                     tropo_tau_s=a.slow_tau_s)
        sensors = dict(suite.sensors) | {"gnss": dataclasses.replace(gnss, budget=budget)}
        suite = dataclasses.replace(suite, sensors=MappingProxyType(sensors))
    recs, st = measure_with_states(suite, truth, seed=a.seed, runs=list(range(a.runs)))
    nav = NavSystem.from_profile(prof)
    rs = nav.run(truth, recs, [stream(a.seed, r, "nav") for r in range(a.runs)], shared_covariance=True, states=st)
    e = np.stack([r.true_error_nav for r in rs])
    d = np.diagonal(np.stack([r.P_nav for r in rs]), axis1=2, axis2=3)
    lay = rs[0].layout
    if lay.has("clk") and "gnss" in recs:  # the receiver clock bias: the filter's clk state against the truth's
        g = recs["gnss"]
        t_g, cb = np.asarray(g.t_s), np.asarray(g.clock_bias_m).reshape(a.runs, -1)
        ic = lay.i("clk")
        idx = [np.clip(np.searchsorted(t_g, r.t_epoch_s + 1e-9, side="right") - 1, 0, t_g.size - 1) for r in rs]
        ec = np.stack([r.x[:, ic] - cb[i, j] for i, (r, j) in enumerate(zip(rs, idx, strict=True))])
        e = np.concatenate([e, ec[..., None]], axis=-1)
        d = np.concatenate([d, np.stack([r.P_diag[:, ic] for r in rs])[..., None]], axis=-1)
    z = (e**2 / d).mean(axis=0)
    later = slice(z.shape[0] // 4, z.shape[0])
    lo, hi = chi2.ppf([0.025, 0.975], a.runs) / a.runs
    print(f"{a.profile}: {a.runs} runs, {z.shape[0]} epochs (from epoch {later.start}); 95 % bounds [{lo:.2f}, "
          f"{hi:.2f}]" + "".join(f"; {s}" for s in a.set)
          + (f"; truth slow taus {a.slow_tau_s:g} s" if a.slow_tau_s is not None else ""))
    print(f"  {'state':6s} {'e^2/P':>6s} {'inside':>7s} {'below':>6s} {'above':>6s} {'sigma':>10s}")
    for c, name in enumerate(STATES + ("clk",) if z.shape[1] > len(STATES) else STATES):
        zc = z[later, c]
        print(f"  {name:6s} {zc.mean():6.2f} {np.mean((zc >= lo) & (zc <= hi)):7.2f} {np.mean(zc < lo):6.2f} "
              f"{np.mean(zc > hi):6.2f} {np.sqrt(d[:, later, c]).mean():10.3g}")


if __name__ == "__main__":
    main()
