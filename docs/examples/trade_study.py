"""A trade study in code: INS grade x GNSS service, every variant evaluated on the same random numbers.

    python docs/examples/trade_study.py              # 20 open-loop runs per variant (about 2 min on 2 cores)
    python docs/examples/trade_study.py --runs 2     # what the tests run (docs/api.md)

Which of Gray & Maybeck's best and worst INS grades (0.4 and 4 nmi/h CEP), with stand-alone GPS L1 C/A (the
broadcast Klobuchar ionosphere) or with SBAS L1 corrections (the default's receiver), reaches which category? The
base is the shipped default profile with the accuracy verdict alone (integrity off: the solution-separation bank
would triple the time). Prints the comparison table and the verdicts, and saves the study figure.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import approachsim as asim

GRADES = ["nav-0.4", "nav-4.0"]
"""Gray & Maybeck's 0.4 and 4 nmi/h CEP navigation grades (docs/profiles.md, [sensors.imu] grade)."""
SERVICES = {
    "stand-alone": {"sensors.gnss.service": "l1ca"},
    "sbas": {"sensors.gnss.service": "sbas-l1"},
}
"""The GNSS service ([sensors.gnss] service, docs/gnss-services.md): stand-alone L1 C/A ranging, or SBAS L1
corrections (RTCA DO-229)."""


def main(runs: int = 20, seed: int = 1, out: Path | None = None, workers: int | None = None) -> asim.StudyResult:
    """Run the study; returns its result (rows, DataFrame, per-variant evaluations)."""
    base = asim.load_profile("default").with_settings({"evaluation.integrity": False}, name="default-accuracy")
    variants = {f"{grade}+{service}": {"sensors.imu.grade": grade, **settings}
                for grade in GRADES for service, settings in SERVICES.items()}
    study = asim.study(base, variants, name="ins-grade-x-gnss-service", runs=runs, seed=seed, mode="open",
                       out=out, workers=workers, progress=False)
    print(study.text())
    for name, verdicts in study.verdicts.items():
        print(f"{name:20} " + ", ".join(f"{cat} {v}" for cat, v in verdicts.items()))
    return study


if __name__ == "__main__":
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--runs", type=int, default=20)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", type=Path, default=None, help="also write the study's files there")
    ap.add_argument("--workers", type=int, default=None)
    a = ap.parse_args()
    st = main(a.runs, a.seed, a.out, a.workers)
    if a.out is not None:
        print(f"wrote {a.out / 'study.csv'}, {a.out / 'study.png'}")
