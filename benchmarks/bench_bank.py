"""The integrity bank's cost per open-loop run (issue 26, speed), CPU time in one process, interleaved:

- one flight group (campaign/pipeline.open_loop_group, 25 runs on one truth) with the bank and accuracy only
  (evaluation.integrity = []), alternately `--repeat` times: the bank's share per run is the difference;
- per run, the bank from what the group's pass left (campaign/bankpass.bank_pass_group, what the pipeline runs),
  from the run's own records (bankpass.bank_pass) and NavSystem.run's batched copies (run_bank(..., compiled=False),
  the path before issue 26's speed work and the oracle), with their BankEpochs compared bit for bit.

    python benchmarks/bench_bank.py [--runs 25] [--repeat 3] [--profile profiles/default.toml]

For the end-to-end figure: `python benchmarks/bench_compiled.py scaling` (with the bank) against `scaling
--accuracy-only`. No pass/fail: figures go in benchmarks/RESULTS.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import statistics
import time
from pathlib import Path

for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):  # as the console script (cli.main)
    os.environ.setdefault(_var, "1")

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=25)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--profile", default=str(ROOT / "profiles" / "default.toml"))
    args = ap.parse_args()

    import numpy as np

    from approachsim.campaign import pipeline
    from approachsim.campaign.bankpass import GroupInputs
    from approachsim.campaign.integrity_bank import run_bank
    from approachsim.campaign.integrity_campaign import bank_profile
    from approachsim.nav.system import NavSystem
    from approachsim.profile import load_profile
    from approachsim.seeding import stream
    from approachsim.sensors.states import start_states
    from approachsim.sensors.suite import SensorSuite

    prof = load_profile(args.profile)
    acc = dataclasses.replace(prof, evaluation=dataclasses.replace(prof.evaluation, integrity=()))
    size = prof.evaluation.flight_group
    runs = list(range(size, size + min(args.runs, size)))  # one whole group (its first run flies the truth)
    pipeline.open_loop_group(prof, 1, [0])  # compile / load every kernel, fly once
    run_bank(bank_profile(prof), pipeline._approach(prof).fly(seed=1, run=0).truth, 1, 0, compiled=False)
    load0 = os.getloadavg()[0]
    with_bank, without = [], []
    for _ in range(args.repeat):
        for lst, p in ((with_bank, prof), (without, acc)):
            t = time.process_time()
            res = pipeline.open_loop_group(p, 1, runs)
            lst.append((time.process_time() - t) / len(runs))
            assert all(r.ok for r in res), [r.error for r in res if not r.ok]
    # per run, after the group's pass (which leaves its starts and INS for the banks)
    truth = pipeline._approach(prof).fly(seed=1, run=runs[0]).truth
    suite = SensorSuite.from_profile(prof)
    errors = suite.draw(truth.t_s, 1, runs)
    records = suite.apply(truth, errors)
    nav = NavSystem.from_profile(prof)
    keep: dict = {}
    nav.run(truth, records, [stream(1, i, "nav") for i in runs], shared_covariance=nav.shares_covariance(),
            states=start_states(suite, truth, errors), keep=keep)
    group = GroupInputs(records, keep)
    bp = bank_profile(prof)
    t_grp, t_own, t_old = [], [], []
    same = True
    for k, i in enumerate(runs):
        t0 = time.process_time()
        ep_g, _ = run_bank(bp, truth, 1, i, group=(group, k))
        t1 = time.process_time()
        ep_n, _ = run_bank(bp, truth, 1, i)
        t2 = time.process_time()
        ep_o, _ = run_bank(bp, truth, 1, i, compiled=False)
        t3 = time.process_time()
        t_grp.append(t1 - t0)
        t_own.append(t2 - t1)
        t_old.append(t3 - t2)
        for ep in (ep_g, ep_n):
            same &= all(np.array_equal(getattr(ep, f), getattr(ep_o, f), equal_nan=True)
                        for f in ("t_s", "e0", "p0", "ek", "pk", "along_m", "height_m"))
            same &= np.array_equal(ep.identification(), ep_o.identification(), equal_nan=True)
    ms, med = 1e3, statistics.median
    print(f"integrity bank, open loop, runs {runs[0]}-{runs[-1]} (one flight group, {Path(args.profile).name}); "
          f"CPU ms per run")
    print(f"  flight group with the bank {min(with_bank) * ms:6.1f}, accuracy only {min(without) * ms:6.1f} (min of "
          f"{args.repeat}, interleaved): the bank adds {(min(with_bank) - min(without)) * ms:6.1f}")
    print(f"  run_bank from the group's pass (pipeline): median {med(t_grp) * ms:6.1f}  min {min(t_grp) * ms:6.1f}")
    print(f"  run_bank from its own records (bank_pass): median {med(t_own) * ms:6.1f}  min {min(t_own) * ms:6.1f}")
    print(f"  run_bank, NavSystem.run copies (before):   median {med(t_old) * ms:6.1f}  min {min(t_old) * ms:6.1f}")
    print(f"  BankEpochs of the three bit-identical: {bool(same)}")
    print(f"  load average {load0:.2f} -> {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
