"""The vertical navigation error at each decision height against the crossing's phase in the 1 s aiding interval,
pooled over a case's seed blocks (run.sh's OUT/CASE-sN/runs.jsonl): least squares e = a + b frac(t) with standard
errors, and the e/sigma RMS and mean. A held estimate between epochs shows as a slope b (the INS's drift, m/s);
the estimate carried by its rate (core/nav/output.py) leaves b at zero within its standard error.

    python studies/baro-days/phase_fit.py OUT CASE
"""

from __future__ import annotations

import glob
import json
import sys

import numpy as np


def fit(out: str, case: str) -> None:
    """Print the fit of case's pooled runs at the CAT I / II / III decision heights."""
    rows = []
    for f in sorted(glob.glob(f"{out}/{case}-s*/runs.jsonl")):
        with open(f) as fh:
            rows += [d["scalars"] for d in map(json.loads, fh) if "scalars" in d]
    print(case, len(rows), "runs")
    for c in ("cat1", "cat2", "cat3"):
        t = np.array([r.get(f"{c}_t_s", np.nan) for r in rows], float)
        e = np.array([r.get(f"{c}_vertical_m", np.nan) for r in rows], float)
        es = np.array([r.get(f"{c}_vertical_e_sigma", np.nan) for r in rows], float)
        ok = np.isfinite(t) & np.isfinite(e)
        A = np.column_stack([np.ones(ok.sum()), t[ok] - np.floor(t[ok])])
        coef = np.linalg.lstsq(A, e[ok], rcond=None)[0]
        r = e[ok] - A @ coef
        se = np.sqrt(np.diag(r @ r / (ok.sum() - 2) * np.linalg.inv(A.T @ A)))
        print(f"  {c}: e/sigma RMS {np.sqrt(np.nanmean(es**2)):.2f}, mean {np.nanmean(es):+.2f}; mean e "
              f"{e[ok].mean():+.3f} m; a {coef[0]:+.3f} ({se[0]:.3f}) m, b {coef[1]:+.3f} ({se[1]:.3f}) m/s")


if __name__ == "__main__":
    fit(sys.argv[1], sys.argv[2])
