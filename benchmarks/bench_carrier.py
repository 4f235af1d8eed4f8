"""Carrier-phase filter benchmark (issue 26): the CAT III candidate's carrier variant against the code-only candidate,
open loop, the same runs and seed, and the carrier variant on the generic per-run path it took before.

    python benchmarks/bench_carrier.py [--runs 20] [--seed 1] [--repeat 1]

Three cases, each `campaign.pipeline.open_loop_group` over runs 0 .. N-1 (the flight, the sensors, the navigation
and the scoring with the integrity bank, as `approachsim evaluate --mode open` does per group):

    code      profiles/gbas-cat3-candidate.toml (the compiled shared-covariance pass)
    carrier   profiles/gbas-carrier-cat3-candidate.toml as shipped (the compiled pass with the carrier states)
    generic   the carrier profile with NavSystem.shares_covariance forced False: per-run filters on the generic numpy
              path (EpochEngine.of is None then): what the carrier variant took before issue 26

Each case is warmed up once (one run: numba's compile and cache load), then the cases are timed interleaved
(--repeat rounds of code, carrier, generic). Prints each round's wall times and ratios, the median over the rounds of
each ratio -- carrier / code (the goal: <= 2), generic / code and generic / carrier (the speed-up) -- and the load
average before and after (a shared machine: the load moves between cases, a round's ratio is the robust figure).
BLAS single-threaded, as `approachsim` and the campaign's workers run it. No pass/fail.
"""

from __future__ import annotations

import argparse
import contextlib
import os
import statistics
import time
from pathlib import Path
from unittest import mock

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # as the console script (cli.main) and
    os.environ.setdefault(_var, "1")  # the campaign's workers: two BLAS threads on a loaded machine cost 60x on eigh

from approachsim.campaign.pipeline import open_loop_group  # noqa: E402 (after the BLAS threads are set)
from approachsim.nav.system import NavSystem  # noqa: E402
from approachsim.profile import load_profile  # noqa: E402

PROFILES = Path(__file__).resolve().parents[1] / "profiles"


def _case(name: str):
    """(profile, context manager) of a case."""
    if name == "code":
        return load_profile(PROFILES / "gbas-cat3-candidate.toml"), contextlib.nullcontext()
    prof = load_profile(PROFILES / "gbas-carrier-cat3-candidate.toml")
    if name == "carrier":
        return prof, contextlib.nullcontext()
    return prof, mock.patch.object(NavSystem, "shares_covariance", lambda self: False)


def _time(name: str, seed: int, runs: list[int]) -> float:
    prof, ctx = _case(name)
    with ctx:
        t0 = time.perf_counter()
        res = open_loop_group(prof, seed, runs)
        dt = time.perf_counter() - t0
    failed = [r for r in res if not r.ok]
    if failed:
        print(f"  note: {name}: {len(failed)} failed runs ({failed[0].error})")
    return dt


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--repeat", type=int, default=1)
    a = ap.parse_args()
    cases = ("code", "carrier", "generic")
    print(f"load average before: {os.getloadavg()}")
    for c in cases:
        _time(c, a.seed, [0])
    runs = list(range(a.runs))
    rounds = []
    for r in range(a.repeat):
        t = {c: _time(c, a.seed, runs) for c in cases}
        rounds.append(t)
        print(f"  round {r + 1}: " + ", ".join(f"{c} {t[c]:.1f} s" for c in cases) + f"; carrier / code "
              f"{t['carrier'] / t['code']:.2f}, generic / code {t['generic'] / t['code']:.2f}, generic / carrier "
              f"{t['generic'] / t['carrier']:.2f}")
    print(f"load average after: {os.getloadavg()}")

    def med(f) -> float:
        return float(statistics.median(f(t) for t in rounds))

    print(f"open loop, {a.runs} runs, seed {a.seed}, median over {a.repeat} interleaved rounds of each round's ratio:")
    print(f"carrier / code            {med(lambda t: t['carrier'] / t['code']):.2f}   (goal <= 2)")
    print(f"generic / code (before)   {med(lambda t: t['generic'] / t['code']):.2f}")
    print(f"generic / carrier         {med(lambda t: t['generic'] / t['carrier']):.2f}   (the speed-up)")


if __name__ == "__main__":
    main()
