"""The integrity bank's cost per open-loop run (issue 26, speed): the compiled reduced-state pass
(integrity/bankpass.py) against NavSystem.run's batched copies (run_bank(..., compiled=False)), interleaved run by
run in one process after the flight group's own pass (as campaign/pipeline.open_loop_group runs them: the group's
pass makes the runs' starts, which the bank then reuses), CPU time per run, with the machine's load.

    python benchmarks/bench_bank.py [--runs 25] [--profile profiles/default.toml]

For the end-to-end figure use `python benchmarks/bench_compiled.py scaling` (with the bank) against
`scaling --accuracy-only`. No pass/fail: figures go in benchmarks/RESULTS.md.
"""

from __future__ import annotations

import argparse
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
    ap.add_argument("--profile", default=str(ROOT / "profiles" / "default.toml"))
    args = ap.parse_args()

    import numpy as np

    from approachsim.campaign import pipeline
    from approachsim.integrity.bank import run_bank
    from approachsim.integrity.campaign import bank_profile
    from approachsim.nav.system import NavSystem
    from approachsim.profile import load_profile
    from approachsim.seeding import stream
    from approachsim.sensors.states import start_states
    from approachsim.sensors.suite import SensorSuite

    prof = load_profile(args.profile)
    runs = list(range(args.runs))
    truth = pipeline._approach(prof).fly(seed=1, run=0).truth
    bp = bank_profile(prof)
    run_bank(bp, truth, 1, runs[-1] + 1)  # compile / load every kernel
    run_bank(bp, truth, 1, runs[-1] + 1, compiled=False)
    load0 = os.getloadavg()[0]
    # the group's own pass (the accuracy path), which leaves each run's converged start for its bank
    t = time.process_time()
    suite = SensorSuite.from_profile(prof)
    errors = suite.draw(truth.t_s, 1, runs)
    records = suite.apply(truth, errors)
    nav = NavSystem.from_profile(prof)
    nav.run(truth, records, [stream(1, i, "nav") for i in runs], shared_covariance=nav.shares_covariance(),
            states=start_states(suite, truth, errors))
    t_group = time.process_time() - t
    new, old = [], []
    same = True
    for i in runs:
        t0 = time.process_time()
        ep_new, _ = run_bank(bp, truth, 1, i)
        t1 = time.process_time()
        ep_old, _ = run_bank(bp, truth, 1, i, compiled=False)
        t2 = time.process_time()
        new.append(t1 - t0)
        old.append(t2 - t1)
        same &= all(np.array_equal(getattr(ep_new, f), getattr(ep_old, f), equal_nan=True)
                    for f in ("e0", "p0", "ek", "pk", "wtest"))
    ms = 1e3
    print(f"bank per run, {len(runs)} runs of one flight group ({Path(args.profile).name}), CPU ms:")
    print(f"  the group's navigation pass (accuracy path): {t_group * ms / len(runs):6.1f} per run")
    print(f"  compiled reduced pass:  median {statistics.median(new) * ms:6.1f}  min {min(new) * ms:6.1f}")
    print(f"  NavSystem.run copies:   median {statistics.median(old) * ms:6.1f}  min {min(old) * ms:6.1f}")
    print(f"  ratio (median): {statistics.median(old) / statistics.median(new):.2f}x; BankEpochs bit-identical: {same}")
    print(f"  load average {load0:.2f} -> {os.getloadavg()[0]:.2f}")


if __name__ == "__main__":
    main()
