"""Words of a finding chosen from the numbers: paired comparisons and the phrases the notes build from them.

A reproduction note states orderings ("sinh below constant"), verdicts ("reproduces" / "does not reproduce")
and ratios. None of these may be fixed text: each is chosen here from a computed value, so a note says what
the runs show. A paired comparison (common random numbers: both variants see the same noise in run i) is
decided by the normal approximation of the mean paired difference d = a - b over the runs,

    z = mean(d) / (std(d) / sqrt(n)),  a > b if z > z_(1-alpha/2), a < b if z < -z_(1-alpha/2),

else "indistinguishable" at that level and run count (conventions, item 14).
"""

from __future__ import annotations

import numpy as np
from scipy import stats

LEVEL = 0.95
"""Two-sided confidence level of every paired comparison in the notes."""


def paired(a: np.ndarray, b: np.ndarray, *, level: float = LEVEL) -> dict:
    """Paired comparison of per-run statistics a, b (same shape (runs,)): mean difference a - b, its standard
    error, z, the level, the run count and the relation '>', '<' or '~' (indistinguishable at that level)."""
    d = np.asarray(a, dtype=float) - np.asarray(b, dtype=float)
    n = d.size
    mean = float(d.mean())
    se = float(d.std(ddof=1) / np.sqrt(n)) if n > 1 else float("inf")
    z = mean / se if se > 0 else (np.inf if mean > 0 else -np.inf if mean < 0 else 0.0)
    crit = float(stats.norm.isf((1.0 - level) / 2.0))
    rel = ">" if z > crit else "<" if z < -crit else "~"
    return {"mean_diff": mean, "se": se, "z": float(z), "level": level, "runs": int(n), "relation": rel}


def relation_words(rel: str) -> str:
    """'>' -> 'above', '<' -> 'below', '~' -> 'indistinguishable from' (for 'X's rms is ... Y's')."""
    return {">": "above", "<": "below", "~": "indistinguishable from"}[rel]


def reproduces(flag: bool) -> str:
    """'reproduces' or 'does NOT reproduce' from a computed verdict."""
    return "reproduces" if flag else "does NOT reproduce"


def compare(x: float, y: float, *, rel_tol: float = 0.0) -> str:
    """'above', 'below' or 'equal to' (within rel_tol of y) for two computed values x, y."""
    if abs(x - y) <= rel_tol * abs(y):
        return "equal to"
    return "above" if x > y else "below"


def fmt_paired(c: dict, unit: str) -> str:
    """'+0.123 +- 0.045 m (z = 2.7, 100 runs)' for a `paired` result."""
    return f"{c['mean_diff']:+.3f} +- {c['se']:.3f} {unit} (z = {c['z']:.1f}, {c['runs']} runs)"
