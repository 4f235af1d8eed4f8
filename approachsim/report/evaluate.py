"""Figures and the self-contained HTML report of an evaluation campaign (verdict table first).

Figures (PNG files in DIR and embedded as base64 in DIR/report.html):

* errors_vs_height.png: lateral and vertical navigation error of every run against true height above the
  threshold, the +-1 sigma envelope (RMS over runs at each height, bias included, the contract's sigma)
  and each category's FAA 1-sigma limit drawn at its decision height;
* histograms_dh.png: the distribution of lateral and vertical error over runs at each decision height;
* stanford.png: vertical and horizontal Stanford diagrams (error against protection level, per epoch of
  the runs that kept time series) with the CAT I alert limit, and the all-run region counts;
* availability.png: fraction of runs whose protection levels are within each category's alert limits,
  against height;
* sky_dop.png (when the series carry GPS geometry): sky plot of the satellites and PDOP of one run;
* touchdown.png (landing campaigns, `evaluate --land`): report/touchdown.py's dispersion box, sink-rate histogram
  and normal probability plots, with the criteria table.

With integrity on (evaluation.integrity), stanford.png and availability.png (covariance K_V / K_H levels) give
way to report/integrity.py's solution-separation figures (integrity_stanford, integrity_availability,
integrity_tta).

Uses matplotlib's object API (Figure, no pyplot state), so it is safe in workers and threads.
"""

from __future__ import annotations

import base64
import html
import io
import multiprocessing
import os
import re
import sys
from concurrent.futures import ProcessPoolExecutor
from concurrent.futures.process import BrokenProcessPool
from pathlib import Path

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.ticker import FuncFormatter, MaxNLocator

from approachsim import units
from approachsim.campaign.outputs import HEADLINE_COLUMNS, headline_rows, verdict_table
from approachsim.campaign.result import RunResult
from approachsim.evaluate.limits import CATEGORIES, LIMITS
from approachsim.evaluate.score import CATEGORY_KEYS, HEIGHT_GRID_FT
from approachsim.evaluate.stats import quantile_ranks
from approachsim.report.integrity import CAPTIONS as INTEGRITY_CAPTIONS
from approachsim.report.integrity import INTEGRITY_HEADER, integrity_figures, integrity_rows
from approachsim.report.touchdown import CAPTIONS as TOUCHDOWN_CAPTIONS
from approachsim.report.touchdown import touchdown_figures, touchdown_table

COLORS = {"CAT I": "tab:green", "CAT II": "tab:orange", "CAT III": "tab:red"}


def _stack(results: list[RunResult], name: str) -> np.ndarray:
    rows = [np.asarray(r.arrays[name], dtype=float) for r in results if r.ok and name in r.arrays]
    return np.array(rows) if rows else np.empty((0, HEIGHT_GRID_FT.size))


def _rms(a: np.ndarray) -> np.ndarray:
    n = np.sum(np.isfinite(a), axis=0)
    s = np.nansum(a**2, axis=0)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(n > 0, np.sqrt(s / np.maximum(n, 1)), np.nan)


def fig_errors_vs_height(results: list[RunResult], dh_ft: dict[str, float]) -> Figure:
    """Lateral and vertical error (ft) of all runs against height above the threshold, +-1 sigma, limits."""
    fig = Figure(figsize=(10, 7), constrained_layout=True)
    axes = fig.subplots(2, 1, sharex=True)
    for ax, name, label, lim_key in (
        (axes[0], "lateral_m", "lateral (cross-track) error, ft", "lateral_1sigma_ft"),
        (axes[1], "vertical_m", "vertical error, ft", "vertical_1sigma_ft"),
    ):
        a = _stack(results, name) / units.FT
        h = HEIGHT_GRID_FT
        for row in a:
            ax.plot(h, row, color="0.6", lw=0.5, alpha=0.5)
        if a.shape[0]:
            s = _rms(a)
            ax.plot(h, s, color="tab:blue", lw=2, label="+-1 sigma (RMS over runs)")
            ax.plot(h, -s, color="tab:blue", lw=2)
        for cat in CATEGORIES:
            lim = getattr(LIMITS[cat], lim_key)
            ax.errorbar([dh_ft[cat]], [0.0], yerr=[[lim], [lim]], color=COLORS[cat], capsize=6, lw=2,
                        label=f"{cat} 1-sigma limit at DH {dh_ft[cat]:g} ft")
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
        ax.axhline(0.0, color="k", lw=0.5)
    axes[0].legend(fontsize=8, loc="upper right")
    axes[1].set_xlabel("true height above threshold, ft")
    axes[1].set_xlim(HEIGHT_GRID_FT.max(), 0.0)
    fig.suptitle(f"Navigation error against height, {a.shape[0]} runs")
    return fig


def fig_histograms(results: list[RunResult], dh_ft: dict[str, float]) -> Figure:
    """Histograms over runs of the lateral and vertical error (ft) at each decision height."""
    fig = Figure(figsize=(12, 6), constrained_layout=True)
    axes = fig.subplots(2, 3)
    for j, cat in enumerate(CATEGORIES):
        key = CATEGORY_KEYS[cat]
        for i, (comp, lim) in enumerate(
            (("lateral", LIMITS[cat].lateral_1sigma_ft), ("vertical", LIMITS[cat].vertical_1sigma_ft))
        ):
            ax = axes[i, j]
            x = np.array([r.scalars[f"{key}_{comp}_m"] for r in results if r.ok]) / units.FT
            if x.size:
                ax.hist(x, bins=max(5, min(40, x.size // 3)), color=COLORS[cat], alpha=0.8)
            for s in (-lim, lim):
                ax.axvline(s, color="k", ls="--", lw=1)
            ax.set_title(f"{cat} (DH {dh_ft[cat]:g} ft): {comp}", fontsize=9)
            ax.set_xlabel("error, ft (dashed: FAA 1-sigma limit)", fontsize=8)
            ax.set_ylabel("runs", fontsize=8)
            ax.yaxis.set_major_locator(MaxNLocator(integer=True))
    n = sum(r.ok for r in results)
    fig.suptitle(f"Error at each decision height over {n} runs (one value per run)", fontsize=10)
    return fig


def _series(out_dir: Path) -> list[dict[str, np.ndarray]]:
    import pyarrow.parquet as pq

    d = out_dir / "series"
    if not d.is_dir():
        return []
    return [{k: np.asarray(v) for k, v in pq.read_table(p).to_pydict().items()} for p in sorted(d.glob("*.parquet"))]


def _down_to(series: dict[str, np.ndarray], dh_m: float) -> slice:
    """The epochs of one run from its start to its first one at or below dh_m (the scoring's window)."""
    below = np.flatnonzero(np.asarray(series["hat_m"]) <= dh_m)
    return slice(0, int(below[0]) + 1 if below.size else len(series["hat_m"]))


def fig_stanford(series: list[dict[str, np.ndarray]], det: dict, dh_ft: dict[str, float] | None = None) -> Figure:
    """Stanford diagrams per category (columns) and axis (rows: vertical, horizontal): per epoch of the runs
    that kept time series, from the start down to the category's DH, position error against protection level,
    as a 2-D histogram (colour: epochs per cell, log scale), with the category's alert limit and the regions
    labelled; the titles give the all-run region counts of details.json."""
    dh_ft = dh_ft or {c: float(det["categories"][c]["height_ft"]) for c in CATEGORIES}
    fig = Figure(figsize=(15, 9), constrained_layout=True)
    axes = fig.subplots(2, len(CATEGORIES), squeeze=False)
    mappable = None
    for j, cat in enumerate(CATEGORIES):
        lim = LIMITS[cat]
        dh_m = dh_ft[cat] * units.FT
        for i, (pe_k, pl_k, al, name) in enumerate((
            ("vertical_m", "vpl_m", lim.vertical_al_m, "vertical"),
            ("hpe_m", "hpl_m", lim.horizontal_al_m, "horizontal"),
        )):
            ax = axes[i, j]
            wins = [_down_to(x, dh_m) for x in series]
            pairs = list(zip(series, wins, strict=True))
            pe = np.concatenate([np.abs(x[pe_k][w]) for x, w in pairs]) if pairs else np.empty(0)
            pl = np.concatenate([x[pl_k][w] for x, w in pairs]) if pairs else np.empty(0)
            ok = np.isfinite(pe) & np.isfinite(pl)
            top = max(2.0 * al, float(np.max(pl[ok], initial=0.0)) * 1.1, float(np.max(pe[ok], initial=0.0)) * 1.1)
            if ok.any():
                *_, im = ax.hist2d(pe[ok], pl[ok], bins=60, range=[[0, top], [0, top]], norm=LogNorm(),
                                   cmap="viridis", cmin=1)
                mappable = im
            ax.plot([0, top], [0, top], "k-", lw=1)
            ax.plot([al, al], [0, al], color="r", lw=1.2)  # PE = AL below the PL = AL line
            ax.axhline(al, color="r", lw=1.2)
            ax.plot([al, top], [al, top], "k-", lw=1)
            box = dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.75)
            ax.text(0.3 * al, 0.85 * al, "normal", fontsize=8, color="0.15", ha="center", va="center", bbox=box)
            ax.text(0.7 * al, 0.2 * al, "MI", fontsize=8, color="tab:orange", weight="bold", ha="center", bbox=box)
            ax.text(al + 0.04 * top, 0.5 * al, "HMI", fontsize=8, color="r", weight="bold", bbox=box)
            ax.text(0.5 * top, al + 0.5 * (top - al), "unavailable\n(PL >= AL)", fontsize=8, color="0.3",
                    ha="center", va="center", bbox=box)
            ax.text(al * 1.02, al * 1.02, f" AL {al:.1f} m", fontsize=7, color="r", va="bottom")
            counts = det["categories"][cat][f"stanford_{name}"]
            ax.set_title(
                f"{cat} {name} (epochs down to DH {dh_ft[cat]:g} ft)\nall runs: normal {counts['normal']}, "
                f"MI {counts['mi']}, HMI {counts['hmi']}, unavailable {counts['unavailable']}",
                fontsize=8,
            )
            ax.set_xlabel(f"{name} position error |PE|, m", fontsize=8)
            ax.set_ylabel(f"{name} protection level PL, m", fontsize=8)
            ax.set_xlim(0, top)
            ax.set_ylim(0, top)
    if mappable is not None:
        fig.colorbar(mappable, ax=axes, shrink=0.8, label="epochs per cell (log scale)")
    fig.suptitle(f"Stanford diagrams, {len(series)} runs with time series", fontsize=11)
    return fig


def fig_availability(results: list[RunResult]) -> Figure:
    """Fraction of runs with VPL <= VAL and HPL <= HAL of each category, against height above threshold."""
    fig = Figure(figsize=(10, 4), constrained_layout=True)
    ax = fig.subplots()
    vpl, hpl = _stack(results, "vpl_m"), _stack(results, "hpl_m")
    # CAT II and CAT III alert limits are nearly equal, so their curves often coincide: distinct line styles and
    # widths (wide solid under narrow dashed under dotted with markers) keep every one visible
    styles = {"CAT I": dict(ls="-", lw=5.0, alpha=0.45), "CAT II": dict(ls="--", lw=2.5),
              "CAT III": dict(ls=":", lw=2.0, marker="o", markersize=3, markevery=0.05)}
    for cat in CATEGORIES:
        if vpl.shape[0]:
            ok = np.isfinite(vpl) & np.isfinite(hpl)
            av = (vpl <= LIMITS[cat].vertical_al_m) & (hpl <= LIMITS[cat].horizontal_al_m) & ok
            frac = np.where(ok.sum(0) > 0, av.sum(0) / np.maximum(ok.sum(0), 1), np.nan)
            lim = LIMITS[cat]
            ax.plot(HEIGHT_GRID_FT, frac, color=COLORS[cat], **styles[cat],
                    label=f"{cat}: VPL <= {lim.vertical_al_m:.1f} m and HPL <= {lim.horizontal_al_m:.1f} m")
    ax.set_xlim(HEIGHT_GRID_FT.max(), 0.0)
    ax.set_ylim(-0.02, 1.02)
    ax.set_xlabel("true height above threshold, ft")
    ax.set_ylabel("availability (fraction of runs)")
    ax.set_title(f"Availability against height, {vpl.shape[0]} runs", fontsize=10)
    if ax.get_lines():
        ax.legend(fontsize=8, loc="center left", framealpha=0.9)
    else:
        ax.text(0.5, 0.5, "no completed run", transform=ax.transAxes, ha="center", va="center")
    ax.grid(True, alpha=0.3)
    return fig


def fig_sky(series: dict[str, np.ndarray]) -> Figure:
    """Sky plot of the GPS satellites above the mask during one run, and PDOP against time."""
    fig = Figure(figsize=(11, 5), constrained_layout=True)
    ax = fig.add_subplot(1, 2, 1, projection="polar")
    ax.set_theta_zero_location("N")
    ax.set_theta_direction(-1)
    for k in sorted(series):
        if not k.startswith("el_deg_prn"):
            continue
        prn = k[len("el_deg_prn"):]
        el, az = series[k], series[f"az_deg_prn{prn}"]
        ok = np.isfinite(el)
        if ok.any():
            ax.plot(np.radians(az[ok]), 90.0 - el[ok], lw=2)
            i = np.flatnonzero(ok)[-1]
            ax.text(np.radians(az[i]), 90.0 - el[i], prn, fontsize=8)
    ax.set_rmax(90.0)
    ax.set_rticks([0, 30, 60, 90], labels=["90", "60", "30", "0"])
    ax.set_title("GPS sky (elevation deg, azimuth from north)", fontsize=9)
    ax2 = fig.add_subplot(1, 2, 2)
    ax2.plot(series["t_s"], series["pdop"])
    ax2.set_xlabel("time, s")
    ax2.set_ylabel("PDOP of the satellites used")
    ax2.grid(True, alpha=0.3)
    return fig


def _png_bytes(fig: Figure) -> bytes:
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=110)
    return buf.getvalue()


_PENDING: dict[str, Figure] = {}
"""The figures being rendered by `_render_all`'s forked workers (they read them from the parent's memory)."""


def _render_one(name: str) -> bytes:
    return _png_bytes(_PENDING[name])


def _render_all(figs: dict[str, Figure], out_dir: Path) -> dict[str, str]:
    """Render every figure to DIR/<name>.png and return them base64-encoded. Rendering (layout and rasterizing)
    is most of a report's time and the figures are independent: where processes can fork, they are rendered in
    parallel, one worker per core (the figures built here are read by the forked workers, nothing is pickled but the
    PNG bytes); else one after the other. The bytes are the same either way."""
    data: dict[str, bytes] = {}
    workers = min(len(figs), os.cpu_count() or 1)
    if workers > 1 and sys.platform.startswith("linux"):
        _PENDING.clear()
        _PENDING.update(figs)
        try:
            ctx = multiprocessing.get_context("fork")
            with ProcessPoolExecutor(max_workers=workers, mp_context=ctx) as pool:
                data = dict(zip(figs, pool.map(_render_one, list(figs)), strict=True))
        except (OSError, BrokenProcessPool):  # no processes to be had: render here
            data = {}
        finally:
            _PENDING.clear()
    for name, fig in figs.items():
        if name not in data:
            data[name] = _png_bytes(fig)
    out = {}
    for name, b in data.items():
        (out_dir / f"{name}.png").write_bytes(b)
        out[name] = base64.b64encode(b).decode("ascii")
    return out


def _cell(x) -> str:
    if x is None:
        return "--"
    if isinstance(x, bool):
        return "YES" if x else "no"
    if isinstance(x, float):
        return f"{x:.3g}" if abs(x) < 1e4 else f"{x:.4g}"
    return html.escape(str(x))


def _table(header: list[str], rows: list[list]) -> str:
    h = "".join(f"<th>{html.escape(c)}</th>" for c in header)
    body = "".join("<tr>" + "".join(f"<td>{_cell(c)}</td>" for c in row) + "</tr>" for row in rows)
    return f"<table><tr>{h}</tr>{body}</table>"


def _min_runs_for_p95_upper() -> int:
    """Smallest run count for which the 95th percentile has a distribution-free 95 % upper bound."""
    n = 1
    while quantile_ranks(n)[1] is None and n < 10000:
        n += 1
    return n


_P95_HI_MIN_RUNS = _min_runs_for_p95_upper()

FIGURE_CAPTIONS = {
    "errors_vs_height": (
        "Navigation error against height",
        "Lateral (top) and vertical (bottom) navigation error, estimate minus truth in the runway frame, of every "
        "run (grey) against the true height above the threshold, the aircraft flying right to left. Blue: +-1 "
        "sigma, the RMS over runs at each height (bias included), the figure the verdict uses. Coloured bars: "
        "each category's FAA 1-sigma limit at its decision height; the category is met where the blue curve at "
        "its decision height lies inside its bar, laterally and vertically.",
    ),
    "histograms_dh": (
        "Error distribution at the decision heights",
        "One value per run: the lateral (top) and vertical (bottom) error when the true aircraft passes each "
        "decision height, in ft; y axis: number of runs per bin. Dashed: the FAA 1-sigma limit. A wide or "
        "off-centre histogram (bias) raises the RMS the verdict uses.",
    ),
    "stanford": (
        "Stanford diagrams (integrity)",
        "For each category (columns) and for the vertical and horizontal axes (rows), every epoch of the runs "
        "that kept time series, from the start down to the category's decision height: position error against "
        "the protection level computed from the filter covariance, in m, as the standards define the alert "
        "limits (AL, red). Colour: epochs per cell, log scale. Above the diagonal and below AL is normal; below "
        "the diagonal the protection level did not bound the error (MI, misleading information), and to the "
        "right of AL below it is hazardous (HMI); above AL the approach is unavailable. The titles count every "
        "run's epochs. Integrity is reported beside the verdict, not part of it.",
    ),
    "availability": (
        "Availability against height",
        "Fraction of the runs whose vertical and horizontal protection levels are both within the category's "
        "alert limits, against the true height above the threshold (right to left as flown). CAT II and CAT III "
        "alert limits are nearly equal, so their curves often overlap (dashed and dotted drawn over the wide "
        "CAT I line). Reported beside the verdict, not part of it.",
    ),
    "sky_dop": (
        "GPS geometry of one run",
        "Left: the satellites above the mask during the first run (elevation from the centre outwards, azimuth "
        "clockwise from north; numbers are PRNs at their last position). Right: PDOP of the satellites used, "
        "against time from the run start.",
    ),
}
"""Per report figure: its heading and its caption (what it shows, how to read it)."""


def evaluation_figures(results: list[RunResult], summary: dict, det: dict,
                       series: list[dict[str, np.ndarray]]) -> dict[str, Figure]:
    """The report's figures by name (FIGURE_CAPTIONS, integrity's and touchdown's captions), not yet rendered:
    series are the time series of the runs that kept them (DIR/series/, or the runs' own in memory)."""
    dh_ft = {c: float(summary["decision_heights"][c]["height_ft"]) for c in CATEGORIES}
    imgs = {
        "errors_vs_height": fig_errors_vs_height(results, dh_ft),
        "histograms_dh": fig_histograms(results, dh_ft),
    }
    integ_figs = integrity_figures(results, det)
    if integ_figs:  # integrity on: the solution-separation levels replace the covariance K_V / K_H ones
        imgs.update(integ_figs)
    else:
        imgs["stanford"] = fig_stanford(series, det, dh_ft)
        imgs["availability"] = fig_availability(results)
    sky = next((x for x in series if "pdop" in x), None)
    if sky is not None:
        imgs["sky_dop"] = fig_sky(sky)
    imgs.update(touchdown_figures(results, det))  # landing campaigns (evaluate --land)
    return imgs


def series_of(out_dir: Path | None, results: list[RunResult]) -> list[dict[str, np.ndarray]]:
    """The kept time series: DIR/series/*.parquet when out_dir has them, else the runs' own (in run order)."""
    if out_dir is not None:
        found = _series(Path(out_dir))
        if found:
            return found
    return [{k: np.asarray(v, dtype=float) for k, v in r.series.items()}
            for r in sorted(results, key=lambda r: r.run) if r.series]


def _headline(summary: dict, det: dict) -> str:
    """The verdict contract's table (outputs.headline_rows): every cell that shows a number carries summary.json's
    value in data-value, and each cell its key in data-key, so a test (or a script) can read the page exactly."""
    head = "".join(f"<th>{html.escape(title)}</th>" for _, title, _ in HEADLINE_COLUMNS)
    body = []
    for row in headline_rows(summary, det):
        cells = []
        for key, _, fmt in HEADLINE_COLUMNS:
            v = row[key]
            attrs = f" data-key='{html.escape(row['category'])}|{key}'"
            if isinstance(v, float | int) and not isinstance(v, bool):
                attrs += f" data-value='{v!r}'"
                text = format(v, fmt) if fmt else str(v)
            else:
                text = "--" if v is None else html.escape(str(v))
            style = f" class='v-{v}'" if key.endswith("verdict") and isinstance(v, str) else ""
            cells.append(f"<td{attrs}{style}>{text}</td>")
        body.append("<tr>" + "".join(cells) + "</tr>")
    return f"<table id='verdict'><tr>{head}</tr>{''.join(body)}</table>"


def write_report(out_dir: Path, results: list[RunResult], summary: dict, det: dict) -> Path:
    """Write the figures and DIR/report.html (the verdict contract's table first, images embedded); returns its
    path."""
    out_dir = Path(out_dir)
    imgs = evaluation_figures(results, summary, det, series_of(out_dir, results))
    b64 = _render_all(imgs, out_dir)
    other_rows = []
    for cat, e in summary["decision_heights"].items():
        lim = det["categories"][cat]["limits_ft"]
        other_rows.append([cat, e["height_ft"], e["lateral_95_ft"], lim["lateral_95_ft"], e["vertical_95_ft"],
                           lim["vertical_95_ft"]])
    detail_rows = []
    for cat, c in det["categories"].items():
        for comp in ("lateral", "vertical", "along", "vpl", "hpl", "lpl", "fte_lat", "fte_vert", "tse_lat", "tse_vert"):
            if f"{comp}_ft" not in c:
                continue
            s = c[f"{comp}_ft"]
            detail_rows.append([cat, comp, s["n"], s["rms"], s["rms_lo"], s["rms_hi"], s["mean"], s["std"], s["p95"],
                                s["p95_lo"], s["p95_hi"]])
    integ_rows = [
        [cat, axis, *(c[f"stanford_{axis}"][k] for k in ("normal", "mi", "hmi", "unavailable")), c["availability"]]
        for cat, c in det["categories"].items()
        for axis in ("vertical", "lateral", "horizontal") if f"stanford_{axis}" in c
    ]
    ta = det["time_averaged_rms_ft"]
    failures = det.get("failures", {})
    title = f"approachsim evaluation: {summary['profile']}"
    parts = [
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>",
        "<style>body{font-family:sans-serif;margin:2em;max-width:1200px}table{border-collapse:collapse;"
        "margin:1em 0}td,th{border:1px solid #bbb;padding:3px 8px;text-align:right}th{background:#eee}"
        "img{max-width:100%}figure{margin:0 0 2em 0}figcaption{max-width:900px;color:#333;font-size:0.95em}"
        "td.v-meets{background:#d6f5d6}td.v-fails{background:#f7d4d4}td.v-indeterminate{background:#fff2c2}"
        "#verdict td:first-child{text-align:left;font-weight:bold}"
        "</style></head><body>",
        f"<h1>{html.escape(title)}</h1>",
        "<h2>Verdict</h2>",
        _headline(summary, det),
        f"<p id='best'><b>Best category: <span data-key='best_category'>"
        f"{html.escape(str(summary['best_category'] or 'none'))}</span></b>; failed runs: <b><span "
        f"data-key='failed_runs' data-value='{summary['failed_runs']}'>{summary['failed_runs']}</span></b> of "
        f"{summary['runs']}; seed {summary['seed']}, {'closed' if summary['closed_loop'] else 'open'} loop.</p>",
        f"<p>1-sigma = RMS over the completed runs, bias included (ft). A category meets when the one-sided "
        f"{det.get('confidence', 0.95):.0%} upper confidence bound of both axes is within the FAA limit (and the "
        "failed runs and, where listed, integrity meet), fails when a lower bound is beyond it, and is indeterminate "
        "otherwise, with the runs that would likely decide it. The same numbers as summary.json and the printed "
        f"table. Verdict uses: {html.escape(det['verdict_limits'])}.</p>",
        *(f"<p><b>{html.escape(n)}</b></p>" for n in verdict_table(summary, det).splitlines() if n.startswith("note:")),
        "<h2>ICAO 95 % accuracy (beside the verdict unless it uses faa+icao), ft</h2>",
        _table(["category", "DH ft", "lateral 95% ft", "ICAO 95%", "vertical 95% ft", "ICAO 95%"], other_rows),
        "<h2>Statistics at decision height (ft; 95 % intervals for the number of runs)</h2>",
        _table(["category", "error", "n", "RMS", "RMS lo", "RMS hi", "mean", "std", "95%", "95% lo", "95% hi"],
               detail_rows),
        "<p>-- : no bound from this many runs (a distribution-free 95 % upper bound on a 95th percentile needs "
        f"at least {_P95_HI_MIN_RUNS} runs).</p>",
        "<h2>Integrity (epochs over the approach down to each DH)</h2>",
        _table(["category", "axis", "normal", "MI", "HMI", "unavailable", "availability"], integ_rows),
        *([_table(INTEGRITY_HEADER, integrity_rows(det))] if "integrity" in det else []),
        "<h2>Time-averaged RMS over the approach (Gray &amp; Maybeck Tables 3-6 quantity), ft</h2>",
        _table(list(ta), [list(ta.values())]),
        *([touchdown_table(det["touchdown"])] if "touchdown" in det else []),
    ]
    if failures:
        parts.append("<h2>Failed runs</h2>" + _table(["run", "reason"], [[k, v] for k, v in failures.items()]))
    for k in imgs:
        title, caption = FIGURE_CAPTIONS.get(k) or INTEGRITY_CAPTIONS.get(k) or TOUCHDOWN_CAPTIONS[k]
        parts.append(f"<h2>{html.escape(title)}</h2><figure><img alt='{k}' src='data:image/png;base64,{b64[k]}'>"
                     f"<figcaption>{html.escape(caption)} (file {k}.png)</figcaption></figure>")
    parts.append("</body></html>")
    path = out_dir / "report.html"
    path.write_text("\n".join(parts), encoding="utf-8")
    return path


_IMG = re.compile(r"<img alt='([^']+)' src='data:image/png;base64,([A-Za-z0-9+/=]*)'>")


def report_problems(out_dir: Path) -> list[str]:
    """What is wrong with DIR/report.html's figures, one line each (empty: nothing), without rendering the page:
    every embedded figure names its file "(file NAME.png)", that file is in DIR and holds the embedded bytes, and
    no figure file named on the page is missing."""
    out_dir = Path(out_dir)
    page = (out_dir / "report.html").read_text(encoding="utf-8")
    problems = []
    embedded = _IMG.findall(page)
    if not embedded:
        problems.append("report.html embeds no figure")
    for name, b64 in embedded:
        f = out_dir / f"{name}.png"
        if f"(file {name}.png)" not in page:
            problems.append(f"figure {name}: its caption does not name its file {name}.png")
        if not f.is_file():
            problems.append(f"figure {name}: no file {str(f)!r}")
        elif f.read_bytes() != base64.b64decode(b64):
            problems.append(f"figure {name}: {str(f)!r} is not the figure embedded in report.html")
    for name in re.findall(r"\(file ([^()\s]+)\.png\)", page):
        if not (out_dir / f"{name}.png").is_file():
            problems.append(f"report.html names {name}.png, which is not in {str(out_dir)!r}")
    return problems


def _plain_tick(v: float, _pos: int | None = None) -> str:
    """A log-axis tick as a plain number (0.3, 1, 30), not 3x10^1."""
    return f"{v:g}"


def _minor_tick(v: float, _pos: int | None = None) -> str:
    """Minor log ticks labelled at 2 and 5 times a decade only (keeps the axis readable)."""
    mant = v / 10.0 ** np.floor(np.log10(v)) if v > 0 else 0.0
    return f"{v:g}" if round(mant) in (2, 5) and abs(mant - round(mant)) < 1e-6 else ""


def write_study_figure(out_dir: Path, rows: list[dict]) -> Path:
    """DIR/study.png: lateral and vertical 1-sigma error at each decision height per variant, with limits."""
    path = Path(out_dir) / "study.png"
    study_figure(rows).savefig(path, dpi=110)
    return path


def study_figure(rows: list[dict]) -> Figure:
    """Lateral and vertical 1-sigma error at each decision height per variant (campaign.study.comparison_rows), on
    a log scale, with the FAA limits dashed."""
    fig = Figure(figsize=(max(8.0, 1.2 * len(rows) + 4.0), 7), constrained_layout=True)
    axes = fig.subplots(2, 1, sharex=True)
    x = np.arange(len(rows))
    w = 0.8 / len(CATEGORIES)
    for ax, comp, lim_key in ((axes[0], "lateral", "lateral_1sigma_ft"), (axes[1], "vertical", "vertical_1sigma_ft")):
        for j, cat in enumerate(CATEGORIES):
            tag = cat.replace(" ", "")
            vals = np.array([np.nan if r[f"{tag}_{comp}_1sigma_ft"] is None else r[f"{tag}_{comp}_1sigma_ft"]
                             for r in rows])
            ax.bar(x + (j - 1) * w, vals, w, color=COLORS[cat], label=f"{cat} (limit dashed)")
            ax.axhline(getattr(LIMITS[cat], lim_key), color=COLORS[cat], ls="--", lw=1)
        ax.set_yscale("log")
        ax.yaxis.set_major_formatter(FuncFormatter(_plain_tick))
        ax.yaxis.set_minor_formatter(FuncFormatter(_minor_tick))
        ax.set_ylabel(f"{comp} 1-sigma at DH, ft (log scale)")
        ax.grid(True, axis="y", alpha=0.3)
    axes[0].legend(fontsize=8)
    axes[0].set_title("1-sigma error (RMS over runs) at each decision height per variant; dashed: FAA limits",
                      fontsize=10)
    axes[1].set_xticks(x, [r["variant"] for r in rows], rotation=30, ha="right", fontsize=8)
    return fig
