"""The note of the Gray & Maybeck reproduction: Tables 3-8 ours beside the paper's, every reason from numbers.

Gray & Maybeck, *An integrated GPS/INS/Baro and radar altimeter system for aircraft precision approach landings*.
note(result, figures) writes the markdown of papers/gray_maybeck.compute's result (the faithful variant or the
closed-loop study, and the sensitivity table when it was run); headline(result) the printed summary. Every
sentence of a reason is built from computed numbers (ours, the paper's printed ones, or the stated model
values); mechanisms are not asserted, the sensitivity table measures them.

The rule "reproduces" of Tables 3-6 (RULE): a row reproduces when its direction does (our 95 % interval of the
% change excludes 0 on the paper's side) and the paper's % change lies inside the central 95 % of our % change
computed from PAPER_RUNS runs drawn from ours (the spread a Monte Carlo of the paper's size would show if our
model were the truth); "direction only" when only the first holds. The two levels of a row are judged for
magnitude by the same range.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from approachsim import units
from approachsim.papers.claims import reproduces
from approachsim.papers.gray_maybeck import PAPER_RUNS, STATES, TITLE
from approachsim.papers.gray_maybeck_sensitivity import METRICS

CAT2_LATERAL_FT = 8.6
"""FAA CAT II lateral 1-sigma limit (Table 1)."""

RULE = (f"**Rule.** A row of Tables 3-6 *reproduces* when (1) its direction does: our 95 % paired bootstrap "
        f"interval of the % change lies entirely on the paper's side of 0, and (2) its magnitude does: the paper's "
        f"% change lies inside the central 95 % of our % change computed from {PAPER_RUNS} runs drawn from ours "
        f"(the paper's Monte Carlo size, assumption 10: the spread its table would show if our model were the "
        f"truth). *Direction only*: (1) without (2). *Magnitude only*: (2) without (1). Each level (ft) is judged "
        f"for magnitude by the same {PAPER_RUNS}-run range (yes / no after the value). **Strict rule** (issue 43, "
        f"column *strict*): both levels within x1.5 of the paper's and the % change with the paper's sign and within "
        f"x1.5 of it (within 5 points where the paper's |%| < 10); a row that passes only the direction test is "
        f"*direction*, not a reproduction.")


def _ci(ci: Sequence[float] | None, fmt: str = ".1f") -> str:
    return "" if ci is None else f" [{ci[0]:{fmt}}, {ci[1]:{fmt}}]"


def _state_word(s: str) -> str:
    return s.replace("_", " ").capitalize()


def _yn(flag: bool) -> str:
    return "yes" if flag else "no"


def _radalt_ft(h_ft: float) -> float:
    """The radar altimeter's 1-sigma (ft) at h_ft AGL: sqrt((0.01 h)^2 + 0.25 m^2)."""
    h = h_ft * units.FT
    return math.sqrt((0.01 * h) ** 2 + 0.25) / units.FT


def _difference_reason(state: str, group: Sequence[str], result: dict) -> str:
    """Numbers beside our averaged error of `state` over the cases `group` and the paper's: what our GPS budget,
    radar altimeter and pseudolite geometry give, and failed runs; only computed values."""
    c0 = result["cases"][group[0]]
    g = c0["gps_implied"]
    if "hdop" not in g:
        return ""
    has_ra, has_pl = c0["radalt"], c0["pseudolite"]
    if state in ("latitude", "longitude"):
        out = (f"our GPS budget gives {g['per_axis_horizontal_ft']:.1f} ft per horizontal axis (zenith UERE "
               f"{g['uere_zenith_m']:.2f} m x HDOP {g['hdop']:.2f} / sqrt 2; the paper's 4 m / sqrt 2 = "
               f"{g['paper_per_axis_horizontal_ft']:.1f} ft)")
        if has_pl:
            geo_pl = c0.get("pseudolite_geometry") or []
            shares = ", ".join(f"{x['cross_share']:.2f} at {x['height_ft']:g} ft" for x in geo_pl)
            out += f"; the cross-track share of the pseudolite's line of sight is {shares}"
        return out + _failed(group, result)
    if state == "altitude":
        out = (f"our GPS budget gives {g['vertical_ft']:.1f} ft vertical (UERE {g['uere_zenith_m']:.2f} m x VDOP "
               f"{g['vdop']:.2f}; the paper's 5 m = {g['paper_vertical_ft']:.1f} ft)")
        if has_ra:
            dh = [result["cases"][k]["tables_7_8"]["categories"]["CAT I"]["vertical_1sigma_ft"] for k in group]
            dh_s = ", ".join("--" if v is None else f"{v:.2f}" for v in dh)
            out += (f"; the radar altimeter's 1-sigma is {_radalt_ft(200.0):.2f} ft at 200 ft, "
                    f"{_radalt_ft(1000.0):.1f} ft at 1000 ft and {_radalt_ft(3000.0):.1f} ft at 3000 ft AGL; our "
                    f"vertical RMS at the CAT I decision height is {dh_s} ft")
        return out + _failed(group, result)
    out = f"our zenith UERE is {g['uere_zenith_m']:.2f} m = {g['uere_zenith_m'] / units.FT:.1f} ft"
    if c0.get("outage_s"):
        out += (f"; over the {c0['outage_s']:.0f} s outage our {c0.get('oscillator', '')} clock-bias process noise "
                f"is {c0['clock_q_outage_sigma_ft']:.1f} ft 1-sigma")
    return out + _failed(group, result)


def _failed(group: Sequence[str], result: dict) -> str:
    failed = [result["cases"][k]["failed_runs"] for k in group]
    if not any(failed):
        return ""
    runs = result["cases"][group[0]]["runs"]
    return (f"; {', '.join(str(n) for n in failed)} of {runs} runs of these cases failed and are not in their "
            "per-case figures (the table uses the runs every case of it completed)")


def _strict_word(st: dict | None) -> str:
    """The strict rule's cell: reproduces, or which of level a, level b, % change miss."""
    if st is None:
        return ""
    if st["reproduces"]:
        return "reproduces"
    miss = [k for k, w in (("a", "level a"), ("b", "level b"), ("pct", "% change")) if not st[k]]
    return "no (" + ", ".join(w for k, w in (("a", "level a"), ("b", "level b"), ("pct", "% change"))
                              if k in miss) + ")"


def _table_section(tid: str, t: dict, result: dict) -> list[str]:
    o, p = t["ours"], t["paper"]
    a, b = "-".join(t["a_cases"]), "-".join(t["b_cases"])
    failed = ", ".join(f"{k} {v}" for k, v in t.get("failed_per_case", {}).items())
    lines = ["", f"## Table {tid}: {t['title']}", "",
             f"Ours over the {o['runs']} runs that completed in every case of the table (common random numbers: the "
             f"same run index in each case); failed runs per case: {failed or 'not recorded'}. Brackets: 95 % "
             f"bootstrap interval; braces: the central 95 % of the same number from {o.get('paper_runs', PAPER_RUNS)}"
             "-run draws (the magnitude rule).", "",
             f"| error state | paper {a} (ft) | ours {a} (ft) | paper {b} (ft) | ours {b} (ft) | paper % change "
             "| ours % change | direction | verdict | strict |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    rng_a = o.get("a_range_paper_runs_ft")
    rng_b = o.get("b_range_paper_runs_ft")
    rng_p = o.get("pct_range_paper_runs")
    for j, s in enumerate(STATES):
        cl = t["claims"][j]
        mag = cl.get("magnitude", {})

        def br(r: Sequence | None, j: int = j) -> str:
            return "" if r is None else f" {{{r[j][0]:.1f}, {r[j][1]:.1f}}}"
        aci = o["a_ci_ft"][j] if o["a_ci_ft"] else None
        bci = o["b_ci_ft"][j] if o["b_ci_ft"] else None
        pci = o["pct_ci"][j] if o["pct_ci"] else None
        lines.append(
            f"| {_state_word(s)} | {p['a_ft'][j]:.1f} | {o['a_ft'][j]:.2f}{_ci(aci)}"
            f"{br(rng_a)}: {_yn(mag.get('a', False))} | {p['b_ft'][j]:.1f} | "
            f"{o['b_ft'][j]:.2f}{_ci(bci)}{br(rng_b)}: {_yn(mag.get('b', False))} "
            f"| {cl['paper_pct_signed']:+.1f} % | {o['pct'][j]:+.1f} %{_ci(pci)}"
            f"{br(rng_p)}: {_yn(mag.get('pct', False))} | paper {cl['paper_direction']}, ours {cl['our_direction']}: "
            f"{reproduces(cl['direction_reproduces'])} | {cl.get('verdict', '')} | {_strict_word(cl.get('strict'))} |")
    lines += ["", f"Numbers beside each row (Table {tid}):", ""]
    for j, s in enumerate(STATES):
        for grp, pv, ov in ((t["a_cases"], p["a_ft"][j], o["a_ft"][j]), (t["b_cases"], p["b_ft"][j], o["b_ft"][j])):
            why = _difference_reason(s, grp, result)
            lines.append(f"- {_state_word(s)}, cases {'-'.join(grp)}: ours {ov:.2f} ft vs paper {pv:.1f} ft "
                         f"(ratio {ov / pv:.2f}){'; ' + why if why else ''}.")
    return lines


def _variant_intro(result: dict) -> list[str]:
    runs = result["runs_per_case"]
    if result.get("variant", "closed") == "closed":
        what = ("Our closed-loop study (`--closed`): the autopilot flies on the navigation solution, the NRC 1995 GPS "
                "budget, R = the range errors' full variance; a finding of ours, not the paper's setup.")
    else:
        what = ("The faithful variant (the default): open loop on one flown truth (the paper's PROFGEN -> MSOFE "
                "chain), the paper's 4 m / 5 m GPS, R tuned by one stated rule, the initial errors of an 8 min "
                "alignment and 60 min of flight per INS grade, short outages.")
    return [f"# Reproduction: {TITLE}", "", what, "",
            f"{runs} runs per case (the paper: 15), campaign seed {result['seed']} common to every case (common random "
            "numbers). Time-averaged RMS: sqrt of the mean over runs of each run's time average of the squared true "
            "error (estimate - truth), from 10 s after the run start; a group of cases is the mean of their RMS, as "
            "the paper averages its three INS grades; % change = (a - b) / a x 100 as the paper computes it "
            "(Table 6 prints |.|). Every comparison of groups uses the runs that completed in all its cases.", "",
            RULE, ""]


def _overrides_section(result: dict) -> list[str]:
    cs = [c for c in result["cases"].values() if c.get("overrides")]
    if not cs:
        return []
    keys = list(cs[0]["overrides"])
    lines = ["", "The faithful variant's computed values per case (papers/gray_maybeck_faithful.py; the initial errors "
             "per INS grade from our free-inertial propagation):", "",
             "| case | " + " | ".join(f"`{k}`" for k in keys) + " |", "|---" * (len(keys) + 1) + "|"]
    for c in cs:
        lines.append(f"| {c['case']} | " + " | ".join(str(c["overrides"].get(k)) for k in keys) + " |")
    return lines


def note(result: dict, figures: Sequence[str]) -> str:
    """The reproduction note (markdown): the cases, Tables 3-8 ours beside the paper, findings from numbers."""
    runs = result["runs_per_case"]
    lines = _variant_intro(result)
    cc = result.get("cell_counts")
    if cc:
        v = cc["verdicts"]
        lines += [f"**Tables 3-6 in short.** {cc['magnitude_cells']} of {cc['cells']} numeric cells (two levels and "
                  f"the % change per row) have the paper's value inside our {PAPER_RUNS}-run range; "
                  f"{cc['direction_rows']} of {cc['rows']} rows reproduce the direction; rows: "
                  + ", ".join(f"{n} {k}" for k, n in sorted(v.items())) + "."
                  + (f" Strict rule: {cc['strict_rows']} of {cc['rows']} rows reproduce, {cc['strict_cells']} of "
                     f"{cc['cells']} cells within it." if "strict_rows" in cc else ""), ""]
    lines += ["## Assumptions and gap fills", ""] + [f"- {a}" for a in result["assumptions"]]
    lines += _overrides_section(result) + [""]
    lines += ["## The cases (Table 2) and the truth / filter split", "",
              "The paper: a 69-state truth (39 INS, 30 GPS) against a 13-state filter (11 INS, 2 GPS clock). Ours: "
              "the sensor models' time-correlated error processes (counted below; white noises are not states) "
              "against our error-state EKF's states.", "",
              "| case | INS | radar alt. | pseudolite | GPS outages (s) | truth states | filter states | failed runs |",
              "|---|---|---|---|---|---|---|---|"]
    for c in result["cases"].values():
        ts, fs = c["truth_states"], c["filter_states"]
        tdet = ", ".join(f"{k} {v}" for k, v in ts.items() if k != "total" and v)
        fdet = ", ".join(f"{k} {v}" for k, v in fs.items() if k != "total")
        outs = "; ".join(f"{a:g}-{b:g}" for a, b in c["gps_outages"]) or "none"
        lines.append(f"| {c['case']} | {c['grade']} | {'yes' if c['radalt'] else 'no'} | "
                     f"{'yes' if c['pseudolite'] else 'no'} | {outs} | {ts['total']} ({tdet}) | {fs['total']} "
                     f"({fdet}) | {c['failed_runs']} |")
    g = next(iter(result["cases"].values()))["gps_implied"]
    if "hdop" in g:
        lines += ["", f"GPS mapping: the paper's receiver is 4 m horizontal / 5 m vertical 1 sigma. Ours has a zenith "
                  f"UERE of {g['uere_zenith_m']:.2f} m; the four used have PDOP {g['pdop']:.2f}, HDOP {g['hdop']:.2f}, "
                  f"VDOP {g['vdop']:.2f} at the CAT I decision height, so ours is {g['horizontal_m']:.1f} m horizontal "
                  f"/ {g['vertical_m']:.1f} m vertical ({g['horizontal_m'] / 4.0:.2f} and "
                  f"{g['vertical_m'] / 5.0:.2f} x the paper's)."]
    lines += ["", "Per case, time-averaged RMS (ft) over the runs that completed (failed runs count against every "
              "category in Tables 7-8):", "",
              "| case | latitude | longitude | altitude | clock bias |", "|---|---|---|---|---|"]
    for c in result["cases"].values():
        ta = c["time_averaged_rms_ft"]
        lines.append(f"| {c['case']} | " + " | ".join("--" if ta[s] is None else f"{ta[s]:.2f}" for s in STATES)
                     + " |")
    for tid, t in result["tables"].items():
        lines += _table_section(tid, t, result)
    lines += _tables_7_8(result, runs)
    if result.get("sensitivity"):
        lines += sensitivity_section(result)
    if figures:
        lines += ["", "## Figures", ""] + [f"![{f}]({f})" for f in figures]
    lines += ["", "Pinned profile values (every case; `approachsim reproduce gray-maybeck` sets them on the shipped "
              "gray-maybeck profile):", ""]
    lines += [f"- `{k}` = {v!r}" for k, v in result["pinned"].items()]
    return "\n".join(lines) + "\n"


def _tables_7_8(result: dict, runs: int) -> list[str]:
    lines = ["", "## Tables 7-8: precision approach categories met (FAA Table 1, 1 sigma at decision height)", "",
             "Verdicts on the one-sided 95 % bounds of the RMS over runs (meets: upper bound inside the limit; "
             "fails: lower bound outside; else indeterminate).", "",
             "| case | paper (Table 7/8) | ours: best met | CAT I lat / vert (upper) ft, verdict | "
             "CAT II lat / vert (upper), verdict | CAT III lat / vert (upper), verdict | Tables 7-8 |",
             "|---|---|---|---|---|---|---|"]

    def f(x: float | None) -> str:
        return "--" if x is None else f"{x:.2f}"
    for c in result["cases"].values():
        v = c["tables_7_8"]
        cells = []
        for cat in ("CAT I", "CAT II", "CAT III"):
            e = v["categories"][cat]
            cells.append(f"{f(e['lateral_1sigma_ft'])} / {f(e['vertical_1sigma_ft'])} "
                         f"({f(e['lateral_1sigma_upper_ft'])} / {f(e['vertical_1sigma_upper_ft'])}), {e['verdict']}")
        cl = c["claim"]
        lines.append(f"| {c['case']} | {cl['paper_best'] or 'none'} | {v['best'] or 'none'} | "
                     + " | ".join(cells) + f" | {cl['status']} |")
    pat = result["pattern"]
    lines += ["", f"Verdict pattern: {pat['reproduces']} of {pat['cases']} cases reproduce Tables 7-8, "
              f"{pat['differs']} differ ({', '.join(pat['differing_cases']) or 'none'}), {pat['indeterminate']} are "
              f"indeterminate at {runs} runs."]
    diff = [c for c in result["cases"].values() if c["claim"]["status"] != "reproduces"]
    if diff:
        lines += ["", "Numbers of each case that does not reproduce:", ""]
        for c in diff:
            lines.append("- " + _category_reason(c, result))
    return lines


def _category_reason(c: dict, result: dict) -> str:
    """The numbers of a case whose verdicts differ from (or do not yet decide) Tables 7-8."""
    cl, v = c["claim"], c["tables_7_8"]["categories"]
    parts = []
    for cat in ("CAT I", "CAT II", "CAT III"):
        e = v[cat]
        lat, ver = e["lateral_1sigma_ft"], e["vertical_1sigma_ft"]
        if lat is None or ver is None:
            parts.append(f"{cat}: no scored runs")
            continue
        lat_up = e["lateral_1sigma_upper_ft"] or float("nan")
        ver_up = e["vertical_1sigma_upper_ft"] or float("nan")
        parts.append(f"{cat} {e['verdict']} (lateral {lat:.2f} ft, upper {lat_up:.2f}, "
                     f"limit {e['limit_lateral_1sigma_ft']:g}; vertical {ver:.2f} ft, upper "
                     f"{ver_up:.2f}, limit {e['limit_vertical_1sigma_ft']:g}"
                     + (f"; ~{e['runs_needed']} runs to decide" if e["runs_needed"] else "") + ")")
    fails = ""
    if c["failed_runs"]:
        why = ", ".join(f"{n} {k}" for k, n in c.get("failure_reasons", {}).items())
        fails = f"; {c['failed_runs']} of {c['runs']} runs failed ({why}), each counted against every category"
    g = c["gps_implied"]
    lateral = ""
    if "hdop" in g:
        pa = g["per_axis_horizontal_ft"]
        ppa = g["paper_per_axis_horizontal_ft"]
        lateral = (f"; our GPS budget gives {pa:.1f} ft per horizontal axis, {_cmp(pa, CAT2_LATERAL_FT)} the CAT II "
                   f"{CAT2_LATERAL_FT:g} ft; the paper's 4 m horizontal gives {ppa:.1f} ft, "
                   f"{_cmp(ppa, CAT2_LATERAL_FT)} it")
        geo_pl = c.get("pseudolite_geometry")
        if geo_pl:
            shares = ", ".join(f"{x['cross_share']:.2f} at {x['height_ft']:g} ft" for x in geo_pl)
            lateral += f"; the cross-track share of the pseudolite's line of sight is {shares}"
    sens = result.get("sensitivity")
    if sens and c["case"] == "XI" and sens.get("table"):
        lateral += "; " + _cat2_sensitivity_words(sens)
    return (f"case {c['case']} (paper: {cl['paper_best'] or 'none'}; ours: {cl['our_best'] or 'none'}, "
            f"{cl['status']}): " + "; ".join(parts) + fails + lateral + ".")


def _cmp(x: float, y: float) -> str:
    return "above" if x > y else "below" if x < y else "equal to"


def _cat2_sensitivity_words(sens: dict) -> str:
    """The sensitivity rows that lower X-XII's CAT II lateral most, and whether any reaches the limit."""
    tab = sens["table"]
    base = tab["faithful"]["value"]["cat2_lat_ft"]
    rows = [(k, r["value"]["cat2_lat_ft"], r["diff_ci"]["cat2_lat_ft"]) for k, r in tab.items() if k != "faithful"]
    best = min(rows, key=lambda x: x[1])
    under = [k for k, v, _ in rows if v < CAT2_LATERAL_FT]
    return (f"sensitivity ({sens['common_runs']} runs): XI's CAT II lateral {base:.2f} ft in the faithful variant, "
            f"lowest with {best[0]} ({best[1]:.2f} ft, {best[1] - base:+.2f} [{best[2][0]:+.2f}, {best[2][1]:+.2f}]); "
            + (f"under {CAT2_LATERAL_FT:g} ft with {', '.join(under)}" if under else
               f"no row brings it under {CAT2_LATERAL_FT:g} ft"))


def sensitivity_section(result: dict) -> list[str]:
    """The sensitivity table (papers/gray_maybeck_sensitivity.py) and its computed findings."""
    sens = result["sensitivity"]
    tab = sens.get("table") or {}
    if not tab:
        return ["", "## Sensitivity of the gap fills", "", "No run completed in every case of the table."]
    keys = list(METRICS)
    lines = ["", "## Sensitivity of the gap fills", "",
             f"Each row is the faithful variant with one gap fill changed, {sens['runs']} runs per case at the same "
             f"seed (paired: run i of every row draws the same noise); {sens['common_runs']} runs completed in every "
             "case of every row. Cell: the row's value, then its difference from the faithful variant with the 95 % "
             "paired bootstrap interval. Cases a row does not change are the faithful runs themselves. One INS grade "
             "per group (2.0 nmi/h: III, VIII, IV, XI) and VI / XVI.", "",
             "| row | cases run | " + " | ".join(METRICS[k]["label"] for k in keys) + " | XI CAT II verdict |",
             "|---|---|" + "---|" * len(keys) + "---|"]
    fv = tab["faithful"]
    paper = " | ".join("--" if METRICS[k]["paper"] is None else f"{METRICS[k]['paper']:.1f}" for k in keys)
    lines.append(f"| the paper | -- | {paper} | CAT II met |")
    lines.append("| faithful | all | " + " | ".join(f"{fv['value'][k]:.2f}{_ci(fv['ci'][k])}" for k in keys)
                 + f" | {_cat2_verdicts(sens, 'faithful')} |")
    labels = {r["key"]: r for r in sens["rows"]}
    for k, r in tab.items():
        if k == "faithful":
            continue
        cells = [f"{r['value'][m]:.2f} ({r['diff'][m]:+.2f}{_ci(r['diff_ci'][m], '+.2f')})" for m in keys]
        lines.append(f"| {k}: {labels[k]['label']} | {', '.join(labels[k]['cases'])} | " + " | ".join(cells)
                     + f" | {_cat2_verdicts(sens, k)} |")
    lines += ["", "Findings (computed from the table):", ""] + [f"- {s}" for s in sensitivity_findings(sens)]
    return lines


def _cat2_verdicts(sens: dict, key: str) -> str:
    v = sens["verdicts"].get(key, {})
    base = sens["verdicts"].get("faithful", {})
    return str(v.get("XI", base.get("XI", "--")))


def _significant(ci: Sequence[float]) -> bool:
    return ci[0] > 0 or ci[1] < 0


def sensitivity_findings(sens: dict) -> list[str]:
    """Sentences from the sensitivity numbers: what moves X-XII across the CAT II line, what moves the pseudolite's
    cut toward the paper's, and what the paper's numbers would need."""
    tab = sens["table"]
    fv = tab["faithful"]["value"]
    rows = {k: r for k, r in tab.items() if k != "faithful"}
    out = []
    base = fv["cat2_lat_ft"]
    under = [k for k, r in rows.items() if r["value"]["cat2_lat_ft"] < CAT2_LATERAL_FT]
    best = min(rows, key=lambda k: rows[k]["value"]["cat2_lat_ft"])
    b = rows[best]
    out.append(f"Case XI's CAT II lateral (X-XII flown as XI): faithful {base:.2f} ft against the "
               f"{CAT2_LATERAL_FT:g} ft limit; the lowest row is {best} at {b['value']['cat2_lat_ft']:.2f} ft "
               f"({b['diff']['cat2_lat_ft']:+.2f} ft "
               f"{_ci(b['diff_ci']['cat2_lat_ft'], '+.2f')}); "
               + (f"rows under the limit: {', '.join(under)}." if under else "no row brings it under the limit."))
    if not under:
        need = CAT2_LATERAL_FT / b["value"]["cat2_lat_ft"]
        out.append(f"To meet CAT II the lateral 1-sigma at 100 ft must fall by the factor {need:.2f} from the best "
                   f"row's ({b['value']['cat2_lat_ft']:.2f} -> {CAT2_LATERAL_FT:g} ft), before the interval margin of "
                   "the verdict.")
        uf, un = sens.get("faithful_uere_m"), sens.get("nrc_uere_m")
        if "gps-nrc" in rows and uf and un and un != uf:
            ln = rows["gps-nrc"]["value"]["cat2_lat_ft"]
            slope = math.log(ln / base) / math.log(un / uf)
            out.append(f"Measured scaling with the GPS budget: the NRC budget (UERE {un:.2f} m against the faithful "
                       f"{uf:.2f} m) gives a CAT II lateral of {ln:.2f} ft against {base:.2f} ft, an exponent of "
                       f"{slope:.2f} (lateral ~ UERE^{slope:.2f})"
                       + (f"; at that exponent CAT II's {CAT2_LATERAL_FT:g} ft needs a UERE of "
                          f"{uf * (CAT2_LATERAL_FT / base) ** (1.0 / slope):.2f} m, i.e. a GPS of "
                          f"{4.0 * (CAT2_LATERAL_FT / base) ** (1.0 / slope):.1f} m horizontal / "
                          f"{5.0 * (CAT2_LATERAL_FT / base) ** (1.0 / slope):.1f} m vertical instead of the paper's "
                          "stated 4 m / 5 m." if slope > 0.05 else
                          "; the exponent is too small to extrapolate a budget from."))
    cut = fv["t3_hvar_pct"]
    pb = max(rows, key=lambda k: rows[k]["value"]["t3_hvar_pct"])
    r = rows[pb]
    paper_cut = METRICS["t3_hvar_pct"]["paper"]
    out.append(f"The pseudolite's cut of the horizontal error variance (Table 3): faithful {cut:.1f} %, the paper "
               f"{paper_cut:.1f} %; the largest is {pb} at {r['value']['t3_hvar_pct']:.1f} % "
               f"({r['diff']['t3_hvar_pct']:+.1f} points {_ci(r['diff_ci']['t3_hvar_pct'], '+.1f')}); latitude / "
               f"longitude cuts there {r['value']['t3_lat_pct']:.1f} / {r['value']['t3_lon_pct']:.1f} % (the paper "
               "48.3 / 57.6 %).")
    single = {k: r for k, r in rows.items() if k.startswith("pl-") and "two" not in k}
    if single:
        sb = max(single, key=lambda k: single[k]["value"]["t3_hvar_pct"])
        out.append(f"With one pseudolite (the paper's number), the largest cut of the horizontal error variance over "
                   f"the sites tried is {sb} at {single[sb]['value']['t3_hvar_pct']:.1f} % (the paper "
                   f"{paper_cut:.1f} %).")
    for m in ("t4_alt_ft", "t6_alt_pct"):
        moved = [(k, rows[k]["diff"][m], rows[k]["diff_ci"][m]) for k in rows if _significant(rows[k]["diff_ci"][m])]
        lab = METRICS[m]["label"]
        if moved:
            big = max(moved, key=lambda x: abs(x[1]))
            out.append(f"{lab}: faithful {fv[m]:.2f} (the paper {METRICS[m]['paper']:g}); rows whose paired "
                       f"interval excludes 0: " + ", ".join(f"{k} {d:+.2f}" for k, d, _ in moved)
                       + f"; the largest {big[0]} to {rows[big[0]]['value'][m]:.2f}.")
        else:
            out.append(f"{lab}: faithful {fv[m]:.2f} (the paper {METRICS[m]['paper']:g}); no row's paired interval "
                       "excludes 0.")
    return out


def headline(result: dict) -> list[str]:
    """Short printed findings, chosen from the numbers."""
    pat = result["pattern"]
    out = [f"variant: {result.get('variant', 'closed')} ({result.get('mode', 'closed')} loop)",
           f"Tables 7-8: {pat['reproduces']}/{pat['cases']} cases reproduce, {pat['differs']} differ "
           f"({', '.join(pat['differing_cases']) or 'none'}), {pat['indeterminate']} indeterminate"]
    cc = result.get("cell_counts")
    if cc:
        out.append(f"Tables 3-6: {cc['magnitude_cells']}/{cc['cells']} cells in magnitude, {cc['direction_rows']}/"
                   f"{cc['rows']} rows in direction; rows " + ", ".join(f"{n} {k}" for k, n in
                                                                         sorted(cc["verdicts"].items()))
                   + (f"; strict rule {cc['strict_rows']}/{cc['rows']} rows, {cc['strict_cells']}/{cc['cells']} "
                      "cells" if "strict_rows" in cc else ""))
    for tid, t in result["tables"].items():
        o = t["ours"]
        cells = ", ".join(
            f"{_state_word(s).lower()} {o['pct'][j]:+.0f} % (paper {t['claims'][j]['paper_pct_signed']:+.0f})"
            for j, s in enumerate(STATES))
        out.append(f"Table {tid} % change: {cells}")
    return out
