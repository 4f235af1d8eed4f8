"""Regression baselines: committed evaluation summaries of the profiles, compared with statistical tolerances.

A baseline (baselines/<profile>.json) stores the contract summary of a small fixed-seed campaign. A new
run of the same campaign is compared field by field:

* 1-sigma (RMS) and 95 % values of each category: the squared ratio new/old of two RMS estimates over n
  runs each is F(n, n) distributed when nothing changed but the random draws; outside the two-sided
  [F(alpha/2), F(1 - alpha/2)] band (alpha = 1e-3 by default) is a regression. The 95 % values use the
  same band (an approximation: a percentile of few runs scatters at least as much).
* meets, best_category: any change is a regression (a verdict must not move silently).
* failed_runs: any increase is a regression.

With fixed seeds an unchanged model reproduces the baseline exactly; the band admits model changes that
only reshuffle random numbers, and catches those that move the statistics.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from scipy import stats as sps

SCHEMA = "approachsim.baseline/1"
STAT_FIELDS = ("lateral_1sigma_ft", "vertical_1sigma_ft", "lateral_95_ft", "vertical_95_ft")


@dataclass(frozen=True)
class Diff:
    """One compared field: where, old and new values, the allowed band of new, and the judgement."""

    field: str
    old: Any
    new: Any
    band: tuple[float, float] | None
    regression: bool

    def line(self) -> str:
        """A readable diff line."""
        mark = "REGRESSION" if self.regression else ("changed" if self.old != self.new else "ok")
        band = f"  allowed [{self.band[0]:.4g}, {self.band[1]:.4g}]" if self.band else ""
        return f"{mark:10} {self.field}: {self.old!r} -> {self.new!r}{band}"


def f_band(n: int, alpha: float = 1e-3) -> tuple[float, float]:
    """Band of (rms_new / rms_old) for two RMS over n runs each of the same distribution: sqrt F(n, n)."""
    lo = sps.f.ppf(alpha / 2.0, n, n)
    hi = sps.f.ppf(1.0 - alpha / 2.0, n, n)
    return float(lo**0.5), float(hi**0.5)


def compare(old: dict, new: dict, alpha: float = 1e-3) -> list[Diff]:
    """Every compared field of two contract summaries (old = baseline)."""
    diffs: list[Diff] = []
    n = max(2, new["runs"] - new["failed_runs"])
    lo, hi = f_band(n, alpha)
    for cat, o in old["decision_heights"].items():
        nw = new["decision_heights"].get(cat, {})
        for k in STAT_FIELDS:
            a, b = o.get(k), nw.get(k)
            if a is None or b is None:
                diffs.append(Diff(f"{cat}.{k}", a, b, None, a != b))
                continue
            band = (a * lo, a * hi)
            diffs.append(Diff(f"{cat}.{k}", a, b, band, not band[0] <= b <= band[1]))
        if o.get("height_ft") != nw.get("height_ft"):
            diffs.append(Diff(f"{cat}.height_ft", o.get("height_ft"), nw.get("height_ft"), None, True))
        diffs.append(Diff(f"{cat}.meets", o["meets"], nw.get("meets"), None, o["meets"] != nw.get("meets")))
    diffs.append(Diff("best_category", old["best_category"], new["best_category"], None,
                      old["best_category"] != new["best_category"]))
    diffs.append(Diff("failed_runs", old["failed_runs"], new["failed_runs"], None,
                      new["failed_runs"] > old["failed_runs"]))
    return diffs


def baseline_doc(profile_path: str, summary: dict, *, runs: int, seed: int, mode: str) -> dict:
    """The JSON document of a baseline."""
    return {"schema": SCHEMA, "profile": profile_path, "runs": runs, "seed": seed, "mode": mode, "summary": summary}


def read_baseline(path: Path) -> dict:
    """A baseline file (ValueError when it is not one)."""
    doc = json.loads(Path(path).read_text(encoding="utf-8"))
    if doc.get("schema") != SCHEMA:
        raise ValueError(f"{path}: not an {SCHEMA} file")
    return doc
