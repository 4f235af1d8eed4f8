"""Campaign results on disk: appended as runs finish, so an interrupted campaign resumes losing nothing.

    DIR/campaign.json     identity of the campaign (profile digest, seed, mode, landing) and the runs asked for
    DIR/runs.jsonl        one JSON line per finished run (RunResult.record), appended and flushed
    DIR/series/run_NNNNNN.parquet   time series of the runs that keep them
    DIR/runs.parquet      the per-run table (run, ok, error, every scalar), written at the end
    DIR/heights.parquet   the per-run arrays in long form (run, index, one column per array)

A run killed mid-write leaves at most one partial last line, which load() drops (and truncates away).
"""

from __future__ import annotations

import hashlib
import json
import re
from collections.abc import Iterable, Mapping
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np

from approachsim.campaign.result import RunResult
from approachsim.config import ProfileError

IDENTITY_KEYS = ("profile_digest", "seed", "mode", "land", "shard")
"""What must match for --resume to continue a campaign (the number of runs may grow); "land" is present (true)
only in landing campaigns (evaluate --land), "shard" ([k, n]) only in a shard's store (campaign/shards.py)."""


def profile_digest(profile: Any) -> str:
    """A stable digest of a profile's content (its repr without the source path or object addresses)."""
    try:
        p = replace(profile, source=None)
    except TypeError:
        p = profile
    text = re.sub(r" at 0x[0-9a-fA-F]+", "", repr(p))
    return hashlib.sha256(text.encode("utf-8")).hexdigest()[:16]


class CampaignStore:
    """The results directory of one campaign."""

    def __init__(self, out_dir: Path) -> None:
        self.dir = Path(out_dir)
        self.meta_path = self.dir / "campaign.json"
        self.jsonl_path = self.dir / "runs.jsonl"
        self.series_dir = self.dir / "series"

    def start(self, meta: Mapping[str, Any], *, resume: bool) -> dict[int, RunResult]:
        """Open for writing; with resume, check the identity and return the runs already finished."""
        self.dir.mkdir(parents=True, exist_ok=True)
        done: dict[int, RunResult] = {}
        if resume and self.meta_path.is_file():
            old = json.loads(self.meta_path.read_text(encoding="utf-8"))
            for k in IDENTITY_KEYS:
                if old.get(k) != meta.get(k):
                    raise ProfileError(
                        f"--resume: {str(self.dir)!r} holds a different campaign ({k} {old.get(k)!r}, now "
                        f"{meta.get(k)!r}); use another --out or drop --resume"
                    )
            done = self.load()
        else:
            self.jsonl_path.write_text("", encoding="utf-8")
        self.meta_path.write_text(json.dumps(dict(meta), indent=2) + "\n", encoding="utf-8")
        return done

    def load(self) -> dict[int, RunResult]:
        """Finished runs by index (first record of a run wins); a partial last line is cut off the file."""
        if not self.jsonl_path.is_file():
            return {}
        raw = self.jsonl_path.read_bytes()
        out: dict[int, RunResult] = {}
        good_end = 0
        pos = 0
        for line in raw.splitlines(keepends=True):
            pos += len(line)
            if not line.endswith(b"\n"):
                break
            try:
                r = RunResult.from_record(json.loads(line))
            except (ValueError, KeyError, TypeError):
                break
            out.setdefault(r.run, r)
            good_end = pos
        if good_end != len(raw):
            with open(self.jsonl_path, "r+b") as f:
                f.truncate(good_end)
        return out

    def append(self, results: Iterable[RunResult]) -> None:
        """Record finished runs (and their series) now, so a kill after this loses none of them."""
        lines = []
        for r in results:
            lines.append(r.json_line() + "\n")
            if r.series:
                self.write_series(r)
        with open(self.jsonl_path, "a", encoding="utf-8") as f:
            f.write("".join(lines))
            f.flush()

    def write_series(self, r: RunResult) -> None:
        """DIR/series/run_NNNNNN.parquet with the run's time series."""
        import pyarrow as pa
        import pyarrow.parquet as pq

        self.series_dir.mkdir(exist_ok=True)
        table = pa.table({k: np.asarray(v, dtype=float) for k, v in r.series.items()})
        pq.write_table(table, self.series_dir / f"run_{r.run:06d}.parquet")

    def write_tables(self, results: list[RunResult]) -> None:
        """runs.parquet (one row per run) and heights.parquet (the per-run arrays, long form)."""
        import pyarrow.parquet as pq

        pq.write_table(runs_table(results), self.dir / "runs.parquet")
        heights = heights_table(results)
        if heights is not None:
            pq.write_table(heights, self.dir / "heights.parquet")


def runs_table(results: list[RunResult]) -> Any:
    """The per-run table as a pyarrow Table: `run`, `ok`, `error` and every scalar (SI, the unit in the name), one
    row per run in the order given; what runs.parquet holds (and the API's `runs` DataFrame)."""
    import pyarrow as pa

    names = sorted({k for r in results for k in r.scalars})
    cols: dict[str, Any] = {
        "run": pa.array([r.run for r in results], pa.int64()),
        "ok": pa.array([r.ok for r in results], pa.bool_()),
        "error": pa.array([r.error for r in results], pa.string()),
    }
    for k in names:
        cols[k] = pa.array([r.scalars.get(k, np.nan) for r in results], pa.float64())
    return pa.table(cols)


def heights_table(results: list[RunResult]) -> Any:
    """The completed runs' arrays on the height grid in long form (`run`, `index`, one column per array) as a
    pyarrow Table, or None when no completed run has arrays; what heights.parquet holds."""
    import pyarrow as pa

    with_arrays = [r for r in results if r.ok and r.arrays]
    if not with_arrays:
        return None
    anames = list(with_arrays[0].arrays)
    m = len(with_arrays[0].arrays[anames[0]])
    long = {
        "run": np.repeat([r.run for r in with_arrays], m),
        "index": np.tile(np.arange(m), len(with_arrays)),
    }
    for a in anames:
        long[a] = np.concatenate([np.asarray(r.arrays[a], dtype=float) for r in with_arrays])
    return pa.table(long)
