"""The carrier variant's integrity bank on the compiled reduced pass against the path it took before (issue 26,
branch carrierbank): CPU time of `campaign.pipeline.open_loop_group` over runs 0 .. N-1 (flight, sensors,
navigation, scoring with the bank), interleaved in one process, and the runs' results compared bit for bit.

    python benchmarks/bench_carrier_bank.py [--runs 25] [--seed 1] [--repeat 2]

Cases (each warmed up once on run 0):

    code       profiles/gbas-cat3-candidate.toml
    carrier    profiles/gbas-carrier-cat3-candidate.toml, the bank's compiled pass (campaign/bankpass.py)
    fallback   the same, the bank through NavSystem.run's copies (bankpass.applicable False for carrier phase: what
               main did before this branch)

Prints each round's CPU seconds (time.process_time: robust on a shared machine) and ratios, the median ratios, the
load average before and after, and whether carrier and fallback gave the same records (every scalar, array and
histogram of every run, np.array_equal). BLAS single-threaded. No pass/fail.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import time
from pathlib import Path
from unittest import mock

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    os.environ.setdefault(_var, "1")

import numpy as np  # noqa: E402

from approachsim.campaign import bankpass  # noqa: E402
from approachsim.campaign.pipeline import open_loop_group  # noqa: E402
from approachsim.nav.engine import EpochEngine  # noqa: E402
from approachsim.profile import load_profile  # noqa: E402

PROFILES = Path(__file__).resolve().parents[1] / "profiles"
_APPLICABLE = bankpass.applicable


def _main_applicable(nav, records) -> bool:
    """bankpass.applicable as on main before this branch: carrier phase takes NavSystem.run's path."""
    eng = EpochEngine.of(nav)
    return _APPLICABLE(nav, records) and eng is not None and not eng.carrier


def _case(name: str):
    if name == "code":
        return load_profile(PROFILES / "gbas-cat3-candidate.toml"), contextlib.nullcontext()
    prof = load_profile(PROFILES / "gbas-carrier-cat3-candidate.toml")
    if name == "carrier":
        return prof, contextlib.nullcontext()
    return prof, mock.patch.object(bankpass, "applicable", _main_applicable)


def _run(name: str, seed: int, runs: list[int]) -> tuple[float, list]:
    prof, ctx = _case(name)
    with ctx:
        t0 = time.process_time()
        res = open_loop_group(prof, seed, runs)
        return time.process_time() - t0, res


def _same(a: list, b: list) -> bool:
    """Every run's ok, scalars, arrays and counts equal bit for bit (nan equal to nan)."""
    if len(a) != len(b):
        return False
    for x, y in zip(a, b, strict=True):
        if x.ok != y.ok or x.error != y.error:
            return False
        for fa, fb in ((x.scalars, y.scalars), (x.arrays, y.arrays), (x.counts, y.counts)):
            if set(fa) != set(fb):
                return False
            if not all(np.array_equal(np.asarray(fa[k]), np.asarray(fb[k]), equal_nan=True) for k in fa):
                return False
    return True


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=25)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=2)
    a = ap.parse_args()
    cases = ("code", "carrier", "fallback")
    print(f"load average before: {os.getloadavg()}")
    for c in cases:
        _run(c, a.seed, [0])
    runs = list(range(a.runs))
    rounds, same = [], []
    for r in range(a.repeat):
        t, res = {}, {}
        for c in cases:
            t[c], res[c] = _run(c, a.seed, runs)
        same.append(_same(res["carrier"], res["fallback"]))
        rounds.append(t)
        print(f"  round {r + 1} (CPU s): " + ", ".join(f"{c} {t[c]:.2f}" for c in cases)
              + f"; carrier / code {t['carrier'] / t['code']:.2f}, fallback / code {t['fallback'] / t['code']:.2f}, "
              f"fallback / carrier {t['fallback'] / t['carrier']:.2f}; records identical: {same[-1]}")
    print(f"load average after: {os.getloadavg()}")

    def med(f) -> float:
        return float(statistics.median(f(t) for t in rounds))

    print(f"open loop, {a.runs} runs, seed {a.seed}, median over {a.repeat} rounds (CPU):")
    print(f"carrier / code            {med(lambda t: t['carrier'] / t['code']):.2f}   (goal <= 2)")
    print(f"fallback / code (before)  {med(lambda t: t['fallback'] / t['code']):.2f}")
    print(f"carrier records == fallback records: {all(same)}")


if __name__ == "__main__":
    main()
