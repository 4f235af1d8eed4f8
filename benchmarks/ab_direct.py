"""In-process A/B of the flight loop: compiled with JSBSim called from it (core/loop/direct.py) against the
Python loop (APPROACHSIM_JSBSIM_DIRECT=0), interleaved in one warm process, with raw JSBSim stepping (trim + run()
from Python) as the floor. CPU time (time.process_time), min and median over the repeats, of the truth flight
(Approach.fly) and of the closed loop (Approach.fly with NavInTheLoop); every pair's results are compared bit for bit.

    python benchmarks/ab_direct.py [--repeat 7] [--profile profiles/default.toml]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")

import numpy as np  # noqa: E402

from approachsim.core.loop import jsbsim_abi  # noqa: E402
from approachsim.flight.fdm import FDM  # noqa: E402
from approachsim.flight.run import Approach  # noqa: E402
from approachsim.flight.trim import start_condition  # noqa: E402
from approachsim.loop.closed_loop import NavInTheLoop  # noqa: E402
from approachsim.profile import load_profile  # noqa: E402


def _arrays(obj, out: list) -> list:
    if dataclasses.is_dataclass(obj):
        for f in dataclasses.fields(obj):
            _arrays(getattr(obj, f.name), out)
    elif isinstance(obj, (tuple, list)):
        for v in obj:
            _arrays(v, out)
    elif isinstance(obj, np.ndarray):
        out.append(obj)
    return out


def _same(a, b) -> bool:
    xa, xb = _arrays(a, []), _arrays(b, [])
    return len(xa) == len(xb) > 0 and all(p.shape == q.shape and np.array_equal(p, q, equal_nan=p.dtype.kind in "fc")
                                          for p, q in zip(xa, xb, strict=True))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--profile", default="profiles/default.toml")
    args = ap.parse_args()
    prof = load_profile(args.profile)
    approach = Approach(prof)
    ic = start_condition(prof, approach.aircraft)

    def raw(n: int) -> float:
        fdm = FDM(approach.aircraft.jsbsim_model, approach.dt_s)
        approach._trim(fdm, ic)
        run = fdm.run
        t = time.process_time()
        for _ in range(n):
            run()
        return time.process_time() - t

    def truth(flag: str, k: int):
        os.environ[jsbsim_abi.ENV_SWITCH] = flag
        t = time.process_time()
        res = approach.fly(seed=1, run=k)
        return time.process_time() - t, res

    def closed(flag: str, k: int):
        os.environ[jsbsim_abi.ENV_SWITCH] = flag
        t = time.process_time()
        src = NavInTheLoop(prof, seed=1, run=k, max_time_s=approach.time_budget_s)
        res = approach.fly(seed=1, run=k, nav_source=src)
        nav = src.result(res.truth)
        return time.process_time() - t, (res, nav)

    for f in (truth, closed):  # warm: numba's cache, first-touch
        f("1", 0), f("0", 0)
    times: dict[str, list[float]] = {k: [] for k in ("raw", "truth 1", "truth 0", "closed 1", "closed 0")}
    differ = 0
    steps = 0
    for k in range(1, args.repeat + 1):
        for name, f in (("truth", truth), ("closed", closed)):
            (t1, r1), (t0, r0) = f("1", k), f("0", k)
            times[f"{name} 1"].append(t1)
            times[f"{name} 0"].append(t0)
            differ += not _same(r1, r0)
            if name == "truth":
                steps = len(r1.truth.t_s)
                times["raw"].append(raw(steps))
    os.environ.pop(jsbsim_abi.ENV_SWITCH, None)
    print(f"ab_direct: {args.profile}, {args.repeat} interleaved repeats, ~{steps} steps; CPU s, min / median; "
          f"load average {' '.join(f'{x:.2f}' for x in os.getloadavg())}")
    r = min(times["raw"])
    for key, what in (("raw", "raw JSBSim stepping (trim + run() from Python)"),
                      ("truth 0", "truth flight, Python loop"), ("truth 1", "truth flight, compiled loop"),
                      ("closed 0", "closed loop, Python loop"), ("closed 1", "closed loop, compiled loop")):
        v = times[key]
        print(f"  {what:50s} {min(v):.3f} / {statistics.median(v):.3f}   / raw {min(v) / r:.2f}")
    print(f"  pairs differing in any array: {differ} of {2 * args.repeat}")


if __name__ == "__main__":
    main()
