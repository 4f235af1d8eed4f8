"""Gray & Maybeck faithful variant (papers/gray_maybeck_faithful.py, _sensitivity.py, _note.py): the closed-loop
case profiles unchanged, the faithful profile's numbers (4 m / 5 m GPS, open loop, the tuning rule, the initial
errors), the magnitude rule on constructed tables, the common run set and the sensitivity table's arithmetic."""

from __future__ import annotations

import hashlib
import json
import math

import numpy as np
import pytest
from gm_tables import mean_squares

from approachsim.config import ProfileError
from approachsim.papers import gray_maybeck as gm
from approachsim.papers import gray_maybeck_faithful as gf
from approachsim.papers import gray_maybeck_note as gn
from approachsim.papers import gray_maybeck_sensitivity as gs
from approachsim.sensors.gnss.receiver import GnssErrorBudget
from approachsim.sensors.presets import PRESETS

CLOSED_SETTINGS_SHA256 = "c2349a8239f77ced345a432c292a9626bc93004062a8b16c9505f797d09b3b96"
"""sha256 of json.dumps(case_settings(case), sort_keys=True, default=str) over the 16 cases, taken on main before
the faithful variant was added: the closed-loop study (and the regress baselines' profiles) is unchanged. Retaken in
issue 39 for one added pinned key, sensors.pseudolite.sync_sigma_ns = 0 on the pseudolite cases: the value the
profiles had before the time-sync error existed (closed_loop_identity: gray-maybeck bit-identical). Retaken again
in issue 39 (i39a) for three pinned baro keys, temperature_scale_sigma = static_source_sigma_m = qnh_sigma_hPa = 0:
the paper's baro, as before the physical baro existed (regress: cases I and VII equal within the cross-machine
floor)."""


def test_closed_case_profiles_are_unchanged() -> None:
    h = hashlib.sha256()
    for c in gm.CASES:
        h.update(json.dumps(gm.case_settings(c), sort_keys=True, default=str).encode())
    assert h.hexdigest() == CLOSED_SETTINGS_SHA256
    p = gm.case_profile(gm.CASES[9])  # the default variant is the closed one (regress builds it so)
    assert p.run.mode == "closed" and p.name == "gray-maybeck[case X]"
    assert p.sensors.gnss.budget_scale == 1.0 and p.nav.gps_sigma_scale == 1.0
    assert p.sensors.gnss.budget().clock_ephemeris_m == 3.6


def test_unknown_variant_is_a_profile_error() -> None:
    with pytest.raises(ProfileError, match="variant"):
        gm.case_settings(gm.CASES[0], "half-open")


@pytest.mark.parametrize("case", [gm.CASES[0], gm.CASES[9], gm.CASES[15]], ids=lambda c: c.roman)
def test_faithful_profile_has_the_papers_gps_and_open_loop(case: gm.Case) -> None:
    p = gm.case_profile(case, "faithful")
    assert p.run.mode == "open" and p.nav.channel_states is False and p.nav.feedback is False
    assert p.nav.initial_error.start == "converged" and p.evaluation.integrity == ()
    d = gf.approach_dops(p)
    uere = gf.budget_uere_m(p.sensors.gnss.budget())
    # the scaled budget's 3-D error at the pinned sky is the paper's sqrt(4^2 + 5^2) m (to the rounding of the factor)
    assert uere * math.hypot(d["hdop"], d["vdop"]) == pytest.approx(math.hypot(4.0, 5.0), rel=1e-3)
    assert 1.9 < d["pdop"] < 2.2  # assumption 13
    # correlation times are kept, only the sigmas scale
    b0, b = gm.case_profile(case).sensors.gnss.budget(), p.sensors.gnss.budget()
    assert b.clock_ephemeris_tau_s == b0.clock_ephemeris_tau_s and b.multipath_tau_s == b0.multipath_tau_s
    assert b.multipath_m / b0.multipath_m == pytest.approx(p.sensors.gnss.budget_scale)
    windows = [(f.start_s, f.end_s) for f in p.faults]
    assert windows == list(gf.OUTAGE_WINDOWS_S[case.gps_outages])
    assert all(e - s == 20.0 for s, e in windows)


def test_tuning_rule_by_hand() -> None:
    """R = sum s^2 max(1, min(2 tau, T) / dt): a bias-like term (tau >> T) counts T / dt, a short one 2 tau / dt,
    white noise once."""
    b = GnssErrorBudget(clock_ephemeris_m=2.0, iono_zenith_m=0.0, tropo_zenith_m=0.0, multipath_m=1.0,
                        code_noise_m=0.5, clock_ephemeris_tau_s=7200.0, multipath_tau_s=30.0)
    assert gf.tuned_r_m2(b, 270.0, 1.0) == pytest.approx(4.0 * 270.0 + 1.0 * 60.0 + 0.25)
    assert gf.full_r_m2(b) == pytest.approx(5.25)
    assert gf.sigma_scale(b, 270.0, 1.0) == pytest.approx(math.sqrt((1080.0 + 60.0 + 0.25) / 5.25))
    # the profile's nav.gps_sigma_scale is the rule applied to the profile's own budget, T and dt
    p = gm.case_profile(gm.CASES[9], "faithful")
    t = gf.approach_duration_s(p)
    assert t == pytest.approx(10.0 * 1852.0 / (133.0 * 1852.0 / 3600.0), rel=1e-3)
    assert p.nav.gps_sigma_scale == pytest.approx(gf.sigma_scale(p.sensors.gnss.budget(), t, 1.0), abs=1e-3)


def test_free_inertial_initial_errors_per_grade() -> None:
    """Alignment: heading = east gyro bias / (Omega cos lat); after 60 min the CEP rate is of the grade's order and
    grows with the grade."""
    lat = math.radians(39.8)
    g = PRESETS["nav-2.0"]
    a = gf.free_inertial_errors(g, lat, flight_s=0.0)
    assert a["position_m"] == pytest.approx(0.0, abs=1e-9) and a["velocity_mps"] == pytest.approx(0.0, abs=1e-12)
    assert a["tilt_mrad"] == pytest.approx(g.accel_bias_mps2 / 9.80665 * 1e3, rel=1e-6)
    wn, wd = gf.OMEGA_IE * math.cos(lat), -gf.OMEGA_IE * math.sin(lat)
    head = math.sqrt((g.gyro_bias_radps / wn) ** 2 + (wd * g.accel_bias_mps2 / (wn * 9.80665)) ** 2)
    assert a["heading_mrad"] == pytest.approx(head * 1e3, rel=1e-6)
    ceps = [gf.free_inertial_errors(PRESETS[f"nav-{x}"], lat)["cep_nmi_per_h"] for x in ("0.4", "2.0", "4.0")]
    assert ceps == sorted(ceps)
    for c, nominal in zip(ceps, (0.4, 2.0, 4.0), strict=True):
        assert 0.5 * nominal < c < 1.5 * nominal


def _ms(values_ft: dict[int, list[float]], n: int) -> dict[int, dict[str, np.ndarray]]:
    """Per-run mean squares whose RMS over runs is values_ft (per state), spread 0.3, seed 11."""
    return mean_squares(values_ft, n, spread=0.3, seed=11)


def test_magnitude_rule_on_a_constructed_table() -> None:
    """Ours: latitude 9 -> 4.5 ft (50 % cut), longitude 9 -> 8 (11 %), altitude unchanged, clock 9 -> 4.5. The
    paper's 48 % is inside our 15-run range (reproduces); the paper's 57 % longitude is not (direction only); the
    paper's 21 % altitude against our 0 (does not reproduce)."""
    ms = _ms({1: [9.0, 9.0, 15.0, 9.0], 2: [4.5, 8.0, 15.0, 4.5]}, n=400)
    o = gm.compare_groups(ms, (1,), (2,), seed=3)
    lo, hi = o["pct_range_paper_runs"][0]
    assert lo < 48.3 < hi and o["pct_ci"][0][0] > lo  # the 15-run range is wider than the 400-run interval
    cl = gm.table_claims(o, {"a_ft": (8.9, 9.2, 15.0, 9.0), "b_ft": (4.6, 3.9, 11.8, 4.9)})
    assert [c["verdict"] for c in cl] == ["reproduces", "direction only", "does not reproduce", "reproduces"]
    assert cl[0]["magnitude"] == {"a": True, "b": True, "pct": True}
    assert cl[1]["magnitude"]["b"] is False  # paper 3.9 ft against our 8 ft
    counts = gm.cell_counts({"3": {"claims": cl}})
    assert counts["cells"] == 12 and counts["rows"] == 4 and counts["direction_rows"] == 3
    assert counts["verdicts"] == {"reproduces": 2, "direction only": 1, "does not reproduce": 1}
    assert gm.row_verdict(False, True) == "magnitude only"


def test_common_run_set() -> None:
    by_run = {1: {0: 1, 1: 1, 2: 1, 5: 1}, 2: {0: 1, 2: 1, 5: 1, 7: 1}, 3: {2: 1, 5: 1, 0: 1}}
    assert gm.common_runs(by_run, (1, 2, 3)) == [0, 2, 5]
    assert gm.common_runs(by_run, (1,)) == [0, 1, 2, 5]
    assert gm.common_runs(by_run, ()) == []


def _sens_data(n: int, lat_pl: float, cat2: float) -> dict[int, dict[str, np.ndarray]]:
    rng = np.random.default_rng(2)
    w = np.abs(1.0 + 0.1 * rng.standard_normal(n))
    w = w / np.sqrt(np.mean(w**2))
    out = {}
    for c in gs.ALL_CASES:
        lat = lat_pl if c in gs.PL_CASES else 10.0
        alt = 3.0 if c in (4, 6, 11) else 6.0 if c == 16 else 20.0
        out[c] = {"ta_latitude_ft2": (lat * w) ** 2, "ta_longitude_ft2": (10.0 * w) ** 2,
                  "ta_altitude_ft2": (alt * w) ** 2, "ta_clock_bias_ft2": (5.0 * w) ** 2,
                  "cat2_lat_ft2": (cat2 * w) ** 2, "cat2_vert_ft2": (0.5 * w) ** 2}
    return out


def test_sensitivity_metrics_and_pairing() -> None:
    ref = _sens_data(200, lat_pl=9.0, cat2=12.0)
    m = gs.metrics(ref, np.arange(200))
    assert m["t3_lat_pct"] == pytest.approx(10.0) and m["t3_lon_pct"] == pytest.approx(0.0, abs=1e-9)
    assert m["t3_hvar_pct"] == pytest.approx((200.0 - 181.0) / 200.0 * 100.0)
    assert m["cat2_lat_ft"] == pytest.approx(12.0) and m["t4_alt_ft"] == pytest.approx(3.0)
    assert m["t6_alt_pct"] == pytest.approx(-100.0)
    tab = gs.paired_table(ref, {"same": ref, "better": _sens_data(200, lat_pl=5.0, cat2=8.0)}, seed=1)
    assert tab["same"]["diff"]["cat2_lat_ft"] == 0.0 and tab["same"]["diff_ci"]["cat2_lat_ft"] == [0.0, 0.0]
    assert tab["better"]["diff"]["cat2_lat_ft"] == pytest.approx(-4.0)
    lo, hi = tab["better"]["diff_ci"]["t3_lat_pct"]
    assert lo < 40.0 < hi  # 50 % - 10 %, paired: the common run weights cancel
    sens = {"runs": 200, "common_runs": 200, "rows": [{"key": "same", "label": "s", "cases": ["XI"]},
                                                        {"key": "better", "label": "b", "cases": ["XI"]}],
            "table": tab, "verdicts": {"faithful": {"XI": "fails"}}, "faithful_uere_m": 3.2, "nrc_uere_m": 4.1}
    words = gn.sensitivity_findings(sens)
    assert "rows under the limit: better" in words[0]


def test_note_rows_carry_no_fixed_mechanism_text() -> None:
    """The old fixed phrases are gone from the reasons (every reason sentence is computed)."""
    import inspect

    src = inspect.getsource(gn)
    for phrase in ("2 h correlation", "10-30 ft radar altimeter", "of the same order", "cannot correct it"):
        assert phrase not in src


def test_shared_keys_checked_at_load_and_applied() -> None:
    """[nav] gps_sigma_scale needs channel_states = false; [sensors.gnss] budget_scale scales every sigma; the filter
    sees the GNSS record's nominal sigma times gps_sigma_scale (nav.system.tuned_records)."""
    from dataclasses import dataclass

    from approachsim.nav.system import tuned_records

    with pytest.raises(ProfileError, match="gps_sigma_scale"):
        gm.case_profile(gm.CASES[0], "faithful", (("nav.channel_states", True),))
    with pytest.raises(ProfileError, match="budget_scale"):
        gm.case_profile(gm.CASES[0], "faithful", (("sensors.gnss.budget_scale", 0.0),))
    p = gm.case_profile(gm.CASES[0], "closed", (("sensors.gnss.budget_scale", 0.5),))
    b = p.sensors.gnss.budget()
    assert (b.clock_ephemeris_m, b.multipath_m, b.code_noise_m) == pytest.approx((1.8, 0.9, 0.3))

    @dataclass(frozen=True)
    class Rec:
        sigma_m: np.ndarray

    recs = {"gnss": Rec(np.array([1.0, 2.0])), "baro": "unchanged"}
    assert tuned_records(recs, 1.0) is recs
    out = tuned_records(recs, 3.0)
    assert out["gnss"].sigma_m.tolist() == [3.0, 6.0] and out["baro"] == "unchanged"
    assert recs["gnss"].sigma_m.tolist() == [1.0, 2.0]
