"""The flight loop's compiled pieces against their readable oracles, driven with the same random input sequences
(hundreds of steps): the autopilot (flight/autopilot.Autopilot) through saturation, integrator freeze and the
flare, the Dryden turbulence (flight/turbulence.DrydenTurbulence) through the low-altitude, blended and table
regimes, the stabilized-approach monitor (flight/envelope.StabilityMonitor) firing each of its reasons: outputs and
state equal bit for bit. Then the termination function, and fly_step as the composition of its pieces (against
the same composition written in Python on the oracles, as the flight loop used to be)."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from approachsim import geo, units
from approachsim.core import layouts, tables
from approachsim.core.entry import entry_point
from approachsim.core.loop import flight_step as fk
from approachsim.flight import vectors as fv
from approachsim.flight.aircraft import load_aircraft
from approachsim.flight.autopilot import Autopilot, Geometry, Trim
from approachsim.flight.design import AutopilotGains
from approachsim.flight.envelope import (
    MON_GLIDEPATH,
    MON_LOCALIZER,
    MON_OK,
    MON_SINK,
    MON_SPEED,
    StabilityMonitor,
    unstabilized_reason,
)
from approachsim.flight.run import termination_reason
from approachsim.flight.turbulence import DrydenTurbulence, scales
from approachsim.glidepath import GlidePath
from approachsim.profile import load_profile

pytestmark = pytest.mark.equality  # also run compiled for the generic CPU target (scripts/test.sh)

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
DT = 1.0 / 120.0
GP = math.radians(3.0)
TCH = 50.0 * units.FT


@pytest.fixture(scope="module")
def gains():
    return load_aircraft(load_profile(PROFILES / "default.toml")).gains


LAT = math.radians(39.8)


def _autopilot(gains):
    return Autopilot(gains, Trim(theta_rad=0.03, throttle=0.45, cas_mps=72.0),
                     Geometry(heading_rad=0.4, glidepath_rad=GP, tch_m=TCH, threshold_lat_rad=LAT), DT,
                     gear_arm_m=10.11)


def test_the_autopilot_gain_layout_is_the_gains_dataclass():
    import dataclasses

    assert layouts.AP_GAINS == tuple(f.name for f in dataclasses.fields(AutopilotGains))
    assert layouts.N_AP_PAR == len(layouts.AP_GAINS) + 14


def _autopilot_inputs(rng, n, *, flare):
    """n steps of guidance and inner-loop inputs around a 3 deg approach, with excursions large enough to hit the
    pitch and bank limits and throttle saturation; with flare, the main gear descends through the flare and
    retard heights to the ground."""
    x = np.linspace(-6000.0, -300.0, n)
    z = TCH - x * math.tan(GP) + rng.normal(0.0, 3.0, n)
    z[n // 5:n // 5 + 40] += 80.0  # far above the path: pitch command limited, glidepath integral frozen
    y = rng.normal(0.0, 5.0, n)
    y[n // 3:n // 3 + 40] += 400.0  # far right: bank command limited, localizer integral frozen
    v = np.column_stack([70.0 + rng.normal(0.0, 1.0, n), rng.normal(0.0, 1.0, n), 3.7 + rng.normal(0.0, 0.5, n)])
    cas = 72.0 + rng.normal(0.0, 1.0, n)
    tas = cas * 1.05 + rng.normal(0.0, 0.5, n)
    cas[n // 2:n // 2 + 150] -= 30.0  # far too slow (CAS only: no TAS change): throttle at 1, integral frozen
    cas[2 * n // 3:2 * n // 3 + 150] += 30.0  # far too fast: throttle at 0
    tas[::7] = np.nan  # no speed complement at these steps
    att = rng.normal(0.0, 0.05, (n, 6))  # phi, theta, p, q, beta, yaw rate r
    psi = 0.4 + rng.normal(0.0, 0.1, n)  # heading about the runway's (_autopilot: 0.4 rad), crabbed
    psi[::5] += 2.0 * math.pi  # the crab is wrapped
    h_gear = np.full(n, np.nan)
    if flare:
        h_gear = np.linspace(40.0, -1.0, n)
    return x, y, z, v, att, cas, h_gear, tas, psi


@pytest.mark.parametrize("law", ["classic", "tecs"])
@pytest.mark.parametrize("flare", [False, True])
def test_autopilot_kernel_equals_the_oracle_bit_for_bit(gains, flare, law):
    import dataclasses

    gains = dataclasses.replace(gains, tecs=law == "tecs")
    if flare:  # the nose-gear floor high enough to bind part of the time under these inputs (and be left)
        gains = dataclasses.replace(gains, flare_pitch_min_rad=math.radians(6.0), flare_pitch_min_height_m=30.0)
    rng = np.random.default_rng(5 + flare)
    n = 600
    x, y, z, v, att, cas, h_gear, tas, psi = _autopilot_inputs(rng, n, flare=flare)
    ap = _autopilot(gains)
    ap.surface_slope = 0.012 if flare else 0.0  # the flare's closing speed on a 1.2 % runway slope
    par, st = fv.autopilot_arrays(ap)
    seen = {"pitch limited": 0, "bank limited": 0, "throttle 1": 0, "throttle 0": 0, "flaring": 0, "idle": 0,
            "aligning": 0, "sideslip limited": 0, "full decrab": 0, "floored": 0, "above the floor": 0}
    floor = gains.flare_pitch_min_rad + math.atan(ap.surface_slope)
    sq = ap.trim.cas_mps / gains.align_cas_mps
    b_max = min(gains.align_sideslip_max_rad,  # the partial decrab's sideslip limit
                gains.align_bank_max_rad / (gains.k_phi_align * sq * sq))
    for k in range(n):
        args = (x[k], y[k], z[k], *v[k], att[k, 0], att[k, 1], att[k, 2], att[k, 3], att[k, 4], cas[k])
        int_p = ap.int_b if gains.tecs else ap.int_d
        int_y = ap.int_y
        hg = None if math.isnan(h_gear[k]) else h_gear[k]
        want = ap.step(*args, hg, None if math.isnan(tas[k]) else tas[k],
                       yaw=None if hg is None else (psi[k], att[k, 5]))
        got = fk.autopilot_step(par, st, args[:6], (*args[6:], h_gear[k], tas[k],
                                                     psi[k] if hg is not None else math.nan, att[k, 5]))
        # exact: the kernel and its Python oracle do the same scalar IEEE operations in the same order (numba emits
        # no FMA without fastmath, both call the same libm), which the generic-CPU pass checks as well
        assert got == want, f"step {k}"
        np.testing.assert_array_equal(st, np.array(ap.state()), err_msg=f"state at step {k}")
        seen["pitch limited"] += (ap.int_b if gains.tecs else ap.int_d) == int_p and not ap.flaring
        seen["bank limited"] += ap.int_y == int_y
        seen["throttle 1"] += want[3] == 1.0
        seen["throttle 0"] += want[3] == 0.0
        seen["flaring"] += ap.flaring
        seen["idle"] += ap.flaring and h_gear[k] <= gains.retard_height_m
        below = ap.flaring and h_gear[k] <= gains.flare_pitch_min_height_m
        seen["floored"] += below and ap.state()[layouts.APS_THETA_C] == floor and want[3] == 0.0
        seen["above the floor"] += below and ap.state()[layouts.APS_THETA_C] > floor
        seen["aligning"] += ap.aligning
        eta = abs(math.remainder(psi[k] - 0.4, 2.0 * math.pi) + att[k, 4])  # crab + beta (convergence: < 1e-4)
        seen["sideslip limited"] += ap.aligning and eta > 1.05 * b_max
        seen["full decrab"] += ap.aligning and eta < 0.95 * b_max
    assert seen["pitch limited"] > 0 and seen["bank limited"] > 0, seen
    assert seen["throttle 1"] > 0 and seen["throttle 0"] > 0, seen
    if flare:
        assert seen["flaring"] > 100 and seen["idle"] > 0 and seen["aligning"] > 100, seen
        assert seen["floored"] > 20 and seen["above the floor"] > 20, seen
        assert seen["sideslip limited"] > 20 and seen["full decrab"] > 20, seen
    else:
        assert seen["flaring"] == 0 and seen["aligning"] == 0, seen


def test_dryden_scales_follow_the_standard_across_the_regimes():
    """The kernel's three regimes and the table's held ends against the standard's forms written here (MIL-F-8785C:
    the low-altitude model below 1000 ft, numpy.interp of the fig. 7 row above 2000 ft, linear in between). The
    interpolation rounds in another order than numpy.interp's: the tolerance is a few eps of the table's sigmas
    (under 20 ft/s), 4 eps x 20 = 1.8e-14 ft/s; the scale lengths' arithmetic is the same expression (equal)."""
    heights = np.concatenate([[-5.0, 0.0, 10.0, 1000.0, 2000.0, 500.0, 1750.0, 80000.0, 90000.0],
                              np.random.default_rng(2).uniform(0.0, 90000.0, 400)])
    tol = 4 * np.finfo(float).eps * 20.0
    for level, (w20, index) in (("light", (25.0, 3)), ("moderate", (50.0, 4)), ("severe", (75.0, 6))):
        turb = DrydenTurbulence(level, np.random.default_rng(0), 1, DT, 0.0)
        par, _ = fv.dryden_arrays(turb)
        alt, sig = par[layouts.TB_PAR.slice("poe_alt_ft")], par[layouts.TB_PAR.slice("poe_sigma_fps")]
        for h_in in heights:
            h = max(h_in, 10.0)
            L_u, L_w, s_u, s_w = fk.dryden_scales(h_in, w20, alt, sig)
            if h <= 1000.0:
                den = 0.177 + 0.000823 * h
                assert (L_u, L_w) == (h / den**1.2, h), (level, h)
                assert s_w == 0.1 * w20 and s_u == 0.1 * w20 / den**0.4, (level, h)
                continue
            table = float(np.interp(h, alt, sig))
            f = min((h - 1000.0) / 1000.0, 1.0)
            want = 0.1 * w20 + f * (table - 0.1 * w20) if h <= 2000.0 else table
            assert abs(s_u - want) <= tol and s_w == s_u, (level, h, s_u, want)
            assert L_u == L_w == (1000.0 + f * 750.0 if h <= 2000.0 else 1750.0), (level, h)
        assert scales(1500.0, w20, index) == fk.dryden_scales(1500.0, w20, alt, sig)  # the same table


@pytest.mark.parametrize("level", ["light", "moderate", "severe"])
def test_dryden_kernel_equals_the_oracle_bit_for_bit(level):
    """Heights from 3000 ft down to the ground (table, blend and low-altitude regimes) at varying speed; the
    sequence starts at step 5 so the coefficients are first evaluated off the COEFF_EVERY grid."""
    n = 700
    rng = np.random.default_rng(11)
    turb = DrydenTurbulence(level, np.random.default_rng(3), n + 5, DT, wind_to_rad=2.2)
    par, st = fv.dryden_arrays(turb)
    nu = turb.nu.copy()
    h = np.linspace(3000.0, -3.0, n) * units.FT + rng.normal(0.0, 2.0, n)
    vt = 70.0 + rng.normal(0.0, 3.0, n)
    vt[100] = 0.1  # the speed floor of 1 ft/s
    for i in range(n):
        k = i + 5
        want = turb.step(k, h[i], vt[i])
        got = fk.dryden_step(par, st, nu, k, h[i], vt[i])
        assert got == want, f"step {k}"
        np.testing.assert_array_equal(st, np.array(turb.state()), err_msg=f"state at step {k}")


def _monitor_inputs(rng, n, reason):
    """n steps descending from tables.WATCH_HEIGHT_M on the path at the target speed, disturbed so that `reason`
    fires."""
    z = np.linspace(tables.WATCH_HEIGHT_M, 100.0, n)
    x = (TCH - z) / math.tan(GP)
    y = rng.normal(0.0, 2.0, n)
    cas = 72.0 + rng.normal(0.0, 0.5, n)
    gs = 70.0 + rng.normal(0.0, 0.5, n)
    vd = gs * math.tan(GP) + rng.normal(0.0, 0.3, n)
    late = z < 900.0 * units.FT
    if reason == MON_GLIDEPATH:
        z = z + np.where(late, 0.3 * (900.0 * units.FT - z), 0.0)
    elif reason == MON_LOCALIZER:
        y = y + np.where(late, 1.0 * (900.0 * units.FT - z), 0.0)
    elif reason == MON_SPEED:
        cas = cas + np.where(z < 950.0 * units.FT, 8.0, 0.0)
    elif reason == MON_SINK:
        vd = vd + np.where(late, 4.0, 0.0)
    return x, y, z, cas, vd, gs


@pytest.mark.parametrize("reason", [MON_GLIDEPATH, MON_LOCALIZER, MON_SPEED, MON_SINK])
def test_monitor_kernel_equals_the_oracle_and_each_reason_fires(reason):
    n = 12000  # ~100 s from 1400 ft: the 10 s sink window fills above 1000 ft
    x, y, z, cas, vd, gs = _monitor_inputs(np.random.default_rng(reason), n, reason)
    mon = StabilityMonitor(GP, TCH, 72.0, DT)
    ref = StabilityMonitor(GP, TCH, 72.0, DT)
    par, st, ring = fv.monitor_arrays(mon)
    for k in range(n):
        want = mon.check(x[k], y[k], z[k], cas[k], vd[k], gs[k])
        words = ref.step(x[k], y[k], z[k], cas[k], vd[k], gs[k])
        got = fk.monitor_step(par, st, ring, x[k], y[k], z[k], cas[k], vd[k], gs[k])
        assert got == want, f"step {k}"
        np.testing.assert_array_equal(st, np.array(mon.state()), err_msg=f"state at step {k}")
        np.testing.assert_array_equal(ring, np.array(mon.windows()))
        if got[0] != MON_OK:
            assert words == unstabilized_reason(got[0], z[k], got[1], got[2])
            break
        assert words is None
    assert got[0] == reason
    assert z[k] < 1000.0 * units.FT


def _step_vectors(gains, *, land=False, turbulent=True, stop_h=-math.inf, n_steps=100, monitor_floor=None):
    ap = _autopilot(gains)
    mon = StabilityMonitor(GP, TCH, 72.0, DT)
    turb = DrydenTurbulence("light", np.random.default_rng(4), n_steps, DT, 1.0) if turbulent else None
    frame = geo.RunwayFrame(math.radians(39.8), math.radians(-104.7), 1600.0, 0.4)
    rw = SimpleNamespace(frame=frame, elevation_m=1600.0, glidepath_rad=GP, tch_m=TCH, heading_rad=0.4,
                         threshold_lat_rad=frame.threshold_lat_rad)
    const = fv.imu_point_constants(np.array([9.0, 0.3, -1.1]), frame.threshold_lat_rad, rw, DT)
    par, st = fv.flight_vectors(const, ap, mon, turb, np.array([-20000.0, 0.0]), np.array([1650.0, 1600.0]),
                                pitch_trim=-0.1, stop_height_m=stop_h, land=land,
                                monitor_floor_m=(monitor_floor if monitor_floor is not None
                                                 else gains.flare_height_m if land else -math.inf),
                                wind_ned_mps=(-2.0, 1.0))
    return par, st, ap, mon, turb, const, rw


def test_termination_codes_in_order_and_their_words(gains):
    par, st, *_ = _step_vectors(gains, land=True, stop_h=10.0)
    fpar, fst = par[layouts.FLIGHT_PAR.slice("step")], st[layouts.FLIGHT_STATE.slice("step")]
    mpar, mst = par[layouts.P_MN:layouts.P_MN + layouts.N_MN_PAR], st[layouts.S_MN:layouts.S_MN + layouts.N_MN_STATE]
    ring = st[layouts.S_RING:]
    air = dict(vn=70.0, ve=0.0, vd=3.7, h_agl=500.0, phi=0.0, wow_nose=0.0, wow_left=0.0, wow_right=0.0,
               vn_cg=70.0, ve_cg=0.0, vd_cg=3.7, cas=72.0, tas=75.0)

    def term(x, y, z, **kw):
        a = {**air, **kw}
        return fk.termination(fpar, fst, mpar, mst, ring, (x, y, z, a["vn"], a["ve"], a["vd"]), a["h_agl"],
                              a["phi"], (a["wow_nose"], a["wow_left"], a["wow_right"]),
                              (a["vn_cg"], a["ve_cg"], a["vd_cg"]), a["cas"], a["tas"])

    high = 1500.0 * units.FT
    x_high = (TCH - high) / math.tan(GP)
    assert term(x_high, 0.0, high) == fk.TERM_NONE
    assert term(0.0, 0.0, 9.0, wow_left=1.0) == fk.TERM_STOP  # the stop height comes first
    assert term(400.0, 0.0, 11.0, wow_left=1.0) == fk.TERM_TOUCHDOWN
    assert fst[layouts.FS_TD_X] == 400.0 and fst[layouts.FS_TD_SINK] == 3.7
    assert term(-36.576, 0.0, 11.0, wow_right=1.0) == fk.TERM_SHORT
    assert termination_reason(fk.TERM_SHORT, fst) == "touchdown short of the threshold (120 ft)"
    assert term(400.0, 0.0, 11.0, wow_left=1.0, wow_nose=1.0) == fk.TERM_GROUND  # nose gear first
    assert term(x_high, 0.0, high, h_agl=0.0) == fk.TERM_GROUND
    assert term(x_high, 0.0, high, phi=1.01) == fk.TERM_DIVERGED
    on_cone = float(GlidePath(GP, TCH, 0.4, LAT).height_m(x_high))  # _autopilot's geometry
    assert term(x_high, 0.0, on_cone + 299.0) == fk.TERM_NONE
    assert term(x_high, 0.0, on_cone + 301.0) == fk.TERM_DIVERGED
    assert term(x_high, -1501.0, high) == fk.TERM_DIVERGED
    low = 600.0 * units.FT
    assert term((TCH - low) / math.tan(GP), 0.0, low + 30.0) == fk.TERM_UNSTABLE  # 1 dot is ~22 m here
    assert fst[layouts.FS_MON] == MON_GLIDEPATH and fst[layouts.FS_MON_Z] == low + 30.0
    assert termination_reason(fk.TERM_UNSTABLE, fst) == "unstabilized at 698 ft: glidepath deviation +1.37 dots"
    for code, words in ((fk.TERM_STOP, "reached stop height"), (fk.TERM_TOUCHDOWN, "touchdown"),
                        (fk.TERM_GROUND, "ground contact"), (fk.TERM_DIVERGED, "diverged"),
                        (fk.TERM_NONE, "timeout")):
        assert termination_reason(code, fst) == words
    # below the flare height the monitor is not consulted on a landing run
    assert term(-200.0, 0.0, 0.9 * gains.flare_height_m, h_agl=5.0) == fk.TERM_NONE


def _synthetic_raw(rng, n, along_m=(-9000.0, -7000.0)):
    """n steps of JSBSim reads (RAW_FIELDS order, JSBSim units) of an aircraft on a 3 deg approach to a runway at
    39.8 N, heading 0.4 rad, 1600 m, from along_m[0] to along_m[1] (m, runway frame)."""
    frame = geo.RunwayFrame(math.radians(39.8), math.radians(-104.7), 1600.0, 0.4)
    along = np.linspace(along_m[0], along_m[1], n)
    h = 1600.0 + TCH - along * math.tan(GP) + rng.normal(0.0, 1.0, n)
    ecef = frame.origin_ecef + np.outer(along, frame.c_ecef_to_rwy[0])
    lat, lon, _ = geo.ecef_to_geodetic(ecef)
    raw = np.empty((n, len(layouts.RAW_FIELDS)))
    raw[:, 0], raw[:, 1], raw[:, 2] = lat, lon, h / units.FT
    vg = 70.0 / units.FPS
    raw[:, 3:6] = [vg * math.cos(0.4), vg * math.sin(0.4), vg * math.tan(GP)]
    raw[:, 3:6] += rng.normal(0.0, 2.0, (n, 3))
    raw[:, 6:9] = np.column_stack([rng.normal(0.0, 0.05, n), 0.03 + rng.normal(0.0, 0.01, n),
                                   0.4 + rng.normal(0.0, 0.01, n)])
    raw[:, 9:12] = rng.normal(0.0, 0.03, (n, 3))
    raw[:, 12:15] = rng.normal(0.0, 0.1, (n, 3))
    raw[:, 15:18] = rng.normal([2e3, 0.0, -1.5e5], [5e2, 3e2, 2e4], (n, 3))
    raw[:, 18] = 4000.0
    raw[:, 19] = rng.uniform(1700.0, 1750.0, n)
    raw[:, 20] = rng.uniform(500.0, 510.0, n)
    raw[:, 21] = 140.0 + rng.normal(0.0, 2.0, n)
    raw[:, 22] = rng.normal(0.0, 0.01, n)
    raw[:, 23] = raw[:, 21] * 1.75
    return raw


def test_fly_step_is_the_composition_of_its_pieces(gains):
    """fly_step on synthetic reads against the same step composed in Python from the oracles: the truth row
    (imu_point_rows_reference), JSBSim's rates p, q (earth_rates_reference), the turbulence at the CG's height above
    the terrain, the autopilot on the truth, the controls in the row; the commands agree to 1e-12 (the derived rates
    differ from the oracle's in rounding), the gusts bit for bit."""
    n = 300
    par, st, ap, mon, turb, const, rw = _step_vectors(gains, n_steps=n)
    raw = _synthetic_raw(np.random.default_rng(8), n)
    along, height = np.array([-20000.0, 0.0]), np.array([1650.0, 1600.0])
    rows = fv.imu_point_rows_reference(raw, const, along, height, np.arange(n) * DT)
    pqr = fv.earth_rates_reference(raw)
    buf = np.full((n, 36), np.nan)
    nu = turb.nu.copy()
    de, da, dr, thr = 0.0, 0.0, 0.0, ap.trim.throttle
    for k in range(n):
        reads = (*raw[k], *layouts.GEAR_AIRBORNE)
        code, *cmd, gn, ge, gd, terr_ft, near = fk.fly_step(k, reads, buf, nu, par, st, True)
        assert code == fk.TERM_NONE and not near
        row = rows[k]
        terr = float(np.interp(row[26], along, height))
        assert terr_ft == pytest.approx(terr / units.FT, rel=1e-12)
        tn, te, td = turb.step(k, raw[k, 2] * units.FT - terr, raw[k, 23] * units.FPS)
        assert (gn, ge, gd) == (tn / units.FPS, te / units.FPS, td / units.FPS)
        want = ap.step(row[26], row[27], row[28], row[7], row[8], row[9], raw[k, 6], raw[k, 7], pqr[k, 0], pqr[k, 1],
                       raw[k, 22], raw[k, 21] * units.KT, None, raw[k, 23] * units.FPS)
        np.testing.assert_allclose(cmd, want, rtol=1e-12, atol=1e-12)  # normalized commands: 1e-12 of full scale
        de, da, dr, thr = want
        np.testing.assert_allclose(buf[k, 31:35], [de - 0.1, da, dr, thr], rtol=1e-12, atol=1e-12)
        cols = [c for c in range(36) if not 31 <= c < 35]
        np.testing.assert_allclose(buf[k, cols], row[cols], rtol=1e-12, atol=1e-9)
    assert st[layouts.S_STEP + layouts.FS_LOWEST] == buf[:, 28].min()


def test_navigation_guidance_path_equals_the_guided_step(gains):
    """fly_step without guidance, then fly_control on the same position and velocity, is the guided step."""
    n = 200
    raw = _synthetic_raw(np.random.default_rng(9), n)
    par_a, st_a, *_ = _step_vectors(gains, n_steps=n)
    par_b, st_b, ap_b, _, turb_b, *_ = _step_vectors(gains, n_steps=n)
    buf_a, buf_b = np.full((n, 36), np.nan), np.full((n, 36), np.nan)
    nu = turb_b.nu.copy()
    guidance = np.full((n, 6), np.nan)
    for k in range(n):
        reads = (*raw[k], *layouts.GEAR_AIRBORNE)
        out_a = fk.fly_step(k, reads, buf_a, nu, par_a, st_a, True)
        out_b = fk.fly_step(k, reads, buf_b, nu, par_b, st_b, False)
        if k:  # the row holds the commands in force (the previous step's), pitch trim added
            np.testing.assert_array_equal(buf_b[k, 31:35], buf_a[k - 1, 31:35])
        guidance[k, 0:3], guidance[k, 3:6] = buf_b[k, 26:29], buf_b[k, 7:10]
        in_force = st_b[layouts.S_STEP + layouts.FS_DE:layouts.S_STEP + layouts.FS_THR + 1]
        assert out_b[1:5] == tuple(in_force)  # the ones in force
        assert fk.fly_control(k, guidance, buf_b, par_b, st_b) == out_a[1:5]
        assert out_a[5:] == out_b[5:]
    np.testing.assert_array_equal(buf_a, buf_b)
    np.testing.assert_array_equal(st_a, st_b)


def test_the_gear_counts_only_near_the_ground(gains):
    """Gear reads above LOW_READ_HEIGHT_M are taken as airborne, below it they end the run; the next step's read is
    asked for from LOW_READ_HEIGHT_M + GEAR_READ_MARGIN_M down (the monitor is off here: its floor is infinite)."""
    par, st, *_ = _step_vectors(gains, turbulent=False, monitor_floor=math.inf)
    raw = _synthetic_raw(np.random.default_rng(10), 1, along_m=(-1500.0, -1500.0))[0]
    nu = np.zeros((1, 3))
    mains_down = (0.0, 1.0, 1.0, 0.0, 0.0)

    def at(h_agl_m, gear):
        r, buf = raw.copy(), np.full((1, 36), np.nan)
        fk.fly_step(0, (*r, *layouts.GEAR_AIRBORNE), buf, nu, par, st.copy(), True)
        r[2] += (h_agl_m - buf[0, 25]) / units.FT
        out = fk.fly_step(0, (*r, *gear), buf, nu, par, st.copy(), True)
        assert buf[0, 25] == pytest.approx(h_agl_m, abs=0.01)
        return out[0], out[-1]

    assert at(250.0, mains_down) == (fk.TERM_NONE, False)
    assert at(fk.LOW_READ_HEIGHT_M + fk.GEAR_READ_MARGIN_M - 1.0, mains_down) == (fk.TERM_NONE, True)
    assert at(fk.LOW_READ_HEIGHT_M + 1.0, mains_down) == (fk.TERM_NONE, True)
    assert at(fk.LOW_READ_HEIGHT_M - 1.0, mains_down) == (fk.TERM_GROUND, True)
    assert at(fk.LOW_READ_HEIGHT_M - 1.0, layouts.GEAR_AIRBORNE) == (fk.TERM_NONE, True)


def test_entry_point_calls_the_same_compiled_step(gains):
    n = 3
    par, st, *_ = _step_vectors(gains, n_steps=n)
    raw = _synthetic_raw(np.random.default_rng(12), n)
    buf = np.full((n, 36), np.nan)
    nu = np.zeros((n, 3))
    reads = (*raw[0], *layouts.GEAR_AIRBORNE)
    entry = entry_point(fk.fly_step, 0, reads, buf, nu, par, st, True)
    assert entry is not fk.fly_step  # numba still exposes it (else the loop falls back on the dispatcher)
    st2, buf2 = st.copy(), buf.copy()
    assert entry(0, reads, buf, nu, par, st, True) == fk.fly_step(0, reads, buf2, nu, par, st2, True)
    np.testing.assert_array_equal(st, st2)
    np.testing.assert_array_equal(buf, buf2)
