"""What the evaluation figures show, checked on their matplotlib objects: Stanford diagrams per category with a
colour scale and labelled regions, labelled histogram axes, every availability curve drawn distinctly, plain
log ticks on the study figure, and a caption for every report figure."""

from __future__ import annotations

import numpy as np
from evalpairs import cross_axis_ned, make_nav, make_truth

from approachsim import units
from approachsim.campaign.outputs import evaluate_results
from approachsim.campaign.result import RunResult
from approachsim.evaluate.config import EvaluationConfig
from approachsim.evaluate.limits import CATEGORIES
from approachsim.evaluate.score import score_run
from approachsim.report import evaluate as rep


def _campaign(n: int = 8):
    cfg = EvaluationConfig()
    truth = make_truth(hz=4.0)
    rng = np.random.default_rng(11)
    results = []
    for i in range(n):
        e = rng.normal(0.0, 3.0) * units.FT * cross_axis_ned() + np.array([0.0, 0.0, rng.normal(0.0, 1.0)])
        sc, arr, ser = score_run(truth, make_nav(truth, e, sigma_ned_m=(2.0, 2.0, 1.0)), cfg, keep_series=i < 3)
        results.append(RunResult(run=i, ok=True, scalars=sc, arrays=arr, series=ser))
    summary, det = evaluate_results(results, cfg, profile="synthetic", seed=1, closed_loop=False)
    return results, summary, det


def _texts(ax) -> list[str]:
    return [t.get_text() for t in ax.texts]


def test_stanford_has_a_panel_per_category_and_axis_with_colour_scale_and_regions():
    results, summary, det = _campaign()
    series = [dict(r.series) for r in results if r.series is not None]
    fig = rep.fig_stanford(series, det)
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert len(panels) == 2 * len(CATEGORIES)
    assert any(ax.get_label() == "<colorbar>" for ax in fig.axes)  # the colour scale
    titles = " ".join(ax.get_title() for ax in panels)
    for cat in CATEGORIES:
        assert f"{cat} vertical" in titles and f"{cat} horizontal" in titles
    for ax in panels:
        joined = " ".join(_texts(ax))
        for region in ("normal", "MI", "HMI", "unavailable"):
            assert region in joined, (ax.get_title(), joined)
        assert ax.get_xlabel().endswith(", m") and ax.get_ylabel().endswith(", m")
    # each category's panel carries its own alert limit (the requirements table's: VAL 10 m for every category,
    # HAL 40 m at CAT I and 17 m at CAT II / III since issue 41)
    from approachsim.evaluate.limits import LIMITS

    for ax in panels:
        cat = next(c for c in sorted(CATEGORIES, key=len, reverse=True) if ax.get_title().startswith(c))
        lim = LIMITS[cat].vertical_al_m if "vertical" in ax.get_title() else LIMITS[cat].horizontal_al_m
        al = next(t for t in _texts(ax) if t.strip().startswith("AL"))
        assert al.strip() == f"AL {lim:.1f} m", (ax.get_title(), al)


def test_histograms_have_labelled_axes():
    results, summary, _ = _campaign()
    dh = {c: float(summary["decision_heights"][c]["height_ft"]) for c in CATEGORIES}
    fig = rep.fig_histograms(results, dh)
    for ax in fig.axes:
        assert ax.get_ylabel() == "runs" and "ft" in ax.get_xlabel()


def test_availability_curves_are_each_visible():
    results, _, _ = _campaign()
    ax = rep.fig_availability(results).axes[0]
    lines = [ln for ln in ax.get_lines() if not ln.get_label().startswith("_")]
    assert len(lines) == 3
    styles = {(ln.get_linestyle(), ln.get_linewidth(), ln.get_marker()) for ln in lines}
    assert len(styles) == 3  # coinciding CAT II / CAT III curves stay distinguishable
    assert all("VPL <=" in ln.get_label() for ln in lines)


def test_study_figure_log_ticks_are_plain_numbers(tmp_path):
    rows = []
    for name, lat, ver in (("a", 3.0, 0.5), ("b", 30.0, 4.0)):
        r = {"variant": name}
        for tag in ("CATI", "CATII", "CATIII"):
            r[f"{tag}_lateral_1sigma_ft"], r[f"{tag}_vertical_1sigma_ft"] = lat, ver
        rows.append(r)
    assert rep._plain_tick(30.0) == "30" and rep._plain_tick(0.3) == "0.3" and rep._plain_tick(1000.0) == "1000"
    assert rep._minor_tick(20.0) == "20" and rep._minor_tick(3.0) == ""
    path = rep.write_study_figure(tmp_path, rows)
    assert path.stat().st_size > 1000


def test_every_report_figure_has_a_caption(tmp_path):
    results, summary, det = _campaign()
    page = rep.write_report(tmp_path, results, summary, det).read_text()
    assert page.count("<figcaption>") == page.count("<img")
    for key in ("errors_vs_height", "histograms_dh", "stanford", "availability"):
        title, caption = rep.FIGURE_CAPTIONS[key]
        assert title in page and len(caption.split()) > 25
    assert set(rep.FIGURE_CAPTIONS) >= {"errors_vs_height", "histograms_dh", "stanford", "availability", "sky_dop"}


def test_report_of_a_campaign_where_every_run_failed_draws_without_warnings(tmp_path):
    """Warnings are errors in the test suite: an all-failed campaign still gets a report naming the reason."""
    results = [RunResult.failed(i, "ProfileError: aircraft.name: no aircraft file a380.toml") for i in range(3)]
    summary, det = evaluate_results(results, EvaluationConfig(), profile="p", seed=1, closed_loop=True)
    page = rep.write_report(tmp_path, results, summary, det).read_text()
    assert "no aircraft file a380.toml" in page and page.count("<figcaption>") == 4
