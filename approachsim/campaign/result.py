"""RunResult: what one Monte Carlo run hands back to the campaign, and its JSON-line form.

Small on purpose: named per-run scalars (SI, units in the names), small fixed-size arrays (e.g. error on a
height grid) and, for a few runs, full time series. A run that failed carries its error text instead.
The JSON line round-trips every float64 bit for bit (Python's shortest repr), so results read back from
disk after a resume equal those computed in memory.
"""

from __future__ import annotations

import json
import math
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

Array = np.ndarray


def _empty() -> dict:
    return {}


def _sparse(v: Array) -> dict:
    """{"size": n, "index": [...], "count": [...]} of the nonzero cells of a (n,) count array."""
    v = np.asarray(v, dtype=float)
    i = np.flatnonzero(v)
    return {"size": int(v.size), "index": [int(x) for x in i], "count": [float(x) for x in v[i]]}


def _dense(d: Mapping) -> Array:
    out = np.zeros(int(d["size"]))
    out[np.asarray(d["index"], dtype=int)] = np.asarray(d["count"], dtype=float)
    return out


@dataclass(frozen=True, eq=False)
class RunResult:
    """One run's outcome. run: index in the campaign; ok False means error says why (and nothing was scored)."""

    run: int
    ok: bool
    error: str | None = None
    scalars: Mapping[str, float] = field(default_factory=_empty)
    """Named per-run numbers (SI; the unit is in the name where not)."""
    arrays: Mapping[str, Array] = field(default_factory=_empty)
    """Small (k,) float arrays of the same length for every run (stored in the results table)."""
    series: Mapping[str, Array] | None = None
    """Time series kept for this run (equal-length (n,) arrays, written to their own file), or None."""
    counts: Mapping[str, Array] = field(default_factory=_empty)
    """Histograms summed over the campaign (integrity: (error, protection level) cells per category and axis,
    campaign.integrity_campaign), stored sparse in the JSON line; empty when integrity is off."""
    path: str | None = None
    """Which code produced the run (loop/paths.py: the flight loop and the navigation's row and epoch paths), or
    None (a failed run, or a line written before paths were recorded)."""

    @classmethod
    def failed(cls, run: int, error: str) -> RunResult:
        """A run that raised or diverged, with the reason (one line)."""
        return cls(run=run, ok=False, error=" ".join(str(error).split()) or "failed")

    def record(self) -> dict:
        """The JSON-line dictionary (without the time series, which go to their own file)."""
        return {
            "run": int(self.run),
            "ok": bool(self.ok),
            "error": self.error,
            "scalars": {k: float(v) for k, v in self.scalars.items()},
            "arrays": {k: [float(x) for x in np.asarray(v, dtype=float)] for k, v in self.arrays.items()},
            **({"counts": {k: _sparse(v) for k, v in self.counts.items()}} if self.counts else {}),
            **({"path": self.path} if self.path is not None else {}),
        }

    def json_line(self) -> str:
        """One line of JSON (nan written as NaN), no trailing newline."""
        return json.dumps(self.record(), separators=(",", ":"), allow_nan=True)

    @classmethod
    def from_record(cls, d: Mapping) -> RunResult:
        """Inverse of record()."""
        return cls(
            run=int(d["run"]),
            ok=bool(d["ok"]),
            error=d.get("error"),
            scalars={k: float(v) for k, v in d.get("scalars", {}).items()},
            arrays={k: np.asarray(v, dtype=float) for k, v in d.get("arrays", {}).items()},
            counts={k: _dense(v) for k, v in d.get("counts", {}).items()},
            path=d.get("path"),
        )

    def same_as(self, other: RunResult) -> bool:
        """Bit-identical outcome (scalars and arrays; nan equals nan)."""
        if (self.run, self.ok, self.error, self.path) != (other.run, other.ok, other.error, other.path):
            return False
        if list(self.scalars) != list(other.scalars) or list(self.arrays) != list(other.arrays):
            return False
        for k, v in self.scalars.items():
            w = other.scalars[k]
            if not (v == w or (math.isnan(v) and math.isnan(w))):
                return False
            if math.copysign(1.0, v) != math.copysign(1.0, w):
                return False
        if list(self.counts) != list(other.counts) or any(
            not np.array_equal(v, other.counts[k]) for k, v in self.counts.items()
        ):
            return False
        return all(
            np.array_equal(np.asarray(v).view(np.uint64), np.asarray(other.arrays[k]).view(np.uint64))
            for k, v in self.arrays.items()
        )
