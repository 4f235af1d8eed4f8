"""The scalar measurement rows of one run at one aiding epoch, in the filter's processing order.

    rows = MeasurementRows(layout, sensors, nav, runway, terrain_h)
    for row in rows.epoch(ins_state, i, r_ins, obs, t_s, db_error):   # baro, radalt, each GNSS channel, each PL
        m = row.build(x_hat)              # nav.measurements: z_lin = z - g(x_hat) + h' x_hat, h, r
        nu = m.z - m.h @ x_hat            # = z - g(x_hat), the exact difference at the run's INS and x_hat

Each row is named by its `Source` (observations.py) and builds its ScalarMeasurement at the estimate it is given
(sequential relinearization: a later row of the same epoch sees the earlier updates). The per-run filters, the
shared-covariance path (innovations of each run at its own estimate), the converged start and the online FDE all
take their rows from here, so there is one measurement model (nav/measurements.py).

Also here: the filter's terrain database (`TerrainDatabase`: the profile terrain along the runway x axis, flat at
the threshold height without one) and the lookups of a run's database error realization at its INS position.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from approachsim import geo
from approachsim.nav import ins
from approachsim.nav import measurements as meas
from approachsim.nav import terrain_db as tdb
from approachsim.nav.base import ScalarMeasurement
from approachsim.nav.config import NavConfig
from approachsim.nav.errormodel import StateLayout
from approachsim.nav.noise import NoiseModel
from approachsim.nav.observations import BARO, CP, FIX, GPS, PL, RADALT, Observations, Source
from approachsim.sensors.config import SensorsConfig

Array = np.ndarray


@dataclass(frozen=True)
class TerrainDatabase:
    """The filter's terrain: ellipsoid height (m) at ECEF points (..., 3) from the profile's Terrain along the
    runway x axis (flat at the threshold height when terrain is None). A picklable callable. Each run's
    database adds its own error realization to it (nav/terrain_db.py)."""

    runway: geo.RunwayFrame
    terrain: Any = None

    def __call__(self, r_ecef: Array) -> Array:
        if self.terrain is None:
            return np.full(np.shape(r_ecef)[:-1], self.runway.threshold_h_m)
        return self.terrain.height_at(self.runway.from_ecef(r_ecef)[..., 0])


@dataclass(frozen=True)
class Row:
    """One scalar measurement of the epoch: its source and the builder of its ScalarMeasurement at x_hat."""

    source: Source
    build: Callable[[Array], ScalarMeasurement]


def along_m(runway: geo.RunwayFrame, r_ecef: Array) -> Array:
    """Runway-frame along-track distance (m) of ECEF points (..., 3), one point at a time: a run's value must
    not depend on the batch it shares (no batch-size-dependent matrix product)."""
    r = np.asarray(r_ecef, dtype=float)
    flat = [float(runway.from_ecef(ri)[0]) for ri in r.reshape(-1, 3)]
    return np.array(flat).reshape(r.shape[:-1])


@dataclass(frozen=True)
class MeasurementRows:
    """Row builders of a navigation configuration (module docstring)."""

    layout: StateLayout
    sensors: SensorsConfig
    nav: NavConfig
    runway: geo.RunwayFrame
    terrain_h: Callable[[Array], Array]

    @property
    def carrier_sigma_m(self) -> float:
        """The carrier rows' white 1-sigma, m (nav/noise.py NoiseModel.carrier_sigma_m)."""
        return NoiseModel(self.sensors, self.nav, self.layout).carrier_sigma_m()

    def radalt_sigma_m(self, h_agl_m: float) -> float:
        """The radar altimeter's white-noise 1-sigma at height h_agl_m: sqrt((p h)^2 + floor^2), m (seed 002)."""
        r = self.sensors.radalt
        return float(np.sqrt((r.percent_sigma * h_agl_m) ** 2 + r.floor_m**2))

    def epoch(self, s: ins.InsState, i: int, r_ins: Array, obs: Observations, t: float,
              db_error: tdb.TerrainDbError | None = None) -> list[Row]:
        """Rows of run i (INS state s[i], its ECEF position r_ins (3,)) from obs; db_error: run i's
        terrain-database error (None: the database is the truth terrain)."""
        lay = self.layout
        lat, lon, h = float(s.lat_rad[i]), float(s.lon_rad[i]), float(s.h_m[i])
        out: list[Row] = []
        if obs.baro_h_m is not None and np.isfinite(obs.baro_h_m[i]):
            hb, sb = float(obs.baro_h_m[i]), float(obs.baro_sigma_m)
            h_ref = float(self.runway.threshold_h_m)
            out.append(Row(Source(BARO), lambda x: meas.baro(
                lay, h, hb, sb, t, h_ref_m=h_ref, dp_d_hat_m=float(x[lay.i("dp", 2)]),
                sb_hat=float(x[lay.i("sb")]) if lay.has("sb") else 0.0)))
        if obs.radalt_h_m is not None and np.isfinite(obs.radalt_h_m[i]):
            hr = float(obs.radalt_h_m[i])
            sr = self.radalt_sigma_m(hr)
            along = float(self.runway.from_ecef(r_ins)[0])
            ts = float(self.nav.terrain_database.sigma_at(along))
            de = 0.0 if db_error is None else float(db_error(along))
            out.append(Row(Source(RADALT), lambda x: meas.radalt(lay, x, lat, lon, h, hr, sr, self.terrain_h, t,
                                                                 tdb_sigma_m=ts, db_error_m=de)))
        c_en = geo.c_ecef_to_ned(lat, lon)
        if obs.has_gnss and self.nav.gps_coupling == "loose":
            r_sv, sig, _ = obs.sky(i)
            fix = meas.gps_fix(r_ins, r_sv, obs.gnss_rho_m[i], sig)
            if fix is not None:
                r_fix, cov = fix
                glat, glon, gh = geo.ecef_to_geodetic(r_fix)
                dz = ins.position_error_ned(lat, lon, h, glat, glon, gh)  # INS - GPS, NED
                sd = np.sqrt(np.diag(c_en @ cov @ c_en.T))
                for m in meas.gps_position(lay, dz, sd, t):
                    out.append(Row(Source(FIX), lambda x, m=m: m))
        elif obs.has_gnss:
            rho = obs.gnss_rho_m[i]
            r_sv, sig_nominal, _ = obs.sky(i)
            channel_states = lay.has("gse")
            sig = self.sensors.gnss.budget().code_noise_m if channel_states else sig_nominal
            for k in np.flatnonzero(np.isfinite(rho)):
                k = int(k)
                sk = float(sig if np.isscalar(sig) else sig[k])
                out.append(Row(Source(GPS, k), lambda x, k=k, sk=sk, rk=float(rho[k]), rs=r_sv[k]: meas.pseudorange(
                    lay, x, r_ins, c_en, rs, rk, sk, t, Source(GPS, k).name, sv=k if channel_states else None)))
            if obs.gnss_phi_m is not None and lay.has("amb"):  # the carrier rows, after every code row
                phi = obs.gnss_phi_m[i]
                sc = self.carrier_sigma_m
                for k in np.flatnonzero(np.isfinite(phi)):
                    k = int(k)
                    out.append(Row(Source(CP, k), lambda x, k=k, pk=float(phi[k]), rs=r_sv[k]: meas.carrier_phase(
                        lay, x, r_ins, c_en, rs, pk, sc, t, Source(CP, k).name, k)))
        if obs.pl_rho_m is not None:
            rho, r_pl = obs.pl_rho_m[i], obs.pl_r_ecef
            p = self.sensors.pseudolite
            for k in np.flatnonzero(np.isfinite(rho)):
                k = int(k)
                if lay.has("pmp"):
                    sk = float(np.sqrt(p.code_noise_m**2 + p.survey_sigma_m**2))
                else:
                    sk = float(obs.pl_sigma_m[k])
                out.append(Row(Source(PL, k), lambda x, k=k, sk=sk, rk=float(rho[k]), rp=r_pl[k]: meas.pseudorange(
                    lay, x, r_ins, c_en, rp, rk, sk, t, Source(PL, k).name, pl=k if lay.has("pmp") else None)))
        return out

    def reference_obs(self, obs: Observations, i: int, ref_h_m: float, r_ref: Array) -> Observations:
        """Run i's observations as seen from a reference trajectory (the truth, one row at height ref_h_m and ECEF
        r_ref): the values that only decide which rows exist are kept, the radar altitude is replaced by the
        reference height above the terrain database (the radalt sigma is taken there: the measured height would
        make it differ by run)."""
        one = obs.run(i)
        if one.radalt_h_m is not None:
            ok = bool(np.isfinite(one.radalt_h_m[0]))
            agl = float(ref_h_m - self.terrain_h(r_ref))
            one = replace(one, radalt_h_m=np.array([agl if ok else np.nan]))
        return one
