"""Outputs of a scored campaign on synthetic pairs: stored runs, summary.json, verdict table, HTML report."""

from __future__ import annotations

import json
from html.parser import HTMLParser

import numpy as np
from evalpairs import cross_axis_ned, make_nav, make_truth
from floors import assert_within, floor

from approachsim import units
from approachsim.campaign.outputs import evaluate_results, verdict_table, write_json
from approachsim.campaign.result import RunResult
from approachsim.campaign.store import CampaignStore
from approachsim.evaluate.config import EvaluationConfig
from approachsim.evaluate.score import score_run
from approachsim.report.evaluate import report_problems, write_report


def test_outputs_and_report(tmp_path):
    cfg = EvaluationConfig(verdict="faa")  # 12-13 runs: the FAA table alone (ICAO 95 % needs >= 59 runs)
    truth = make_truth(hz=4.0)
    rng = np.random.default_rng(5)
    results = []
    for i in range(12):
        e = rng.normal(0.0, 3.0) * units.FT * cross_axis_ned() + np.array([0.0, 0.0, rng.normal(0.0, 1.0)])
        sc, arr, ser = score_run(truth, make_nav(truth, e, sigma_ned_m=(2.0, 2.0, 1.0)), cfg, keep_series=i < 2)
        results.append(RunResult(run=i, ok=True, scalars=sc, arrays=arr, series=ser))
    results.append(RunResult.failed(12, "RunScoreError: the true aircraft never descended through 200 ft"))
    store = CampaignStore(tmp_path)
    store.start({"seed": 1}, resume=False)
    store.append(results)
    store.write_tables(results)
    summary, det = evaluate_results(results, cfg, profile="synthetic", seed=1, closed_loop=False)
    write_json(tmp_path / "summary.json", summary)
    back = json.loads((tmp_path / "summary.json").read_text())
    assert back == summary and back["runs"] == 13 and back["failed_runs"] == 1
    lat = np.array([r.scalars["cat1_lateral_m"] for r in results[:12]]) / units.FT
    # the library's RMS against the formula written here: two computations (equal today by their same operations),
    # a 12-term mean of squares and a sqrt, ~8 roundings: floor(8, rms)
    rms = np.sqrt(np.mean(lat**2))
    assert_within(back["decision_heights"]["CAT I"]["lateral_1sigma_ft"], rms, floor(8, rms), "CAT I RMS")
    table = verdict_table(summary, det)
    assert table.splitlines()[0] == "synthetic: 13 runs (1 failed), seed 1, open loop"
    assert "CAT III" in table and "best category:" in table and "FTE" not in table
    assert "time-averaged RMS over the approach, as in Gray & Maybeck's Tables 3-6 (An integrated GPS/INS/Baro and " \
        "radar altimeter system for aircraft precision approach landings), ft: latitude " in table
    # 12 runs of ~3 ft lateral, ~3.3 ft vertical: CAT I's upper bounds are below 28.1 / 6.8 ft, but the failed
    # run counts against every category (no failure allowed by default): every category fails
    e1 = summary["decision_heights"]["CAT I"]
    assert e1["lateral_1sigma_upper_ft"] < 28.1 and e1["vertical_1sigma_upper_ft"] < 6.8
    assert [e["verdict"] for e in summary["decision_heights"].values()] == ["fails"] * 3
    assert summary["best_category"] is None and "1 of 13 (no failure allowed: every category fails)" in table
    # the same 12 completed runs without the failed one: CAT I meets
    ok, det_ok = evaluate_results(results[:12], cfg, profile="synthetic", seed=1, closed_loop=False)
    assert ok["decision_heights"]["CAT I"]["verdict"] == "meets" and ok["best_category"] == "CAT I"
    assert "CAT I        200 |" in verdict_table(ok, det_ok).splitlines()[2]
    # a 0-failure meets carries the failure probability's upper bound, 1 - 0.05^(1/12) = 0.221, in its text
    assert ("no failed run in 12: CAT I meets with a failure probability per approach <= 0.221 (one-sided "
            "Clopper-Pearson, 95%), not zero") in verdict_table(ok, det_ok)
    assert abs(ok_fraction_upper(det_ok) - (1.0 - 0.05 ** (1.0 / 12.0))) < 1e-12
    closed, det_c = evaluate_results(results, cfg, profile="synthetic", seed=1, closed_loop=True)
    assert "CAT II       100 | RMS ft: FTE lat" in verdict_table(closed, det_c)
    page = write_report(tmp_path, results, summary, det).read_text()
    # the verdict table comes before any figure, and the figures are embedded
    assert page.index("<table>") < page.index("<img")
    assert page.count("data:image/png;base64,") == 4
    assert "never descended" in page
    for name in ("errors_vs_height", "histograms_dh", "stanford", "availability"):
        assert (tmp_path / f"{name}.png").stat().st_size > 1000
    # series that carry GPS geometry add the sky plot / DOP figure
    ser = dict(results[0].series)
    t = ser["t_s"]
    ser |= {"pdop": 2.0 + 0.001 * t, "el_deg_prn01": np.where(t < 50, 30.0 + 0.1 * t, np.nan),
            "az_deg_prn01": 120.0 + 0.05 * t}
    store.write_series(RunResult(run=0, ok=True, series=ser))
    page = write_report(tmp_path, results, summary, det).read_text()
    assert page.count("data:image/png;base64,") == 5 and (tmp_path / "sky_dop.png").is_file()


class _Cells(HTMLParser):
    """The cells of the page's first table: (data-key, data-value or None, text), and the tables' ids in order."""

    def __init__(self) -> None:
        super().__init__()
        self.tables: list[str | None] = []
        self.cells: list[tuple[str | None, str | None, str]] = []
        self._cell: dict | None = None

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "table":
            self.tables.append(a.get("id"))
        if tag == "td" and len(self.tables) == 1:
            self._cell = {"key": a.get("data-key"), "value": a.get("data-value"), "text": ""}

    def handle_data(self, data):
        if self._cell is not None:
            self._cell["text"] += data

    def handle_endtag(self, tag):
        if tag == "td" and self._cell is not None:
            self.cells.append((self._cell["key"], self._cell["value"], self._cell["text"]))
            self._cell = None


def test_report_leads_with_the_verdict_contract(tmp_path):
    """report.html's first table is the verdict contract: per category and axis summary.json's 1-sigma, upper bound
    and limit (the exact values in data-value, shown as the printed table shows them), details.json's verdict per
    axis, the category's verdict; best category and failed runs beside it; every figure it names is in DIR."""
    cfg = EvaluationConfig(verdict="faa")  # 14 runs: the FAA table alone (ICAO 95 % needs >= 59 runs)
    truth = make_truth(hz=4.0)
    rng = np.random.default_rng(7)
    results = []
    for i in range(14):  # CAT I meets (3 ft / 0.6 ft), CAT III's vertical 1 ft limit is beyond reach
        e = rng.normal(0.0, 3.0) * units.FT * cross_axis_ned() + np.array([0.0, 0.0, rng.normal(0.0, 0.6)])
        sc, arr, ser = score_run(truth, make_nav(truth, e, sigma_ned_m=(2.0, 2.0, 1.0)), cfg, keep_series=i < 2)
        results.append(RunResult(run=i, ok=True, scalars=sc, arrays=arr, series=ser))
    store = CampaignStore(tmp_path)
    store.start({"seed": 1}, resume=False)
    store.append(results)
    summary, det = evaluate_results(results, cfg, profile="synthetic", seed=1, closed_loop=False)
    write_json(tmp_path / "summary.json", summary)
    page = write_report(tmp_path, results, summary, det).read_text()
    p = _Cells()
    p.feed(page)
    assert p.tables[0] == "verdict" and page.index("id='verdict'") < page.index("<img")
    back = json.loads((tmp_path / "summary.json").read_text())
    printed = verdict_table(back, det).splitlines()
    cells = {k: (v, t) for k, v, t in p.cells}
    verdicts = {c: e["verdict"] for c, e in back["decision_heights"].items()}
    assert verdicts == {"CAT I": "meets", "CAT II": "meets", "CAT III": "fails"}  # the numbers decide, not a default
    assert len(p.cells) == 3 * 14
    for cat, e in back["decision_heights"].items():
        for axis in ("lateral", "vertical"):
            for key in (f"{axis}_1sigma_ft", f"{axis}_1sigma_upper_ft", f"limit_{axis}_1sigma_ft"):
                value, text = cells[f"{cat}|{key}"]
                assert float(value) == e[key]  # the exact number summary.json holds
                assert text == format(e[key], ".1f" if key.startswith("limit") else ".2f")
            assert cells[f"{cat}|{axis}_verdict"][1] == det["categories"][cat]["bounds_ft"][axis]["verdict"]
            # the same figures as the printed table's row of the category
            row = next(ln for ln in printed if ln.startswith(f"{cat} "))
            assert f"{e[f'{axis}_1sigma_ft']:7.2f} {e[f'{axis}_1sigma_upper_ft']:7.2f}" in row
        assert cells[f"{cat}|verdict"][1] == e["verdict"] and e["verdict"] in printed[2 + list(verdicts).index(cat)]
        assert cells[f"{cat}|failures_verdict"][1] == "meets"
    assert f"data-key='best_category'>{back['best_category']}<" in page
    assert f"data-key='failed_runs' data-value='{back['failed_runs']}'" in page and back["best_category"] == "CAT II"
    assert report_problems(tmp_path) == []
    (tmp_path / "histograms_dh.png").unlink()
    (tmp_path / "stanford.png").write_bytes(b"not the figure")
    assert sorted(report_problems(tmp_path)) == [
        f"figure histograms_dh: no file {str(tmp_path / 'histograms_dh.png')!r}",
        f"figure stanford: {str(tmp_path / 'stanford.png')!r} is not the figure embedded in report.html",
        f"report.html names histograms_dh.png, which is not in {str(tmp_path)!r}",
    ]


def ok_fraction_upper(det: dict) -> float:
    return float(det["categories"]["CAT I"]["failures"]["fraction_upper"])
