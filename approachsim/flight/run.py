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

One loop serves both: per step JSBSim's reads (one LoopIO of flight/fdm.py, bound per run), one compiled call
(core/loop/flight_step.fly_step: Truth row, the Dryden turbulence, the termination checks with the stabilized-approach
monitor and, when the truth guides, the autopilot), the writes (controls, gusts, terrain) and JSBSim's next step.
With a navigation source, fly_step stops after the termination checks, the source steps on row k, and
kernels.fly_control runs the autopilot on its guidance. The autopilot, turbulence and monitor are compiled twins of
flight/autopilot.py, flight/turbulence.py and flight/envelope.py, which stay the readable oracles (equal bit for
bit, tests/unit/flight/test_flight_loop_kernels.py) and fill the kernels' parameter and state vectors. Why a run
ended is a code during the loop, worded after it (termination_reason).

Truth is of the IMU point (aircraft file [imu]), one row per step from the compiled kernel of core/loop/flight_step.py:
position, velocity and specific force are moved from the CG with the rigid-body lever-arm terms (f_imu = f_cg +
w_ib' x l + w_ib x (w_ib x l), in the exact form of JSBSim's Euler step, plus the gravitation gradient; v_imu =
v_cg + C_nb (w_eb x l), resolved on the IMU's own NED axes), and the static pressure is moved hydrostatically to
the IMU height; the lever arm l is fixed at trim (the CG moves by well under a millimetre as fuel burns).
docs/truth.md says why each term is there.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass
from typing import Any

import numpy as np

from approachsim import units
from approachsim.config import ProfileError
from approachsim.core import layouts
from approachsim.core.entry import entry_point
from approachsim.core.loop import closed_step as ck
from approachsim.core.loop import direct as dk
from approachsim.core.loop import flight_step as fk
from approachsim.core.loop import jsbsim_abi
from approachsim.evaluate.touchdown import contact_offsets_m, touchdown_scalars
from approachsim.flight import vectors as fv
from approachsim.flight.aircraft import Aircraft, load_aircraft
from approachsim.flight.autopilot import Autopilot, Geometry, Trim
from approachsim.flight.design import Linearization
from approachsim.flight.envelope import StabilityMonitor, check_envelope, unstabilized_reason
from approachsim.flight.fdm import FDM, InitialCondition, TrimError
from approachsim.flight.path import PathGuidance
from approachsim.flight.trim import (
    CAS_TOLERANCE_MPS,
    PATH_TOLERANCE_RAD,
    StartError,
    solve_start,
    start_condition,
)
from approachsim.flight.turbulence import DrydenTurbulence
from approachsim.flight.vectors import imu_point_constants
from approachsim.flight.wind import varies as wind_varies
from approachsim.glidepath import GlidePath
from approachsim.leadin import lead_in_of
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
_COLS = {name: (layouts.TRUTH_ROW.start(name), layouts.TRUTH_ROW.width(name)) for name in layouts.TRUTH_ROW.names}
"""The row buffer's Truth fields: (first column, width), from core/layouts.py TRUTH_ROW."""
_NCOL = layouts.N_ROW
_COL_STARTS = np.array([c for c, _ in _COLS.values()], dtype=np.int64)


def _final_truth(buf: Array, n: int, runway) -> Truth:
    """The Truth of a flown run: the first n rows of the row buffer as one contiguous array per field."""
    outs = tuple(np.empty((n, w)) for (c, w) in _COLS.values())
    fk.split_rows(buf, n, _COL_STARTS, outs)
    return Truth(**{name: (o[:, 0] if w == 1 else o) for (name, (c, w)), o in zip(_COLS.items(), outs, strict=True)},
                 runway=runway)


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
    """Landing runs: the main gears' mean runway-frame x when a main gear touched down, m past the threshold
    (evaluate.touchdown.touchdown_scalars td_x_m; nan: none)."""
    touchdown_sink_mps: float = math.nan
    """Landing runs: sink rate of the main gear that touched (positive down), m/s (nan: none)."""
    touchdown_y_m: float = math.nan
    """Landing runs: the main-gear centre's runway-frame y at touchdown, m right of the centreline (nan: none)."""
    touchdown_drift_rad: float = math.nan
    """Landing runs: drift (wheel-slip) angle at touchdown, the touching main gear's ground track minus the
    heading, rad (+: the gear moves to the right of where the nose points; nan: none)."""
    touchdown_crab_rad: float = math.nan
    """Landing runs: heading minus the runway heading at touchdown, rad (nan: none)."""
    loop: str = "python"
    """Which flight loop flew it (`flight_loop`): "direct" (JSBSim's C++ called from compiled code) or "python"."""
    loop_reason: str | None = None
    """Why the loop was "python" (None: it was "direct")."""

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
        self._gear: Array | None = None
        self._contact: Array | None = None
        self.lead_in = lead_in_of(profile.runway)
        """The lead-in path flown before the final (runway.lead_in; flight/path.py), None for a straight-in."""

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
    def time_budget_s(self) -> float:
        """The longest a run of this approach may fly (s): twice the still-air time to the threshold at the approach
        speed, at least 60 s; a run still flying then ends as "timeout". A navigation source sized for it
        (NavInTheLoop(max_time_s=...)) covers every row the flight can have."""
        length = self.profile.runway.start_distance_m if self.lead_in is None else self.lead_in.length_m
        return max(60.0, 2.0 * length / self.aircraft.approach_speed_mps)

    @property
    def main_gear_lever_arms_m(self) -> Array:
        """(2, 3) the left and right main gears' contact points relative to the IMU, body axes (x forward, y right,
        z down), m: the JSBSim model's gear/unit[1] and unit[2] (FDM.gear_location_struct_m) less the aircraft
        file's IMU location (read once per Approach)."""
        if self._gear is None:
            fdm = FDM(self.aircraft.jsbsim_model, self.dt_s)
            imu = np.asarray(self.aircraft.imu_location_struct_m, dtype=float)
            d = np.array([fdm.gear_location_struct_m(u) - imu for u in (1, 2)])
            arms = np.column_stack((-d[:, 0], d[:, 1], -d[:, 2]))  # structural (x aft, y right, z up) -> body
            if not arms[0, 1] < 0.0 < arms[1, 1]:
                raise RuntimeError(f"JSBSim model {self.aircraft.jsbsim_model!r}: gear units 1 and 2 are not the "
                                   f"left and right main gear (y {arms[0, 1]:.2f}, {arms[1, 1]:.2f} m)")
            self._gear = arms
        return self._gear

    @property
    def ground_contact_m(self) -> Array | None:
        """(k, 3) the right wing's ground-contact points' offsets from the right main gear's contact point, body
        axes (x forward, y right, z down), m, with the strut at the aircraft file's compression
        (evaluate.touchdown.contact_offsets_m; None: the aircraft file has no [ground_contact] table)."""
        gc = self.aircraft.ground_contact
        if gc is None:
            return None
        if self._contact is None:
            fdm = FDM(self.aircraft.jsbsim_model, self.dt_s)
            self._contact = contact_offsets_m(np.array(gc.points_struct_m), fdm.gear_location_struct_m(2),
                                              gc.gear_compression_m)
        return self._contact

    @property
    def gear_arm_m(self) -> float:
        """Distance along the body x axis from the IMU (the guidance point) back to the main gears' centre, m: the
        autopilot steers the main gear onto the centreline in the runway alignment and flares on its height and
        sink rate (main_gear_lever_arms_m; 10.11 m for the 737)."""
        return float(-np.mean(self.main_gear_lever_arms_m[:, 0]))

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
        src = None if nav_source is None or type(nav_source) is TruthSource else nav_source
        if self.lead_in is not None:  # the autopilot flies the lead-in on guidance along its path (flight/path.py)
            if src is not None:
                raise ProfileError("runway.lead_in: the lead-in is flown open loop only (on the truth), not on a "
                                   "navigation source")
            src = PathGuidance(self.lead_in, GlidePath.of(rw), ac.gains.k_loc_d)
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
        if max_time_s is None:
            max_time_s = self.time_budget_s
        n_max = int(math.ceil(max_time_s / dt)) + 1
        io = fdm.loop_io(layouts.RAW_FIELDS, layouts.GEAR_FIELDS, layouts.GEAR_AIRBORNE)
        par, st, nu = self._kernel_vectors(fdm, ic, seed, run, n_max)
        turbulent = (par[layouts.P_STEP + layouts.F_TURBULENT] != 0.0  # gusts written: turbulence, varying wind
                     or par[layouts.P_STEP + layouts.F_WIND_VARIES] != 0.0)
        if turbulent:
            io.gust_on()
        hilly = par[layouts.P_STEP + layouts.F_N_TERRAIN] > 1
        buf = np.full((n_max, _NCOL), np.nan)
        truth = _truth_views(buf, rw.frame)

        # the loop: JSBSim's reads, one compiled call (fly_step: truth row, turbulence, termination and, guided by
        # the truth, the autopilot), the writes, JSBSim's step; a navigation source sees row k between fly_step
        # and the autopilot (fly_control)
        # A source whose navigation runs compiled (`inloop()`, loop/closed_loop.py) is stepped inside the same call
        # (core/loop/closed_step.py fly_step_closed, on the navigation's packed arrays nw, fa, ia): Python acts
        # only at the rows it asks for (start, baro samples, aiding epochs)
        guided = src is None
        fused = None if src is None else getattr(src, "inloop", lambda: None)()
        if fused is not None:
            if fused.guidance.shape[0] < n_max:
                raise ValueError(f"the navigation source has {fused.guidance.shape[0]} rows, the flight up to {n_max}: "
                                 f"size it for the flight (NavInTheLoop(max_time_s=Approach.time_budget_s))")
            guidance = fused.guidance  # its rows: the kernel writes them
        else:
            guidance = None if src is None else np.full((n_max, 6), np.nan)
        loop, loop_reason = flight_loop(io, guided, fused)
        read, read_near, run_step = io.read, io.read_near, io.run
        if loop == "python":  # the Python loop's compiled steps (the reads are a tuple): compiled only when flown
            raw0 = (0.0,) * (layouts.N_RAW + len(layouts.GEAR_FIELDS))
            step = entry_point(fk.fly_step, 0, raw0, buf, nu, par, st, guided)
            control = None if guided else entry_point(fk.fly_control, 0, guidance, buf, par, st)
            if fused is not None:
                nav_args = (fused.nw, fused.fa, fused.ia)
                step_nav = entry_point(ck.fly_step_closed, 0, raw0, buf, nu, par, st, *nav_args)
                control_nav = entry_point(ck.fly_control_closed, 0, buf, par, st, *nav_args)
                act = fused.act
        set_de, set_da, set_dr, (set_thr0, set_thr1) = io.set_elevator, io.set_aileron, io.set_rudder, io.set_throttle
        set_gn, set_ge, set_gd = io.set_gust_fps
        set_terrain_ft = io.set_terrain_ft
        code = fk.TERM_NONE
        near = True
        k = 0
        direct = io.direct if loop == "direct" else None
        if direct is not None:  # the same loop compiled, JSBSim called from it (core/loop/direct.py)
            raw = np.zeros(layouts.N_READ)
            if guided:
                k, code = entry_point(dk.fly_guided, direct, raw, buf, nu, par, st)(direct, raw, buf, nu, par, st)
            else:
                k, code = self._fly_closed_direct(direct, raw, buf, nu, par, st, fused, truth)
        for k in range(n_max if direct is None else 0):
            raw = read_near() if near else read()
            if fused is not None:
                code, ncode, de, da, dr, thr, gn, ge, gd, terr_ft, near = step_nav(k, raw, buf, nu, par, st,
                                                                                   *nav_args)
                if ncode:  # the source's Python part at this row, then the guidance and the autopilot
                    act(k, truth, ncode)
                    de, da, dr, thr = control_nav(k, buf, par, st, *nav_args)
                if code:
                    break
            else:
                code, de, da, dr, thr, gn, ge, gd, terr_ft, near = step(k, raw, buf, nu, par, st, guided)
                if src is not None:
                    pos, vel = src.step(k, truth)
                    guidance[k, 0:3] = pos
                    guidance[k, 3:6] = vel
                    if code:
                        break
                    de, da, dr, thr = control(k, guidance, buf, par, st)
                elif code:
                    break
            set_de(de)
            set_da(da)
            set_dr(dr)
            set_thr0(thr)
            set_thr1(thr)
            if turbulent:
                set_gn(gn)
                set_ge(ge)
                set_gd(gd)
            if hilly:
                set_terrain_ft(terr_ft)
            run_step()  # JSBSim's step k + 1 (after the last permitted row: one step never read)
        n = k + 1
        final = _final_truth(buf, n, rw.frame)
        if guidance is None:  # guided by the truth
            g_r, g_v = final.r_rwy.copy(), final.v_ned.copy()
        else:
            g_r, g_v = np.ascontiguousarray(guidance[:n, 0:3]), np.ascontiguousarray(guidance[:n, 3:6])
        fs = st[layouts.S_STEP:layouts.S_STEP + layouts.N_F_STATE]
        td = {}
        if code in (fk.TERM_TOUCHDOWN, fk.TERM_SHORT):  # scored at the main gear, not the IMU point
            sc = touchdown_scalars(final, self.main_gear_lever_arms_m, self.ground_contact_m, slope=rw.slope)
            td = {"touchdown_x_m": sc["td_x_m"], "touchdown_sink_mps": sc["td_sink_mps"],
                  "touchdown_y_m": sc["td_y_m"], "touchdown_drift_rad": sc["td_gear_slip_rad"],
                  "touchdown_crab_rad": sc["td_crab_rad"]}
            fs[layouts.FS_TD_X] = sc["td_x_m"]
            code = fk.TERM_TOUCHDOWN if sc["td_x_m"] >= 0.0 else fk.TERM_SHORT
        return FlightResult(
            truth=final,
            guidance_r_rwy=g_r,
            guidance_v_ned=g_v,
            termination=termination_reason(code, fs),
            lowest_height_ft=float(fs[layouts.FS_LOWEST]) / units.FT,
            **td,
            seed=seed,
            run=run,
            turbulence_seed=turb_seed,
            loop=loop,
            loop_reason=loop_reason,
        )

    @staticmethod
    def _fly_closed_direct(direct: Array, raw: Array, buf: Array, nu: Array, par: Array, st: Array, fused: Any,
                           truth: Truth) -> tuple[int, int]:
        """The closed loop on core/loop/direct.fly_closed: compiled between the rows where the navigation needs
        Python (fused.act), where the loop below does what the Python loop does at such a row. Returns (the last
        row k, its TERM_* code)."""
        nav_args = (fused.nw, fused.fa, fused.ia)
        cmd = np.zeros(8)
        n_max = buf.shape[0]
        seg = entry_point(dk.fly_closed, 0, False, cmd, True, direct, raw, buf, nu, par, st, *nav_args)
        control_nav = entry_point(ck.fly_control_closed, 0, buf, par, st, *nav_args)
        act = fused.act
        k, pending, near = 0, False, True
        while True:
            k, code, ncode, near = seg(k, pending, cmd, near, direct, raw, buf, nu, par, st, *nav_args)
            if k == n_max:  # every row flown (and the step after the last one taken)
                return n_max - 1, code
            if not ncode:  # a termination at a row that needed nothing of Python
                return k, code
            act(k, truth, ncode)
            cmd[0], cmd[1], cmd[2], cmd[3] = control_nav(k, buf, par, st, *nav_args)
            if code:
                return k, code
            k, pending = k + 1, True

    def _kernel_vectors(self, fdm: FDM, ic: InitialCondition, seed: int, run: int,
                        n_max: int) -> tuple[Array, Array, Array]:
        """fly_step's parameter and state vectors and the turbulence noise for one run, from the
        trimmed JSBSim instance and fresh oracles (autopilot, monitor, turbulence: their compiled twins start
        from the oracles' state)."""
        prof, ac, rw, dt = self.profile, self.aircraft, self.profile.runway, self.dt_s
        env = prof.environment
        # the IMU-point kernel's constants: lever arm (body axes, m; CG to IMU), geodesy, runway frame
        cg = (fdm["inertia/cg-x-in"], fdm["inertia/cg-y-in"], fdm["inertia/cg-z-in"])
        imu = ac.imu_location_struct_m
        IN = 0.0254
        lever = (cg[0] * IN - imu[0], imu[1] - cg[1] * IN, cg[2] * IN - imu[2])  # structural x aft / z up
        const = imu_point_constants(np.array(lever), ic.lat_rad, rw, dt)
        trim = Trim(theta_rad=fdm["attitude/theta-rad"], throttle=fdm["fcs/throttle-cmd-norm[0]"],
                    cas_mps=ac.approach_speed_mps)
        ap = Autopilot(ac.gains, trim, Geometry(rw.heading_rad, rw.glidepath_rad, rw.tch_m, rw.threshold_lat_rad), dt,
                       gear_arm_m=self.gear_arm_m)
        monitor = StabilityMonitor(rw.glidepath_rad, rw.tch_m, ac.approach_speed_mps, dt,
                                   curvature=ap.cone.curvature)
        turb = None
        nu = np.zeros((1, 3))
        if env.turbulence != "none":
            turb = DrydenTurbulence(env.turbulence, stream(seed, run, "turbulence"), n_max, dt,
                                    env.wind_from_rad + math.pi)
            nu = turb.nu
        par, st = fv.flight_vectors(
            const, ap, monitor, turb, np.asarray(prof.terrain.along_m, dtype=float),
            np.asarray(prof.terrain.height_m, dtype=float),
            pitch_trim=fdm["fcs/pitch-trim-cmd-norm"],
            stop_height_m=self.stop_height_m,
            land=self.land,
            monitor_floor_m=ac.gains.flare_height_m if self.land else -math.inf,  # the flare leaves the glidepath
            # the steady wind (blowing towards from + pi), m/s
            wind_ned_mps=(-env.wind_speed_mps * math.cos(env.wind_from_rad),
                          -env.wind_speed_mps * math.sin(env.wind_from_rad)),
            wind=env if wind_varies(env) else None,
            jsbsim_wind_ned_mps=(-ic.wind_speed_mps * math.cos(ic.wind_from_rad),
                                 -ic.wind_speed_mps * math.sin(ic.wind_from_rad)),
            gear_x_m=self.gear_arm_m if self.land else 0.0,
            divergence_m=(math.inf, math.inf) if self.lead_in is not None else (fk.DIVERGED_VERTICAL_M,
                                                                                fk.DIVERGED_LATERAL_M),
        )
        return par, st, nu




def flight_loop(io: Any, guided: bool, fused: Any) -> tuple[str, str | None]:
    """Which loop flies this run, chosen once: "direct" (core/loop/direct.py: JSBSim's property reads, writes and
    step called from compiled code) when the autopilot flies on the truth (guided) or the navigation source steps in
    the compiled row (fused, its InLoop arrays), and the jsbsim wheel's C++ entry points were found and checked on
    this run's objects (io.direct); else "python" with the reason. Both give the same bits."""
    if not guided and fused is None:
        return "python", "the navigation source steps in Python every row (no compiled row: loop/paths.py)"
    if io.direct is None:
        if os.environ.get(jsbsim_abi.ENV_SWITCH, "1").strip() == "0":
            return "python", f"{jsbsim_abi.ENV_SWITCH}=0"
        return "python", "the jsbsim wheel's C++ entry points were not found or not checked (core/loop/jsbsim_abi.py)"
    return "direct", None


def termination_reason(code: int, fs: Array) -> str:
    """FlightResult.termination in words from fly_step's termination code (core/loop/flight_step.py TERM_*) and the
    figures its state fs (FS_*) keeps; TERM_NONE after the last permitted step is a timeout."""
    if code == fk.TERM_STOP:
        return "reached stop height"
    if code == fk.TERM_TOUCHDOWN:
        return "touchdown"
    if code == fk.TERM_SHORT:
        return f"touchdown short of the threshold ({-fs[layouts.FS_TD_X] / units.FT:.0f} ft)"
    if code == fk.TERM_GROUND:
        return "ground contact"
    if code == fk.TERM_DIVERGED:
        return "diverged"
    if code == fk.TERM_UNSTABLE:
        return unstabilized_reason(int(fs[layouts.FS_MON]), fs[layouts.FS_MON_Z], fs[layouts.FS_MON_A],
                                   fs[layouts.FS_MON_B])
    return "timeout"


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
