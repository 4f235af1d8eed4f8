"""Why the flare lands above its target in turbulence (issue 40): the main gear's sink against its height, and a
linear model of the flare loop's response to gusts.

    python tools/flare_diagnosis.py landings --runs 200 --out F.json     # 20 kt crosswind, light turbulence
    python tools/flare_diagnosis.py landings --runs 1 --turbulence none  # calm air (one flight: deterministic)
    python tools/flare_diagnosis.py model                                # the loop's gust response, its margins
    python tools/flare_diagnosis.py retard                               # a retard's effect on the path (linear)
    [--set NAME=VALUE ...]  AutopilotGains overrides (SI), e.g. --set k_flare=0.03 --set k_flare_i=0.005
    model only: [--gust-ff K]  a pitch feed-forward -K u_g of the airspeed gust added to the law's flare_k_gust
                (rad s/m; analysis); [--gear-fb C]  feed back the IMU's sink plus C l q (1: the main gear's)

`landings` flies the crosswind case of tools/autoland_figures.py (default profile, 20 kt from the right, seed 1,
runs 0..N-1, true-state guidance) and records, for each landing, the main gear's sink rate (the lower gear's,
from the truth rows through evaluate/touchdown.gear_state), the IMU's and the pitch-rate term l q between them as
the gear passes 20, 15, 10, 7, 5, 3, 2, 1, 0.5 and 0.25 ft, and at touchdown. Per height it prints:

- the height-indexed mean and sd (each landing passes each height once: the sample at touchdown is this
  process at h -> 0);
- the time-indexed mean, 1 / mean(1 / s): a height band dh is crossed in dh / s, so the harmonic mean of the
  height-indexed samples is the mean a fixed time would see; the difference is the first-passage (rate)
  weighting, sigma^2 / mu for a stationary process (Rice): the part of the miss that scatter alone makes;
- the law's command s_td + h / tau (tau from the IMU sink at 50 ft, as autopilot.py sets it);

and the correlation of the touchdown sink with the gear's sink 0.5-4 s before touchdown.

The time-indexed mean minus the target is the law's tracking bias; the height-indexed mean minus the time-indexed
one, the first-passage weighting.

`model` closes the flare loop of flight/autopilot.py (linearized: PI on the IMU's sink, the path lead, the
exponential's height term, the gust feed-forward) around the landing linearization's longitudinal states with the
pitch loop closed (as tests/unit/flight/test_flight_design.py does; the speed perturbation kept, so the retard's
phugoid is in it), drives it with MIL-F-8785C's low-altitude
Dryden u and w spectra (light: W20 = 15 kt) at 25 ft, and prints the main gear's and the IMU's sink sd, the loop's
phase and gain margins and crossover, and the gust-to-gear-sink gain's peak. Frequencies below 0.3 rad/s are
left out (the flare lasts about 7 s).
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "tools"))

from approachsim import units  # noqa: E402
from approachsim.evaluate.touchdown import c_nb_from_euler, c_rwy_ned, touchdown_scalars  # noqa: E402
from approachsim.flight.run import Approach  # noqa: E402
from approachsim.profile import load_profile, parse_profile  # noqa: E402

HEIGHTS_FT = (20.0, 15.0, 10.0, 7.0, 5.0, 3.0, 2.0, 1.0, 0.5, 0.25)
BEFORE_S = (0.5, 1.0, 1.5, 2.0, 2.5, 3.0, 3.5, 4.0)


def _approach(wind_kt: float, turb: str, overrides: dict[str, float]) -> Approach:
    import autoland_figures as af

    approach = Approach(parse_profile(af._xwind_profile(None, wind_kt, turb), source=af.DEFAULT), land=True)
    if overrides:
        ac = approach.aircraft
        approach.aircraft = dataclasses.replace(ac, gains=dataclasses.replace(ac.gains, **overrides))
    return approach


def gear_traces(truth, arms: np.ndarray, below_m: float = 40.0 * units.FT) -> np.ndarray:
    """Rows (t, lower main gear's height, its sink, IMU sink, pitch rate) of the truth rows with the IMU below
    below_m (m, m/s, rad/s; runway frame, level runway)."""
    ks = np.flatnonzero(truth.r_rwy[:, 2] < below_m)
    c_rn = c_rwy_ned(truth.runway.heading_rad)
    c_nb = np.array([c_nb_from_euler(truth.euler_rad[k]) for k in ks])
    pos = truth.r_rwy[ks][:, None, :] + np.einsum("ij,mjk,gk->mgi", c_rn, c_nb, arms)
    wl = np.cross(truth.w_ib_body[ks][:, None, :], arms[None, :, :])
    vel = np.einsum("ij,mjk,mgk->mgi", c_rn, c_nb, wl) + (truth.v_ned[ks] @ c_rn.T)[:, None, :]
    low = np.argmin(pos[:, :, 2], axis=1)
    m = np.arange(len(ks))
    return np.column_stack([truth.t_s[ks], pos[m, low, 2], -vel[m, low, 2], truth.v_ned[ks, 2],
                            truth.w_ib_body[ks, 1]])


def landings(runs: int, wind_kt: float, turb: str, overrides: dict[str, float]) -> list[dict]:
    """Per landing: the sinks (m/s) at each height of HEIGHTS_FT as the gear first passes it, and at touchdown."""
    approach = _approach(wind_kt, turb, overrides)
    arms = np.asarray(approach.main_gear_lever_arms_m)
    out = []
    for r in range(runs):
        res = approach.fly(seed=1, run=r)
        if res.termination != "touchdown":
            out.append({"run": r, "termination": res.termination})
            continue
        tr = gear_traces(res.truth, arms)
        td = touchdown_scalars(res.truth, arms)
        row = {"run": r, "termination": "touchdown", "gear": [], "imu": [], "lq": [],
               "td_gear": td["td_sink_mps"], "td_imu": td["td_imu_sink_mps"], "td_pitch_rad": td["td_pitch_rad"],
               "td_cas_mps": td["td_cas_mps"], "td_x_m": td["td_x_m"]}
        # the gear's sink 0.5, 1.0, ... 4.0 s before touchdown (its correlation with the touchdown sink shows the
        # flare loop's oscillation)
        row["before"] = [float(tr[max(int(np.searchsorted(tr[:, 0], tr[-1, 0] - dt)) - 1, 0), 2])
                         for dt in BEFORE_S]
        for h in HEIGHTS_FT:
            j = int(np.argmax(tr[:, 1] <= h * units.FT))
            row["gear"].append(float(tr[j, 2]))
            row["imu"].append(float(tr[j, 3]))
            row["lq"].append(float(tr[j, 2] - tr[j, 3]))
        ks, h_gear = _gear_height_near_ground(res.truth, arms)
        row["entry_sink"] = float(res.truth.v_ned[ks[np.argmax(h_gear <= approach.aircraft.gains.flare_height_m)], 2])
        out.append(row)
    return out


def _gear_height_near_ground(truth, arms: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(rows with the IMU below 100 ft, the lower main gear's height above the level runway there, m)."""
    c_rn = c_rwy_ned(truth.runway.heading_rad)
    ks = np.flatnonzero(truth.r_rwy[:, 2] < 100.0 * units.FT)
    h = np.array([(truth.r_rwy[k][None, :] + arms @ (c_rn @ c_nb_from_euler(truth.euler_rad[k])).T)[:, 2].min()
                  for k in ks])
    return ks, h


def summary(rows: list[dict], td_sink_mps: float) -> dict:
    """Height-indexed and time-indexed means of the gear sink, the command, and the decomposition at h -> 0."""
    ok = [r for r in rows if r["termination"] == "touchdown"]
    fps = 1.0 / units.FPS
    gear = np.array([r["gear"] for r in ok]) * fps
    imu = np.array([r["imu"] for r in ok]) * fps
    lq = np.array([r["lq"] for r in ok]) * fps
    entry = np.array([r["entry_sink"] for r in ok])
    tau = np.array([units.FT * 50.0 / max(s - td_sink_mps, 0.1 * units.FPS) for s in entry])
    sd = (lambda x: float(x.std(ddof=1))) if len(ok) > 1 else (lambda x: 0.0)
    table = []
    for i, h in enumerate(HEIGHTS_FT):
        cmd = (td_sink_mps + h * units.FT / tau) * fps
        time_mean = float(1.0 / np.mean(1.0 / gear[:, i]))
        table.append({"h_ft": h, "gear_mean": float(gear[:, i].mean()), "gear_sd": sd(gear[:, i]),
                      "gear_time_mean": time_mean, "first_passage": float(gear[:, i].mean()) - time_mean,
                      "imu_mean": float(imu[:, i].mean()), "imu_sd": sd(imu[:, i]), "lq_mean": float(lq[:, i].mean()),
                      "lq_sd": sd(lq[:, i]), "command": float(cmd.mean())})
    td_m = np.array([r["td_gear"] for r in ok])
    td = td_m * fps
    last = table[-1]
    before = np.array([r["before"] for r in ok])
    corr = ([float(np.corrcoef(td_m, before[:, i])[0, 1]) for i in range(len(BEFORE_S))] if len(ok) > 2
            else [])
    return {"landings": len(rows), "touchdowns": len(ok), "td_sink_fps": {"mean": float(td.mean()), "sd": sd(td)},
            "td_imu_sink_fps": {"mean": float(np.mean([r["td_imu"] for r in ok]) * fps)},
            "td_pitch_deg": float(np.degrees(np.mean([r["td_pitch_rad"] for r in ok]))),
            "td_cas_kt": float(np.mean([r["td_cas_mps"] for r in ok]) / units.KT),
            "td_x_ft": {"mean": float(np.mean([r["td_x_m"] for r in ok]) / units.FT),
                        "sd": sd(np.array([r["td_x_m"] for r in ok]) / units.FT),
                        "max": float(np.max([r["td_x_m"] for r in ok]) / units.FT)},
            "target_fps": td_sink_mps * fps,
            "miss_fps": float(td.mean()) - td_sink_mps * fps,
            "tracking_bias_fps": last["gear_time_mean"] - td_sink_mps * fps,
            "first_passage_fps": last["first_passage"], "heights": table,
            "corr_td_with_gear_sink_before": dict(zip([f"{b:g} s" for b in BEFORE_S], corr, strict=False))}


# --- the linear model -------------------------------------------------------------------------------------------

def _longitudinal(lin, g):
    """(a_cl, b_theta_c, V, l_imu, l_gear): Vt (m/s), alpha, theta, q with the pitch loop closed; the IMU's and the
    main gear's distances ahead of / behind the CG (m; 737.xml CG x 639 in, IMU x 250 in, gear x 648 in)."""
    idx = [0, 1, 2, 3]
    scale = np.diag([units.FPS, 1.0, 1.0, 1.0])
    a = scale @ lin.A[np.ix_(idx, idx)] @ np.linalg.inv(scale)
    b = (scale @ lin.B[idx, 2:3])[:, 0]
    a_cl = a + np.outer(b, [0.0, 0.0, g.k_theta, g.k_q])
    return a_cl, -g.k_theta * b, lin.vt_mps, (639.0 - 250.0) * units.IN, (648.0 - 639.0) * units.IN


def gust_response(lin, g, w: np.ndarray, tau_s: float = 4.9, k_gust: float = 0.0,
                  gear_fb: float = 0.0) -> dict[str, np.ndarray]:
    """Complex gains from a horizontal (u, along the path, + headwind) and a vertical (w, + up) gust velocity to the
    main gear's and the IMU's sink rate at frequencies w (rad/s), the flare loop closed (autopilot.py linearized).
    The law's own airspeed-gust feed-forward -flare_k_gust u is in it; analysis only (not in the law): k_gust
    (rad s/m) adds to it, gear_fb feeds back the IMU's sink plus this share of the lever-arm term (1: the main
    gear's sink)."""
    a_cl, b_th, v, l_imu, l_gear = _longitudinal(lin, g)
    c_cg = np.array([0.0, v, -v, 0.0])  # sink of the CG: -V (theta - alpha)
    c_imu, c_gear = c_cg + np.array([0.0, 0.0, 0.0, -l_imu]), c_cg + np.array([0.0, 0.0, 0.0, l_gear])
    fb = gear_fb
    k_gust = k_gust + g.flare_k_gust
    out: dict[str, list] = {"gear_u": [], "gear_w": [], "imu_u": [], "imu_w": []}
    for om in w:
        p = 1j * om
        m = np.linalg.inv(p * np.eye(4) - a_cl)
        # a gust enters as the rate of the air-relative speed / angle of attack it makes; a vertical gust also
        # carries the aircraft with it (the inertial sink falls by w)
        for name, bd, feed in (("u", np.array([1.0, 0.0, 0.0, 0.0]) * p, 0.0),
                               ("w", np.array([0.0, 1.0 / v, 0.0, 0.0]) * p, -1.0)):
            xd, xt = m @ bd, m @ b_th
            si_d, si_t = c_imu @ xd + feed, c_imu @ xt
            sg_d, sg_t = c_gear @ xd + feed, c_gear @ xt
            k = g.k_flare + g.k_flare_i / p
            sf_d, sf_t = (1.0 - fb) * si_d + fb * sg_d, (1.0 - fb) * si_t + fb * sg_t
            # theta_c = K (e_fb + s_gear / (tau p)) + T_path s_fb / (tau V) - k_gust u
            lead = g.flare_t_path_s / (tau_s * v)
            ff = -k_gust if name == "u" else 0.0
            th = (k * (sf_d + sg_d / (tau_s * p)) + lead * sf_d + ff) / (1.0 - k * (sf_t + sg_t / (tau_s * p))
                                                                         - lead * sf_t)
            out["gear_" + name].append(sg_d + sg_t * th)
            out["imu_" + name].append(si_d + si_t * th)
    return {k: np.array(v) for k, v in out.items()}


def command_lag(lin, g) -> float:
    """The main gear's sink lag behind the flare's sink command, s: T = -G'(0) / G(0) of G = s_gear / s_c with the
    feed-forward and the PI of autopilot.py (speed held: the alpha, theta, q rows). An exponential of time constant
    tau flown through a lag T (T s' + s = s_c(h), h' = -s) has the characteristic equation T tau l^2 + tau l + 1 = 0
    in l = d ln h / dt: it follows the exponential without overshoot only when tau >= 4 T, and then lands at
    s_td / (1 - T a) with a = (tau - sqrt(tau^2 - 4 tau T)) / (2 tau T) (the lag's own miss, no turbulence)."""
    a_cl, b_th, v, l_imu, l_gear = _longitudinal(lin, g)
    i3 = [1, 2, 3]
    a3, b3 = a_cl[np.ix_(i3, i3)], b_th[i3]
    c_imu = np.array([v, -v, -l_imu])
    c_gear = np.array([v, -v, l_gear])
    c_fb = c_imu

    def gain(p: complex, tau_s: float = 4.9) -> complex:
        xt = np.linalg.solve(p * np.eye(3) - a3, b3)
        sf, sg = c_fb @ xt, c_gear @ xt
        k = g.k_flare + g.k_flare_i / p
        # theta_c = -s_c / V + T_path s_fb / (tau V) + K (s_fb - s_c)
        th = (-1.0 / v - k) / (1.0 - k * sf - g.flare_t_path_s / (tau_s * v) * sf)
        return sg * th

    e = 1e-4
    g0 = gain(1e-7)
    return float(-((gain(e) - gain(-e)) / (2.0 * e) / g0).real)


def dryden_psd(w: np.ndarray, h_ft: float, v_mps: float, w20_kt: float = 15.0) -> tuple[np.ndarray, np.ndarray]:
    """One-sided MIL-F-8785C low-altitude Dryden spectra of u and w, (m/s)^2 per rad/s, at h_ft and speed v_mps."""
    h = max(h_ft, 10.0)
    den = 0.177 + 0.000823 * h
    l_u, l_w = h / den**1.2 * units.FT, h * units.FT
    s_w = 0.1 * w20_kt * units.KT
    s_u = s_w / den**0.4
    phi_u = s_u**2 * 2.0 * l_u / (math.pi * v_mps) / (1.0 + (l_u * w / v_mps) ** 2)
    x = l_w * w / v_mps
    phi_w = s_w**2 * l_w / (math.pi * v_mps) * (1.0 + 3.0 * x**2) / (1.0 + x**2) ** 2
    return phi_u, phi_w


def model(overrides: dict[str, float], k_gust: float = 0.0, gear_fb: float = 0.0) -> dict:
    import control

    ap = Approach(load_profile(ROOT / "profiles" / "default.toml"))
    g = dataclasses.replace(ap.aircraft.gains, **overrides)
    lin = ap.linearization
    w = np.logspace(math.log10(0.3), 2.0, 600)
    r = gust_response(lin, g, w, k_gust=k_gust, gear_fb=gear_fb)
    phi_u, phi_w = dryden_psd(w, 25.0, lin.vt_mps)
    fps = 1.0 / units.FPS

    def sd(key: str) -> float:
        return float(np.sqrt(np.trapezoid(np.abs(r[key + "_u"]) ** 2 * phi_u, w)
                             + np.trapezoid(np.abs(r[key + "_w"]) ** 2 * phi_w, w)) * fps)

    a_cl, b_th, v, l_imu, l_gear = _longitudinal(lin, g)
    plant = control.ss(a_cl, b_th.reshape(4, 1), np.array([[0.0, -v, v, l_imu - gear_fb * (l_imu + l_gear)]]), 0.0)
    s = control.tf("s")
    gm, pm, _, wc = control.margin((g.k_flare + g.k_flare_i / s) * plant)
    lag = command_lag(lin, g)
    return {"command_lag_s": lag, "gear_sink_sd_fps": sd("gear"), "imu_sink_sd_fps": sd("imu"),
            "gear_sink_sd_u_only_fps": float(np.sqrt(np.trapezoid(np.abs(r["gear_u"]) ** 2 * phi_u, w)) * fps),
            "peak_gear_per_u": float(np.abs(r["gear_u"]).max()),
            "peak_gear_per_u_at_rad_s": float(w[np.argmax(np.abs(r["gear_u"]))]),
            "peak_gear_per_w": float(np.abs(r["gear_w"]).max()),
            "phase_margin_deg": float(pm), "gain_margin_db": float(20.0 * math.log10(gm)) if np.isfinite(gm) else None,
            "crossover_rad_s": float(wc), "pitch_loop_natural_rad_s": float(np.max(np.abs(np.linalg.eigvals(a_cl))))}


def retard_response(lin, g, c: float, t_s: np.ndarray) -> np.ndarray:
    """The CG's climb rate (m/s) at times t_s (s, ascending) after the throttle is cut by one unit, with the pitch
    loop closed on the command theta_c = flare_k_v (V_0 - V) + c (the flare's speed feed-forward and a step c per
    unit of throttle withheld, rad), the linearization's Vt, alpha, theta, q (speed free): the retard's effect on
    the path that a feed-forward would have to cancel (docs/touchdown.md sec. 4, fifth part)."""
    from scipy.linalg import expm

    idx = [0, 1, 2, 3]
    scale = np.diag([units.FPS, 1.0, 1.0, 1.0])
    a = scale @ lin.A[np.ix_(idx, idx)] @ np.linalg.inv(scale)
    b_thr, b_de = scale @ lin.B[idx, 0], scale @ lin.B[idx, 2]
    # de = -k_theta (theta_c - theta) + k_q q with theta_c = -k_v V + c u
    a_cl = a + np.outer(b_de, [g.k_theta * g.flare_k_v, 0.0, g.k_theta, g.k_q])
    b = b_thr * -1.0 + (-g.k_theta * b_de) * c
    out, x, t0 = [], np.zeros(4), 0.0
    for t in t_s:
        m = expm(np.block([[a_cl, b[:, None]], [np.zeros((1, 5))]]) * (t - t0))
        x = m[:4, :4] @ x + m[:4, 4]
        t0 = t
        out.append(lin.vt_mps * (x[2] - x[1]))
    return np.array(out)


def retard_feed_forward(lin, g, horizon_s: float) -> float:
    """The step in pitch command per unit of throttle withheld (rad) that leaves the height lost `horizon_s` after
    the retard at zero, in the model of retard_response (linear in c: two evaluations)."""
    t = np.linspace(0.0, horizon_s, 401)

    def height(c: float) -> float:
        return float(np.trapezoid(retard_response(lin, g, c, t), t))

    h0, h1 = height(0.0), height(1.0)
    return -h0 / (h1 - h0)


def pitch_command_gain(lin, g) -> float:
    """Pitch per pitch command at constant path (alpha and theta change together) with the proportional pitch loop
    closed, M_de k_theta / (M_alpha + M_theta + M_de k_theta), over the angle of attack the trim elevator's own lift
    adds, (A_aa + A_at + B_a,de (-(M_a + M_t) / M_de)) / (A_aa + A_at): how much of an angle-of-attack feed-forward
    a pitch command delivers."""
    a, b = lin.A, lin.B
    m_a, m_de = a[3, 1] + a[3, 2], b[3, 2]
    droop = m_de * g.k_theta / (m_a + m_de * g.k_theta)
    lift = (a[1, 1] + a[1, 2] + b[1, 2] * (-m_a / m_de)) / (a[1, 1] + a[1, 2])
    return droop * lift


def retard(overrides: dict[str, float]) -> dict:
    ap = Approach(load_profile(ROOT / "profiles" / "default.toml"))
    g = dataclasses.replace(ap.aircraft.gains, **overrides)
    lin = ap.linearization
    t = np.arange(1.0, 8.0)
    c = retard_feed_forward(lin, g, 5.3)
    return {"pitch_command_gain": pitch_command_gain(lin, g),
            "climb_rate_mps_1_to_7_s": [round(float(x), 3) for x in retard_response(lin, g, 0.0, t)],
            "feed_forward_rad_per_unit_throttle": {f"{h:g} s": retard_feed_forward(lin, g, h) for h in (4.0, 5.3, 6.0)},
            "climb_rate_with_it_5.3_s_mps": [round(float(x), 3) for x in retard_response(lin, g, c, t)]}


def _print_summary(s: dict) -> None:
    print(f"{s['touchdowns']} of {s['landings']} landed; touchdown sink {s['td_sink_fps']['mean']:.2f} +- "
          f"{s['td_sink_fps']['sd']:.2f} ft/s (target {s['target_fps']:.2f}: miss {s['miss_fps']:+.2f} = tracking "
          f"bias {s['tracking_bias_fps']:+.2f} + first passage {s['first_passage_fps']:+.2f}); pitch "
          f"{s['td_pitch_deg']:.2f} deg, CAS {s['td_cas_kt']:.1f} kt; main gear x {s['td_x_ft']['mean']:.0f} +- "
          f"{s['td_x_ft']['sd']:.0f} ft (max {s['td_x_ft']['max']:.0f})")
    print("   h ft | gear mean +- sd | time mean | first passage | IMU mean +- sd | l q mean +- sd | command")
    for t in s["heights"]:
        print(f"  {t['h_ft']:5.2f} | {t['gear_mean']:5.2f} +- {t['gear_sd']:4.2f} | {t['gear_time_mean']:9.2f} | "
              f"{t['first_passage']:13.2f} | {t['imu_mean']:5.2f} +- {t['imu_sd']:4.2f} | {t['lq_mean']:+5.2f} +- "
              f"{t['lq_sd']:4.2f} | {t['command']:.2f}")
    if s["corr_td_with_gear_sink_before"]:
        print("  correlation of the touchdown sink with the gear's sink before touchdown: "
              + ", ".join(f"{k} {v:+.2f}" for k, v in s["corr_td_with_gear_sink_before"].items()))


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("what", choices=("landings", "model", "retard"))
    ap.add_argument("--runs", type=int, default=200)
    ap.add_argument("--wind-kt", type=float, default=20.0)
    ap.add_argument("--turbulence", default="light")
    ap.add_argument("--set", action="append", default=[], metavar="NAME=VALUE")
    ap.add_argument("--gust-ff", type=float, default=0.0)
    ap.add_argument("--gear-fb", type=float, default=0.0)
    ap.add_argument("--out", type=Path)
    a = ap.parse_args()
    overrides = {k: float(v) for k, v in (s.split("=", 1) for s in a.set)}
    t0 = time.process_time()
    if a.what == "landings":
        rows = landings(a.runs, a.wind_kt, a.turbulence, overrides)
        td = _approach(a.wind_kt, a.turbulence, overrides).aircraft.gains.touchdown_sink_mps
        out = {"runs": a.runs, "wind_kt": a.wind_kt, "turbulence": a.turbulence, "overrides": overrides,
               **summary(rows, td)}
        _print_summary(out)
    elif a.what == "retard":
        out = {"overrides": overrides, **retard(overrides)}
        print(json.dumps(out, indent=1))
    else:
        out = {"overrides": overrides, "gust_ff": a.gust_ff, "gear_fb": a.gear_fb,
               **model(overrides, a.gust_ff, a.gear_fb)}
        print(json.dumps(out, indent=1))
    out["cpu_s"] = time.process_time() - t0
    if a.out:
        a.out.write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
