"""The touchdown figure and table of a landing campaign (`approachsim evaluate --land`), from the per-run touchdown
scalars (evaluate/touchdown.py) and details.json "touchdown".

touchdown.png, four panels:

* dispersion box: every run's main gear at touchdown, longitudinal point past the threshold against lateral
  position (a bar from the left to the right main gear, a dot at the centre), with the longitudinal, lateral and
  outboard-gear limits (each labelled with its source mark: V read in the standard, S secondary, U not found);
* sink rate: histogram of the main-gear sink rate at touchdown with the fitted normal and the sink limits;
* normal probability plots of the longitudinal point and of the sink rate: the runs' ordered values against the
  standard normal quantile of their rank (Blom plotting positions (i - 3/8) / (n + 1/4)), the fitted normal as a
  line drawn on out to the quantile each limit's required probability needs. Where the dots leave the line the
  distribution is not normal; everything beyond the last dot is the normal model's extrapolation, not data.

Uses matplotlib's object API (Figure, no pyplot state).
"""

from __future__ import annotations

import html
import math

import numpy as np
from matplotlib.figure import Figure
from matplotlib.ticker import MaxNLocator
from scipy import stats as sps

from approachsim import units
from approachsim.campaign.result import RunResult

LIMIT_STYLE = {"V": "-", "S": "--", "U": ":"}
"""Line style of a limit by its source mark."""

CAPTIONS = {
    "touchdown": (
        "Touchdown dispersion (landing runs)",
        "Top left: where each run's main gear touched down, distance past the threshold (x) against distance right "
        "of the centreline (y), ft; a grey bar joins the left and right main gear, the dot is their centre. Top "
        "right: the main-gear sink rate at touchdown, ft/s, with the normal fitted to the runs. Bottom: normal "
        "probability plots of the touchdown point and of the sink rate: each dot is a run, at the normal quantile "
        "of its rank; the line is the fitted normal, drawn out to the quantile the required probability needs "
        "(4.75 sd for 1e-6). Limits in red, line style by source: solid V (read in the standard), dashed S "
        "(secondary source), dotted U (not found, a candidate): no limit here is V, so no touchdown verdict is "
        "given. Beyond the last dot the probability is the normal model's, not the runs' (docs/touchdown.md).",
    ),
}
"""Per figure: its heading and caption."""


def _col(results: list[RunResult], name: str) -> np.ndarray:
    return np.array([r.scalars.get(name, np.nan) for r in results if r.ok], dtype=float)


def _blom(n: int) -> np.ndarray:
    """Standard normal quantiles of the ranks 1..n (Blom's plotting positions)."""
    return sps.norm.ppf((np.arange(1, n + 1) - 0.375) / (n + 0.25))


def _limit_label(c: dict) -> str:
    return f"{c['limit']:.4g} {c['unit']} [{c['mark']}] (p {c['probability_required']:g})"


def _probability_plot(ax, x: np.ndarray, crits: list[dict], unit: str, what: str) -> None:
    """Normal probability plot of x (display unit) with the fitted line out to the criteria's required
    quantiles and the limits."""
    x = np.sort(x[np.isfinite(x)])
    n = x.size
    if n < 3:
        ax.text(0.5, 0.5, "fewer than 3 landings", ha="center", transform=ax.transAxes)
        return
    q = _blom(n)
    ax.plot(q, x, "o", ms=4, color="tab:blue", label=f"{n} runs")
    m, s = float(np.mean(x)), float(np.std(x, ddof=1))
    zmax = max([abs(c["z_required"]) for c in crits] + [abs(q[0]), 3.0]) + 0.3
    zz = np.linspace(-zmax, zmax, 50)
    ax.plot(zz, m + s * zz, color="tab:blue", lw=1, label=f"normal fit: {m:.3g} +- {s:.3g} {unit}")
    ax.axvspan(q[0], q[-1], color="tab:blue", alpha=0.06, lw=0)
    for c in crits:
        ls = LIMIT_STYLE.get(c["mark"], ":")
        ax.axhline(c["limit"], color="tab:red", ls=ls, lw=1.2, label=f"{c['key']}: {_limit_label(c)}")
        zr = c["z_required"] if c["side"] == "above" else -c["z_required"]
        ax.plot([zr], [m + s * zr], "x", color="tab:red", ms=8)
    ax.set_xlabel("standard normal quantile (shaded: the runs' range; x: where the fit is at the required "
                  "probability)", fontsize=8)
    ax.set_ylabel(f"{what}, {unit}")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper left")


def fig_touchdown(results: list[RunResult], td: dict) -> Figure:
    """The four-panel touchdown figure (module docstring)."""
    crit = {k: {**c, "key": k} for k, c in td["criteria"].items()}
    x = _col(results, "td_x_m") / units.FT
    y = _col(results, "td_y_m") / units.FT
    yl = _col(results, "td_left_gear_y_m") / units.FT
    yr = _col(results, "td_right_gear_y_m") / units.FT
    sink = _col(results, "td_sink_mps") / units.FPS
    fig = Figure(figsize=(13, 10), constrained_layout=True)
    (a_box, a_sink), (a_qx, a_qs) = fig.subplots(2, 2)

    for xi, l, r in zip(x, yl, yr, strict=True):
        a_box.plot([xi, xi], [l, r], color="0.6", lw=1)
    a_box.plot(x, y, "o", ms=4, color="tab:blue", label=f"main-gear centre ({x.size} landings)")
    for key in ("short", "long"):
        c = crit.get(key)
        if c:
            a_box.axvline(c["limit"], color="tab:red", ls=LIMIT_STYLE.get(c["mark"], ":"), lw=1.2,
                          label=f"{key}: {_limit_label(c)}")
    for key, color in (("lateral", "tab:red"), ("outboard_gear", "tab:purple")):
        c = crit.get(key)
        if c:
            for sgn in (-1.0, 1.0):
                a_box.axhline(sgn * c["limit"], color=color, ls=LIMIT_STYLE.get(c["mark"], ":"), lw=1.2,
                              label=f"{key}: {_limit_label(c)}" if sgn > 0 else None)
    a_box.axhline(0.0, color="k", lw=0.5)
    a_box.set_xlabel("main gear past the threshold, ft")
    a_box.set_ylabel("right of the centreline, ft")
    a_box.set_title("Touchdown points (bar: left to right main gear)", fontsize=10)
    a_box.grid(True, alpha=0.3)
    a_box.legend(fontsize=7, loc="upper right")

    s = sink[np.isfinite(sink)]
    if s.size:
        a_sink.hist(s, bins=max(5, min(30, s.size // 3)), color="tab:blue", alpha=0.7, label=f"{s.size} landings")
        if s.size > 2 and np.std(s) > 0:
            m, sd = float(np.mean(s)), float(np.std(s, ddof=1))
            hi = max(m + 5.0 * sd, *(crit[k]["limit"] for k in ("sink", "sink_limit_risk") if k in crit))
            g = np.linspace(min(0.0, m - 4.0 * sd), hi, 200)
            w = (s.max() - s.min()) / max(5, min(30, s.size // 3)) if s.max() > s.min() else 1.0
            a_sink.plot(g, s.size * w * sps.norm.pdf(g, m, sd), color="tab:blue", lw=1,
                        label=f"normal fit {m:.2f} +- {sd:.2f} ft/s")
    for key in ("sink", "sink_limit_risk"):
        c = crit.get(key)
        if c:
            a_sink.axvline(c["limit"], color="tab:red", ls=LIMIT_STYLE.get(c["mark"], ":"), lw=1.2,
                           label=f"{key}: {_limit_label(c)}")
    a_sink.set_xlabel("main-gear sink rate at touchdown, ft/s")
    a_sink.set_ylabel("runs")
    a_sink.yaxis.set_major_locator(MaxNLocator(integer=True))
    a_sink.set_title("Sink rate", fontsize=10)
    a_sink.legend(fontsize=7)
    a_sink.grid(True, alpha=0.3)

    _probability_plot(a_qx, x, [crit[k] for k in ("short", "long") if k in crit], "ft",
                      "touchdown point past the threshold")
    _probability_plot(a_qs, sink, [crit[k] for k in ("sink", "sink_limit_risk") if k in crit], "ft/s",
                      "main-gear sink rate")
    fig.suptitle(f"Touchdown: {td['landings']} landings of {td['runs']} runs ({td['failed_runs']} failed), verdict "
                 f"{td['verdict']}", fontsize=11)
    return fig


def touchdown_figures(results: list[RunResult], det: dict) -> dict[str, Figure]:
    """{"touchdown": figure} for a landing campaign (details.json has "touchdown"), else {}."""
    td = det.get("touchdown")
    return {} if td is None else {"touchdown": fig_touchdown(results, td)}


TABLE_HEADER = ["criterion", "limit", "mark", "required p", "exceedances", "empirical upper", "z of limit",
                "z required", "normal p", "normal p upper", "normality p", "landings to decide", "outcome", "verdict"]


def _f(x, fmt: str) -> str:
    return "--" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, fmt)


def _shapiro(normality: dict | None) -> float | None:
    """The Shapiro-Wilk p of a criterion's fit (two fits: the smaller)."""
    if not normality:
        return None
    ps = [normality.get(k, {}).get("shapiro_p") for k in ("upper", "lower")] + [normality.get("shapiro_p")]
    ps = [p for p in ps if p is not None]
    return min(ps) if ps else None


def touchdown_table(td: dict) -> str:
    """The report's HTML table of the touchdown criteria, then each criterion's source and reason."""
    rows = []
    notes = []
    for key, c in td["criteria"].items():
        n = c["normal"] or {}
        sign = {"below": "&lt; ", "above": "&gt; ", "abs_above": "|x| &gt; "}[c["side"]]
        rows.append([html.escape(key), f"{sign}{c['limit']:.4g} {html.escape(c['unit'])}", c["mark"],
                     f"{c['probability_required']:g}", f"{c['exceedances']}/{c['runs']}",
                     _f(c["empirical"]["upper"], ".2g"), _f(n.get("z_limit"), ".2f"), f"{c['z_required']:.2f}",
                     _f(n.get("probability"), ".2g"), _f(n.get("probability_upper"), ".2g"),
                     _f(_shapiro(n.get("normality")), ".3g"), _f(n.get("runs_needed"), "d"),
                     c["outcome"], c["verdict"]])
        notes.append(f"<li><b>{html.escape(key)}</b> [{c['mark']}]: {html.escape(c['source'])}. "
                     f"<i>{html.escape(c['why'])}</i></li>")
    head = "".join(f"<th>{html.escape(h)}</th>" for h in TABLE_HEADER)
    body = "".join("<tr>" + "".join(f"<td>{v}</td>" for v in row) + "</tr>" for row in rows)
    q = td["quantities"]
    qrows = "".join(
        f"<tr><td>{html.escape(name)}</td><td>{html.escape(e['what'])}</td><td>{html.escape(e['unit'])}</td>"
        f"<td>{e['n']}</td><td>{_f(e.get('mean'), '.4g')}</td><td>{_f(e.get('sd'), '.3g')}</td>"
        f"<td>{_f(e.get('p1'), '.4g')}</td><td>{_f(e.get('p50'), '.4g')}</td><td>{_f(e.get('p99'), '.4g')}</td>"
        f"<td>{_f(e.get('min'), '.4g')}</td><td>{_f(e.get('max'), '.4g')}</td></tr>"
        for name, e in q.items()
    )
    return (
        f"<h2>Touchdown ({td['landings']} landings of {td['runs']} runs; verdict {html.escape(td['verdict'])})</h2>"
        "<table><tr><th>quantity</th><th>what</th><th>unit</th><th>n</th><th>mean</th><th>sd</th><th>1%</th>"
        f"<th>50%</th><th>99%</th><th>min</th><th>max</th></tr>{qrows}</table>"
        f"<table><tr>{head}</tr>{body}</table><ul>{''.join(notes)}</ul>"
        "<p>Failed runs count as exceedances of every criterion. Bounds are one-sided at the campaign confidence "
        f"({td['confidence']:g}); the normal ones are exact for normal data and extrapolate far beyond what the runs "
        "map out (about their 1/N quantile). Marks: V read in the standard, S secondary source, U not found; only a "
        "V limit gives a meets / fails verdict (docs/touchdown.md).</p>"
    )
