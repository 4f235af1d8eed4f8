"""Integrity figures of an evaluation campaign with integrity on (details.json `integrity`,
campaign.integrity_campaign):

* integrity_stanford.png: Stanford diagram per category (columns) and axis (rows: vertical, lateral) over
  every run's filter epochs: |error| of the protected output against its solution-separation protection level,
  log colour scale of epochs per cell, the diagonal, the alert limit at the decision height, the four regions
  labelled (normal, MI, HMI, unavailable) with their epoch counts;
* integrity_availability.png: fraction of runs whose protection levels are inside the category's alert limits
  (both axes) against distance to the threshold;
* integrity_tta.png (faults injected): time to alert (detection minus the first epoch at which the
  unprotected error exceeded its protection level) and detection delay after the fault onset, per category,
  with the category's time-to-alert requirement.

Object API only (Figure, no pyplot state).
"""

from __future__ import annotations

import numpy as np
from matplotlib.colors import LogNorm
from matplotlib.figure import Figure
from matplotlib.ticker import LogLocator, NullFormatter

from approachsim import units
from approachsim.campaign.result import RunResult
from approachsim.evaluate.limits import CATEGORIES
from approachsim.evaluate.score import CATEGORY_KEYS

COLORS = {"CAT I": "tab:green", "CAT II": "tab:orange", "CAT III": "tab:red"}
AXES = (("vertical", "vertical"), ("lateral", "lateral"))
LINES = {"CAT I": "-", "CAT II": "--", "CAT III": ":"}


def _hist(cells: list[list[int]], nb: int) -> np.ndarray:
    h = np.zeros((nb, nb))
    for i, j, c in cells:
        h[i, j] = c
    return h


def fig_integrity_stanford(det: dict) -> Figure:
    """Stanford diagrams per category and axis from the campaign histograms (module docstring)."""
    integ = det["integrity"]
    edges = np.asarray(integ["stanford_edges_m"])
    nb = edges.size - 1
    cats = [c for c in CATEGORIES if c in integ["categories"]]
    # a fixed layout, not constrained_layout: its two passes over the 12 log axes' tick labels were half of this
    # figure's rendering, the longest of a report (1.2 -> 0.6 s of CPU); margins in inches, as the labels need
    w, h = 4.6 * max(len(cats), 1), 8.4
    fig = Figure(figsize=(w, h))
    right = 1.0 - 1.25 / w  # room for the colour bar and its label
    axes = np.atleast_2d(fig.subplots(2, len(cats), squeeze=False, gridspec_kw={
        "left": 0.75 / w, "right": right, "bottom": 0.6 / h, "top": 1.0 - 0.75 / h, "wspace": 0.9 / 4.6 * 1.5,
        "hspace": 1.2 / (h / 2)}))
    vmax = max([1.0] + [max((c for *_, c in integ["categories"][k]["stanford_hist"][a]), default=1)
                        for k in cats for a, _ in AXES])
    norm = LogNorm(vmin=1, vmax=vmax)
    mesh = None
    for col, cat in enumerate(cats):
        e = integ["categories"][cat]
        req = e["requirement"]
        for row, (axis, label) in enumerate(AXES):
            ax = axes[row, col]
            h = _hist(e["stanford_hist"][axis], nb)
            # x: protection level, y: |error| (the usual orientation: PL along x, error up)
            mesh = ax.pcolormesh(edges, edges, np.where(h > 0, h, np.nan), norm=norm, cmap="viridis", shading="flat")
            al = req["val_at_dh_m"] if axis == "vertical" else req["lal_at_dh_m"]
            lo, hi = edges[0], edges[-1]
            ax.plot([lo, hi], [lo, hi], color="k", lw=1)
            ax.axvline(al, color="tab:red", lw=1.5)
            ax.axhline(al, color="tab:red", lw=1.0, ls="--")
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.set_xlim(lo, hi)
            ax.set_ylim(lo, hi)
            for a in (ax.xaxis, ax.yaxis):  # minor ticks at 2 and 5 per decade, unlabelled: the default's 8 per
                a.set_minor_locator(LogLocator(subs=(2.0, 5.0)))  # decade on 12 log axes were most of the report's
                a.set_minor_formatter(NullFormatter())  # rendering time (2.2 -> 1.2 s of CPU for this figure)
            cnt = e["stanford"][axis]
            kw = {"fontsize": 8, "ha": "center", "va": "center",
                  "bbox": {"boxstyle": "round", "fc": "white", "alpha": 0.8, "lw": 0.5}}
            ax.text(al / 4, al / 200, f"normal\n{cnt['normal']}", **kw)
            ax.text(np.sqrt(al * lo) / 3, np.sqrt(al * lo) * 1.5, f"MI\n{cnt['mi']}", **kw)
            ax.text(np.sqrt(al * lo) / 3, np.sqrt(al * hi) * 3, f"HMI\n{cnt['hmi']}", **kw)
            ax.text(np.sqrt(al * hi) * 3, np.sqrt(al * hi) * 3, f"unavailable\n{cnt['unavailable']}", **kw)
            ax.set_xlabel(f"{label} protection level, m")
            ax.set_ylabel(f"{label} |error|, m")
            ax.set_title(f"{cat} {label}: AL {al:g} m at DH (red), {e['epochs']} epochs, {e['runs']} runs",
                         fontsize=9)
    if mesh is not None:
        cax = fig.add_axes((right + 0.25 / w, 0.2, 0.18 / w, 0.6))
        fig.colorbar(mesh, cax=cax, label="epochs per cell (log)")
    fig.suptitle("Stanford diagrams: solution-separation protection levels at the filter epochs", fontsize=11)
    return fig


def _stack(results: list[RunResult], name: str) -> np.ndarray:
    rows = [np.asarray(r.arrays[name], float) for r in results if r.ok and name in r.arrays]
    return np.array(rows) if rows else np.empty((0, 0))


def fig_integrity_availability(results: list[RunResult]) -> Figure:
    """Fraction of runs available (PL < AL on both axes) against distance to the threshold, per category."""
    fig = Figure(figsize=(10, 4.8), constrained_layout=True)
    ax = fig.subplots()
    dist = _stack(results, "int_distance_m")
    for cat in CATEGORIES:
        m = _stack(results, f"{CATEGORY_KEYS[cat]}_int_margin_m")
        if not m.size or not dist.size:
            continue
        ok = np.isfinite(m)
        n = ok.sum(axis=0)
        frac = np.where(n > 0, np.sum(ok & (m > 0), axis=0) / np.maximum(n, 1), np.nan)
        has = ok.any(axis=0)
        d_nmi = np.full(m.shape[1], np.nan)
        d_nmi[has] = np.nanmedian(np.where(ok, dist, np.nan)[:, has], axis=0) / units.NMI
        ax.plot(d_nmi, frac, color=COLORS[cat], lw=3 - CATEGORIES.index(cat), ls=LINES[cat], label=f"{cat}")
    ax.set_xlabel("distance to the threshold, nmi (aircraft flies right to left)")
    ax.set_ylabel("availability (fraction of runs, PL < AL)")
    ax.set_ylim(-0.03, 1.03)
    ax.invert_xaxis()
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title(f"Availability against distance, {dist.shape[0]} runs (each category down to its DH)", fontsize=10)
    return fig


def fig_integrity_tta(results: list[RunResult], det: dict) -> Figure | None:
    """Time-to-alert and detection-delay histograms per category (faults injected), else None."""
    cats = [c for c in CATEGORIES if (det["integrity"]["categories"].get(c) or {}).get("time_to_alert")]
    if not cats:
        return None
    fig = Figure(figsize=(10, 6.5), constrained_layout=True)
    axes = fig.subplots(2, 1)
    ok = [r for r in results if r.ok]

    def values(key: str) -> np.ndarray:
        return np.array([r.scalars.get(key, np.nan) for r in ok])

    bins = {}
    for ax_i, name in ((0, "tta_s"), (1, "delay_s")):
        allv = np.concatenate([values(f"{CATEGORY_KEYS[c]}_int_{name}") for c in cats])
        allv = allv[np.isfinite(allv)]
        lo, hi = (float(allv.min()), float(allv.max())) if allv.size else (0.0, 1.0)
        bins[ax_i] = np.linspace(np.floor(lo) - 0.5, np.ceil(hi) + 0.5, int(min(60, np.ceil(hi) - np.floor(lo) + 2)))
    for cat in cats:
        key = CATEGORY_KEYS[cat]
        tta = np.array([r.scalars.get(f"{key}_int_tta_s", np.nan) for r in ok])
        delay = np.array([r.scalars.get(f"{key}_int_delay_s", np.nan) for r in ok])
        t_req = det["integrity"]["categories"][cat]["time_to_alert"]["tta_required_s"]
        for i, (ax, x) in enumerate(((axes[0], tta), (axes[1], delay))):
            fin = x[np.isfinite(x)]
            if fin.size:
                ax.hist(fin, bins=bins[i], histtype="step", lw=3 - CATEGORIES.index(cat), ls=LINES[cat],
                        color=COLORS[cat], label=f"{cat} ({fin.size} runs)")
        axes[0].axvline(t_req, color=COLORS[cat], ls="--", lw=1)
        missed = int(np.sum(tta == np.inf))
        if missed:
            axes[0].plot([], [], " ", label=f"{cat}: {missed} missed detections")
    axes[0].set_xlabel("time to alert, s (detection - first epoch the unprotected error exceeded its PL; "
                       "< 0: detected before; dashed: requirement)")
    axes[1].set_xlabel("detection delay after the fault onset, s")
    for ax in axes:
        ax.set_ylabel("runs")
        ax.grid(True, alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle("Time to alert of the injected fault (solution-separation bank)", fontsize=11)
    return fig


CAPTIONS = {
    "integrity_stanford": (
        "Stanford diagrams (integrity)",
        "For each category (columns) and for the vertical and lateral axes of the approach (rows), every filter "
        "epoch of every run from the filter's settling down to the category's decision height: the protected "
        "output's |error| against its solution-separation protection level (the larger of the fault-free and "
        "single-fault levels, K factors from the category's integrity risk), in m. Colour: epochs per cell, log "
        "scale. Red: the alert limit at the decision height (solid: PL = AL, dashed: error = AL); CAT I's limits "
        "grow with distance (ICAO Annex 10 Tables B-68 / B-69), and the region counts use the limit at each "
        "epoch's position. Below the diagonal (error < PL) and left of the solid AL line is normal; above it the "
        "PL did not bound the error (MI), and above the dashed AL line while available it is hazardous (HMI); "
        "right of the solid line the approach is unavailable.",
    ),
    "integrity_availability": (
        "Availability against distance",
        "Fraction of the runs whose vertical and lateral protection levels are both inside the category's alert "
        "limits, against distance to the threshold (right to left as flown), down to each category's decision "
        "height. The verdict uses the value at the decision height.",
    ),
    "integrity_tta": (
        "Time to alert",
        "Top: per run, the detection time minus the first epoch at which the unprotected main solution's error "
        "exceeded its protection level (runs where it did; negative: detected before the error was unprotected); "
        "dashed: the category's time-to-alert requirement (CAT I 6 s, CAT II / III 2 s). Bottom: the delay from "
        "the fault onset to the detection.",
    ),
}
"""Heading and caption of each integrity figure."""


def integrity_figures(results: list[RunResult], det: dict) -> dict[str, Figure]:
    """The integrity figures of a campaign with integrity on (empty when details carry no `integrity`)."""
    if "integrity" not in det:
        return {}
    out = {"integrity_stanford": fig_integrity_stanford(det),
           "integrity_availability": fig_integrity_availability(results)}
    tta = fig_integrity_tta(results, det)
    if tta is not None:
        out["integrity_tta"] = tta
    return out


def integrity_rows(det: dict) -> list[list]:
    """Report table rows: per category availability (epochs, at DH, bounds), MI, HMI, false alerts, TTA."""
    rows = []
    for cat, e in det.get("integrity", {}).get("categories", {}).items():
        fa = e.get("false_alert") or {}
        tt = e.get("time_to_alert") or {}
        rows.append([cat, "yes" if e["in_verdict"] else "no", e.get("verdict", "--"), e["availability"]["fraction"],
                     e["availability_dh"]["fraction"], e["availability_dh"]["lower"], e["requirement"]["availability"],
                     e["mi"]["count"], e["hmi"]["count"], e["hmi"]["rate_per_epoch_upper"],
                     fa.get("rate_per_15s_upper", "--"), tt.get("fraction_within_tta", "--"),
                     tt.get("missed_detections", "--")])
    return rows


INTEGRITY_HEADER = ["category", "in verdict", "integrity verdict", "availability (epochs)", "availability at DH",
                    "lower bound", "required", "MI epochs", "HMI epochs", "HMI rate upper", "false alerts / 15 s upper",
                    "TTA met (fraction)", "missed detections"]
