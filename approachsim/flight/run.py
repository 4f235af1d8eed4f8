"""The approach run loop: JSBSim flies the profile's approach under the autopilot and produces the Truth record.

Two lines fly the default profile on truth navigation:

    approach = Approach(load_profile("profiles/default.toml"))
    result = approach.fly(seed=1, run=0)

`Approach` parses the aircraft, checks the profile against its approach envelope (flight.envelope) and solves
the trimmed start once; `fly` builds a fresh JSBSim instance per run (a few ms), sets the day's atmosphere,
wind and seeded turbulence, trims at the approach CAS on the glidepath in the wind (checked) and steps at the
IMU rate. After writing Truth row k it calls `nav_source.step(k, truth)` (records.NavigationSource) and the
autopilot flies guidance on the position and velocity it returns; what guidance flew on is kept in the
FlightResult, so that

    flight technical error = guidance estimate - desired path,  navigation error = estimate - truth,
    total system error = truth - desired path.

The run ends when the IMU descends to `stop_height_m` above the threshold ("reached stop height"), or, with
`land=True`, after a flare when the main gear touches ("touchdown"), or as a failed approach: unstabilized
below 1000 ft (flight.envelope's monitor), ground contact, a touchdown short of the threshold, divergence or
timeout (`FlightResult.ok` / `failure`). The Truth arrays are preallocated for the longest permitted run (NaN
until written) and trimmed at the end; a navigation source sees that record and may read rows <= k only.

Truth is of the IMU point (aircraft file [imu]), one row per step from the compiled kernel of flight/kernels.py:
position, velocity and specific force are moved from the CG with the rigid-body lever-arm terms (f_imu = f_cg +
w_ib' x l + w_ib x (w_ib x l), in the exact form of JSBSim's Euler step, plus the gravitation gradient; v_imu =
v_cg + C_nb (w_eb x l), resolved on the IMU's own NED axes), and the static pressure is moved hydrostatically to
the IMU height; the lever arm l is fixed at trim (the CG moves by well under a millimetre as fuel burns).
docs/truth.md says why each term is there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from approachsim import units
from approachsim.config import ProfileError
from approachsim.flight.aircraft import Aircraft, load_aircraft
from approachsim.flight.autopilot import Autopilot, Geometry, Trim
from approachsim.flight.design import Linearization
from approachsim.flight.envelope import WATCH_HEIGHT_M, StabilityMonitor, check_envelope
from approachsim.flight.fdm import FDM, InitialCondition, TrimError
from approachsim.flight.kernels import RAW_FIELDS, imu_point_constants, imu_point_row
from approachsim.flight.trim import (
    CAS_TOLERANCE_MPS,
    PATH_TOLERANCE_RAD,
    StartError,
    solve_start,
    start_condition,
)
from approachsim.flight.turbulence import DrydenTurbulence
from approachsim.profile import Profile
from approachsim.records import NavigationSource, Truth
from approachsim.seeding import stream, stream_int

Array = np.ndarray

STOP_HEIGHT_M = 50.0 * units.FT
"""Default end of the run: the IMU 50 ft above the threshold (the CAT III decision height)."""

R_AIR = 287.05287
"""Specific gas constant of dry air, J/(kg K) (US Standard Atmosphere 1976, as JSBSim's Rdry), for the
hydrostatic move of JSBSim's static pressure from the CG to the IMU point."""

SUCCESS = ("reached stop height", "touchdown")
"""Terminations of a successful approach; every other one is a failed approach."""

LINEARIZATION_HEIGHT_M = 1000.0 * units.FT
"""Height above the threshold of the design linearization (the top of the 1000-200 ft scored segment)."""

# column layout of the one (n, 36) buffer the Truth arrays are views of while flying
_COLS = {
    "t_s": (0, 1), "lat_rad": (1, 1), "lon_rad": (2, 1), "h_m": (3, 1), "r_ecef": (4, 3), "v_ned": (7, 3),
    "q_nb": (10, 4), "euler_rad": (14, 3), "w_ib_body": (17, 3), "f_body": (20, 3), "p_static_pa": (23, 1),
    "t_air_k": (24, 1), "h_agl_m": (25, 1), "r_rwy": (26, 3), "gs_dev_m": (29, 1), "loc_dev_m": (30, 1),
    "controls": (31, 4), "airspeed_mps": (35, 1),
}
_NCOL = 36
_CTRL = 31

_READ = RAW_FIELDS
"""The JSBSim properties read every step, in the kernel's order (flight/kernels.py)."""
_READ_LOW = ("gear/unit[0]/WOW", "gear/unit[1]/WOW", "gear/unit[2]/WOW", "gear/unit[1]/AGL-ft", "gear/unit[2]/AGL-ft")
"""Read only below LOW_READ_HEIGHT_M: the gear (nose, left main, right main)."""
LOW_READ_HEIGHT_M = 100.0
"""IMU height above the terrain below which the gear state is read (the gear hangs about 4 m below it)."""


def _truth_views(buf: Array, runway) -> Truth:
    kw = {}
    for name, (c, w) in _COLS.items():
        kw[name] = buf[:, c] if w == 1 else buf[:, c:c + w]
    return Truth(**kw, runway=runway)


class TruthSource:
    """The default navigation source: guidance flies on the true IMU position and velocity."""

    def step(self, k: int, truth: Truth) -> tuple[Array, Array]:
        """Row k of the truth's runway-frame position (m) and NED velocity (m/s)."""
        return truth.r_rwy[k], truth.v_ned[k]


@dataclass(frozen=True)
class FlightResult:
    """One flown approach. Arrays have time on axis 0, on the Truth's time base."""

    truth: Truth
    guidance_r_rwy: Array
    """(n, 3) the position guidance flew on (runway frame: along, cross, height above threshold), m."""
    guidance_v_ned: Array
    """(n, 3) the NED velocity guidance flew on, m/s."""
    termination: str
    """Why the run ended: "reached stop height" or "touchdown" (landing runs) when it succeeded; otherwise the
    failure: "unstabilized at <h> ft: <what>" (flight.envelope's stabilized-approach criterion), "touchdown short
    of the threshold ...", "ground contact" (anything else touching), "diverged", "timeout"."""
    lowest_height_ft: float
    """Lowest true IMU height above the threshold reached, ft."""
    seed: int
    run: int
    turbulence_seed: int
    """The simulation/randomseed JSBSim used (the turbulence itself comes from the run's "turbulence" stream)."""

    touchdown_x_m: float = math.nan
    """Landing runs: IMU runway-frame x when the main gear touched down, m past the threshold (nan: none)."""
    touchdown_sink_mps: float = math.nan
    """Landing runs: sink rate at touchdown (IMU, positive down), m/s (nan: none)."""

    @property
    def ok(self) -> bool:
        """True when the approach ended where it should: at the stop height, or (landing runs) on the runway."""
        return self.termination in SUCCESS

    @property
    def failure(self) -> str | None:
        """None for a successful approach, else why it failed (the termination reason)."""
        return None if self.ok else self.termination

    def reached(self, height_ft: float) -> bool:
        """True when the aircraft descended to height_ft above the threshold."""
        return self.lowest_height_ft <= height_ft


class Approach:
    """A profile's approach, ready to fly many times: the aircraft is parsed and linearized once."""

    def __init__(self, profile: Profile, *, stop_height_m: float = STOP_HEIGHT_M, land: bool = False) -> None:
        self.profile = profile
        self.aircraft: Aircraft = load_aircraft(profile)
        check_envelope(profile, self.aircraft.limits, self.aircraft.name, self.aircraft.approach_speed_mps)
        self.dt_s = 1.0 / profile.rates.imu_hz
        self.stop_height_m = -math.inf if land else stop_height_m
        self.land = land
        """Fly on through a flare to touchdown (main gear on the ground) instead of stopping at stop_height_m."""
        self._lin: Linearization | None = None
        self._start: InitialCondition | None = None

    def start(self) -> InitialCondition:
        """The initial-condition command that JSBSim trims at the approach CAS on the glidepath in the profile's
        wind (trim.solve_start; solved once per Approach: it depends only on the profile). ProfileError when the
        aircraft cannot be trimmed there at all."""
        if self._start is None:
            ic = start_condition(self.profile, self.aircraft)
            try:
                self._start, _, _ = solve_start(lambda: FDM(self.aircraft.jsbsim_model, self.dt_s), ic)
            except (TrimError, StartError) as e:
                raise ProfileError(self._trim_message(e)) from None
        return self._start

    def _trim_message(self, e: Exception) -> str:
        env = self.profile.environment
        return (
            f"aircraft.approach_speed_kt: {e} (wind {env.wind_speed_mps / units.KT:.0f} kt from "
            f"{math.degrees(env.wind_from_rad):.0f} deg, ISA{env.isa_dev_k:+.0f} C, field "
            f"{self.profile.runway.elevation_m / units.FT:.0f} ft); choose a speed the {self.aircraft.name} trims at "
            f"with these flaps (the 737 with flaps 1: about 130-160 kt)"
        )

    @property
    def linearization(self) -> Linearization:
        """FGLinearization in still air (the profile's temperature and pressure), trimmed on the glidepath
        1000 ft above the threshold (the top of the scored segment), approach configuration (computed once)."""
        if self._lin is None:
            rw = self.profile.runway
            along = -(LINEARIZATION_HEIGHT_M - rw.tch_m) / math.tan(rw.glidepath_rad)
            fdm = FDM(self.aircraft.jsbsim_model, self.dt_s)
            self._trim(fdm, start_condition(self.profile, self.aircraft, still_air=True, along_m=along))
            self._lin = fdm.linearize(-self.profile.runway.glidepath_rad)
        return self._lin

    def _trim(self, fdm: FDM, ic) -> None:
        """Trim; a condition the aircraft cannot trim at is a profile error naming the approach speed."""
        try:
            fdm.initialize_and_trim(ic)
        except TrimError as e:
            raise ProfileError(self._trim_message(e)) from None

    def fly(self, seed: int, run: int = 0, nav_source: NavigationSource | None = None,
            max_time_s: float | None = None) -> FlightResult:
        """Fly run `run` of the campaign seeded `seed`; guidance flies on nav_source (default: truth)."""
        prof = self.profile
        ac = self.aircraft
        rw = prof.runway
        dt = self.dt_s
        src = TruthSource() if nav_source is None else nav_source
        on_truth = type(src) is TruthSource
        ic = self.start()
        fdm = FDM(ac.jsbsim_model, dt)
        self._trim(fdm, ic)
        cas0, gamma0 = fdm.cas_and_path()  # JSBSim's own state after initialisation, checked against the targets
        if (abs(cas0 - ac.approach_speed_mps) > CAS_TOLERANCE_MPS
                or abs(gamma0 + rw.glidepath_rad) > PATH_TOLERANCE_RAD):
            raise StartError(
                f"start not trimmed: JSBSim flies {cas0 / units.KT:.1f} KCAS on a {-math.degrees(gamma0):.2f} deg "
                f"path, the profile asks {ac.approach_speed_mps / units.KT:.1f} KCAS on "
                f"{math.degrees(rw.glidepath_rad):.2f} deg"
            )
        turb_seed = stream_int(seed, run, "turbulence")
        fdm.set_seed(turb_seed)

        # time budget: twice the still-air time to the threshold, at least 60 s
        if max_time_s is None:
            max_time_s = max(60.0, 2.0 * rw.start_distance_m / ac.approach_speed_mps)
        n_max = int(math.ceil(max_time_s / dt)) + 1
        env = prof.environment
        turb = None
        if env.turbulence != "none":
            turb = DrydenTurbulence(env.turbulence, stream(seed, run, "turbulence"), n_max, dt,
                                    env.wind_from_rad + math.pi)
            set_tn, set_te, set_td = fdm.turbulence_setters()
            turb_step = turb.step
        buf = np.full((n_max, _NCOL), np.nan)
        gbuf = None if on_truth else np.full((n_max, 6), np.nan)
        truth = _truth_views(buf, rw.frame)

        getters = [fdm.node(n).get_double_value for n in _READ]
        getters_low = [fdm.node(n).get_double_value for n in _READ_LOW]
        w0 = w1 = w2 = 0.0
        g1_ft = g2_ft = math.inf
        set_de = fdm.node("fcs/elevator-cmd-norm").set_double_value
        set_da = fdm.node("fcs/aileron-cmd-norm").set_double_value
        set_dr = fdm.node("fcs/rudder-cmd-norm").set_double_value
        set_thr = [fdm.node(f"fcs/throttle-cmd-norm[{i}]").set_double_value for i in range(2)]
        pitch_trim = fdm["fcs/pitch-trim-cmd-norm"]
        terrain = prof.terrain
        flat_terrain = len(terrain.along_m) == 1
        terr_along = np.asarray(terrain.along_m, dtype=float)
        terr_height = np.asarray(terrain.height_m, dtype=float)
        set_terrain = fdm.node("position/terrain-elevation-asl-ft").set_double_value

        # constants of the IMU-point kernel: lever arm (body axes, m; CG to IMU), geodesy, runway frame
        cg = (fdm["inertia/cg-x-in"], fdm["inertia/cg-y-in"], fdm["inertia/cg-z-in"])
        imu = ac.imu_location_struct_m
        IN = 0.0254
        lever = (cg[0] * IN - imu[0], imu[1] - cg[1] * IN, cg[2] * IN - imu[2])  # structural x aft / z up
        const = imu_point_constants(np.array(lever), ic.lat_rad, rw, dt)
        raw = np.empty(len(_READ))
        FT, FPS, KT = units.FT, units.FPS, units.KT
        tan_gp = math.tan(rw.glidepath_rad)
        tch = rw.tch_m
        sqrt = math.sqrt

        trim = Trim(theta_rad=fdm["attitude/theta-rad"], throttle=fdm["fcs/throttle-cmd-norm[0]"],
                    cas_mps=ac.approach_speed_mps)
        ap = Autopilot(ac.gains, trim, Geometry(rw.heading_rad, rw.glidepath_rad, rw.tch_m, rw.threshold_lat_rad), dt)
        ap_step = ap.step
        monitor = StabilityMonitor(rw.glidepath_rad, rw.tch_m, ac.approach_speed_mps, dt)
        mon_step = monitor.step
        monitor_floor = ac.gains.flare_height_m if self.land else -math.inf  # the flare leaves the glidepath
        w_n = -env.wind_speed_mps * math.cos(env.wind_from_rad)  # the steady wind (blowing towards from + pi), m/s
        w_e = -env.wind_speed_mps * math.sin(env.wind_from_rad)
        stop_h = self.stop_height_m
        land = self.land
        touchdown = (math.nan, math.nan)
        run_step = fdm.run
        termination = "timeout"
        lowest = math.inf
        k = 0
        de = da = dr = 0.0
        thr = trim.throttle
        for k in range(n_max):
            if k > 0:
                run_step()
            vals = [gv() for gv in getters]
            raw[:] = vals
            row = buf[k]
            # the IMU point's truth row (flight/kernels.py: lever arm, gravitation terms, step-mean specific
            # force, IMU-point NED axes, hydrostatic pressure, runway frame); returns the terrain under it
            terr = imu_point_row(raw, const, terr_along, terr_height, k * dt, row)
            (_lat, _lon, h_ft, vn_f, ve_f, vd_f, phi, th, _psi, _pi, _qi, _ri, p, q, _r, _pid, _qid, _rid,
             _fx, _fy, _fz, _m, _p_psf, _t_r, vc_kt, beta, vt_fps) = vals
            rv = row.tolist()
            vn, ve, vd = rv[7], rv[8], rv[9]
            h_i, xr, yr, zr = rv[3], rv[26], rv[27], rv[28]
            cas = vc_kt * KT
            if not flat_terrain:
                set_terrain(terr / FT)
            if h_i - terr < LOW_READ_HEIGHT_M:
                w0, w1, w2, g1_ft, g2_ft = [gv() for gv in getters_low]
            if turb is not None:  # turbulence for the next step, at the CG's height above the terrain
                tn, te, td = turb_step(k, h_ft * FT - terr, vt_fps * FPS)
                set_tn(tn)
                set_te(te)
                set_td(td)
            # the controls of the previous step act on this row until replaced below
            row[_CTRL], row[_CTRL + 1], row[_CTRL + 2], row[_CTRL + 3] = de + pitch_trim, da, dr, thr
            # termination checks on the true state
            if zr < lowest:
                lowest = zr
            term = None
            if zr <= stop_h:
                term = "reached stop height"
            elif land and (w1 > 0.0 or w2 > 0.0) and w0 == 0.0:
                term = "touchdown" if xr >= 0.0 else f"touchdown short of the threshold ({-xr / FT:.0f} ft)"
                touchdown = (xr, vd)
            elif w0 > 0.0 or w1 > 0.0 or w2 > 0.0 or h_i - terr <= 0.0:
                term = "ground contact"
            elif abs(phi) > 1.0 or abs(zr - (tch - xr * tan_gp)) > 300.0 or abs(yr) > 1500.0:
                term = "diverged"
            elif monitor_floor < zr < WATCH_HEIGHT_M:  # speed through the mean air mass (gusts removed), as CAS
                an, ae = vn_f * FPS - w_n, ve_f * FPS - w_e
                v_air = sqrt(an * an + ae * ae + (vd_f * FPS) ** 2)
                term = mon_step(xr, yr, zr, v_air * cas / (vt_fps * FPS), vd, sqrt(vn * vn + ve * ve))
            if on_truth:
                gx, gy, gz, gvn, gve, gvd = xr, yr, zr, vn, ve, vd
            else:  # the navigation source sees row k (and rows before it)
                gr, gv = src.step(k, truth)
                gx, gy, gz = float(gr[0]), float(gr[1]), float(gr[2])
                gvn, gve, gvd = float(gv[0]), float(gv[1]), float(gv[2])
                gbuf[k] = (gx, gy, gz, gvn, gve, gvd)
            if term is not None:
                termination = term
                break
            h_gear = min(g1_ft, g2_ft) * FT if land else None
            de, da, dr, thr = ap_step(gx, gy, gz, gvn, gve, gvd, phi, th, p, q, beta, cas, h_gear, vt_fps * FPS)
            row[_CTRL], row[_CTRL + 1], row[_CTRL + 2], row[_CTRL + 3] = de + pitch_trim, da, dr, thr
            # the controls for the next step
            set_de(de)
            set_da(da)
            set_dr(dr)
            set_thr[0](thr)
            set_thr[1](thr)
        n = k + 1
        if on_truth:
            gbuf = np.concatenate([truth.r_rwy[:n], truth.v_ned[:n]], axis=1)
        final = Truth(**{name: np.ascontiguousarray(v[:n]) for name, v in truth.arrays().items()}, runway=rw.frame)
        return FlightResult(
            truth=final,
            guidance_r_rwy=np.ascontiguousarray(gbuf[:n, :3]),
            guidance_v_ned=np.ascontiguousarray(gbuf[:n, 3:]),
            termination=termination,
            lowest_height_ft=lowest / FT,
            touchdown_x_m=touchdown[0],
            touchdown_sink_mps=touchdown[1],
            seed=seed,
            run=run,
            turbulence_seed=turb_seed,
        )


def tracking_stats(result: FlightResult, profile: Profile, upper_ft: float = 1000.0,
                   lower_ft: float = 200.0) -> dict[str, float]:
    """RMS and max of the true vertical and lateral deviation (ft) while the IMU is between upper_ft and
    lower_ft above the threshold, and the calibrated airspeed range there (kt)."""
    tr = result.truth
    z_ft = tr.r_rwy[:, 2] / units.FT
    sel = (z_ft <= upper_ft) & (z_ft >= lower_ft)
    if not np.any(sel):
        nan = math.nan
        return {"vertical_rms_ft": nan, "lateral_rms_ft": nan, "vertical_max_ft": nan, "lateral_max_ft": nan,
                "cas_min_kt": nan, "cas_max_kt": nan, "samples": 0}
    v = tr.gs_dev_m[sel] / units.FT
    lat = tr.loc_dev_m[sel] / units.FT
    cas = tr.airspeed_mps[sel] / units.KT
    return {
        "vertical_rms_ft": float(np.sqrt(np.mean(v**2))),
        "lateral_rms_ft": float(np.sqrt(np.mean(lat**2))),
        "vertical_max_ft": float(np.max(np.abs(v))),
        "lateral_max_ft": float(np.max(np.abs(lat))),
        "cas_min_kt": float(cas.min()),
        "cas_max_kt": float(cas.max()),
        "samples": int(sel.sum()),
    }
