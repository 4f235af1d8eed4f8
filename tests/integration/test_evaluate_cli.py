"""`approachsim evaluate` at the edge: every bad option exits 2 with one line; a missing stage exits 1."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from approachsim.cli import main

ROOT = Path(__file__).resolve().parents[2]
DEFAULT = str(ROOT / "profiles" / "default.toml")


@pytest.mark.parametrize(
    ("argv", "needle"),
    [
        (["--runs", "0"], "--runs"),
        (["--runs", "100001"], "--runs"),
        (["--runs", "ten"], "--runs"),
        (["--seed", "-1"], "--seed"),
        (["--seed", "1.5"], "--seed"),
        (["--mode", "sideways"], "--mode"),
        (["--workers", "0"], "--workers"),
        (["--workers", "two"], "--workers"),
        (["--scheduler", "not an address"], "--scheduler"),
        (["--scheduler", "tcp://127.0.0.1:8786", "--workers", "2"], "--workers"),
        (["--bogus"], "--bogus"),
    ],
)
def test_bad_option_exits_2_with_one_line(argv, needle, capsys, tmp_path):
    with pytest.raises(SystemExit) as e:
        code = main(["evaluate", DEFAULT, "--out", str(tmp_path / "o"), *argv])
        raise SystemExit(code)
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and needle in err, err


def test_an_existing_campaign_is_not_discarded_silently(tmp_path, capsys):
    out = tmp_path / "o"
    out.mkdir()
    (out / "runs.jsonl").write_text('{"run": 0}\n')
    assert main(["evaluate", DEFAULT, "--out", str(out)]) == 2
    assert main(["evaluate", DEFAULT, "--out", str(out), "--resume", "--overwrite"]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 2 and "already holds a campaign; add --resume" in err[0] and "--overwrite" in err[1]
    assert (out / "runs.jsonl").read_text() == '{"run": 0}\n'


def test_bad_out_and_profile_exit_2(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("x")
    assert main(["evaluate", DEFAULT, "--out", str(f)]) == 2
    assert main(["evaluate", str(tmp_path / "missing.toml")]) == 2
    bad = tmp_path / "bad.toml"
    bad.write_text(Path(DEFAULT).read_text() + "\n[evaluation]\ndh_cat1_ft = 'high'\n")
    assert main(["evaluate", str(bad)]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 3 and "--out" in err[0] and "missing.toml" in err[1] and "evaluation.dh_cat1_ft" in err[2]


def test_unreachable_scheduler_exits_2_with_one_line_and_writes_nothing(tmp_path, capsys):
    from approachsim.campaign.pipeline import require_stages

    require_stages("open")  # every stage exists now: a missing one is a failure, not a skip
    out = tmp_path / "o"
    assert main(["evaluate", DEFAULT, "--runs", "1", "--mode", "open", "--scheduler", "tcp://127.0.0.1:9",
                 "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "--scheduler: cannot connect to 'tcp://127.0.0.1:9'" in err, err
    assert not out.exists()


def test_missing_navigation_stage_exits_1_with_one_line(tmp_path):
    code = (
        "import sys; sys.modules['approachsim.nav.system'] = None\n"
        "from approachsim.cli import main\n"
        f"sys.exit(main(['evaluate', {DEFAULT!r}, '--runs', '2', '--out', {str(tmp_path / 'o')!r}]))\n"
    )
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.returncode == 1
    assert p.stderr.count("\n") == 1 and "navigation system" in p.stderr, p.stderr
    assert p.stdout == ""
    assert not (tmp_path / "o" / "summary.json").exists()


@pytest.mark.slow
def test_open_loop_evaluation_end_to_end(tmp_path, capsys):
    """The real pipeline (JSBSim truth, sensor suite, INS + filter, scoring) on 2 open-loop runs."""
    import json

    from approachsim.campaign.pipeline import require_stages

    require_stages("open")  # every stage exists now: a missing one is a failure, not a skip
    out = tmp_path / "ev"
    code = main(["evaluate", DEFAULT, "--runs", "2", "--seed", "3", "--mode", "open", "--workers", "1",
                 "--out", str(out)])
    assert code == 0
    s = json.loads((out / "summary.json").read_text())
    assert set(s) == {"schema", "profile", "runs", "seed", "closed_loop", "decision_heights", "best_category",
                      "failed_runs"}
    assert (s["profile"], s["runs"], s["seed"], s["closed_loop"], s["failed_runs"]) == ("default", 2, 3, False, 0)
    for cat, e in s["decision_heights"].items():
        # a GPS-aided INS is good to tens of feet at worst: finite, positive, far below a nonsense scale
        assert 0.0 < e["lateral_1sigma_ft"] < 200.0 and 0.0 < e["vertical_1sigma_ft"] < 200.0, (cat, e)
    printed = capsys.readouterr().out
    assert "best category:" in printed and "CAT III" in printed
    assert (out / "report.html").is_file() and (out / "runs.parquet").is_file()
    assert len(list((out / "series").glob("*.parquet"))) == 2
    # the same campaign on a Dask cluster (loopback) gives bit-identical per-run results
    import distributed  # in the test extra
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, protocol="tcp://",
                                  host="127.0.0.1", dashboard_address=":0") as cluster:
        out2 = tmp_path / "ev-dask"
        assert main(["evaluate", DEFAULT, "--runs", "2", "--seed", "3", "--mode", "open", "--scheduler",
                     cluster.scheduler_address, "--out", str(out2), "--no-report"]) == 0
    lines = sorted((out / "runs.jsonl").read_text().splitlines())
    assert lines == sorted((out2 / "runs.jsonl").read_text().splitlines()) and len(lines) == 2
    assert json.loads((out2 / "summary.json").read_text()) == s
