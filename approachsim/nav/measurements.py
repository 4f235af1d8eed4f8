"""Scalar measurement rows of the error-state filter: z = h' x + v for each aiding observation.

Every observation is a *difference* measurement (seed 002 sec. 6): the value the INS predicts minus the
value the sensor reports, so that z is a function of the error state x (error = INS - truth). Where the
measurement is nonlinear in the error (ranges to nearby pseudolites, terrain under the radar altimeter) the
row is an EKF linearization about the current estimate x_hat: with g(x) the exact difference,

    z_lin = z - g(x_hat) + h' x_hat        so that the innovation z_lin - h' x_hat = z - g(x_hat).

Rows (index names from errormodel.StateLayout):
    baro      z = h_ins - h_baro        = -dp_D - bb - (h - H_ref) sb + v            (seed 002; seed 003 eq. 6 with
              the scale factor on the height above the altimeter setting's reference H_ref, the field)
    radalt    z = (h_ins - T(ins)) - h_R = -dp_D - grad T . dp_h - rab - ram - sigma_db(x) tdb + v,
              R = (0.01 h)^2 + floor^2 (seed 002; rab, ram, tdb: errormodel, nav/terrain_db.py)
    range     z = |r_ins - r_tx| - rho  = e . dp - clk - gse - gmp (+ pseudolite terms: pmp, ptr, pclk or psy)
              - F_pp(el) (giz_0 + (d / d_5)(sin az giz_E + cos az giz_N)) - M(el) gtz (a satellite's row, with the
              zenith ionospheric / tropospheric states)
              + v   (seed 002 sec. 6)
              (- gio too with carrier phase, whose states split the ionosphere off gse: nav/noise.py)
    carrier   z = |r_ins - r_sv| - phi  = e . dp - clk - gse + gio - amb + v                 (sensors/gnss/carrier.py:
              the code's geometry, clock and slow error, the ionosphere with the opposite sign, the arc's ambiguity)
    position  z = p_ins - p_gps (NED, per axis)  (loosely-coupled option)

The baro, radalt and range rows have compiled versions in core/nav/measurements.py that write h into a buffer
and return the innovation nu = z - g(x_hat) (for a per-run loop, and over runs for the shared covariance); the
functions here are their test oracle. `terrain_arrays` and `database_arrays` give the kernels the terrain
database as arrays.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

import numpy as np

from approachsim import geo
from approachsim.core.sensors import gnss_errors as ge
from approachsim.nav.base import ScalarMeasurement
from approachsim.nav.errormodel import StateLayout
from approachsim.nav.terrain_db import TerrainDbConfig, TerrainDbError

Array = np.ndarray


def terrain_arrays(runway: geo.RunwayFrame, terrain: Any = None) -> tuple[Array, Array, Array]:
    """The filter's terrain for kernels.measurements: (tx (k,) runway-frame along-track x, m; th (k,) ellipsoid
    height, m; rwy (6,) the frame's ECEF origin (m) and ECEF -> along-track row). terrain: a profile.Terrain
    (along_m, height_m), or None for flat at the threshold height (one point)."""
    if terrain is None:
        tx, th = np.zeros(1), np.array([float(runway.threshold_h_m)])
    else:
        tx, th = np.array(terrain.along_m, dtype=float), np.array(terrain.height_m, dtype=float)
    rwy = np.concatenate([runway.origin_ecef, runway.c_ecef_to_rwy[0]])
    return tx, th, rwy


def database_arrays(config: TerrainDbConfig, error: TerrainDbError | None) -> tuple[Array, Array, Array]:
    """A run's terrain-database error for kernels.measurements: (dbp (4,) = (bias m, sigma_m, outer_sigma_m,
    area4_length_m), db_x (k,) the realization's grid (m; empty without one), db_u (k,) its unit Gauss-Markov)."""
    bias = 0.0 if error is None else float(error.bias_m)
    dbp = np.array([bias, config.sigma_m, config.outer_sigma_m, config.area4_length_m], dtype=float)
    if error is None:
        return dbp, np.zeros(0), np.zeros(0)
    return dbp, np.ascontiguousarray(error.x_m, dtype=float), np.ascontiguousarray(error.u, dtype=float)


def _row(layout: StateLayout) -> Array:
    return np.zeros(layout.n)


def baro(layout: StateLayout, h_ins_m: float, h_baro_m: float, sigma_m: float, t_s: float,
         name: str = "baro", h_ref_m: float = 0.0, dp_d_hat_m: float = 0.0, sb_hat: float = 0.0
         ) -> ScalarMeasurement:
    """Baro altitude difference: h = [-(1 + sb_hat) at dp_D, -1 at bb, -(h - H_ref) at sb]; R = sigma^2 (white
    noise), m; h_ref_m = H_ref the altimeter setting's reference (the field), m; sb_hat the estimate's scale factor.

    The baro reads h_B = h + (h - H_ref) S + B + v of the true height h = h_ins + dp_D, so a height error moves it by
    (1 + S) dp_D: the EKF's dp_D coefficient is -(1 + sb_hat). With -1 the row under-stated the baro's sensitivity by
    S (12 % at ISA -30 uncorrected): the filter's height over-claimed on cold days and under-claimed on hot ones
    (issue 39: e^2 / P 1.06 at ISA -30, 0.92 at ISA +30, 0.97 on the ISA day, the same seeds; docs/consistency.md).

    h in the sb column is the navigation's height h_ins + dp_D_hat (dp_d_hat_m: the estimate's dp_D), not the INS
    height: the damping loop drags the INS toward a baro that is off by sb (h - H_ref) (117 m at 985 m above a
    5434 ft field at ISA -30), so h_ins is off by as much, and sb times that (14 m) would be a model error in the row;
    with it the estimate ran away (issue 39: KDEN ISA -30, 98 m vertical error). z is the EKF's linearization
    z - g(x_hat) + h x_hat = (h_ins - h_baro) - sb_hat dp_D_hat (module docstring), g(x_hat) = -dp_D - bb -
    (h_ins + dp_D - H_ref) sb the prediction at the estimate: h x_hat exceeds it by sb dp_D, the bilinear term
    counted twice by the Jacobian."""
    h = _row(layout)
    h[layout.i("dp", 2)] = -1.0  # dh = -dp_D
    h[layout.i("bb")] = -1.0
    if layout.has("sb"):
        h[layout.i("dp", 2)] = -(1.0 + sb_hat)
        h[layout.i("sb")] = -(h_ins_m + dp_d_hat_m - h_ref_m)
    z = h_ins_m - h_baro_m
    if layout.has("sb"):
        z = z - sb_hat * dp_d_hat_m
    return ScalarMeasurement(z=float(z), h=h, r=float(sigma_m**2), name=name, t_s=t_s)


def radalt(
    layout: StateLayout,
    x_hat: Array,
    lat_rad: float,
    lon_rad: float,
    h_ins_m: float,
    h_agl_m: float,
    sigma_m: float,
    terrain_h: Callable[[Array], Array],
    t_s: float,
    name: str = "radalt",
    tdb_sigma_m: float = 0.0,
    db_error_m: float = 0.0,
) -> ScalarMeasurement:
    """Radar altimeter: INS height above the terrain database minus the measured height above terrain.

    terrain_h(r_ecef (..., 3)) -> terrain ellipsoid height (...,), m; the filter's database at the INS position
    is terrain_h(r_ins) + db_error_m (the run's database error there, nav/terrain_db.py). The terrain gradient
    enters through the horizontal position error (central differences over 10 m). The correlated errors enter
    linearly: -1 at rab (altimeter + database bias) and ram (altimeter Markov), -tdb_sigma_m (the database's
    correlated 1-sigma at the aircraft, m) at tdb (its unit Gauss-Markov), where the layout has them.
    """
    c_ne = geo.c_ecef_to_ned(lat_rad, lon_rad).T
    r_ins = geo.geodetic_to_ecef(lat_rad, lon_rad, h_ins_m)
    dp_hat = x_hat[layout.index["dp"]]
    r_hat = r_ins - c_ne @ dp_hat  # corrected position (truth estimate)
    steps = np.array([[10.0, 0, 0], [-10.0, 0, 0], [0, 10.0, 0], [0, -10.0, 0]]) @ c_ne.T
    t4 = terrain_h(r_hat + steps)
    grad = np.array([(t4[0] - t4[1]) / 20.0, (t4[2] - t4[3]) / 20.0])  # dT/dN, dT/dE, m/m
    t_ins = float(terrain_h(r_ins))
    t_hat = float(terrain_h(r_hat))
    z = (h_ins_m - t_ins - db_error_m) - h_agl_m
    g_hat = (h_ins_m - t_ins) - ((h_ins_m + dp_hat[2]) - t_hat)  # exact difference at x_hat
    h = _row(layout)
    h[layout.i("dp", 0)] = -grad[0]
    h[layout.i("dp", 1)] = -grad[1]
    h[layout.i("dp", 2)] = -1.0
    for g, c in (("rab", -1.0), ("ram", -1.0), ("tdb", -tdb_sigma_m)):
        if layout.has(g):
            h[layout.i(g)] = c
            g_hat += c * float(x_hat[layout.i(g)])  # linear in the correlated-error states
    return ScalarMeasurement(z=float(z - g_hat + h @ x_hat), h=h, r=float(sigma_m**2), name=name, t_s=t_s)


def iono_field_row(u_ned: Array) -> tuple[float, float, float]:
    """(F, F (d / d_5) sin az, F (d / d_5) cos az) of a satellite in direction u_ned (unit, position -> satellite, NED):
    the slant delay per unit of the zenith ionospheric field's common part and east / north planar gradient per d_5
    (F = DO-229's F_pp, d the pierce distance: gnss_errors.iono_obliquity, pierce_distance_m)."""
    cos_el = float(np.hypot(u_ned[0], u_ned[1]))
    el = float(np.arctan2(-u_ned[2], cos_el))
    f = ge.iono_obliquity(cos_el, ge.IONO_SHELL_M)
    g = f * ge.pierce_distance_m(el, ge.IONO_SHELL_M) / ge.pierce_distance_m(ge.GRADIENT_REFERENCE_EL_RAD,
                                                                             ge.IONO_SHELL_M)
    return f, g * float(u_ned[1]) / cos_el, g * float(u_ned[0]) / cos_el


def pseudorange(
    layout: StateLayout,
    x_hat: Array,
    r_ins_ecef: Array,
    c_ecef_ned: Array,
    r_tx_ecef: Array,
    rho_m: float,
    sigma_m: float,
    t_s: float,
    name: str,
    *,
    sv: int | None = None,
    pl: int | None = None,
) -> ScalarMeasurement:
    """A code pseudorange to a satellite (sv = its channel) or pseudolite (pl = its unit), tightly coupled.

    z = |r_ins - r_tx| - rho ; g(x) = |r_ins - r_tx| - |r_ins - C' dp - r_tx| - clk - (channel errors);
    h: e' at dp (e the unit vector transmitter -> corrected position, NED), -1 at the receiver clock and
    the channel's error states, minus iono_field_row's (F_pp, F_pp (d / d_5) sin az, F_pp (d / d_5) cos az) at the
    zenith ionospheric states giz, -M(el) at the zenith troposphere gtz (sin el = e_D: gnss_errors.tropo_mapping);
    pseudolite troposphere: -range at ptr. R = sigma^2 (white code noise), m.
    """
    h = _row(layout)
    dp_hat = x_hat[layout.index["dp"]]
    r_hat = r_ins_ecef - c_ecef_ned.T @ dp_hat
    d_hat = r_hat - r_tx_ecef
    rng_hat = float(np.linalg.norm(d_hat))
    e_ned = c_ecef_ned @ (d_hat / rng_hat)
    rng_ins = float(np.linalg.norm(r_ins_ecef - r_tx_ecef))
    h[layout.index["dp"]] = e_ned
    if layout.has("clk"):
        h[layout.i("clk")] = -1.0
    if sv is not None and layout.has("gse"):
        h[layout.i("gse", sv)] = -1.0
        h[layout.i("gmp", sv)] = -1.0
        if layout.has("gio"):
            h[layout.i("gio", sv)] = -1.0
        if layout.has("giz"):  # the zenith ionospheric field at the pierce point seen from the corrected position
            h[layout.index["giz"]] = -np.asarray(iono_field_row(-e_ned))
        if layout.has("gtz"):  # the zenith troposphere times M(el), sin el = e_D
            h[layout.i("gtz")] = -ge.tropo_mapping(float(e_ned[2]))
    if pl is not None and layout.has("pmp"):
        h[layout.i("pmp", pl)] = -1.0
        h[layout.i("ptr", pl)] = -rng_hat
        h[layout.index["dp"]] = e_ned * (1.0 + x_hat[layout.i("ptr", pl)])  # range (1 + T): its gradient
        if layout.has("pclk"):
            h[layout.i("pclk", 2 * pl)] = -1.0
        if layout.has("psy"):  # a synchronized transmitter's time-sync error
            h[layout.i("psy", pl)] = -1.0
    z = rng_ins - rho_m
    lin = h.copy()
    lin[layout.index["dp"]] = 0.0
    if pl is not None and layout.has("ptr"):
        lin[layout.i("ptr", pl)] = 0.0
        g_hat = rng_ins - rng_hat * (1.0 + x_hat[layout.i("ptr", pl)]) + float(lin @ x_hat)
    else:
        g_hat = rng_ins - rng_hat + float(lin @ x_hat)  # exact in dp, linear in the rest
    return ScalarMeasurement(z=float(z - g_hat + h @ x_hat), h=h, r=float(sigma_m**2), name=name, t_s=t_s)


def carrier_phase(layout: StateLayout, x_hat: Array, r_ins_ecef: Array, c_ecef_ned: Array, r_sv_ecef: Array,
                  phi_m: float, sigma_m: float, t_s: float, name: str, sv: int) -> ScalarMeasurement:
    """A GPS channel's carrier phase (channel sv; the layout's carrier states), tightly coupled.

    z = |r_ins - r_sv| - phi ; g(x) = |r_ins - r_sv| - |r_ins - C' dp - r_sv| - clk - gse + gio - amb;
    h: e' at dp as the code's row, -1 at the clock, gse and amb, +1 at gio (the ionosphere advances the phase).
    R = sigma^2: the carrier's white-equivalent noise (nav/noise.py carrier_sigma_m), m."""
    h = _row(layout)
    dp_hat = x_hat[layout.index["dp"]]
    d_hat = r_ins_ecef - c_ecef_ned.T @ dp_hat - r_sv_ecef
    rng_hat = float(np.linalg.norm(d_hat))
    h[layout.index["dp"]] = c_ecef_ned @ (d_hat / rng_hat)
    if layout.has("clk"):
        h[layout.i("clk")] = -1.0
    h[layout.i("gse", sv)] = -1.0
    h[layout.i("gio", sv)] = 1.0
    h[layout.i("amb", sv)] = -1.0
    rng_ins = float(np.linalg.norm(r_ins_ecef - r_sv_ecef))
    lin = h.copy()
    lin[layout.index["dp"]] = 0.0
    g_hat = rng_ins - rng_hat + float(lin @ x_hat)  # exact in dp, linear in the rest
    return ScalarMeasurement(z=float(rng_ins - phi_m - g_hat + h @ x_hat), h=h, r=float(sigma_m**2), name=name,
                             t_s=t_s)


def gps_position(layout: StateLayout, dp_ins_minus_gps_ned: Array, sigma_ned_m: Array, t_s: float
                 ) -> list[ScalarMeasurement]:
    """Loosely coupled: the INS minus GPS position in NED (3,), m, as three scalars with sigmas (3,)."""
    out = []
    for k, axis in enumerate("NED"):
        h = _row(layout)
        h[layout.i("dp", k)] = 1.0
        out.append(ScalarMeasurement(z=float(dp_ins_minus_gps_ned[k]), h=h, r=float(sigma_ned_m[k] ** 2),
                                     name=f"gps_{axis}", t_s=t_s))
    return out


def gps_fix(r_guess_ecef: Array, r_sv_ecef: Array, rho_m: Array, sigma_m: Array, iterations: int = 6
            ) -> tuple[Array, Array] | None:
    """Least-squares GPS position (ECEF, m) and its covariance (3, 3) from k >= 4 pseudoranges (weighted by
    1 / sigma^2), Gauss-Newton from r_guess; None with fewer than 4. The receiver clock is solved and dropped."""
    ok = np.isfinite(rho_m)
    if ok.sum() < 4:
        return None
    rsv, rho, w = r_sv_ecef[ok], rho_m[ok], 1.0 / np.asarray(sigma_m, dtype=float)[ok] ** 2
    x = np.append(np.asarray(r_guess_ecef, dtype=float), 0.0)
    for _ in range(iterations):
        d = x[:3] - rsv
        rng = np.linalg.norm(d, axis=1)
        G = np.column_stack([d / rng[:, None], np.ones(len(rho))])
        res = rho - (rng + x[3])
        N = G.T @ (w[:, None] * G)
        x = x + np.linalg.solve(N, G.T @ (w * res))
    cov = np.linalg.inv(N)
    return x[:3], cov[:3, :3]
