"""Loop design check on the landing-configuration linearization (JSBSim FGLinearization, still air).

On the landing linearization of each shipped profile (its runway, speed, temperature; no wind), every
autopilot loop, broken one at a time with the others closed, must have a gain margin >= 6 dB and a
phase margin >= 45 deg (python-control stability_margins), and the fully closed linear loop must be stable.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
import pytest

from approachsim.flight import design
from approachsim.flight.run import Approach
from approachsim.profile import load_profile

PROFILES = Path(__file__).resolve().parents[3] / "profiles"

pytestmark = pytest.mark.slow  # trims and linearizes JSBSim for every shipped profile

GM_MIN_DB = 6.0
PM_MIN_DEG = 45.0


NAMES = ("default", "gray-maybeck", "hot-high-crosswind")


@pytest.fixture(scope="module", params=NAMES)
def setup(request):
    profile = load_profile(PROFILES / f"{request.param}.toml")
    approach = Approach(profile)
    return approach.linearization, approach.aircraft, profile.runway.glidepath_rad


def test_linearization_is_the_landing_configuration(setup):
    lin, ac, gp = setup
    assert lin.A.shape == (12, 12) and lin.B.shape == (12, 4)
    # TAS / CAS: 1.02 at 1000 ft above a sea-level runway, 1.14 at 6400 ft ISA +20 (hot-high)
    assert 1.0 < lin.vt_mps / ac.approach_speed_mps < 1.2
    # open-loop short period and Dutch roll are there and stable (reference/jsbsim.md: -0.56+-0.88j, -0.26+-1.06j)
    ev = np.linalg.eigvals(lin.A)
    assert np.any(np.abs(ev - (-0.56 + 0.88j)) < 0.15)
    assert np.any(np.abs(ev - (-0.26 + 1.06j)) < 0.15)


def test_every_loop_has_its_margins(setup):
    lin, ac, gp = setup
    result = design.loop_margins(lin, ac.gains, gp, ac.engine_lag_s)
    assert [m.loop for m in result] == list(design.LOOPS)
    for m in result:
        print(f"{m.loop:10s} GM {m.gm_db:6.1f} dB  PM {m.pm_deg:6.1f} deg  wc {m.wc_rad_s:.3f} rad/s")
        assert m.gm_db >= GM_MIN_DB, m
        assert m.pm_deg >= PM_MIN_DEG, m
    # the loops that do the tracking really cross over (not trivially small gains)
    by = {m.loop: m for m in result}
    assert by["glidepath"].wc_rad_s > 0.3
    assert by["localizer"].wc_rad_s > 0.2
    assert by["elevator"].wc_rad_s > 0.5


def test_closed_loop_is_stable(setup):
    lin, ac, gp = setup
    assert np.max(design.closed_loop_poles(lin, ac.gains, gp, ac.engine_lag_s).real) < 0.0


def test_the_check_can_fail(setup):
    """Ten times the glidepath gains (the law's own: the classic PID's, or TECS's pitch-channel gains) destroys
    the margins: the check has teeth."""
    lin, ac, gp = setup
    g = ac.gains
    if g.tecs:
        g = dataclasses.replace(g, tecs_k_pitch_damp=10 * g.tecs_k_pitch_damp, tecs_k_pitch_i=10 * g.tecs_k_pitch_i)
    else:
        g = dataclasses.replace(g, k_gs_p=10 * g.k_gs_p, k_gs_d=10 * g.k_gs_d)
    poles = design.closed_loop_poles(lin, g, gp, ac.engine_lag_s)
    m = {x.loop: x for x in design.loop_margins(lin, g, gp, ac.engine_lag_s)}["glidepath"]
    assert np.max(poles.real) >= 0.0 or m.gm_db < GM_MIN_DB or m.pm_deg < PM_MIN_DEG


def test_loop_transfer_of_a_known_system():
    """margins() on L = 2/(s (s+1)): PM = 38.7 deg at w = 1.25 rad/s, infinite GM (textbook)."""
    import control

    gm_db, pm_deg, wc = design.margins(control.tf([2.0], [1.0, 1.0, 0.0]))
    assert pm_deg == pytest.approx(38.67, abs=0.05)
    assert wc == pytest.approx(1.249, abs=0.005)
    assert gm_db == float("inf")


def test_tecs_loops_have_their_margins(setup):
    """The total energy control law (the aircraft file's TECS gains, design.tecs_gains) on the same
    linearization: every loop GM >= 6 dB, PM >= 45 deg, closed loop stable."""
    lin, ac, gp = setup
    g = dataclasses.replace(ac.gains, tecs=True)
    assert np.max(design.closed_loop_poles(lin, g, gp, ac.engine_lag_s).real) < 0.0
    result = design.loop_margins(lin, g, gp, ac.engine_lag_s)
    for m in result:
        print(f"TECS {m.loop:10s} GM {m.gm_db:6.1f} dB  PM {m.pm_deg:6.1f} deg  wc {m.wc_rad_s:.3f} rad/s")
        assert m.gm_db >= GM_MIN_DB, m
        assert m.pm_deg >= PM_MIN_DEG, m
    by = {m.loop: m for m in result}
    assert by["glidepath"].wc_rad_s > 0.3  # it tracks, as the classic law's (test_every_loop_has_its_margins)


@pytest.mark.parametrize("spd_weight", [0.0, 0.5, 1.0])
def test_tecs_design_rule_keeps_the_margins_at_every_speed_weight(setup, spd_weight):
    """design.tecs_gains at the profile's own trim speed, for path priority (0), 0.5 and Lambregts' equal
    weighting (1): every loop keeps GM >= 6 dB and PM >= 45 deg. Without step 2 of the rule (the pitch gains not
    divided by w_p + w_k) the equal-weight law loses them: the step is what keeps the elevator loop's margin."""
    lin, ac, gp = setup
    gains = design.tecs_gains(ac.gains, lin.vt_mps, spd_weight)
    g = dataclasses.replace(ac.gains, tecs=True, **gains)
    assert np.max(design.closed_loop_poles(lin, g, gp, ac.engine_lag_s).real) < 0.0
    for m in design.loop_margins(lin, g, gp, ac.engine_lag_s):
        print(f"TECS w_k {spd_weight} {m.loop:10s} GM {m.gm_db:6.1f} dB  PM {m.pm_deg:6.1f} deg  wc {m.wc_rad_s:.3f}")
        assert m.gm_db >= GM_MIN_DB, m
        assert m.pm_deg >= PM_MIN_DEG, m
    if spd_weight == 1.0:
        share = 2.0  # w_p + w_k
        bad = dataclasses.replace(g, tecs_k_pitch_damp=share * g.tecs_k_pitch_damp,
                                  tecs_k_pitch_i=share * g.tecs_k_pitch_i)
        by = {m.loop: m for m in design.loop_margins(lin, bad, gp, ac.engine_lag_s)}
        assert by["elevator"].pm_deg < PM_MIN_DEG or by["glidepath"].pm_deg < PM_MIN_DEG


@pytest.mark.parametrize("setup", ["default"], indirect=True)
def test_tecs_file_gains_are_the_design_rule(setup):
    """The aircraft file's TECS gains are design.tecs_gains of its classic gains at the default profile's trim TAS
    (73.1 m/s), written to 3 significant digits: within half a unit of the third digit, 5e-3 relative."""
    lin, ac, gp = setup
    assert lin.vt_mps == pytest.approx(73.1, abs=0.05)
    g = ac.gains
    for name, want in design.tecs_gains(g, lin.vt_mps, g.tecs_spd_weight).items():
        print(f"{name} file {getattr(g, name)} rule {want:.4f}")
        assert getattr(g, name) == pytest.approx(want, rel=5e-3, abs=1e-12), name


def test_tecs_thrust_gain_and_decrab_gains_are_the_linearizations(setup):
    """K_thr = g / (dV'/d throttle) and the decrab's sideslip-holding rudder, bank and aileron come from the
    landing linearization's derivatives (aircraft file comments); the file holds the default profile's (140 KCAS,
    sea level), within 15 % of every shipped profile's (gray-maybeck flies 133 kt: its yaw-rate gain is 6.5, 13 %
    above; the gains are not scheduled with speed)."""
    lin, ac, gp = setup
    from approachsim import units

    a, b = lin.A, lin.B
    beta, phi, p, r = 4, 5, 6, 8
    k_thr = units.G0 / (b[0, 0] * units.FT)
    n_dr, n_r, n_b = b[r, 3], a[r, r], a[r, beta]
    k_beta = -n_b / n_dr
    k_phi = -(a[beta, beta] + b[beta, 3] * k_beta) / a[beta, phi]
    k_da = -(a[p, beta] + b[p, 3] * k_beta) / b[p, 1]
    k_r = (1.0 / (ac.gains.align_tau_s / 3.0) + n_r) / -n_dr  # pole of r' = N_r r + N_dr k (r - r_c) at -1/tau_r
    g = ac.gains
    print(f"K_thr {k_thr:.3f} k_beta_align {k_beta:.3f} k_phi_align {k_phi:.3f} k_da_align {k_da:.3f} "
          f"k_r_align {k_r:.3f}")
    for want, got in ((k_thr, g.tecs_thr_per_rad), (k_beta, g.k_beta_align), (k_phi, g.k_phi_align),
                      (k_da, g.k_da_align), (k_r, g.k_r_align)):
        assert got == pytest.approx(want, rel=0.15)


def test_the_decrab_sideslip_limit_follows_the_dynamic_pressure(setup):
    """The partial decrab's sideslip limit is align_bank_max / (k_phi_align (V_c / V_design)^2): the bank per
    sideslip of each shipped profile's own linearization (-(Y_beta + Y_dr k_beta_align) / (g / V), as the aircraft
    file derives k_phi_align at 140 KCAS) is the design value scaled by the dynamic pressure ratio, within 3 %
    (gray-maybeck flies 133 kt: 0.794 against 0.778; hot-high flies 140 KCAS at a higher TAS: the same q)."""
    lin, ac, gp = setup
    g = ac.gains
    k_phi = design.bank_per_sideslip(lin)
    sq = ac.approach_speed_mps / g.align_cas_mps
    scheduled = g.k_phi_align * sq * sq
    print(f"bank per sideslip: linearization {k_phi:.3f}, scheduled {scheduled:.3f}; sideslip limit "
          f"{np.degrees(g.align_bank_max_rad / scheduled):.2f} deg for {np.degrees(g.align_bank_max_rad):.1f} deg")
    assert scheduled == pytest.approx(k_phi, rel=0.03)


def test_flare_gains_are_the_linearizations(setup):
    """The flare's path lag T_theta2 = -1 / A[alpha, alpha] (aircraft file flare_t_path_s, the default profile's
    2.26 s; within 15 % of every shipped profile's), and the flare loop (sink-rate error -> pitch command -> the
    pitch loop -> the guidance point's climb rate V (theta - alpha) + l q, l = 9.88 m from the CG forward to the IMU:
    737.xml CG x 639 in, the aircraft file's IMU x 250 in) with k_flare and k_flare_i: phase margin >= 45 deg, and
    its crossover below the closed pitch loop's natural frequency (loop separation)."""
    import control

    from approachsim import units

    lin, ac, gp = setup
    g = ac.gains
    t2 = -1.0 / lin.A[1, 1]
    print(f"T_theta2 {t2:.3f} s (file {g.flare_t_path_s})")
    assert g.flare_t_path_s == pytest.approx(t2, rel=0.15)
    idx = [0, 1, 2, 3]  # Vt, alpha, theta, q; elevator
    scale = np.diag([units.FPS, 1.0, 1.0, 1.0])
    a = scale @ lin.A[np.ix_(idx, idx)] @ np.linalg.inv(scale)
    b = scale @ lin.B[idx, 2:3]
    a_cl = a + b @ np.array([[0.0, 0.0, g.k_theta, g.k_q]])  # de = -k_theta (theta_c - theta) + k_q q
    l_imu = (639.0 - 250.0) * units.IN
    plant = control.ss(a_cl, -g.k_theta * b, np.array([[0.0, -lin.vt_mps, lin.vt_mps, l_imu]]), 0.0)
    s = control.tf("s")
    gm, pm, _, wc = control.margin((g.k_flare + g.k_flare_i / s) * plant)
    wn = float(np.max(np.abs(np.linalg.eigvals(a_cl))))
    # MIL-F-8785C low-altitude Dryden scale of the horizontal gust at 25 ft, L_u = h / (0.177 + 0.000823 h)^1.2
    h_ft = 25.0
    l_u = h_ft / (0.177 + 0.000823 * h_ft) ** 1.2 * units.FT
    corner = lin.vt_mps / l_u
    print(f"flare loop: PM {pm:.1f} deg at {wc:.2f} rad/s, GM {gm}, pitch loop natural frequency {wn:.2f} rad/s, "
          f"horizontal gust corner V / L_u {corner:.2f} rad/s")
    assert pm >= PM_MIN_DEG
    assert not np.isfinite(gm) or 20.0 * np.log10(gm) >= GM_MIN_DB
    assert wc < wn
    # below the gust band: a loop crossing inside it amplifies the gust at the main gear (docs/touchdown.md sec. 4)
    assert wc < 0.5 * corner


def test_flare_feed_forwards_are_the_linearizations(setup):
    """The flare's angle-of-attack feed-forwards (aircraft file) against each shipped profile's landing
    linearization: flare_k_v = A[alpha, V] / (A[alpha, alpha] + A[alpha, theta]) (speed lost at constant lift and
    path) and flare_k_gust = A[alpha, V] / A[alpha, alpha] = Z_V / Z_alpha (an airspeed gust at constant lift),
    rad s/m; one aircraft file serves the three profiles, whose speeds and densities differ (the default's 0.00838
    and 0.00824; gray-maybeck's 14 % higher), hence 15 % as for T_theta2."""
    from approachsim import units

    lin, ac, gp = setup
    g = ac.gains
    a = lin.A
    k_v = a[1, 0] / (a[1, 1] + a[1, 2]) / units.FT  # A[alpha, Vt] is per ft/s
    k_gust = a[1, 0] / a[1, 1] / units.FT
    print(f"k_v {k_v:.5f} (file {g.flare_k_v}), k_gust {k_gust:.5f} (file {g.flare_k_gust})")
    assert g.flare_k_v == pytest.approx(k_v, rel=0.15)
    assert g.flare_k_gust == pytest.approx(k_gust, rel=0.15)


def test_flare_ground_effect_is_the_models_table():
    """The flare's ground-effect lift factor 1 + k exp(-h_arp / h_g) (aircraft file flare_ge_*) against JSBSim's
    737.xml kCLge table (lift factor against the reference point's height over the span, b = 94.7 ft): within
    0.01 of every point (the fit's largest error is 0.006, and the flare's pitch follows ln k_ge, so 0.01 is 1 %
    of the lift, 0.2 deg of angle of attack); the reference point's height above the main gear is 737.xml's AERORP
    z less the main gear's z."""
    import xml.etree.ElementTree as ET

    import jsbsim

    from approachsim import units
    from approachsim.flight.aircraft import load_aircraft

    g = load_aircraft(load_profile(PROFILES / "default.toml")).gains
    root = ET.parse(Path(jsbsim.get_default_root_dir()) / "aircraft" / "737" / "737.xml").getroot()
    span_ft = float(root.find("metrics/wingspan").text)
    arp_z_in = float(root.find("metrics/location[@name='AERORP']/z").text)
    gear_z_in = float(root.find("ground_reactions/contact[@name='Left Main Gear']/location/z").text)
    assert g.flare_ge_arp_m == pytest.approx((arp_z_in - gear_z_in) * units.IN, abs=0.5 * units.IN)
    table = root.find(".//function[@name='aero/function/kCLge']/table/tableData").text.split()
    hb, k = np.array(table[0::2], float), np.array(table[1::2], float)
    fit = 1.0 + g.flare_ge_k * np.exp(-hb * span_ft * units.FT / g.flare_ge_decay_m)
    print("fit - table:", np.round(fit - k, 4))
    assert np.max(np.abs(fit - k)) < 0.01


def test_the_nose_gear_floor_is_the_gear_geometry():
    """The flare's nose-gear floor (aircraft file flare_pitch_min_deg) is the pitch at which the main gear, touching
    first, takes the aircraft's weight before the nose gear touches, plus a margin for the pitch's scatter: JSBSim's
    737.xml puts the nose and main gear contact points at the same body z (so any nose-down pitch touches the nose
    first), 490 in apart; at its static load split (CG x between them) the main struts compress by W (x_cg - x_n) /
    (2 L k_m) and the nose strut by W (x_m - x_cg) / (L k_n), so the nose wheels stay clear while the mains take the
    weight above atan((d_m - d_n) / L) = 0.62 deg at the heaviest landing weight (114,000 lb). The margin, 0.4 deg,
    is about one sd of the touchdown pitch in light turbulence (0.39 deg in the 10 kt tailwind condition,
    docs/touchdown.md sec. 5); the file's 1.0 deg is their sum, rounded to 0.05 deg."""
    import math
    import xml.etree.ElementTree as ET

    import jsbsim

    from approachsim.flight.aircraft import load_aircraft

    ac = load_aircraft(load_profile(PROFILES / "default.toml"))
    root = ET.parse(Path(jsbsim.get_default_root_dir()) / "aircraft" / "737" / "737.xml").getroot()

    def contact(name: str) -> tuple[float, float, float]:
        c = root.find(f"ground_reactions/contact[@name='{name}']")
        return (float(c.find("location/x").text), float(c.find("location/z").text),
                float(c.find("spring_coeff").text))

    x_n, z_n, k_n = contact("Nose Gear")
    x_m, z_m, k_m = contact("Left Main Gear")
    assert z_n == z_m  # the same contact height: pitch 0 touches both at once
    x_cg = float(root.find("mass_balance/location[@name='CG']/x").text)
    span_in = x_m - x_n
    w = ac.mass.max_landing_weight_lb
    d_m = w * (x_cg - x_n) / span_in / 2.0 / k_m * 12.0  # in
    d_n = w * (x_m - x_cg) / span_in / k_n * 12.0
    geometric_deg = math.degrees(math.atan((d_m - d_n) / span_in))
    floor_deg = math.degrees(ac.gains.flare_pitch_min_rad)
    print(f"main strut {d_m:.2f} in, nose strut {d_n:.2f} in, geometric minimum {geometric_deg:.3f} deg, "
          f"floor {floor_deg:.2f} deg")
    assert floor_deg == pytest.approx(geometric_deg + 0.4, abs=0.05)
