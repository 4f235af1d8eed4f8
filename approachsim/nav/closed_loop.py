"""Navigation in the loop: a NavigationSource that runs the INS + filter step by step inside the flight loop,
and the flight technical / navigation system / total system error split of a flown approach.

    source = NavInTheLoop(profile, seed, run)          # sensor errors drawn once, applied row by row
    result = Approach(profile).fly(seed, run, nav_source=source)
    errors = approach_errors(result.truth, result.guidance_r_rwy, profile.runway)   # TSE = FTE + NSE

The source reads truth rows <= k only (records.NavigationSource): at row k it applies the pre-drawn IMU
errors to the increment (k-1, k], steps the INS, and at aiding epochs applies the other sensors' pre-drawn
errors to row k and runs the filter (system.NavSystem.aid). Guidance gets the navigation output
(feed-forward INS - estimated error, or the fed-back INS) in the runway frame.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Any

import numpy as np

from approachsim import geo
from approachsim.nav import ins
from approachsim.nav.system import NavRun, NavSystem, StatusLog
from approachsim.records import ApproachErrors, NavSolution, Truth
from approachsim.seeding import stream
from approachsim.sensors.suite import SensorSuite, SuiteErrors

Array = np.ndarray


@dataclass
class NavInTheLoop:
    """NavigationSource running this profile's navigation system for Monte Carlo run `run` of campaign `seed`.

    max_time_s bounds the flight (sensor errors are drawn for it once). After the flight, `result(truth)`
    gives the NavRun (solution at every truth row, status log, filter history).
    """

    profile: Any
    seed: int
    run: int = 0
    max_time_s: float | None = None
    nav: NavSystem = field(init=False)
    suite: SensorSuite = field(init=False)

    def __post_init__(self) -> None:
        self.nav = NavSystem.from_profile(self.profile)
        self.suite = SensorSuite.from_profile(self.profile)
        self.dt = 1.0 / self.profile.rates.imu_hz
        t_max = self.max_time_s or max(60.0, 2.0 * self.profile.runway.start_distance_m / 40.0)
        self.t_s = np.arange(int(math.ceil(t_max / self.dt)) + 1) * self.dt
        self.errors = self.suite.draw(self.t_s, self.seed, self.run)
        # truth row -> sample index, per sensor
        self.sample_at = {name: {int(r): j for j, r in enumerate(e.rows)} for name, e in self.errors.sensors.items()}
        self.epoch_rows = max(1, int(round(self.profile.rates.imu_hz / self.nav.nav.aiding_rate_hz)))
        self.gains = self.nav.loop_gains()
        self.s: ins.InsState | None = None
        self.runs: list = []
        self.h_baro_hold = math.nan
        self.f_sum = np.zeros((1, 3))
        self.t_last = 0.0
        self.out: dict[str, list] = {k: [] for k in ("lat", "lon", "h", "v", "c", "ppos", "clk", "clk_sd")}
        self.epochs: dict[str, list] = {"t": [], "x": [], "pd": [], "pnav": [], "err": []}

    def _apply(self, name: str, k: int, truth: Truth) -> Any:
        """The record of sensor `name` at truth row k (one sample), or None when it has no sample there."""
        j = self.sample_at.get(name, {}).get(k)
        if j is None:
            return None
        e = self.errors.sensors[name]
        one = replace(e, index=e.index[j:j + 1], rows=e.rows[j:j + 1], t_s=e.t_s[j:j + 1],
                      series={k: v[j:j + 1] for k, v in e.series.items()})  # a view: no copy of the long draw
        sub = SuiteErrors(MappingProxyType({name: one}), self.errors.clock)
        return self.suite.apply(truth, sub, names=[name])[name]

    def step(self, k: int, truth: Truth) -> tuple[Array, Array]:
        """Runway-frame position (m) and NED velocity (m/s) of the navigation output at truth row k."""
        nav = self.nav
        if k == 0:
            g = self.errors.sensors.get("gnss")
            el = None
            if g is not None:
                rec = self._apply("gnss", 0, truth)
                el = rec.elevation_rad[0] if rec is not None else None
            self.s, self.runs = nav.start(truth, [stream(self.seed, self.run, "nav")], 0, elevation_rad=el)
        else:
            imu = self._apply("imu", k, truth)
            dth = imu.dtheta_body.reshape(1, 3)
            dv = imu.dv_body.reshape(1, 3)
            if nav.nav.feedback:
                dth = dth - self.runs[0].bg_fb * self.dt
                dv = dv - self.runs[0].ba_fb * self.dt
            self.f_sum += np.einsum("nij,nj->ni", self.s.c_bn, dv)
            hb = None
            if self.gains is not None:
                hb = np.array([self.h_baro_hold])
            self.s = ins.step(self.s, dth, dv, self.dt, h_baro_m=hb, loop=self.gains if hb is not None else None)
            if k % self.epoch_rows == 0:
                t = float(truth.t_s[k])
                recs = {name: r for name in ("baro", "radalt", "gnss", "pseudolite")
                        if (r := self._apply(name, k, truth)) is not None}
                obs = nav.observations(recs, t, 0.25 * self.dt, False)
                self.s = nav.aid(self.s, self.runs, t, t - self.t_last, self.f_sum / (t - self.t_last), obs)
                self.f_sum[:] = 0.0
                self.t_last = t
                self._epoch(k, truth)
        if self.gains is not None and (b := self._apply("baro", k, truth)) is not None:
            self.h_baro_hold = float(np.ravel(b.h_baro_m)[0])
            if k == 0:
                self.s = ins.replace(self.s, h_m=np.array([self.h_baro_hold]))
        o, P, x = nav.output(self.s, self.runs)
        self._record(o, P, x)
        r_ecef = ins.position_ecef(o)[0]
        r_rwy = self.profile.runway.frame.from_ecef(r_ecef)
        r_rwy[2] = float(o.h_m[0]) - self.profile.runway.elevation_m  # height above threshold, as truth.r_rwy
        return r_rwy, o.v_ned[0]

    def _record(self, o: ins.InsState, P: Array, x: Array) -> None:
        lay = self.nav.layout
        d = self.out
        d["lat"].append(o.lat_rad[0])
        d["lon"].append(o.lon_rad[0])
        d["h"].append(o.h_m[0])
        d["v"].append(o.v_ned[0])
        d["c"].append(o.c_bn[0])
        d["ppos"].append(P[0, 0:3, 0:3])
        if lay.has("clk"):
            d["clk"].append(x[0, lay.i("clk")])
            d["clk_sd"].append(math.sqrt(P[0, lay.i("clk"), lay.i("clk")]))
        else:
            d["clk"].append(math.nan)
            d["clk_sd"].append(math.nan)

    def _epoch(self, k: int, truth: Truth) -> None:
        o, P, x = self.nav.output(self.s, self.runs)
        e = self.epochs
        e["t"].append(float(truth.t_s[k]))
        e["x"].append(x[0])
        e["pd"].append(np.diag(P[0]))
        e["pnav"].append(P[0, 0:9, 0:9])
        e["err"].append(NavSystem._true_error(o, truth, k)[0])

    def result(self, truth: Truth) -> NavRun:
        """The navigation run over the flown truth (call after the flight)."""
        n = len(truth)
        d = self.out
        lat, lon, h = (np.array(d[k][:n]) for k in ("lat", "lon", "h"))
        sol = NavSolution(
            t_s=np.asarray(truth.t_s[:n], dtype=float),
            r_ecef=geo.geodetic_to_ecef(lat, lon, h),
            v_ned=np.array(d["v"][:n]),
            euler_rad=ins.euler_from_cbn(np.array(d["c"][:n])),
            P_pos_ned=np.array(d["ppos"][:n]),
            clock_bias_m=np.array(d["clk"][:n]),
            clock_bias_sigma_m=np.array(d["clk_sd"][:n]),
        )
        e = self.epochs
        return NavRun(
            solution=sol, status=StatusLog.from_records(self.runs[0].statuses), t_epoch_s=np.array(e["t"]),
            x=np.array(e["x"]), P_diag=np.array(e["pd"]), P_nav=np.array(e["pnav"]),
            true_error_nav=np.array(e["err"]), layout=self.nav.layout,
        )


def path_deviation(r_rwy: Array, runway: Any) -> Array:
    """Deviation (..., 2) of runway-frame points from the desired path: (cross-track y, height above the
    ideal glidepath z - (tch - x tan gp)), m."""
    r = np.asarray(r_rwy, dtype=float)
    return np.stack([r[..., 1], r[..., 2] - (runway.tch_m - r[..., 0] * math.tan(runway.glidepath_rad))], axis=-1)


def approach_errors(truth: Truth, guidance_r_rwy: Array, runway: Any) -> ApproachErrors:
    """FTE, NSE and TSE (lateral, vertical) of a flown approach (RNP convention, records.ApproachErrors).

    FTE = deviation of the position guidance flew on from the desired path; TSE = deviation of the true
    position; NSE = TSE - FTE = d(true) - d(estimate): the navigation error seen in path terms, so that
    TSE = FTE + NSE (the along-track error enters NSE through the glidepath slope).
    """
    fte = path_deviation(guidance_r_rwy, runway)
    tse = path_deviation(truth.r_rwy, runway)
    return ApproachErrors(t_s=np.asarray(truth.t_s, dtype=float), fte_m=fte, nse_m=tse - fte, tse_m=tse)
