"""The tables of docs/integrity.md "Integrity risk" from integrity_risk.json files (the totals recomputed with
campaign.integrity_risk.totals, so a change of the combination is seen on stored studies).

    PYTHONPATH=. python benchmarks/integrity_risk_tables.py DIR/integrity_risk.json [...]
    PYTHONPATH=. python benchmarks/integrity_risk_tables.py --merge A/integrity_risk.json B/integrity_risk.json

--merge: one study from several runs of the same profile and seed with different --modes (run side by side): the
first file's fault-free term, every file's modes (a mode in two files: the later file's, e.g. a mode rerun after a
fix), the runs and wall times summed (a replaced mode's runs included: they were spent).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

from approachsim.campaign.integrity_risk import totals


def g(x: float | None) -> str:
    return "-" if x is None else f"{x:.2g}"


def merged(paths: list[str]) -> dict:
    """One study from several (module docstring)."""
    studies = [json.loads(Path(p).read_text()) for p in paths]
    out = dict(studies[0])
    out["modes"] = {}
    for st in studies:
        if (st["profile"], st["seed"]) != (out["profile"], out["seed"]):
            raise SystemExit("--merge: the files are not of one profile and seed")
        for k, v in st["modes"].items():
            out["modes"][k] = v
    out["samples"] = sum(st["samples"] for st in studies)
    out["wall_s"] = sum(st["wall_s"] for st in studies)
    return out


def main() -> None:
    args = sys.argv[1:]
    runs = [merged(args[1:])] if args and args[0] == "--merge" else [json.loads(Path(p).read_text()) for p in args]
    for r in runs:
        cats = totals(r, r["confidence"])
        print(f"\n### {r['profile']} (seed {r['seed']}, {r['method']}, {r['samples_per_step']} per step, "
              f"bank sensor modes {r.get('bank_sensor_modes', False)}): {r['samples']} runs, {r['wall_s']:.0f} s\n")
        ff = r["fault_free"]
        print(f"fault-free: {ff['runs']} runs, normalized error RMS v/l/sep "
              f"{g(ff['normalized_error_rms']['vertical'])}/{g(ff['normalized_error_rms']['lateral'])}/"
              f"{g(ff['normalized_error_rms']['separation'])}, upper "
              f"{g(ff['normalized_error_rms_upper']['vertical'])}/{g(ff['normalized_error_rms_upper']['lateral'])}/"
              f"{g(ff['normalized_error_rms_upper']['separation'])}, largest |e|/sigma "
              f"{g(ff['largest_normalized_error'])}\n")
        print("| mode | prior | runs | steps | CAT I P(HMI given fault) [lower, upper] (hits/N) | CAT II | CAT III | "
              "worst profile |")
        print("|---|---|---|---|---|---|---|---|")
        for name, m in r["modes"].items():
            cells = []
            for cat in ("CAT I", "CAT II", "CAT III"):
                c = m["categories"].get(cat, {})
                if c.get("shown"):
                    cells.append(f"{g(c['probability'])} [{g(c['lower'])}, {g(c['upper'])}] ({c['hits']}/"
                                 f"{c['samples']})")
                else:
                    cells.append(f"<= {g(c.get('upper'))} ({c.get('bound', '')})")
            wp = m.get("worst_profile")
            w = "-" if not wp else (f"{wp['magnitude']:.3g} {wp['unit']}, onset {wp['onset_s_before_lowest_dh']:.0f} s "
                                    "before the lowest DH")
            print(f"| {name} | {g(m['prior'])} [{m['prior_mark']}] | {m['samples']} | {m['estimator']['steps']} | "
                  + " | ".join(cells) + f" | {w} |")
        print("\n| category | P(HMI) | lower | upper (worst bin) | sourced upper | allocation | verdict (sourced "
              "priors, specific risk) | with assumed priors | average upper | average verdict | P(FA)/15 s (Gaussian, "
              "overbound) | P(FA)/15 s MC upper | FA verdict |")
        print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
        for cat, c in cats.items():
            print(f"| {cat} | {g(c['p_hmi'])} | {g(c['p_hmi_lower'])} | {g(c['p_hmi_upper'])} | "
                  f"{g(c['p_hmi_upper_sourced'])} | {g(c['allocation'])} {c['allocation_unit']} | {c['verdict']}"
                  f"{' ([U]: ' + ', '.join(c['unsourced_terms']) + ')' if c['unsourced_terms'] else ''} | "
                  f"{c['verdict_assumed']} | {g(c['p_hmi_average_upper'])} | {c['verdict_average']} | "
                  f"{g(c['p_false_alert_per_15s_gaussian'])} | "
                  f"{g(c['p_false_alert_per_15s_upper_mc'])} | {c['false_alert_verdict']} |")
        wb = [(cat, k, t) for cat, c in cats.items() for k, t in c["terms"].items() if "worst_bin" in t]
        if wb:
            print("\n| mode | category | worst bin | onset | P(HMI given bin) [lower, upper] | samples (n_eff) | "
                  "x prior | shown | average upper x prior |")
            print("|---|---|---|---|---|---|---|---|---|")
            for cat, k, t in wb:
                b = t["worst_bin"]
                print(f"| {k} | {cat} | {b['magnitude'][0]:g}-{b['magnitude'][1]:g} {r['modes'][k]['unit']} | "
                      f"{b.get('onset') or str(b['onset_third']) + '/3'} | "
                      f"{g(b['probability'])} [{g(b['lower'])}, {g(b['upper'])}] | "
                      f"{b['samples']:.0f} ({b['from']}) | {g(t['specific_upper'])} | "
                      f"{'no [U]' if t.get('prior_mark') == 'U' else ('yes' if t['specific_shown'] else 'no')} | "
                      f"{g(t['upper'])} |")
        print("\n| mode | prior used | largest prior within its share (worst bin): CAT I | CAT II | CAT III |")
        print("|---|---|---|---|---|")
        for name, m in r["modes"].items():
            allowed = [cats[cat]["terms"].get(name, {}).get("prior_allowed") for cat in ("CAT I", "CAT II", "CAT III")]
            print(f"| {name} | {g(m['prior'])} [{m['prior_mark']}] | " + " | ".join(g(a) for a in allowed) + " |")
        need = {f"{cat} {k}": t["first_step_needed"] for cat, c in cats.items() for k, t in c["terms"].items()
                if "first_step_needed" in t}
        need_sp = {f"{cat} {k}": t["first_step_needed_specific"] for cat, c in cats.items()
                   for k, t in c["terms"].items() if "first_step_needed_specific" in t}
        if need_sp:
            print("\nfirst-step runs that would bound every bin of a term by its share (0 HMI):", need_sp)
        if need:
            print("\nfirst-step runs that would bound a term not estimated (0 HMI):", need)


if __name__ == "__main__":
    main()
