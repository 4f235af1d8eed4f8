"""`evaluate --shard K/N` and `merge` on the real pipeline: 3 shards merged are the single campaign's outputs bit for
bit (summary.json, details.json but its wall time, the Parquet tables, the time series, campaign.json, the runs)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from approachsim.cli import main

ROOT = Path(__file__).resolve().parents[2]
pytestmark = pytest.mark.slow


def _profile(tmp_path: Path) -> Path:
    """The shipped default, open loop, accuracy verdict alone, flight groups of 2 (a group falls in two shards)."""
    text = (ROOT / "tests" / "data" / "default-py.toml").read_text().replace('name = "default"', 'name = "sharded"', 1)
    p = tmp_path / "sharded.toml"
    p.write_text(text + "\n[evaluation]\nintegrity = false\nflight_group = 2\nseries_runs = 2\n")
    return p


def test_three_shards_merged_equal_one_campaign(tmp_path, capsys):
    prof = str(_profile(tmp_path))
    base = ["evaluate", prof, "--runs", "5", "--seed", "2", "--mode", "open", "--workers", "1", "--no-report"]
    assert main([*base, "--out", str(tmp_path / "one")]) == 0
    shards = [tmp_path / f"shard{k}" for k in (1, 2, 3)]
    for k, d in enumerate(shards, start=1):
        assert main([*base, "--shard", f"{k}/3", "--out", str(d)]) == 0
        assert not (d / "summary.json").exists()
    out = capsys.readouterr().out
    assert "shard 2/3: runs 1-2, 2 completed, 0 failed" in out and "shard 3/3: runs 3-4, 2 completed" in out
    assert json.loads((shards[1] / "shard.json").read_text())["runs"] == [1, 3]
    assert main(["merge", prof, *map(str, shards), "--out", str(tmp_path / "merged"), "--no-report"]) == 0
    a, b = tmp_path / "one", tmp_path / "merged"
    for name in ("summary.json", "runs.parquet", "heights.parquet", "campaign.json", "series/run_000000.parquet",
                 "series/run_000001.parquet"):
        assert (a / name).read_bytes() == (b / name).read_bytes(), name
    da, db = (json.loads((d / "details.json").read_text()) for d in (a, b))
    assert da.pop("wall_s") > 0 and db.pop("wall_s") > 0 and da == db
    assert sorted((a / "runs.jsonl").read_text().splitlines()) == sorted((b / "runs.jsonl").read_text().splitlines())
    s = json.loads((b / "summary.json").read_text())
    assert s["runs"] == 5 and s["failed_runs"] == 0 and s["decision_heights"]["CAT I"]["lateral_1sigma_ft"] > 0
    # the merged campaign is an ordinary one: resumed, nothing is rerun and nothing changes
    assert main([*base, "--out", str(b), "--resume"]) == 0
    assert (a / "summary.json").read_bytes() == (b / "summary.json").read_bytes()


def test_shard_and_merge_refuse_bad_input_in_one_line(tmp_path, capsys):
    prof = str(_profile(tmp_path))
    for argv, needle in (
        (["evaluate", prof, "--runs", "2", "--shard", "3/2", "--out", str(tmp_path / "x")], "--shard: must be K/N"),
        (["evaluate", prof, "--runs", "2", "--shard", "1/3", "--out", str(tmp_path / "x")], "--shard: 3 shards for 2"),
        (["evaluate", prof, "--runs", "4", "--shard", "1/2", "--require", "CAT I", "--out", str(tmp_path / "x")],
         "--require: a shard has no verdict"),
        (["merge", prof, str(tmp_path / "none"), "--out", str(tmp_path / "m")], "SHARD_DIR: no such file"),
    ):
        assert main(argv) == 2
        err = capsys.readouterr().err
        assert needle in err and len(err.strip().splitlines()) == 1, err
