"""The baro-days acceptance table (issue 39) from the campaigns of run.sh: one markdown table on stdout.

    python studies/baro-days/table.py OUT_DIR

Per case (the blocks of one profile on several seeds pooled): runs, failed runs with the one-sided 95 %
Clopper-Pearson upper bound, the vertical 1-sigma (RMS over runs, the evaluator's FAA statistic) with its one-sided
95 % bounds and verdict at each DH, the vertical 1-sigma relative to the same field's ISA day (CAT I), and the RMS of
the per-run vertical e / sigma at each DH with its 95 % band for that many runs (evaluate's runs.jsonl columns
`<cat>_vertical_m`, `<cat>_vertical_e_sigma`; evaluate/verdict.py for the statistics).
"""

from __future__ import annotations

import json
import math
import sys
from pathlib import Path

import numpy as np
from scipy import stats as sps

from approachsim import units
from approachsim.evaluate.limits import LIMITS
from approachsim.evaluate.verdict import axis_verdict, clopper_pearson

CASES = ("sea-isa+0", "sea-isa-30", "sea-isa+30", "kden-isa+0", "kden-isa-30", "kden-isa+30", "sea-inversion10",
         "cat3-sync1ns", "cat3-sync3ns")
CATS = (("CAT I", "cat1"), ("CAT II", "cat2"), ("CAT III", "cat3"))


def load(out: Path, case: str) -> tuple[int, int, dict[str, np.ndarray], list[str]]:
    """(runs, failed, {column: values of the completed runs}, seeds) of a case, its blocks pooled (a seed marked *:
    a block stopped before its end)."""
    runs = failed = 0
    cols: dict[str, list[float]] = {}
    seeds = []
    for d in sorted(out.glob(f"{case}-s*")):
        f = d / "runs.jsonl"
        if not d.is_dir() or not f.exists():
            continue
        # a stopped block's finished runs count: runs are independent draws, kept in run order
        seeds.append(d.name.rsplit("-s", 1)[1] + ("" if (d / "summary.json").exists() else "*"))
        for line in f.read_text().splitlines():
            r = json.loads(line)
            runs += 1
            if not r["ok"]:
                failed += 1
                continue
            for k, v in r["scalars"].items():
                cols.setdefault(k, []).append(float(v) if v is not None else math.nan)
    return runs, failed, {k: np.asarray(v) for k, v in cols.items()}, seeds


def main(out: Path) -> None:
    rows = []
    ref: dict[str, float] = {}
    print("| case | runs (seeds) | failed (CP 95 % upper) | DH | vertical 1-sigma ft (95 % bounds) | verdict "
          "| vs ISA day | e/sigma RMS [95 % band] | e/sigma mean |")
    print("|---|---|---|---|---|---|---|---|---|")
    for case in CASES:
        n, k, c, seeds = load(out, case)
        if n == 0:
            continue
        _, cp_hi = clopper_pearson(k, n)
        for cat, key in CATS:
            if f"{key}_vertical_m" not in c:
                rows.append(f"| {case} | {n} ({','.join(seeds)}) | {k} ({cp_hi:.3f}) | {cat} | - | - | - | "
                            "- | - |")
                continue
            x = c[f"{key}_vertical_m"] / units.FT
            lim = LIMITS[cat]
            v = axis_verdict(x, lim.vertical_1sigma_ft, lim.vertical_95_ft, True, 0.95)
            rms = float(np.sqrt(np.mean(x**2)))
            field = case.split("-")[0]
            if case.endswith("isa+0"):
                ref[(field, cat)] = rms
            rel = ref.get((field, cat))
            rel_s = f"{rms / rel:.2f}" if rel and not case.startswith("cat3") else "-"
            es = c[f"{key}_vertical_e_sigma"]
            es = es[np.isfinite(es)]
            m = es.size
            band = [math.sqrt(sps.chi2.ppf(q, m) / m) for q in (0.025, 0.975)]
            rows.append(f"| {case} | {n} ({','.join(seeds)}) | {k} ({cp_hi:.3f}) | {cat} | {rms:.2f} "
                        f"({v.rms_lower_ft:.2f}, {v.rms_upper_ft:.2f}) | {v.verdict} | {rel_s} | "
                        f"{math.sqrt(float(np.mean(es**2))):.2f} [{band[0]:.2f}, {band[1]:.2f}] | "
                        f"{float(np.mean(es)):+.2f} |")
    print("\n".join(rows))


if __name__ == "__main__":
    main(Path(sys.argv[1]))
