"""Autopilot geometry and signs: deviations from the ideal glidepath and centreline, and the direction of
each loop's response, checked without JSBSim."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import pytest

from approachsim import units
from approachsim.flight.aircraft import load_aircraft
from approachsim.flight.autopilot import Autopilot, Geometry, Trim
from approachsim.glidepath import GlidePath
from approachsim.profile import load_profile

PROFILES = Path(__file__).resolve().parents[3] / "profiles"

GP = math.radians(3.0)
TCH = 50.0 * units.FT


@pytest.fixture(params=["classic", "tecs"])
def ap(request):
    ac = load_aircraft(load_profile(PROFILES / "default.toml"))
    geom = Geometry(heading_rad=0.0, glidepath_rad=GP, tch_m=TCH, threshold_lat_rad=0.0)
    gains = dataclasses.replace(ac.gains, tecs=request.param == "tecs")
    return Autopilot(gains, Trim(theta_rad=0.02, throttle=0.47, cas_mps=72.0), geom, 1.0 / 120.0)


CONE = GlidePath(GP, TCH, 0.0, 0.0)


def _on_path(x):
    """Height of the straight glide path cone (approachsim.glidepath) in the runway frame's z at x."""
    return float(CONE.height_m(x))


def _sink_on_path(x, v):
    """Sink rate (m/s) that follows the cone at ground speed v along the runway: v times its slope at x."""
    return v * (_on_path(x - 0.5) - _on_path(x + 0.5))


def test_on_the_glidepath_flying_down_it_has_zero_deviation(ap):
    x = -5000.0
    v = 70.0
    d, d_dot, y, y_dot = ap.deviations(x, 0.0, _on_path(x), v, 0.0, _sink_on_path(x, v))
    assert d == pytest.approx(0.0, abs=1e-9)
    assert d_dot == pytest.approx(0.0, abs=1e-6)  # the slope by a 1 m central difference: O(1e-7) m/s
    assert y == 0.0 and y_dot == pytest.approx(0.0, abs=1e-12)


def test_deviation_signs(ap):
    x = -3000.0
    d, _, y, y_dot = ap.deviations(x, 12.0, float(CONE.height_m(x, 12.0)) + 7.0, 70.0, 1.5, 3.67)
    assert d == pytest.approx(7.0)
    assert y == 12.0
    assert y_dot == pytest.approx(1.5)  # heading north: east velocity drifts right


def test_above_the_path_pitches_down_and_right_of_centreline_banks_left(ap):
    x = -3000.0
    de, da, dr, thr = ap.step(x, 30.0, _on_path(x) + 10.0, 70.0, 0.0, 3.67, 0.0, 0.02, 0.0, 0.0, 0.0, 72.0)
    assert de > 0.0  # + elevator = nose down
    assert da < 0.0  # bank left towards the centreline
    if ap.g.tecs:  # 10 m above the path on speed: an energy excess, so less thrust (total-energy rate error)
        assert thr < 0.47
    else:  # the classic autothrottle holds speed alone: on speed, the trim throttle
        assert thr == pytest.approx(0.47, abs=1e-6)


def test_slow_adds_throttle_and_sideslip_gets_rudder(ap):
    for _ in range(120):
        _, _, dr, thr = ap.step(-3000.0, 0.0, _on_path(-3000.0), 70.0, 0.0, 3.67, 0.0, 0.02, 0.0, 0.0, 0.05, 67.0)
    assert thr > 0.47
    assert dr < 0.0  # beta > 0 (wind from the right): yaw right, rudder negative


def test_meridian_convergence_rotates_the_runway_axes():
    """East of the threshold at 60 N, flying the runway's true heading is not flying parallel to it."""
    ac = load_aircraft(load_profile(PROFILES / "default.toml"))
    lat = math.radians(60.0)
    ap = Autopilot(ac.gains, Trim(0.0, 0.5, 72.0), Geometry(0.0, GP, TCH, lat), 1 / 120)
    # 10 km east of a north-pointing runway: the local north differs by 10e3 tan(60 deg)/R ~ 0.156 deg
    _, _, _, y_dot = ap.deviations(0.0, 10e3, 0.0, 70.0, 0.0, 0.0)
    assert y_dot == pytest.approx(-70.0 * 10e3 * math.tan(lat) / 6.394e6, rel=0.01)


def test_the_flare_command_starts_at_the_entry_sink_and_ends_at_the_touchdown_sink(ap):
    """Exponential flare h'_c = -(h - h_off) / tau with tau, h_off from continuity at entry (autopilot.py): at
    entry the sink-rate error is zero (no step in the pitch command), at h = 0 the command is the touchdown sink."""
    g = ap.g
    h0, sink0 = g.flare_height_m - 0.01, 3.8
    x = -300.0
    ap.step(x, 0.0, _on_path(x), 70.0, 0.0, sink0, 0.0, 0.02, 0.0, 0.0, 0.0, 72.0, h0)
    assert ap.flaring
    tau = ap._flare_tau
    assert tau == pytest.approx(h0 / (sink0 - g.touchdown_sink_mps))
    assert ap._int_flare == pytest.approx(0.0, abs=1e-12)  # zero sink-rate error at entry
    assert ap._flare_h_off == pytest.approx(-tau * g.touchdown_sink_mps)
    # the command at the runway: h'_c(0) = h_off / tau = -touchdown sink
    assert -(0.0 - ap._flare_h_off) / tau == pytest.approx(-g.touchdown_sink_mps)


def test_the_flare_feeds_the_commanded_path_angle_forward(ap):
    """Pitch command of the flare (autopilot.py): at entry (zero sink-rate error) the theta_entry + T_theta2 s_0 /
    (tau V) lead; one step later, with the sink held, the commanded path-angle change (s_0 - s_c) / V joins it,
    the ground effect's angle of attack -(k_v V_0 / 2) ln(k_ge(h) / k_ge(h_f)) with it, and the P and I terms act
    on e = s_0 - s_c. V: the smoothed true airspeed (here TAS = ground speed, no wind: no speed change, no gust)."""
    g = ap.g
    assert g.flare_t_path_s == pytest.approx(2.26) and g.k_flare == pytest.approx(0.03)
    h0, sink0, v = g.flare_height_m - 0.01, 3.8, 70.0
    vg = math.hypot(v, sink0)
    x = -300.0
    ap.step(x, 0.0, _on_path(x), v, 0.0, sink0, 0.0, 0.02, 0.0, 0.0, 0.0, 72.0, h0, tas=vg)
    tau = ap._flare_tau
    lead = g.flare_t_path_s * sink0 / (tau * vg)
    assert ap._theta_c - ap._theta_flare0 == pytest.approx(lead, rel=1e-12)
    assert math.degrees(lead) == pytest.approx(1.4, abs=0.2)  # 2.26 s x 3.8 m/s / (4.8 s x 70 m/s)
    h1 = h0 - 0.5
    ap.step(x + 0.6, 0.0, _on_path(x), v, 0.0, sink0, 0.0, 0.02, 0.0, 0.0, 0.0, 72.0, h1, tas=vg)
    sink_c = (h1 - ap._flare_h_off) / tau
    e = sink0 - sink_c
    k_ge = [1.0 + g.flare_ge_k * math.exp(-(h + g.flare_ge_arp_m) / g.flare_ge_decay_m) for h in (h1, h0)]
    ge = -0.5 * g.flare_k_v * vg * math.log(k_ge[0] / k_ge[1])
    assert ge < 0.0  # more lift near the ground: less angle of attack
    want = (ap._theta_flare0 + (sink0 - sink_c) / vg + g.flare_t_path_s * sink0 / (tau * vg) + ge + g.k_flare * e
            + g.k_flare_i * e * ap.dt)
    assert ap._theta_c == pytest.approx(want, rel=1e-12)


def _full_decrab(ap):
    g = dataclasses.replace(ap.g, align_bank_max_rad=math.inf, align_sideslip_max_rad=math.inf)
    return Autopilot(g, ap.trim, Geometry(heading_rad=0.0, glidepath_rad=GP, tch_m=TCH, threshold_lat_rad=0.0), ap.dt)


def test_the_alignment_engages_at_450_ft(ap):
    """The 737 MAX alignment mode's height (aircraft file, 737 MAX FCOM): not aligning at 451 ft main-gear height,
    aligning at 449 ft, and latched from then on."""
    g = ap.g
    assert g.align_height_m == pytest.approx(450.0 * units.FT)
    x = -2600.0
    ap.step(x, 0.0, _on_path(x), 70.0, 0.0, 3.6, 0.0, 0.02, 0.0, 0.0, 0.0, 72.0, 451.0 * units.FT,
            yaw=(math.radians(8.0), 0.0))
    assert not ap.aligning
    ap.step(x, 0.0, _on_path(x), 70.0, 0.0, 3.6, 0.0, 0.02, 0.0, 0.0, 0.0, 72.0, 449.0 * units.FT,
            yaw=(math.radians(8.0), 0.0))
    assert ap.aligning


def test_the_alignment_steers_the_main_gear_onto_the_centreline(ap):
    """While aligning, the localizer loop flies the main gears' centre, gear_arm behind the guidance point:
    crabbed 3 deg right with the guidance point on the centreline, the gear trails l sin(3 deg) left, and the
    bank command (hence the aileron, k_phi per rad) moves right by k_loc_p l sin(3 deg); a yaw rate adds
    k_loc_d l cos(crab) r."""
    g = ap.g
    geom = Geometry(heading_rad=0.0, glidepath_rad=GP, tch_m=TCH, threshold_lat_rad=0.0)
    at_imu = Autopilot(g, ap.trim, geom, ap.dt)
    at_gear = Autopilot(g, ap.trim, geom, ap.dt, gear_arm_m=10.11)
    crab, r = math.radians(3.0), 0.01
    x = -200.0
    args = (x, 0.0, _on_path(x), 70.0, 0.0, 3.6, 0.0, 0.02, 0.0, 0.0, 0.0, 72.0, 0.5 * g.align_height_m)
    da0 = at_imu.step(*args, yaw=(crab, r))[1]
    da1 = at_gear.step(*args, yaw=(crab, r))[1]
    want = g.k_phi * (g.k_loc_p * 10.11 * math.sin(crab) + g.k_loc_d * 10.11 * math.cos(crab) * r)
    assert da1 - da0 == pytest.approx(want, rel=1e-9)
    assert da1 > da0  # towards the side the gear trails from


def test_the_decrab_yaws_towards_the_runway_and_holds_the_sideslip(ap):
    """Full decrab (no bank allowance): below the align height, crabbed 8 deg right of the runway (heading 0) with
    the wind from the right (beta > 0 once aligned): rudder nose left (+) from the heading error; the sideslip terms
    add rudder, bank and aileron into the wind (right)."""
    x = -200.0
    ap = _full_decrab(ap)
    g = ap.g
    h = 0.5 * g.align_height_m
    de, da, dr, thr = ap.step(x, 0.0, _on_path(x), 70.0, 0.0, 3.6, 0.0, 0.02, 0.0, 0.0, 0.0, 72.0, h,
                              yaw=(math.radians(8.0), 0.0))
    assert ap.aligning
    assert dr == pytest.approx(g.k_r_align * math.radians(8.0) / g.align_tau_s)
    _, da_b, dr_b, _ = ap.step(x, 0.0, _on_path(x), 70.0, 0.0, 3.6, 0.0, 0.02, 0.0, 0.0, 0.1, 72.0, h,
                               yaw=(0.0, 0.0))
    assert dr_b == pytest.approx(g.k_beta_align * 0.1, rel=1e-9)  # aligned: the rudder that holds beta = 0.1
    assert da_b > 0.0  # right wing down into the wind


def _align_step(ap, crab_rad, beta_rad):
    x = -200.0
    return ap.step(x, 0.0, _on_path(x), 70.0, 0.0, 3.6, 0.0, 0.02, 0.0, 0.0, beta_rad, 72.0,
                   0.5 * ap.g.align_height_m, yaw=(crab_rad, 0.0))


def test_the_partial_decrab_limits_the_sideslip_to_5_deg(ap):
    """The sideslip limit is the smaller of the 737 MAX's 5 deg and the bank allowance over the bank per sideslip at
    the approach speed, bank_max / (k_phi_align (V_c / V_design)^2) = 5.7 deg at 140 KCAS: 5 deg binds. Crabbed
    8 deg with no sideslip yet (wind correction eta = crab + beta = 8 deg > b_max): the heading error the rudder
    works on is b_max, so the aircraft keeps 8 deg - b_max of crab; within the limit (eta = 4 deg) the law is the
    full decrab's, bit for bit."""
    g = ap.g
    assert math.isfinite(g.align_bank_max_rad) and g.align_cas_mps > 0.0
    assert math.degrees(g.align_sideslip_max_rad) == pytest.approx(5.0)
    sq = ap.trim.cas_mps / g.align_cas_mps
    b_bank = g.align_bank_max_rad / (g.k_phi_align * sq * sq)
    assert math.degrees(b_bank) == pytest.approx(5.7, abs=0.05)  # 4.9 deg / 0.862 at 72 m/s (140 KCAS: 72.02 m/s)
    b_max = g.align_sideslip_max_rad
    full = _full_decrab(ap)
    _, _, dr, _ = _align_step(ap, math.radians(8.0), 0.0)
    assert dr == pytest.approx(g.k_r_align * b_max / g.align_tau_s, rel=1e-12)
    _, _, dr_full, _ = _align_step(full, math.radians(8.0), 0.0)
    assert dr_full == pytest.approx(g.k_r_align * math.radians(8.0) / g.align_tau_s, rel=1e-12)
    # crab 3 deg left, sideslip 1 deg: inside the limit, the same commands as the full decrab
    ap2 = Autopilot(g, ap.trim, Geometry(heading_rad=0.0, glidepath_rad=GP, tch_m=TCH, threshold_lat_rad=0.0), ap.dt)
    full2 = _full_decrab(ap)
    assert _align_step(ap2, math.radians(3.0), math.radians(1.0)) == _align_step(full2, math.radians(3.0),
                                                                                   math.radians(1.0))
    # at the held limit (beta = b_max, crab = eta - b_max) the heading error is zero and the bank fed forward,
    # k_pb 5 deg = 4.3 deg, is inside the allowance
    ap3 = Autopilot(g, ap.trim, Geometry(heading_rad=0.0, glidepath_rad=GP, tch_m=TCH, threshold_lat_rad=0.0), ap.dt)
    _, _, dr3, _ = _align_step(ap3, math.radians(2.5), b_max)
    assert dr3 == pytest.approx(g.k_beta_align * b_max, rel=1e-9)
    assert g.k_phi_align * sq * sq * b_max < g.align_bank_max_rad


def test_the_sideslip_limit_is_scheduled_with_speed(ap):
    """The bank per sideslip grows with the dynamic pressure, so above about 150 KCAS the bank allowance, not the
    5 deg, limits the sideslip: at 160 kt the limit is bank_max / (k_phi_align (160 / 140)^2) = 4.4 deg; at 133 and
    140 kt it is 5 deg (crabbed 12 deg, no sideslip)."""
    g = ap.g

    def dr_at(kt):
        a = Autopilot(g, Trim(theta_rad=0.02, throttle=0.47, cas_mps=kt * units.KT),
                      Geometry(heading_rad=0.0, glidepath_rad=GP, tch_m=TCH, threshold_lat_rad=0.0), ap.dt)
        return _align_step(a, math.radians(12.0), 0.0)[2]

    five = g.k_r_align * g.align_sideslip_max_rad / g.align_tau_s
    assert dr_at(133.0) == pytest.approx(five, rel=1e-12)
    assert dr_at(140.0) == pytest.approx(five, rel=1e-12)
    b_fast = g.align_bank_max_rad / (g.k_phi_align * (160.0 * units.KT / g.align_cas_mps) ** 2)
    assert math.degrees(b_fast) == pytest.approx(4.37, abs=0.02)
    assert dr_at(160.0) == pytest.approx(g.k_r_align * b_fast / g.align_tau_s, rel=1e-12)
