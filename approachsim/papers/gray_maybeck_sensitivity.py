"""Gray & Maybeck, faithful variant: the sensitivity of every gap fill, each row paired against the faithful variant.

Gray & Maybeck, *An integrated GPS/INS/Baro and radar altimeter system for aircraft precision approach landings*,
leaves some inputs out (the pseudolite's site, the outages' times, the baro's correlation, the filter's R); the
faithful variant fills them (papers/gray_maybeck_faithful.py) and this table measures how much each fill moves
the results the paper reports. Every row is the faithful variant with one fill changed (ROWS), flown open loop at
the same seed and run indices as the faithful reference (common random numbers: run i of every row and case draws
from (seed, i)); a case the row does not change (the pseudolite rows leave the cases without a pseudolite alone,
the outage rows every case without an outage) is the faithful reference's own runs, bit for bit.

Metrics (METRICS), each for the row and its paired difference from the faithful reference with a 95 % percentile
bootstrap interval over the common run index:

The table flies one INS grade per group (2.0 nmi/h: case III for I-III-V, VIII for VII-VIII-IX, IV for II-IV-VI,
XI for X-XII) and VI / XVI for Table 6 (GROUP_* below):

- t3_lat_pct, t3_lon_pct: Table 3's % change of latitude / longitude (case III vs VIII, the pseudolite's cut; the
  paper 48.3 / 57.6 %);
- t3_hvar_pct: the same for the horizontal error variance lat^2 + lon^2 (the paper (164 - 36) / 164 = 78 %);
- cat2_lat_ft, cat2_vert_ft: the 1-sigma (RMS over runs) lateral / vertical error at the CAT II decision height
  of case XI (FAA limits 8.6 / 2.8 ft), and its CAT II verdict;
- t4_alt_ft: case XI's time-averaged altitude error (the paper's X-XII 2.4 ft);
- t6_alt_pct: Table 6's altitude % change, case VI vs XVI (the paper -56.5 %, an increase).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from approachsim import seeding, units
from approachsim.papers import gray_maybeck_faithful as gf

STATES = ("latitude", "longitude", "altitude", "clock_bias")
BOOTSTRAP = 2000
"""Bootstrap resamples of the run index for every interval of the table."""
LEVEL = 0.95
"""Two-sided level of the intervals."""
GROUP_A = (3,)
"""Table 3's cases without aid, as the table flies them: the 2.0 nmi/h INS only (case III). The paper averages the
three grades because they were "virtually indistinguishable"; one grade keeps the table's cost at a third (the
faithful study at 1000 runs gives each grade's own numbers)."""
GROUP_PL = (8,)
"""Table 3's pseudolite cases as flown: case VIII (2.0 nmi/h)."""
GROUP_RA_PL = (11,)
"""Cases X-XII as flown: case XI (2.0 nmi/h)."""
GROUP_RA = (4,)
"""Cases II-IV-VI as flown: case IV (2.0 nmi/h)."""
PL_CASES = GROUP_PL + GROUP_RA_PL
"""Flown cases with the pseudolite."""
OUTAGE_CASES = (16,)
"""The outage case the metrics use (Table 6: VI vs XVI)."""
ALL_CASES = GROUP_A + GROUP_PL + GROUP_RA + GROUP_RA_PL + (6, 16)
"""Every case a metric reads."""
DH_CAT1_ALONG_FT = -(200.0 - 50.0) / math.tan(math.radians(3.0))
"""Along-track of the glidepath at the CAT I decision height (200 ft, TCH 50 ft, 3 deg), ft from the threshold."""


@dataclass(frozen=True)
class Row:
    """One gap fill changed: key, what it is, the profile settings after the faithful variant's, the cases it
    changes (the others are the faithful reference's runs)."""

    key: str
    label: str
    settings: tuple[tuple[str, Any], ...]
    cases: tuple[int, ...]


def _pl(along_ft: float, cross_ft: float, height_ft: float = 30.0) -> tuple[tuple[str, Any], ...]:
    return (("sensors.pseudolite.units", [{"along_ft": along_ft, "cross_ft": cross_ft, "height_ft": height_ft}]),)


def _outages(windows: Sequence[tuple[float, float]]) -> tuple[tuple[str, Any], ...]:
    return (("faults", [{"sensor": "gnss", "kind": "outage", "start_s": a, "end_s": b} for a, b in windows]),)


THIRD_PASS_ROWS: tuple[Row, ...] = (
    Row("profgen-trajectory", "trajectory: the PROFGEN-like lead-in (runway.lead_in = profgen: downwind "
        "descent, two 90 deg turns, level segments, glideslope intercept; 480 s) instead of the 10 nmi final; "
        "start, R rule and outage times as the faithful variant's", (("runway.lead_in", "profgen"),), ALL_CASES),
    Row("profgen-filter-start", "trajectory and the filter from its start: the lead-in with the free-inertial "
        "prior drawn (start = prior) instead of the converged start",
        (("runway.lead_in", "profgen"), ("nav.initial_error.start", "prior")), ALL_CASES),
    Row("swept-tuning", "tuning: the swept R scale and clock Q (PROFGEN_TUNING, tools/gray_maybeck_tuning.py) on "
        "the 10 nmi final instead of the R rule", tuple(gf.PROFGEN_TUNING.items()), ALL_CASES),
    Row("profgen-variant", "the profgen variant whole: lead-in, filter from its start, swept tuning, its outage "
        "times (100-120 s, 400-420 s)", gf.PROFGEN_SETTINGS + _outages(gf.PROFGEN_OUTAGE_WINDOWS_S[2]),
        ALL_CASES),
)
"""Issue 43's trajectory and tuning rows (the third pass), at the end of ROWS."""

ROWS: tuple[Row, ...] = (
    Row("pl-centreline", "pseudolite on the extended centreline, 1000 ft past the threshold, 30 ft up",
        _pl(1000.0, 0.0), PL_CASES),
    Row("pl-abeam-dh", f"pseudolite abeam the CAT I decision height ({DH_CAT1_ALONG_FT:.0f} ft), 500 ft left",
        _pl(DH_CAT1_ALONG_FT, -500.0), PL_CASES),
    Row("pl-abeam-dh-1.5km", "pseudolite abeam the CAT I decision height, 1.5 km left",
        _pl(DH_CAT1_ALONG_FT, -1500.0 / units.FT), PL_CASES),
    Row("pl-abeam-mid-1.5km", "pseudolite abeam the middle of the final (5 nmi out), 1.5 km left",
        _pl(-5.0 * units.NMI / units.FT, -1500.0 / units.FT), PL_CASES),
    Row("pl-two-abeam-dh-1.5km", "two pseudolites abeam the CAT I decision height, 1.5 km left and 1.5 km right (not "
        "the paper's: it has one; what a second line of sight gives)",
        (("sensors.pseudolite.units", [{"along_ft": DH_CAT1_ALONG_FT, "cross_ft": s * 1500.0 / units.FT,
                                        "height_ft": 30.0} for s in (-1.0, 1.0)]),), PL_CASES),
    Row("gps-nrc", "GPS: the NRC 1995 budget unscaled (5.3 m / 7.0 m) instead of the paper's 4 m / 5 m",
        (("sensors.gnss.budget_scale", 1.0),), ALL_CASES),
    Row("baro-50", "baro correlated error 50 ft 1-sigma (faithful: 100 ft)",
        (("sensors.baro.bias_sigma_m", 50.0 * units.FT),), ALL_CASES),
    Row("baro-150", "baro correlated error 150 ft 1-sigma",
        (("sensors.baro.bias_sigma_m", 150.0 * units.FT),), ALL_CASES),
    Row("outage-60s", "double outage of 60 s each, 60-120 s and 160-220 s (the closed study's; faithful: 20 s)",
        _outages(((60.0, 120.0), (160.0, 220.0))), OUTAGE_CASES),
    Row("outage-late", "double outage of 20 s each, the second ending at the CAT I decision height "
        "(150-170 s, 238-258 s)", _outages(((150.0, 170.0), (238.0, 258.0))), OUTAGE_CASES),
    Row("untuned", "filter R untuned: the full variance of the range errors (nav.gps_sigma_scale = 1)",
        (("nav.gps_sigma_scale", 1.0),), ALL_CASES),
    Row("channel-states", "filter with per-channel range-error states (nav.channel_states = true, R = the white "
        "code noise): not the paper's 13-state filter; what carrying the correlated GPS errors as states gives",
        (("nav.channel_states", True), ("nav.gps_sigma_scale", 1.0)), ALL_CASES),
    Row("prior-start", "initial errors: the closed study's independent prior draw (5 m, 0.05 m/s, 0.05 / 0.5 mrad) "
        "instead of the converged start after the free-inertial prior",
        (("nav.initial_error.start", "prior"), ("nav.initial_error.position_m", 5.0),
         ("nav.initial_error.velocity_mps", 0.05), ("nav.initial_error.tilt_mrad", 0.05),
         ("nav.initial_error.heading_mrad", 0.5)), ALL_CASES),
    *THIRD_PASS_ROWS,
)
"""The sensitivity rows (module docstring)."""

METRICS: dict[str, dict[str, Any]] = {
    "t3_lat_pct": {"label": "Table 3 latitude % cut", "paper": 48.3},
    "t3_lon_pct": {"label": "Table 3 longitude % cut", "paper": 57.6},
    "t3_hvar_pct": {"label": "Table 3 horizontal variance % cut", "paper": (164.05 - 36.37) / 164.05 * 100.0},
    "cat2_lat_ft": {"label": "XI CAT II lateral 1-sigma (ft)", "paper": None},
    "cat2_vert_ft": {"label": "XI CAT II vertical 1-sigma (ft)", "paper": None},
    "t4_alt_ft": {"label": "XI altitude (ft)", "paper": 2.4},
    "t6_alt_pct": {"label": "Table 6 altitude % change", "paper": -56.5},
}
"""The metrics: label and the paper's value (None: the paper gives only the verdict, CAT II met)."""


def _rms(x: np.ndarray, idx: np.ndarray) -> float:
    return math.sqrt(float(np.mean(x[idx])))


def metrics(data: dict[int, dict[str, np.ndarray]], idx: np.ndarray) -> dict[str, float]:
    """The metrics of one row from per-case per-run arrays (common run order): ta_<state>_ft2 (time-averaged
    squared error, ft^2) and cat2_lat_ft2 / cat2_vert_ft2 (squared error at the CAT II decision height, ft^2);
    idx the run indices used (a bootstrap draw)."""
    def grp(cases: Sequence[int], col: str) -> float:
        return float(np.mean([_rms(data[c][col], idx) for c in cases]))

    a, b = GROUP_A, GROUP_PL
    lat_a, lat_b = grp(a, "ta_latitude_ft2"), grp(b, "ta_latitude_ft2")
    lon_a, lon_b = grp(a, "ta_longitude_ft2"), grp(b, "ta_longitude_ft2")
    alt6, alt16 = grp((6,), "ta_altitude_ft2"), grp((16,), "ta_altitude_ft2")
    return {
        "t3_lat_pct": (lat_a - lat_b) / lat_a * 100.0,
        "t3_lon_pct": (lon_a - lon_b) / lon_a * 100.0,
        "t3_hvar_pct": ((lat_a**2 + lon_a**2) - (lat_b**2 + lon_b**2)) / (lat_a**2 + lon_a**2) * 100.0,
        "cat2_lat_ft": grp(GROUP_RA_PL, "cat2_lat_ft2"),
        "cat2_vert_ft": grp(GROUP_RA_PL, "cat2_vert_ft2"),
        "t4_alt_ft": grp(GROUP_RA_PL, "ta_altitude_ft2"),
        "t6_alt_pct": (alt6 - alt16) / alt6 * 100.0,
    }


def paired_table(ref: dict[int, dict[str, np.ndarray]], rows: dict[str, dict[int, dict[str, np.ndarray]]], *,
                 seed: int) -> dict[str, dict]:
    """Per row: its metrics and their paired difference from the reference (row - reference) with 95 % bootstrap
    intervals; the reference's own metrics and intervals under "faithful". All arrays share the run order."""
    n = len(next(iter(ref.values()))["ta_latitude_ft2"])
    full = np.arange(n)
    rng = seeding.stream(seed, 0, "gray-maybeck-sensitivity")
    draws = [rng.integers(0, n, n) for _ in range(BOOTSTRAP)]
    q = [50 * (1 - LEVEL), 100 - 50 * (1 - LEVEL)]
    base = metrics(ref, full)
    base_boot = [metrics(ref, i) for i in draws]
    out: dict[str, dict] = {"faithful": {"runs": n, "value": base, "ci": {
        k: np.percentile([b[k] for b in base_boot], q).tolist() for k in METRICS}}}
    for key, data in rows.items():
        val = metrics(data, full)
        diffs = [{k: m[k] - b[k] for k in METRICS} for m, b in zip((metrics(data, i) for i in draws), base_boot,
                                                                   strict=True)]
        out[key] = {"runs": n, "value": val, "diff": {k: val[k] - base[k] for k in METRICS},
                    "diff_ci": {k: np.percentile([d[k] for d in diffs], q).tolist() for k in METRICS}}
    return out


def _case_arrays(ev: Any, columns: Callable[[list], dict[str, np.ndarray]]) -> dict[int, dict[str, float]]:
    """run -> the metric columns (ft^2) of one campaign's completed runs."""
    cols = columns(ev.results)
    ok = [r.run for r in ev.results if r.ok]
    out: dict[int, dict[str, float]] = {}
    for i, r in enumerate(ok):
        d = {f"ta_{s}_ft2": float(cols[f"ta_{s}_ft2"][i]) for s in STATES}
        d["cat2_lat_ft2"] = float(cols["cat2_lateral_m"][i] / units.FT) ** 2
        d["cat2_vert_ft2"] = float(cols["cat2_vertical_m"][i] / units.FT) ** 2
        out[r] = d
    return out


def run_table(*, seed: int, runs: int, root: Path, evaluate: Any, columns: Any, cases: Sequence[Any],
              case_profile: Callable[..., Any], workers: int | None = None, rows: Sequence[Row] = ROWS) -> dict:
    """Fly the faithful reference and every row (open loop, `runs` runs per case, the same seed), then the paired
    table. cases: the paper's cases (papers/gray_maybeck.CASES) and case_profile(case, variant, extra, label=) the
    profile of one (gray_maybeck.case_profile), handed in by gray_maybeck.compute, which runs this table (this
    module stays below it). Returns {"runs", "rows": [{key, label, cases}], "table": paired_table(...), "failed":
    {row: {case: n}}, "verdicts": {row: {case: CAT II verdict}}, "common_runs", "wall_s"}."""
    by_num = {c.number: c for c in cases}
    per: dict[str, dict[int, dict[int, dict[str, float]]]] = {}
    failed: dict[str, dict[str, int]] = {}
    verdicts: dict[str, dict[str, str]] = {}
    wall = 0.0
    for key, extra, cases in [("faithful", (), ALL_CASES)] + [(r.key, r.settings, r.cases) for r in rows]:
        per[key], failed[key], verdicts[key] = {}, {}, {}
        for c in cases:
            case = by_num[c]
            prof = case_profile(case, "faithful", extra, label=key if key != "faithful" else "")
            ev = evaluate(prof, runs=runs, seed=seed, mode="open", out_dir=root / key / case.roman,
                          workers=workers, resume=True, progress=False)
            wall += ev.wall_s
            per[key][c] = _case_arrays(ev, columns)
            failed[key][case.roman] = int(ev.summary["failed_runs"])
            verdicts[key][case.roman] = ev.summary["decision_heights"]["CAT II"]["verdict"]
    # a row's unchanged cases are the reference's runs
    for key in per:
        for c in ALL_CASES:
            per[key].setdefault(c, per["faithful"][c])
    common = sorted(set.intersection(*(set(per[k][c]) for k in per for c in ALL_CASES)))

    def arrays(key: str) -> dict[int, dict[str, np.ndarray]]:
        return {c: {col: np.array([per[key][c][r][col] for r in common]) for col in per[key][c][common[0]]}
                for c in ALL_CASES}

    ref_prof = case_profile(by_num[11], "faithful")
    uere_f = gf.budget_uere_m(ref_prof.sensors.gnss.budget())
    uere_n = gf.budget_uere_m(case_profile(by_num[11], "faithful", (("sensors.gnss.budget_scale", 1.0),))
                              .sensors.gnss.budget())
    table = paired_table(arrays("faithful"), {r.key: arrays(r.key) for r in rows}, seed=seed) if common else {}
    return {"runs": runs, "common_runs": len(common), "rows": [{"key": r.key, "label": r.label,
                                                                 "cases": [by_num[c].roman for c in r.cases]}
                                                                for r in rows],
            "table": table, "failed": failed, "verdicts": verdicts, "wall_s": wall,
            "faithful_uere_m": uere_f, "nrc_uere_m": uere_n}
