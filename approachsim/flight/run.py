"""The approach run loop: JSBSim flies the profile's approach under the autopilot and produces the Truth record.

Two lines fly the default profile on truth navigation:

    approach = Approach(load_profile("profiles/default.toml"))
    result = approach.fly(seed=1, run=0)

`Approach` parses the aircraft and linearizes it once; `fly` builds a fresh JSBSim instance per run (a few
ms), sets the day's atmosphere, wind and seeded turbulence, trims on the glidepath and steps at the IMU
rate. After writing Truth row k it calls `nav_source.step(k, truth)` (records.NavigationSource) and the
autopilot flies guidance on the position and velocity it returns; what guidance flew on is kept in the
FlightResult, so that

    flight technical error = guidance estimate - desired path,  navigation error = estimate - truth,
    total system error = truth - desired path.

The run ends when the IMU descends to `stop_height_m` above the threshold ("reached stop height"), or, with
`land=True`, after a flare when the main gear touches ("touchdown"), or on ground contact, divergence or
timeout (each a termination reason). With a navigation source, the Truth arrays are preallocated for the
longest permitted run (NaN until written) and trimmed at the end; the source sees that record and may read
rows <= k only. On truth navigation (the default) nothing reads the record during the run, so the rows are
collected in a list and stacked at the end (same values; tested).

Truth is of the IMU point (aircraft file [imu]): position, velocity and specific force are moved from the
CG with the rigid-body lever-arm terms (f_imu = f_cg + w_ib' x l + w_ib x (w_ib x l), in the exact form of
JSBSim's Euler step, plus the gravitation gradient; v_imu = v_cg + C_nb (w_eb x l), resolved on the IMU's own
NED axes), and the static pressure is moved hydrostatically to the IMU height; the lever arm l is fixed at
trim (the CG moves by well under a millimetre as fuel burns). docs/truth.md says why each term is there.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from approachsim import geo, units
from approachsim.config import ProfileError
from approachsim.flight.aircraft import Aircraft, load_aircraft
from approachsim.flight.autopilot import Autopilot, Geometry, Trim
from approachsim.flight.design import Linearization
from approachsim.flight.envelope import WATCH_HEIGHT_M, StabilityMonitor, check_envelope
from approachsim.flight.fdm import FDM, InitialCondition, TrimError
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

_READ = (
    "position/lat-geod-rad", "position/long-gc-rad", "position/geod-alt-ft",
    "velocities/v-north-fps", "velocities/v-east-fps", "velocities/v-down-fps",
    "attitude/phi-rad", "attitude/theta-rad", "attitude/psi-rad",
    "velocities/pi-rad_sec", "velocities/qi-rad_sec", "velocities/ri-rad_sec",
    "velocities/p-rad_sec", "velocities/q-rad_sec", "velocities/r-rad_sec",
    "accelerations/pidot-rad_sec2", "accelerations/qidot-rad_sec2", "accelerations/ridot-rad_sec2",
    "forces/fbx-total-lbs", "forces/fby-total-lbs", "forces/fbz-total-lbs", "inertia/mass-slugs",
    "atmosphere/P-psf", "atmosphere/T-R", "velocities/vc-kts", "aero/beta-rad",
    "velocities/vtrue-fps",
)
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
        if on_truth:
            rows: list[tuple[float, ...]] = []
            rows_append = rows.append
        else:
            buf = np.full((n_max, _NCOL), np.nan)
            gbuf = np.full((n_max, 6), np.nan)
            truth = _truth_views(buf, rw.frame)

        nodes = [fdm.node(n) for n in _READ]
        getters = [n.get_double_value for n in nodes]
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
        terr0 = terrain.height_m[0]
        set_terrain = fdm.node("position/terrain-elevation-asl-ft").set_double_value

        # constants: lever arm (body axes, m), geodesy, runway frame
        cg = (fdm["inertia/cg-x-in"], fdm["inertia/cg-y-in"], fdm["inertia/cg-z-in"])
        imu = ac.imu_location_struct_m
        IN = 0.0254
        lx = cg[0] * IN - imu[0]  # structural x aft, body x forward
        ly = imu[1] - cg[1] * IN
        lz = cg[2] * IN - imu[2]  # structural z up, body z down
        r_n, r_e = geo.radii(ic.lat_rad)
        r_n, r_e = float(r_n), float(r_e)
        a, e2 = geo.A_WGS84, geo.E2_WGS84
        c_rwy = rw.frame.c_ecef_to_rwy
        o = rw.frame.origin_ecef
        ox, oy, oz = float(o[0]), float(o[1]), float(o[2])
        c00, c01, c02 = (float(v) for v in c_rwy[0])
        c10, c11, c12 = (float(v) for v in c_rwy[1])
        h_thr = rw.elevation_m
        tan_gp = math.tan(rw.glidepath_rad)
        tch = rw.tch_m
        FT, FPS, KT = units.FT, units.FPS, units.KT
        LBF_PER_SLUG = units.LBF / units.SLUG  # (lbf/slug) -> m/s^2
        PSF = units.PSF
        gm = geo.GM_JSBSIM
        hdt = 0.5 * dt
        omega = geo.OMEGA_JSBSIM
        RANKINE = 1.8  # Rankine per kelvin
        g0_over_r = units.G0 / R_AIR
        sin, cos, sqrt = math.sin, math.cos, math.sqrt

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
            (lat, lon, h_ft, vn_f, ve_f, vd_f, phi, th, psi, pi_, qi, ri, p, q, r, pid, qid, rid,
             fx, fy, fz, m, p_psf, t_r, vc_kt, beta, vt_fps) = [gv() for gv in getters]
            h = h_ft * FT
            # body -> NED direction cosines from the Euler angles
            sf, cf, st, ct, sp, cp = sin(phi), cos(phi), sin(th), cos(th), sin(psi), cos(psi)
            n00, n01, n02 = ct * cp, sf * st * cp - cf * sp, cf * st * cp + sf * sp
            n10, n11, n12 = ct * sp, sf * st * sp + cf * cp, cf * st * sp - sf * cp
            n20, n21, n22 = -st, sf * ct, cf * ct
            # lever-arm terms: w_eb x l (velocity), w_ib' x l + w_ib x (w_ib x l) (specific force)
            ux, uy, uz = q * lz - r * ly, r * lx - p * lz, p * ly - q * lx
            wx, wy, wz = qi * lz - ri * ly, ri * lx - pi_ * lz, pi_ * ly - qi * lx
            s = LBF_PER_SLUG / m
            # lever-arm acceleration over the step, exactly as JSBSim's rectangular-Euler step moves the IMU point:
            # (R (w1 x l) - w x l) / dt, w1 = w + dt w' the next inertial rate, R the body rotation of the step
            # (q(+) = normalize(q (1, dt w / 2))): w' x l + w x (w x l) + O(dt)
            ex, ey, ez = hdt * pi_, hdt * qi, hdt * ri
            ux1, uy1, uz1 = pi_ + dt * pid, qi + dt * qid, ri + dt * rid
            ax, ay, az = uy1 * lz - uz1 * ly, uz1 * lx - ux1 * lz, ux1 * ly - uy1 * lx  # w1 x l
            bx, by, bz = ey * az - ez * ay, ez * ax - ex * az, ex * ay - ey * ax  # e x (w1 x l)
            k2 = 2.0 / (1.0 + ex * ex + ey * ey + ez * ez)
            fbx = fx * s + (ax + k2 * (bx + ey * bz - ez * by) - wx) / dt
            fby = fy * s + (ay + k2 * (by + ez * bx - ex * bz) - wy) / dt
            fbz = fz * s + (az + k2 * (bz + ex * by - ey * bx) - wz) / dt
            vn = vn_f * FPS + n00 * ux + n01 * uy + n02 * uz
            ve = ve_f * FPS + n10 * ux + n11 * uy + n12 * uz
            vd = vd_f * FPS + n20 * ux + n21 * uy + n22 * uz
            # IMU position: geodetic offset of C_nb l, then ECEF and runway frame
            dn = n00 * lx + n01 * ly + n02 * lz
            dE = n10 * lx + n11 * ly + n12 * lz
            dd = n20 * lx + n21 * ly + n22 * lz
            lat_i = lat + dn / (r_n + h)
            slat, clat = sin(lat_i), cos(lat_i)
            lon_i = lon + dE / ((r_e + h) * cos(lat))
            h_i = h - dd
            re_i = a / sqrt(1.0 - e2 * slat * slat)
            x_e = (re_i + h_i) * clat * cos(lon_i)
            y_e = (re_i + h_i) * clat * sin(lon_i)
            z_e = (re_i * (1.0 - e2) + h_i) * slat
            # gravitation at the IMU differs from the CG's (JSBSim's, in f_cg) by the gradient GM/r^3 (3 uu' - I) d,
            # d = C_nb l: the accelerometer there feels f_imu = ... - (G_imu - G_cg), in body axes
            # GM/r^3 (l - 3 d_D C_nb' e_D)  (J2 part of the gradient: < 1e-8 m/s^2)
            kg = gm / (x_e * x_e + y_e * y_e + z_e * z_e) ** 1.5
            fbx += kg * (lx - 3.0 * dd * n20)
            fby += kg * (ly - 3.0 * dd * n21)
            fbz += kg * (lz - 3.0 * dd * n22)
            # JSBSim's Euler step applies the gravitation of the step's start, G(r_i[k]), while the point moves at
            # its inertial velocity v_i = v + W x r (~300 m/s east): the recorded trajectory is that of gravitation
            # at the step's midpoint plus the specific force f + G(r_i[k]) - G(r_i[k] + v_i dt/2)
            # = f + GM/r^3 dt/2 (v_i - 3 u (u . v_i)) (u up; <= 3e-6 m/s^2, JSBSim's O(dt) error put where an
            # accelerometer on this trajectory would see it)
            kv = kg * hdt
            gn_, ge_, gd_ = kv * vn, kv * (ve + omega * sqrt(x_e * x_e + y_e * y_e)), -2.0 * kv * vd
            fbx += n00 * gn_ + n10 * ge_ + n20 * gd_
            fby += n01 * gn_ + n11 * ge_ + n21 * gd_
            fbz += n02 * gn_ + n12 * ge_ + n22 * gd_
            # JSBSim holds that specific force fixed in inertial axes over the step while the body turns at w: the
            # record holds its body-axis mean, (1/dt) int_0^dt Exp(-[w x] t) dt f = f - c1 phi x f + c2 phi x (phi x f)
            # (phi = w dt; c1 = (1 - cos a)/a^2, c2 = (a - sin a)/a^3, a = |phi|, series), so that dt f_body is the
            # exact velocity increment of the step in body axes
            px, py, pz = 2.0 * ex, 2.0 * ey, 2.0 * ez
            a2 = px * px + py * py + pz * pz
            c1, c2 = 0.5 - a2 / 24.0, 1.0 / 6.0 - a2 / 120.0
            qx, qy, qz = py * fbz - pz * fby, pz * fbx - px * fbz, px * fby - py * fbx  # phi x f
            fbx, fby, fbz = (fbx - c1 * qx + c2 * (py * qz - pz * qy), fby - c1 * qy + c2 * (pz * qx - px * qz),
                             fbz - c1 * qz + c2 * (px * qy - py * qx))
            # the IMU's own NED axes are turned from the CG's by t = (dE/(R_E+h), -dN/(R_N+h), -dE tan L/(R_E+h))
            # (l/R ~ 1.4e-6 rad): velocity and attitude are resolved on them, x_imu = (I - [t x]) x_cg
            ta, tb, tc = dE / (r_e + h), -dn / (r_n + h), -dE * math.tan(lat) / (r_e + h)
            vn, ve, vd = vn - tb * vd + tc * ve, ve - tc * vn + ta * vd, vd - ta * ve + tb * vn
            m00, m10, m20 = n00 - tb * n20 + tc * n10, n10 - tc * n00 + ta * n20, n20 - ta * n10 + tb * n00
            m21, m22 = n21 - ta * n11 + tb * n01, n22 - ta * n12 + tb * n02
            phi_i = math.atan2(m21, m22)
            th_i = -math.asin(m20)
            psi_i = psi + math.remainder(math.atan2(m10, m00) - psi, 2.0 * math.pi)
            # static pressure at the IMU point: hydrostatic over the CG-to-IMU height difference (JSBSim gives it
            # at the CG), dp = -p g0 / (R_air T) dz  (ISA hydrostatics in geopotential height, dH = dz here)
            p_imu = p_psf * PSF * math.exp(dd * g0_over_r / (t_r / RANKINE))
            dx, dy, dz = x_e - ox, y_e - oy, z_e - oz
            xr = c00 * dx + c01 * dy + c02 * dz
            yr = c10 * dx + c11 * dy + c12 * dz
            zr = h_i - h_thr
            if flat_terrain:
                terr = terr0
            else:
                terr = float(np.interp(xr, terrain.along_m, terrain.height_m))
                set_terrain(terr / FT)
            if h_i - terr < LOW_READ_HEIGHT_M:
                w0, w1, w2, g1_ft, g2_ft = [gv() for gv in getters_low]
            if turb is not None:  # turbulence for the next step, at the CG's height above the terrain
                tn, te, td = turb_step(k, h - terr, vt_fps * FPS)
                set_tn(tn)
                set_te(te)
                set_td(td)
            # body -> NED quaternion (scalar first) from the IMU point's Euler angles
            s1, c1 = sin(0.5 * phi_i), cos(0.5 * phi_i)
            s2, c2 = sin(0.5 * th_i), cos(0.5 * th_i)
            s3, c3 = sin(0.5 * psi_i), cos(0.5 * psi_i)
            head = (
                k * dt, lat_i, lon_i, h_i, x_e, y_e, z_e, vn, ve, vd,
                c1 * c2 * c3 + s1 * s2 * s3, s1 * c2 * c3 - c1 * s2 * s3,
                c1 * s2 * c3 + s1 * c2 * s3, c1 * c2 * s3 - s1 * s2 * c3,
                phi_i, th_i, psi_i, pi_, qi, ri, fbx, fby, fbz, p_imu, t_r / 1.8, h_i - terr,
                xr, yr, zr, zr - (tch - xr * tan_gp), yr,
            )
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
                term = mon_step(xr, yr, zr, v_air * (vc_kt * KT) / (vt_fps * FPS), vd, sqrt(vn * vn + ve * ve))
            if on_truth:
                # TruthSource.step would return this row's r_rwy and v_ned: fly on them directly, and keep the
                # rows in a list (no one reads the arrays during the run)
                if term is not None:  # the controls of the previous step still act on the last row
                    rows_append(head + (de + pitch_trim, da, dr, thr, vc_kt * KT))
                    termination = term
                    break
                h_gear = min(g1_ft, g2_ft) * FT if land else None
                de, da, dr, thr = ap_step(xr, yr, zr, vn, ve, vd, phi, th, p, q, beta, vc_kt * KT, h_gear,
                                          vt_fps * FPS)
                rows_append(head + (de + pitch_trim, da, dr, thr, vc_kt * KT))
            else:
                # the navigation source sees row k (controls: those of the previous step until replaced below)
                buf[k] = head + (de + pitch_trim, da, dr, thr, vc_kt * KT)
                gr, gv = src.step(k, truth)
                gx, gy, gz = float(gr[0]), float(gr[1]), float(gr[2])
                gvn, gve, gvd = float(gv[0]), float(gv[1]), float(gv[2])
                gbuf[k] = (gx, gy, gz, gvn, gve, gvd)
                if term is not None:
                    termination = term
                    break
                h_gear = min(g1_ft, g2_ft) * FT if land else None
                de, da, dr, thr = ap_step(gx, gy, gz, gvn, gve, gvd, phi, th, p, q, beta, vc_kt * KT, h_gear,
                                          vt_fps * FPS)
                buf[k, _CTRL:_CTRL + 4] = (de + pitch_trim, da, dr, thr)
            # the controls for the next step
            set_de(de)
            set_da(da)
            set_dr(dr)
            set_thr[0](thr)
            set_thr[1](thr)
        n = k + 1
        if on_truth:
            buf = np.array(rows, dtype=float).reshape(n, _NCOL)
            truth = _truth_views(buf, rw.frame)
            gbuf = np.concatenate([truth.r_rwy, truth.v_ned], axis=1)
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
