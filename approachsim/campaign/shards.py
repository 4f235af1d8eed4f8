"""Shards: one campaign run as n independent pieces (a SLURM job array, machines with no scheduler between them),
then merged into exactly the outputs the single campaign writes.

Shard k of n (k = 1..n) holds the runs [floor((k - 1) R / n), floor(k R / n)) of the campaign of R runs: contiguous,
deterministic, sizes differing by at most one. A run draws its random numbers from (seed, run index) alone
(approachsim.seeding), so a shard's runs are bit for bit those of the single campaign; open-loop runs of one flight
group that fall in two shards fly the group's identical, seeded truth in each (pipeline.open_loop_group).

A shard directory holds the run store (campaign.json with `"shard": [k, n]`, runs.jsonl, series/, runs.parquet and
heights.parquet of its runs) and shard.json (its runs, completed count, wall time); it is resumable like a campaign
(`--shard k/n --resume`). `merge_shards` checks that the n shards are one campaign (same profile digest, seed,
mode, landing, run count and n; every k once; every run present) and writes the single campaign's outputs: the
same summary.json, details.json (but its wall_s: the shards' sum), runs.parquet, heights.parquet and series/ files,
and runs.jsonl in run order (a single campaign's is in the order runs finished).
"""

from __future__ import annotations

import json
import re
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from approachsim.campaign.result import RunResult
from approachsim.campaign.store import IDENTITY_KEYS, CampaignStore, profile_digest
from approachsim.config import ProfileError

SHARD_FILE = "shard.json"


def parse_shard(text: str, field: str = "--shard") -> tuple[int, int]:
    """(k, n) from "K/N" with 1 <= K <= N; ProfileError naming `field` otherwise."""
    m = re.fullmatch(r"\s*(\d+)\s*/\s*(\d+)\s*", str(text))
    if m is None:
        raise ProfileError(f"{field}: must be K/N (shard K of N, 1 <= K <= N), got {text!r}")
    k, n = int(m.group(1)), int(m.group(2))
    if not 1 <= k <= n:
        raise ProfileError(f"{field}: must be K/N with 1 <= K <= N, got {text!r}")
    return k, n


def shard_runs(runs: int, k: int, n: int) -> list[int]:
    """The run indices of shard k of n of a campaign of `runs` runs (module docstring); ProfileError when there are
    fewer runs than shards."""
    if n > runs:
        raise ProfileError(f"--shard: {n} shards for {runs} runs; give at most one shard per run")
    return list(range((k - 1) * runs // n, k * runs // n))


def write_shard_record(out_dir: Path, shard: tuple[int, int], runs: Sequence[int], results: list[RunResult],
                       wall_s: float) -> None:
    """DIR/shard.json: which shard, its runs [first, last + 1), how many completed, its wall time (s)."""
    doc = {"shard": [int(shard[0]), int(shard[1])], "runs": [int(runs[0]), int(runs[-1]) + 1] if runs else [0, 0],
           "completed": sum(r.ok for r in results), "failed": sum(not r.ok for r in results), "wall_s": wall_s}
    (Path(out_dir) / SHARD_FILE).write_text(json.dumps(doc, indent=2) + "\n", encoding="utf-8")


def _read_json(path: Path, what: str) -> dict:
    if not path.is_file():
        raise ProfileError(f"{what}: no such file {str(path)!r}")
    try:
        return json.loads(path.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as e:
        raise ProfileError(f"{what}: {str(path)!r} is not valid JSON ({e})") from None


def read_shards(dirs: Sequence[Path], profile: Any | None = None) -> tuple[dict, list[RunResult], float]:
    """(the campaign's identity, all its runs in run order, the shards' summed wall time) from n shard directories;
    ProfileError (one line naming the directory or file) unless they are the n shards of one campaign, complete,
    and (profile given) of this profile."""
    if not dirs:
        raise ProfileError("SHARD_DIR: name the directories of every shard of the campaign")
    metas, by_k = [], {}
    for d in dirs:
        d = Path(d)
        meta = _read_json(d / "campaign.json", "SHARD_DIR")
        if not isinstance(meta.get("shard"), list) or len(meta["shard"]) != 2:
            raise ProfileError(f"SHARD_DIR: {str(d)!r} is not a shard (its campaign.json has no \"shard\"); "
                               "shards are written by evaluate --shard K/N")
        k, n = (int(x) for x in meta["shard"])
        if k in by_k:
            raise ProfileError(f"SHARD_DIR: {str(by_k[k])!r} and {str(d)!r} are both shard {k}/{n}")
        by_k[k] = d
        metas.append((d, meta))
    d0, m0 = metas[0]
    n = int(m0["shard"][1])
    for d, m in metas[1:]:
        for key in (*(k for k in IDENTITY_KEYS if k != "shard"), "runs"):
            if m.get(key) != m0.get(key):
                raise ProfileError(f"SHARD_DIR: {str(d)!r} is of another campaign than {str(d0)!r} ({key} "
                                   f"{m.get(key)!r}, not {m0.get(key)!r})")
        if int(m["shard"][1]) != n:
            raise ProfileError(f"SHARD_DIR: {str(d)!r} is shard {m['shard'][0]}/{m['shard'][1]}, the others are of {n}")
    missing = sorted(set(range(1, n + 1)) - set(by_k))
    if missing:
        raise ProfileError(f"SHARD_DIR: shard(s) {', '.join(f'{k}/{n}' for k in missing)} missing: give all {n}")
    if profile is not None and profile_digest(profile) != m0.get("profile_digest"):
        raise ProfileError(f"PROFILE: is not the profile the shards ran ({m0.get('profile')!r}, digest "
                           f"{m0.get('profile_digest')}); give that profile, unchanged")
    runs = int(m0["runs"])
    results: dict[int, RunResult] = {}
    wall = 0.0
    for k, d in sorted(by_k.items()):
        want = shard_runs(runs, k, n)
        got = CampaignStore(d).load()
        lost = [i for i in want if i not in got]
        if lost:
            raise ProfileError(f"SHARD_DIR: shard {k}/{n} in {str(d)!r} is unfinished ({len(lost)} of its "
                               f"{len(want)} runs missing, first {lost[0]}); finish it with evaluate --shard {k}/{n} "
                               "--resume")
        results.update({i: got[i] for i in want})
        rec = d / SHARD_FILE
        wall += float(_read_json(rec, "SHARD_DIR").get("wall_s") or 0.0) if rec.is_file() else 0.0
    meta = {key: v for key, v in m0.items() if key not in ("shard", "runs")}
    return meta, [results[i] for i in range(runs)], wall


def merge_store(dirs: Sequence[Path], out_dir: Path, meta: dict, results: list[RunResult]) -> None:
    """Write the merged run store into out_dir: campaign.json (the single campaign's identity), runs.jsonl in run
    order, the shards' series files, runs.parquet and heights.parquet."""
    out_dir = Path(out_dir)
    store = CampaignStore(out_dir)
    store.start({**meta, "runs": len(results)}, resume=False)
    store.append(results)
    for d in dirs:
        src = Path(d) / "series"
        if src.is_dir():
            store.series_dir.mkdir(exist_ok=True)
            for f in sorted(src.glob("run_*.parquet")):
                shutil.copyfile(f, store.series_dir / f.name)
    store.write_tables(results)
