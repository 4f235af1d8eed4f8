"""Gray & Maybeck reproduction (approachsim/papers/gray_maybeck.py): the case table against the paper's Table 2,
the pinned values in every case's profile, the pinned sky's PDOP, the % change and the claims computed from
numbers, and the command end to end on two cases."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest
from gm_tables import mean_squares

from approachsim import geo, units
from approachsim.cli import main
from approachsim.papers import gray_maybeck as gm

# Table 2 of the paper, transcribed column by column: (INS CEP nmi/h, aid row, outage row). Cases I-VI print no
# outage row (no outage); the aid row of I, III, V is empty ("None"), of II, IV, VI "Radar Altimeter".
TABLE_2 = {
    "I": (0.4, "None", "No GPS Outage"), "II": (0.4, "Radar Altimeter", "No GPS Outage"),
    "III": (2.0, "None", "No GPS Outage"), "IV": (2.0, "Radar Altimeter", "No GPS Outage"),
    "V": (4.0, "None", "No GPS Outage"), "VI": (4.0, "Radar Altimeter", "No GPS Outage"),
    "VII": (0.4, "Pseudolite", "No GPS Outage"), "VIII": (2.0, "Pseudolite", "No GPS Outage"),
    "IX": (4.0, "Pseudolite", "No GPS Outage"),
    "X": (0.4, "Radar Altimeter and Pseudolite", "No GPS Outage"),
    "XI": (2.0, "Radar Altimeter and Pseudolite", "No GPS Outage"),
    "XII": (4.0, "Radar Altimeter and Pseudolite", "No GPS Outage"),
    "XIII": (0.4, "None", "Single GPS Outage"), "XIV": (2.0, "None", "Single GPS Outage"),
    "XV": (4.0, "None", "Single GPS Outage"), "XVI": (4.0, "Radar Altimeter", "Double GPS Outages"),
}
OUTAGES = {"No GPS Outage": 0, "Single GPS Outage": 1, "Double GPS Outages": 2}


def test_case_table_matches_table_2() -> None:
    assert [c.roman for c in gm.CASES] == list(TABLE_2)
    for c in gm.CASES:
        cep, aid, outage = TABLE_2[c.roman]
        assert c.ins_cep_nmi_h == cep
        assert c.radalt == ("Radar Altimeter" in aid), c.roman
        assert c.pseudolite == ("Pseudolite" in aid), c.roman
        assert c.gps_outages == OUTAGES[outage], c.roman


@pytest.mark.parametrize("case", gm.CASES, ids=lambda c: c.roman)
def test_every_case_profile_carries_the_case_and_the_pinned_values(case: gm.Case) -> None:
    p = gm.case_profile(case)
    s = p.sensors
    assert s.imu.grade == f"nav-{TABLE_2[case.roman][0]:.1f}"
    assert (s.radalt is not None) == case.radalt
    assert (s.pseudolite is not None) == case.pseudolite
    assert s.baro is not None and s.gnss is not None  # baro and P-code GPS in every case
    outs = [f for f in p.faults if f.sensor == "gnss" and f.kind == "outage"]
    assert len(outs) == case.gps_outages
    g = s.gnss
    assert (g.code, g.selection, g.epoch, g.epoch_utc) == ("P(Y)", "best4-fixed", "fixed", gm.EPOCH_UTC)
    assert (g.multipath_model, g.clock_ephemeris) == ("nrc1995", "nrc1995")
    assert g.budget().clock_ephemeris_m == 3.6
    assert g.rate_hz == 1.0 and s.baro.rate_hz == 1.0
    assert s.baro.bias_sigma_m == pytest.approx(100.0 * units.FT)
    if case.radalt:
        r = s.radalt
        assert (r.percent_sigma, r.floor_m, r.markov_sigma_m, r.rate_hz) == (0.01, 0.5, 0.0, 1.0)
        assert r.max_range_m == pytest.approx(3000.0 * units.FT)
    if case.pseudolite:
        pl = s.pseudolite
        assert pl.synchronized and (pl.multipath_m, pl.survey_sigma_m, pl.tropo_ppm_sigma) == (0.0, 0.0, 0.0)
    assert p.nav.feedback is False and p.nav.gps_coupling == "tight" and p.nav.channel_states is False


def test_filter_and_truth_state_counts() -> None:
    """Filter: position, velocity, attitude, gyro and accel biases (15), baro bias, GPS clock bias + drift = 18
    (the paper's 13: 11 INS + 2 clock). Truth: 9 navigation + 30 IMU + 1 baro + 4 x 4 per satellite + 2 clock."""
    p = gm.case_profile(gm.CASES[0])
    assert gm.filter_states(p)["total"] == 18
    t = gm.truth_states(p)
    assert (t["ins_navigation"], t["imu"], t["baro"], t["gps"], t["total"]) == (9, 30, 1, 18, 58)


def test_pinned_sky_has_the_papers_pdop_of_two() -> None:
    """Assumption 13 (average PDOP 2): the best-PDOP four at the runway and EPOCH_UTC, over the approach."""
    from approachsim.sensors.gnss.constellation import Constellation, dops, look_angles
    from approachsim.sensors.gnss.receiver import best_pdop_four

    p = gm.case_profile(gm.CASES[0])
    rw = p.runway
    lat, lon = np.array([rw.threshold_lat_rad]), np.array([rw.threshold_lon_rad])
    r = geo.geodetic_to_ecef(lat, lon, np.array([rw.elevation_m + 300.0])).reshape(1, 3)
    const = Constellation.nominal(gm.EPOCH_UTC)
    pd = []
    for t in (0.0, 120.0, 240.0):
        _, u, el, _ = look_angles(r, const.positions_ecef(np.array([t])))
        sel = best_pdop_four(u, el >= math.radians(5.0))
        pd.append(dops(u, sel, geo.c_ecef_to_ned(lat, lon))[1][0])
    assert 1.9 < float(np.mean(pd)) < 2.2


@pytest.mark.parametrize("tid", list(gm.PAPER_TABLES))
def test_percent_change_formula_is_the_papers(tid: str) -> None:
    """(a - b) / a x 100 from the paper's own columns gives its printed % change (|.| in Table 6) to rounding."""
    t = gm.PAPER_TABLES[tid]
    for a, b, pct in zip(t["a_ft"], t["b_ft"], t["pct"], strict=True):
        assert abs(abs((a - b) / a * 100.0) - pct) < 0.35, (tid, a, b, pct)


def _ms(values_ft: dict[int, list[float]], n: int) -> dict[int, dict[str, np.ndarray]]:
    """Per-run mean squares whose RMS over runs is values_ft (per state), spread 0.1, seed 5."""
    return mean_squares(values_ft, n, spread=0.1, seed=5)


def test_group_comparison_and_its_claims_follow_the_numbers() -> None:
    ms = _ms({1: [9.0, 9.0, 15.0, 9.0], 2: [4.5, 4.0, 15.0, 5.0]}, n=15)
    o = gm.compare_groups(ms, (1,), (2,), seed=1)
    assert o["a_ft"] == pytest.approx([9.0, 9.0, 15.0, 9.0])
    assert o["pct"][0] == pytest.approx(50.0)
    assert o["pct"][2] == pytest.approx(0.0, abs=1e-9)
    assert o["pct_ci"][0][0] < 50.0 < o["pct_ci"][0][1]
    paper = {"a_ft": (8.9, 9.2, 15.0, 9.0), "b_ft": (4.6, 3.9, 11.8, 4.9)}
    cl = gm.table_claims(o, paper)
    assert [c["our_direction"] for c in cl] == ["reduction", "reduction", "indistinguishable", "reduction"]
    assert [c["direction_reproduces"] for c in cl] == [True, True, False, True]
    # the same numbers the other way round turn every reduction into an increase
    back = gm.compare_groups(ms, (2,), (1,), seed=1)
    assert [gm.direction(ci) for ci in back["pct_ci"]][:2] == ["increase", "increase"]


def _verdicts(v1: str, v2: str, v3: str, best: str | None) -> dict:
    return {"best": best, "categories": {c: {"verdict": v} for c, v in
                                         (("CAT I", v1), ("CAT II", v2), ("CAT III", v3))}}


def test_category_claims_follow_the_verdicts() -> None:
    assert gm.category_claim(2, _verdicts("meets", "fails", "fails", "CAT I"))["status"] == "reproduces"
    assert gm.category_claim(2, _verdicts("meets", "meets", "fails", "CAT II"))["status"] == "differs"
    assert gm.category_claim(2, _verdicts("indeterminate", "fails", "fails", None))["status"] == "indeterminate"
    assert gm.category_claim(1, _verdicts("fails", "fails", "fails", None))["status"] == "reproduces"
    assert gm.category_claim(1, _verdicts("meets", "fails", "fails", "CAT I"))["status"] == "differs"
    assert gm.category_claim(10, _verdicts("meets", "meets", "fails", "CAT II"))["status"] == "reproduces"
    assert gm.category_claim(10, _verdicts("meets", "meets", "meets", "CAT III"))["status"] == "differs"


def test_unknown_case_is_a_one_line_error(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["reproduce", "gray-maybeck", "--out", str(tmp_path), "--cases", "XVII"]) == 2
    assert "--cases" in capsys.readouterr().err


@pytest.mark.slow
def test_reproduce_gray_maybeck_end_to_end(tmp_path: Path) -> None:
    """Cases VI and XVI (Table 6), 2 runs each, through the CLI: the JSON, the note and the figure."""
    assert main(["reproduce", "gray-maybeck", "--out", str(tmp_path), "--cases", "VI,XVI", "--runs", "2"]) == 0
    doc = json.loads((tmp_path / "gray-maybeck.json").read_text())
    assert set(doc["cases"]) == {"VI", "XVI"} and doc["runs_per_case"] == 2
    t6 = doc["tables"]["6"]
    assert t6["paper"]["a_ft"] == [8.8, 9.4, 2.3, 6.0]
    ours = t6["ours"]
    for j in range(4):  # the table's numbers are the cases' time-averaged RMS
        s = gm.STATES[j]
        ta_vi, ta_xvi = doc["cases"]["VI"]["time_averaged_rms_ft"][s], doc["cases"]["XVI"]["time_averaged_rms_ft"][s]
        if doc["cases"]["VI"]["failed_runs"] == 0 and doc["cases"]["XVI"]["failed_runs"] == 0:
            assert ours["a_ft"][j] == pytest.approx(ta_vi, rel=1e-9)
            assert ours["b_ft"][j] == pytest.approx(ta_xvi, rel=1e-9)
        assert ours["pct"][j] == pytest.approx((ours["a_ft"][j] - ours["b_ft"][j]) / ours["a_ft"][j] * 100.0)
    md = (tmp_path / "gray-maybeck.md").read_text()
    assert "Gray & Maybeck, *An integrated GPS/INS/Baro and radar altimeter system" in md
    assert "seed 002" not in md and "## Table 6" in md and "Tables 7-8" in md
    assert (tmp_path / "gray-maybeck_cases.png").is_file()
    assert (tmp_path / "faithful" / "XVI" / "summary.json").is_file()
    assert doc["variant"] == "faithful" and doc["mode"] == "open"


def test_failure_reasons_are_counted_by_kind() -> None:
    f = {"3": "RuntimeError: failed approach: unstabilized at 145 ft: glidepath deviation -1.00 dots",
         "4": "RuntimeError: failed approach: unstabilized at 473 ft: glidepath deviation -1.00 dots",
         "9": "RunScoreError: navigation solution is not finite at the CAT I decision height (diverged)"}
    assert gm.failure_reasons(f) == {"failed approach: unstabilized": 2,
                                     "navigation solution is not finite": 1}


def test_pseudolite_line_of_sight_shares() -> None:
    """Glidepath point at 200 ft: 2862 ft before the threshold (3 deg, TCH 50 ft); the pseudolite 1000 ft past it,
    500 ft left, 30 ft up: range sqrt(3862^2 + 500^2 + 170^2) ft, cross share 500 / range."""
    g = gm.pseudolite_geometry(gm.case_profile(gm.CASES[9]), heights_ft=(200.0,))[0]
    x = 150.0 / math.tan(math.radians(3.0))
    r = math.sqrt((1000.0 + x) ** 2 + 500.0**2 + 170.0**2)
    assert g["range_ft"] == pytest.approx(r, rel=1e-6)
    assert g["cross_share"] == pytest.approx(500.0 / r, rel=1e-6)
    assert gm.pseudolite_geometry(gm.case_profile(gm.CASES[0])) is None
