"""INS error-state model: the continuous dynamics F, the noise G Q G' and their discretization (Van Loan).

Error convention: error = INS - truth (the feed-forward output is INS - estimated error, seed 002 sec. 5).
States (a `StateLayout` says which are present and where):

    dp   (3)  position error, local NED axes at the true position, m
    dv   (3)  velocity error, NED, m/s
    psi  (3)  attitude error, NED: C_ins = (I - [psi x]) C_true, rad
    bg   (3)  gyro bias, body axes, rad/s         (random constant + random walk)
    ba   (3)  accelerometer bias, body, m/s^2    (random constant + random walk)
    bb   (1)  baro bias, m                        (first-order Gauss-Markov, seed 001 eq. 2, seed 003 eq. 1)
    sb   (1)  baro scale factor on the height above the setting's reference H_ref (the field; random constant,
              seed 003 eq. 1): the baro row and the loop see -(h - H_ref) sb
    clk  (2)  GPS receiver clock bias (m) and drift (m/s)   (seed 002 two-state clock, sec. 6)
    ac   (1)  baro damping-loop compensator, m/s^2 (only when the INS runs the 3rd-order loop, seed 003 eq. 3)
    giz  (3)  zenith ionospheric field, m, Gauss-Markov: a single-frequency service's vertical ionospheric residual
              field (SBAS L1, stand-alone L1 C/A; sensors/gnss/service.py), its common part and its east and north
              planar gradient per d_5 (the pierce distance of a 5 deg satellite), in every GPS code row times the
              satellite's obliquity F_pp(el) (1, (d / d_5) sin az, (d / d_5) cos az), d its pierce distance; gse then
              keeps the field's local part
    gtz  (1)  zenith tropospheric error, m, Gauss-Markov: a service's residual of the MOPS tropospheric model (one
              zenith value, sensors/gnss/service.py), in every GPS code row times the satellite's mapping M(el);
              gse then leaves the troposphere out
    gse  (k)  per-GPS-channel slow range error (SV clock/ephemeris + mapped iono + tropo), m, Gauss-Markov
    gmp  (k)  per-GPS-channel multipath, m, Gauss-Markov
    pmp  (p)  per-pseudolite multipath, m, Gauss-Markov
    ptr  (p)  per-pseudolite tropospheric residual, fraction of the range (random constant)
    pclk (2p) per-pseudolite transmitter clock bias and drift (unsynchronized pseudolites only)
    psy  (p)  per-pseudolite time-sync error of a synchronized (GPS-disciplined) transmitter, m, Gauss-Markov
              (sensors/pseudolite.py); after pclk, before rab
    rab  (1)  radar-altimeter bias + terrain-database bias, m (random constant: both enter the radalt row as -1)
    ram  (1)  radar-altimeter Markov error, m (Gauss-Markov, seed 000 eq. 5)
    tdb  (1)  terrain-database along-track error, unit Gauss-Markov u (the error is sigma(x) u, nav/terrain_db.py)
              in time with tau = L / ground speed (exact for a constant speed along the track)
    gio  (k)  per-GPS-channel ionospheric range error of the code, m, Gauss-Markov (carrier phase only: then gse
              leaves the ionosphere out; the carrier sees -gio, nav/measurements.py)
    amb  (k)  per-GPS-channel carrier float ambiguity, m (random constant, reset to its prior at a new arc: carrier
              phase only)

The channel states are what make the filter honest about time-correlated range errors: seed 002's 2-state
GPS model absorbed them in a tuned R; here they are carried (and decoupled, so discretized exactly).

Dynamics (Titterton & Weston eq. 12.8, 12.12; Groves eq. 14.64-14.66 with the position error in metres):

    dp'  = dv + (velocity-dependent frame terms)
    dv'  = [f_n x] psi + C_bn ba - (2 w_ie + w_en) x dv + v x (2 dw_ie + dw_en) + (2 g / R) dp_D e_D
    psi' = -w_in x psi + dw_ie + dw_en - C_bn bg
    bg' = w_bg, ba' = w_ba ; bb' = -bb / tau_b + w_b ; sb' = 0 ; clk' = [[0, 1], [0, 0]] clk + w_clk

With the baro loop (seed 003 eq. 3, linearized gains C1, C2, C3, loop error e = dh - bb - S (h - H_ref) - v_b):
    dh' += -C1 e ; dv_up' += -C2 e - ac ; ac' = C3 e    (dh = -dp_D, dv_up = -dv_D)
and the baro white noise v_b enters the process noise through the gains.

Discretization over the aiding interval: Phi = expm(F dt) and Qd from Van Loan's method (scipy.linalg.expm).

`dynamics` and `discretize` run the compiled kernels of core/nav/errormodel.py on plain arrays (the layout and
the noise packed once per frozen object: `StateLayout.packed`, `kernel_noise`); `dynamics_reference` and
`discretize_reference` are the readable numpy versions, kept as the kernels' test oracle
(tests/unit/nav/test_epoch_kernels.py: F, Qc equal, Phi, Qd to 1e-12 relative).
"""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from functools import cached_property, lru_cache
from typing import Any

import numpy as np
from scipy.linalg import expm

from approachsim import geo
from approachsim.core.nav import errormodel as ek
from approachsim.nav import ins
from approachsim.nav import vertical_loop as vl

Array = np.ndarray


@dataclass(frozen=True)
class StateLayout:
    """Which error states are present and their index ranges; `n` states in all."""

    baro_scale: bool = True
    clock: bool = True
    loop: bool = False
    n_sv: int = 0
    """GPS channels with their own error states (0: none)."""
    n_pl: int = 0
    """Pseudolites with their own error states (0: none)."""
    pl_clock: bool = False
    """Pseudolites carry their own clock (unsynchronized)."""
    pl_sync: bool = False
    """Synchronized pseudolites carry a time-sync error state each (psy)."""
    radalt_bias: bool = False
    radalt_markov: bool = False
    terrain_db: bool = False
    """Radar-altimeter / terrain-database error states rab, ram, tdb (module docstring)."""
    carrier: bool = False
    """GPS carrier phase: per-channel ionospheric (gio) and float-ambiguity (amb) states after every other group
    (needs n_sv channels)."""
    iono_zenith: bool = False
    """The zenith ionospheric states giz (module docstring; needs n_sv channels)."""
    tropo_zenith: bool = False
    """The zenith tropospheric state gtz (module docstring; needs n_sv channels)."""
    index: dict[str, slice] = field(init=False, compare=False)
    n: int = field(init=False, compare=False)

    def __post_init__(self) -> None:
        sizes = [("dp", 3), ("dv", 3), ("psi", 3), ("bg", 3), ("ba", 3), ("bb", 1)]
        if self.baro_scale:
            sizes.append(("sb", 1))
        if self.clock:
            sizes.append(("clk", 2))
        if self.loop:
            sizes.append(("ac", 1))
        for g, on, k in (("giz", self.iono_zenith, 3), ("gtz", self.tropo_zenith, 1)):
            if on and not self.n_sv:
                raise ValueError(f"StateLayout: the zenith state {g} needs the GPS channel states (n_sv > 0)")
            if on:
                sizes.append((g, k))
        if self.n_sv:
            sizes += [("gse", self.n_sv), ("gmp", self.n_sv)]
        if self.n_pl:
            sizes += [("pmp", self.n_pl), ("ptr", self.n_pl)]
            if self.pl_clock:
                sizes.append(("pclk", 2 * self.n_pl))
            if self.pl_sync:
                sizes.append(("psy", self.n_pl))
        sizes += [(g, 1) for g, on in (("rab", self.radalt_bias), ("ram", self.radalt_markov),
                                       ("tdb", self.terrain_db)) if on]
        if self.carrier:  # last: every other group keeps its index (the compiled kernels' layout)
            if not self.n_sv:
                raise ValueError("StateLayout: carrier-phase states need the GPS channel states (n_sv > 0)")
            sizes += [("gio", self.n_sv), ("amb", self.n_sv)]
        index, i = {}, 0
        for name, k in sizes:
            index[name] = slice(i, i + k)
            i += k
        object.__setattr__(self, "index", index)
        object.__setattr__(self, "n", i)

    def has(self, name: str) -> bool:
        """True when the layout holds state group `name`."""
        return name in self.index

    def i(self, name: str, k: int = 0) -> int:
        """Index of element k of state group `name`."""
        return self.index[name].start + k

    @property
    def groups(self) -> tuple[str, ...]:
        """State group names in order."""
        return tuple(self.index)

    @cached_property
    def packed(self) -> Array:
        """The layout as kernels.errormodel's int64 array: lay[L_N] = n, lay[L_<group>] its first index (-1
        absent), lay[L_NSV], lay[L_NPL] the channel counts, lay[L_GIO], lay[L_AMB] the carrier groups, lay[L_PSY] the
        pseudolites' sync group, lay[L_GIZ], lay[L_GTZ] the zenith ionosphere and troposphere (built once per layout
        object: do not modify)."""
        lay = np.full(ek.LAY_SIZE, -1, dtype=np.int64)
        lay[ek.L_N], lay[ek.L_NSV], lay[ek.L_NPL] = self.n, self.n_sv, self.n_pl
        for k, g in enumerate(ek.LAY_GROUPS):
            if g in self.index:
                lay[1 + k] = self.index[g].start
        for g, at in (("gio", ek.L_GIO), ("amb", ek.L_AMB), ("psy", ek.L_PSY), ("giz", ek.L_GIZ), ("gtz", ek.L_GTZ)):
            if g in self.index:
                lay[at] = self.index[g].start
        return lay


@dataclass(frozen=True)
class ErrorNoise:
    """Process-noise strengths and correlation times of the error model (continuous-time, SI).

    gyro_arw_rad_sqrts: angle random walk (rad/sqrt(s)); accel_vrw_mps_sqrts: velocity random walk;
    gyro_bias_rw: gyro bias random-walk density (rad/s/sqrt(s)); accel_bias_rw (m/s^2/sqrt(s));
    baro_bias_sigma_m, baro_bias_tau_s: baro bias Gauss-Markov; baro_noise_sigma_m and baro_rate_hz: the
    baro white noise (enters the process only through the damping loop); clock_sf, clock_sg: clock
    bias / drift noise densities (m^2/s, m^2/s^3: c^2 h0/2 and c^2 2 pi^2 h_-2, sensors/gnss/clock.py).
    """

    gyro_arw_rad_sqrts: float
    accel_vrw_mps_sqrts: float
    gyro_bias_rw: float
    accel_bias_rw: float
    baro_bias_sigma_m: float
    baro_bias_tau_s: float
    baro_noise_sigma_m: float = 1.0
    baro_rate_hz: float = 10.0
    clock_sf: float = 0.0
    clock_sg: float = 0.0
    gse_sigma_m: float | Array = 0.0
    """Per-channel slow range-error 1-sigma (scalar or (n_sv,) by elevation), m."""
    gse_tau_s: float = 1800.0
    gmp_sigma_m: float | Array = 0.0
    """Per-channel multipath 1-sigma (scalar, or (n_sv,) by elevation under the DO-253 model), m."""
    gmp_tau_s: float = 60.0
    pmp_sigma_m: float = 0.0
    pmp_tau_s: float = 30.0
    pclk_sf: float = 0.0
    pclk_sg: float = 0.0
    ram_sigma_m: float = 0.0
    ram_tau_s: float = 10.0
    tdb_correlation_m: float = 300.0
    """Along-track correlation length of the terrain-database error, m (tau = L / max(ground speed, 1 m/s))."""
    gio_sigma_m: float | Array = 0.0
    """Per-channel ionospheric range-error 1-sigma (scalar or (n_sv,) by elevation), m (carrier phase only)."""
    gio_tau_s: float = 1800.0
    baro_ref_m: float = 0.0
    """The baro scale factor's reference H_ref, m: the altimeter-setting reference (the field); not a noise, the
    constant of the sb terms -(h - H_ref) sb (seed 003 eq. 1 with the scale factor on the height above the setting's
    reference: a QNH altimeter is exact at the field whatever its scale error)."""
    psy_sigma_m: float = 0.0
    psy_tau_s: float = 600.0
    """Synchronized pseudolites' time-sync error: 1-sigma (m) and correlation time (s) of each psy state."""
    gyro_axis_q_x: float = 0.0
    gyro_axis_q_y: float = 0.0
    gyro_axis_q_z: float = 0.0
    """White rate noise of the gyro scale-factor / misalignment errors on body axes x, y, z, rad^2/s: the unbounded
    part of the attitude error (S + M) w_ib makes on the flown airframe (nav/noise.py gyro_axis_q); rotated to NED,
    added to the attitude's ARW."""
    giz_sigma_m: float = 0.0
    giz_gradient_sigma_m: float = 0.0
    giz_tau_s: float = 1800.0
    """The zenith ionospheric states giz: 1-sigma of the common part and of each gradient component (m) and their
    correlation time (s) (sensors/gnss/service.py ServiceModel.filter_iono_zenith)."""
    gtz_sigma_m: float = 0.0
    gtz_tau_s: float = 3600.0
    """The zenith tropospheric state gtz: 1-sigma (m) and correlation time (s) (ServiceModel.filter_tropo_zenith)."""

    @cached_property
    def _kernel_arrays(self) -> dict[int, tuple[Array, Array, Array]]:
        """kernel_noise's cache, by channel count (the object is frozen: its arrays are packed once)."""
        return {}

    @cached_property
    def _carrier_arrays(self) -> dict[int, Array]:
        """kernel_carrier's cache, by channel count."""
        return {}


def kernel_noise(noise: ErrorNoise, n_sv: int) -> tuple[Array, Array, Array]:
    """The noise as kernels.errormodel's arrays: q (Q_SIZE,) the scalars at ek.Q_*, and the per-channel
    gse_sigma_m, gmp_sigma_m broadcast to (n_sv,), m. Packed once per noise object and channel count; each call
    returns its own writable copies (a read-only array is another argument type to the compiled kernels, and a
    shared cached array written by one caller would reach the next)."""
    cache = noise._kernel_arrays
    if n_sv not in cache:
        q = np.array([float(getattr(noise, f)) for f in ek.Q_FIELDS])
        per = [np.array(np.broadcast_to(np.asarray(a, dtype=float), (n_sv,))) if n_sv else np.zeros(0)
               for a in (noise.gse_sigma_m, noise.gmp_sigma_m)]
        cache[n_sv] = (q, per[0], per[1])
    q, gse, gmp = cache[n_sv]
    return q.copy(), gse.copy(), gmp.copy()


def kernel_carrier(noise: ErrorNoise, n_sv: int) -> tuple[Array, float]:
    """The carrier-phase states' noise as kernels.carrier.dynamics' arguments: gio_sigma_m broadcast to (n_sv,) m,
    and gio_tau_s. Packed once beside kernel_noise's; each call returns its own writable copy (kernel_noise says
    why)."""
    cache = noise._carrier_arrays
    if n_sv not in cache:
        cache[n_sv] = (np.array(np.broadcast_to(np.asarray(noise.gio_sigma_m, dtype=float), (n_sv,)))
                       if n_sv else np.zeros(0))
    return cache[n_sv].copy(), float(noise.gio_tau_s)


_NO_LOOP = np.zeros(ek.LOOP_SIZE)


@lru_cache(maxsize=64)
def kernel_loop(loop: vl.LoopGains | None) -> Array:
    """The damping loop as kernels.errormodel's (LOOP_SIZE,) array (1, C1, C2, C3) of its linearized gains;
    zeros without a loop."""
    if loop is None:
        return _NO_LOOP
    lin = loop.linearized()
    return np.array([1.0, lin.c1, lin.c2, lin.c3])


def kernel_inputs(layout: StateLayout, noise: ErrorNoise, loop: vl.LoopGains | None = None
                  ) -> tuple[Array, Array, Array, Array, Array]:
    """(lay, q, gse_sigma, gmp_sigma, loop) for kernels.errormodel.dynamics, from the frozen objects (cached):
    what a compiled per-run loop passes with the nav state and its preallocated F, Qc."""
    if layout.has("ac") and loop is None:
        raise ValueError("layout has the loop state 'ac' but no loop gains were given")
    q, gse, gmp = kernel_noise(noise, layout.n_sv)
    return layout.packed, q, gse, gmp, kernel_loop(loop if layout.has("ac") else None)


def _markov(F: Array, Qc: Array, sl: slice, sigma: float | Array, tau_s: float) -> None:
    """First-order Gauss-Markov states x' = -x / tau + w, E[w w'] = 2 sigma^2 / tau (in place)."""
    k = np.arange(sl.start, sl.stop)
    F[k, k] = -1.0 / tau_s
    Qc[k, k] = 2.0 * np.broadcast_to(np.asarray(sigma, dtype=float), k.shape) ** 2 / tau_s


def _dw_in(lat: float, h: float, v: Array, r_n: float, r_e: float) -> tuple[Array, Array, Array]:
    """Jacobians of w_ie + w_en (NED) with respect to dp (3), dv (3): (3, 3) each; and w_ie (3,)."""
    tl, cl, sl = np.tan(lat), np.cos(lat), np.sin(lat)
    rn, re = r_n + h, r_e + h
    vn, ve = v[0], v[1]
    om = geo.OMEGA_E
    d_dp = np.zeros((3, 3))
    d_dv = np.zeros((3, 3))
    # Earth rate through latitude: dL = dp_N / (R_N + h)
    d_dp[0, 0] += -om * sl / rn
    d_dp[2, 0] += -om * cl / rn
    # transport rate (Groves eq. 5.44), dh = -dp_D
    d_dv[0, 1] = 1.0 / re
    d_dp[0, 2] += ve / re**2
    d_dv[1, 0] = -1.0 / rn
    d_dp[1, 2] += -vn / rn**2
    d_dv[2, 1] = -tl / re
    d_dp[2, 0] += -ve / (re * cl**2 * rn)
    d_dp[2, 2] += -ve * tl / re**2
    return d_dp, d_dv, np.array([om * cl, 0.0, -om * sl])


def linear_height(layout: StateLayout, h_ins_m: float, x_hat: Array, v_down_ins_mps: float = 0.0,
                  dt_s: float = 0.0, F_start: Array | None = None) -> float:
    """The height (m) the per-run error model is linearized at over an aiding interval of dt_s ending at the INS
    height h_ins_m and down velocity v_down_ins_mps: the INS height, or with a baro scale-factor state the
    navigation's, h_ins + dp_D_hat, with the damping loop at the interval's midpoint (with v_D - dv_D_hat;
    core/nav/errormodel.interval_height:
    the damping loop drags the INS toward a baro off by sb (h - H_ref), and the loop's sb coefficient -(h - H_ref)
    must be the true height's along the interval; nav/measurements.baro says why). F_start: the interval's model
    taken at that height first; with it dp_D_hat is moved to the interval's end by its rate (core/nav/errormodel.
    end_height), as the compiled per-run epoch does (core/nav/epoch.run_epoch)."""
    if not layout.has("sb"):
        return h_ins_m
    if not layout.has("ac"):  # no damping loop: the INS height and the estimate, as before the interval's midpoint
        return h_ins_m + float(x_hat[layout.i("dp", 2)])
    h_nav = h_ins_m + float(x_hat[layout.i("dp", 2)])
    if F_start is not None:
        h_nav = float(ek.end_height(layout.packed, np.ascontiguousarray(F_start, dtype=float),
                                    np.ascontiguousarray(x_hat, dtype=float), h_nav, float(dt_s)))
    return ek.interval_height(layout.packed, h_nav, v_down_ins_mps - float(x_hat[layout.i("dv", 2)]), dt_s)


def loop_jacobian(layout: StateLayout, F: Array, loop: vl.LoopGains | None, loop_held: bool, sb: float
                  ) -> Array | None:
    """The EKF's Jacobian of an interval's model F of the estimate at its baro scale factor sb: a copy of F with the
    damping loop's rows at dp_D taking -g sb more (core/nav/errormodel.loop_jacobian says why), or None when F is
    the Jacobian as it is (no sb state, no loop, or the loop held). loop: the gains F was built with."""
    Fj = np.array(F, dtype=float, order="C")
    lv = kernel_loop(loop if layout.has("ac") else None)
    if not ek.loop_jacobian(layout.packed, lv, bool(loop_held), float(sb), Fj, np.empty(3)):
        return None
    return Fj


def predict_mean(F: Array, phi: Array, x: Array, dt_s: float) -> Array:
    """The estimate x (n,) predicted over dt_s by its own model F where the covariance takes the Jacobian's Phi
    (core/nav/errormodel.predict_mean: exp(F dt) x on F's coupled states, Phi x on the rest); a new array."""
    out = np.array(x, dtype=float)
    ek.predict_mean(np.ascontiguousarray(F, dtype=float), np.ascontiguousarray(phi, dtype=float), out, float(dt_s))
    return out


@dataclass(frozen=True)
class MeanModel:
    """An interval's model of the estimate where the covariance takes another: x' = F x + b over dt_s (s), F (n, n)
    the estimate's continuous model (`loop_jacobian`: the covariance's is the Jacobian), b (n,) a constant pull
    beyond it or None (an adaptive damping loop's E[k(e)] beyond its slope, NavSystem.loop_linearization)."""

    F: Array
    dt_s: float
    b: Array | None = None

    def predict(self, phi: Array, x: Array) -> Array:
        """x predicted by F and b (`predict_mean`; phi the covariance's, for the decoupled states); a new array. With
        b, the action of exp on the augmented [[F, b], [0, 0]] on (x, 1)."""
        if self.b is None:
            return predict_mean(self.F, phi, x, self.dt_s)
        n = self.F.shape[0]
        Fa = np.zeros((n + 1, n + 1))
        Fa[:n, :n] = self.F
        Fa[:n, n] = self.b
        pa = np.zeros((n + 1, n + 1))
        pa[:n, :n] = phi
        pa[n, n] = 1.0
        return predict_mean(Fa, pa, np.append(x, 1.0), self.dt_s)[:n]

    @staticmethod
    def predict_state(filt: Any, fs: Any, phi: Array, qd: Array, mean: MeanModel | None) -> Any:
        """filt.predict(fs, phi, qd) (a nav.base.NavFilter and its FilterState), its estimate from `mean` when
        given."""
        out = filt.predict(fs, phi, qd)
        return out if mean is None else replace(out, x=mean.predict(phi, fs.x))


def interval_height(layout: StateLayout, h_m: float, v_down_mps: float, dt_s: float) -> float:
    """The height (m) a reference's interval model is taken at (h_m, v_down_mps at the interval's end): its midpoint
    with a baro scale-factor state and the damping loop, else h_m (core/nav/errormodel.interval_height)."""
    return float(ek.interval_height(layout.packed, h_m, v_down_mps, dt_s))


def dynamics(
    layout: StateLayout,
    lat_rad: float,
    h_m: float,
    v_ned: Array,
    f_ned: Array,
    c_bn: Array,
    noise: ErrorNoise,
    loop: vl.LoopGains | None = None,
    loop_held: bool = False,
) -> tuple[Array, Array]:
    """Continuous error dynamics F (n, n) and process-noise spectral density G Q G' (n, n) about a nav state.

    lat_rad, h_m, v_ned (3,), f_ned (3,) specific force in NED (m/s^2), c_bn (3, 3): the INS solution
    (the best available linearization point). The module docstring gives the equations; computed by the
    compiled kernel (kernels.errormodel.dynamics), equal to `dynamics_reference`.
    """
    lay, q, gse, gmp, lv = kernel_inputs(layout, noise, loop)
    n = layout.n
    F = np.empty((n, n))
    Qc = np.empty((n, n))
    ek.dynamics(lay, q, gse, gmp, float(lat_rad), float(h_m), np.ascontiguousarray(v_ned, dtype=float),
                np.ascontiguousarray(f_ned, dtype=float), np.ascontiguousarray(c_bn, dtype=float), lv,
                bool(loop_held), F, Qc)
    _carrier_states(layout, noise, F, Qc)
    return F, Qc


def _carrier_states(layout: StateLayout, noise: ErrorNoise, F: Array, Qc: Array) -> None:
    """The carrier-phase groups, after every kernel-known group (in place): gio Gauss-Markov; amb random constants
    (zero rows, as the kernel left them)."""
    if layout.has("gio"):
        _markov(F, Qc, layout.index["gio"], noise.gio_sigma_m, noise.gio_tau_s)


def dynamics_reference(
    layout: StateLayout,
    lat_rad: float,
    h_m: float,
    v_ned: Array,
    f_ned: Array,
    c_bn: Array,
    noise: ErrorNoise,
    loop: vl.LoopGains | None = None,
    loop_held: bool = False,
) -> tuple[Array, Array]:
    """Continuous error dynamics F (n, n) and process-noise spectral density G Q G' (n, n) about a nav state.

    lat_rad, h_m, v_ned (3,), f_ned (3,) specific force in NED (m/s^2), c_bn (3, 3): the INS solution
    (the best available linearization point). The module docstring gives the equations. The readable numpy
    version: `dynamics`'s test oracle.
    """
    n = layout.n
    F = np.zeros((n, n))
    Qc = np.zeros((n, n))
    ix = layout.index
    P, V, A = ix["dp"], ix["dv"], ix["psi"]
    v = np.asarray(v_ned, dtype=float)
    r_n, r_e = (float(x) for x in geo.radii(lat_rad))
    rn, re = r_n + h_m, r_e + h_m
    tl = np.tan(lat_rad)
    vn, ve, vd = v
    # position error (metres) kinematics, from lat' = vN/(R_N+h), lon' = vE/((R_E+h) cos L), h' = -vD
    F[P, V] = np.eye(3)
    fp = np.array(
        [
            [-vd / rn, 0.0, vn / rn],
            [ve * tl / rn, -vd / re - tl * vn / rn, ve / re],
            [0.0, 0.0, 0.0],
        ]
    )
    F[P, P] = fp
    d_dp, d_dv, w_ie = _dw_in(lat_rad, h_m, v, r_n, r_e)
    w_en = np.array([ve / re, -vn / rn, -ve * tl / re])
    w_in = w_ie + w_en
    # velocity error: [f x] psi + C ba - (2 w_ie + w_en) x dv + v x (2 dw_ie + dw_en) + dg
    d_ie_dp = np.zeros((3, 3))
    d_ie_dp[0, 0] = -geo.OMEGA_E * np.sin(lat_rad) / rn
    d_ie_dp[2, 0] = -geo.OMEGA_E * np.cos(lat_rad) / rn
    d_en_dp = d_dp - d_ie_dp
    vx = ins.skew(v)
    F[V, A] = ins.skew(np.asarray(f_ned, dtype=float))
    F[V, V] = -ins.skew(2.0 * w_ie + w_en) + vx @ d_dv
    F[V, P] = vx @ (2.0 * d_ie_dp + d_en_dp)
    dg_dh = float((geo.gravity_ned(lat_rad, h_m + 10.0)[2] - geo.gravity_ned(lat_rad, h_m - 10.0)[2]) / 20.0)
    F[V.start + 2, P.start + 2] += -dg_dh  # dg_D = (dg/dh) dh = -(dg/dh) dp_D  (about +2 g / R)
    F[V, ix["ba"]] = c_bn
    # attitude error: -w_in x psi + dw_in - C bg
    F[A, A] = -ins.skew(w_in)
    F[A, P] = d_dp
    F[A, V] = d_dv
    F[A, ix["bg"]] = -c_bn
    # sensor error states
    i_bb = layout.i("bb")
    F[i_bb, i_bb] = -1.0 / noise.baro_bias_tau_s
    Qc[i_bb, i_bb] = 2.0 * noise.baro_bias_sigma_m**2 / noise.baro_bias_tau_s
    Qc[V, V] = noise.accel_vrw_mps_sqrts**2 * np.eye(3)
    Qc[A, A] = noise.gyro_arw_rad_sqrts**2 * np.eye(3) + c_bn @ np.diag(
        [noise.gyro_axis_q_x, noise.gyro_axis_q_y, noise.gyro_axis_q_z]) @ c_bn.T
    Qc[ix["bg"], ix["bg"]] = noise.gyro_bias_rw**2 * np.eye(3)
    Qc[ix["ba"], ix["ba"]] = noise.accel_bias_rw**2 * np.eye(3)
    if layout.has("clk"):
        ic = layout.i("clk")
        F[ic, ic + 1] = 1.0
        Qc[ic, ic] = noise.clock_sf
        Qc[ic + 1, ic + 1] = noise.clock_sg
    if layout.has("gse"):
        _markov(F, Qc, ix["gse"], noise.gse_sigma_m, noise.gse_tau_s)
        _markov(F, Qc, ix["gmp"], noise.gmp_sigma_m, noise.gmp_tau_s)
    if layout.has("pmp"):
        _markov(F, Qc, ix["pmp"], noise.pmp_sigma_m, noise.pmp_tau_s)
    if layout.has("pclk"):
        for j in range(layout.n_pl):
            ic = layout.i("pclk", 2 * j)
            F[ic, ic + 1] = 1.0
            Qc[ic, ic] = noise.pclk_sf
            Qc[ic + 1, ic + 1] = noise.pclk_sg
    if layout.has("psy"):
        _markov(F, Qc, ix["psy"], noise.psy_sigma_m, noise.psy_tau_s)
    if layout.has("ram"):
        _markov(F, Qc, ix["ram"], noise.ram_sigma_m, noise.ram_tau_s)
    if layout.has("giz"):
        _markov(F, Qc, ix["giz"], np.array([noise.giz_sigma_m, noise.giz_gradient_sigma_m,
                                            noise.giz_gradient_sigma_m]), noise.giz_tau_s)
    if layout.has("gtz"):
        _markov(F, Qc, ix["gtz"], noise.gtz_sigma_m, noise.gtz_tau_s)
    if layout.has("tdb"):
        _markov(F, Qc, ix["tdb"], 1.0, noise.tdb_correlation_m / max(float(np.hypot(vn, ve)), 1.0))
    _carrier_states(layout, noise, F, Qc)
    if layout.has("ac"):
        if loop is None:
            raise ValueError("layout has the loop state 'ac' but no loop gains were given")
        lin = loop.linearized()
        ia = layout.i("ac")
        i_h, i_v = P.start + 2, V.start + 2  # dp_D = -dh, dv_D = -dv_up
        # loop error e = dh - bb - S (h - H_ref) - v_b, written in dp_D: e = -dp_D - bb - (h - H_ref) sb - v_b, h the
        # navigation's height. Unlike the baro row (nav/measurements.baro: -(1 + sb) at dp_D) the dp_D coefficient
        # stays -1: F also carries the estimate (x- = Phi x+), and with h_nav = h_ins + dp_D_hat this row gives the
        # exact loop error at the estimate, F x_hat = e(x_hat); the Jacobian's extra -sb dp_D would add sb dp_D_hat
        # to it, and dp_D_hat holds the INS's baro-dragged error sb (h - H_ref) (70 m at 600 m, ISA -30): tried, the
        # estimate ran off by 7.6 sigma (issue 39)
        e_row = np.zeros(n)
        e_row[i_h] = -1.0
        e_row[i_bb] = -1.0
        if layout.has("sb"):
            e_row[layout.i("sb")] = -(h_m - noise.baro_ref_m)
        F[i_v, ia] += 1.0
        if not loop_held:  # held (no baro): the compensator stays as it is and only ac acts (kernels.strapdown)
            F[i_h, :] += lin.c1 * e_row  # dp_D' = -dh' gets +C1 e
            F[i_v, :] += lin.c2 * e_row  # dv_D' = -dv_up' gets +C2 e + ac
            F[ia, :] += lin.c3 * e_row  # ac' = C3 e
            g = np.zeros(n)  # the baro white noise through the gains
            g[i_h], g[i_v], g[ia] = -lin.c1, -lin.c2, -lin.c3
            Qc += np.outer(g, g) * noise.baro_noise_sigma_m**2 / noise.baro_rate_hz
    return F, Qc


def _expm(M: Array) -> Array:
    """Matrix exponential by scaling and squaring of an 8th-order Taylor series (error < 1e-15 relative for
    the small, well-scaled matrices here); scipy.linalg.expm when the norm is large."""
    norm = float(np.abs(M).sum(axis=0).max())
    if norm > 1e3:
        return expm(M)
    s = max(0, int(np.ceil(np.log2(max(norm, 1e-300) / 0.25))))
    A = M / 2.0**s
    E = np.eye(M.shape[0])
    term = np.eye(M.shape[0])
    for k in range(1, 9):
        term = term @ A / k
        E = E + term
    for _ in range(s):
        E = E @ E
    return E


def van_loan(F: Array, Qc: Array, dt_s: float) -> tuple[Array, Array]:
    """Discrete Phi = expm(F dt) and Qd = int_0^dt Phi(s) Qc Phi(s)' ds by Van Loan's method (1978).

    M = [[-F, Qc], [0, F']] dt ; expm(M) = [[., Phi^-1 Qd], [0, Phi']] ; Qd = Phi (Phi^-1 Qd).
    """
    n = F.shape[0]
    M = np.zeros((2 * n, 2 * n))
    M[:n, :n] = -F * dt_s
    M[:n, n:] = Qc * dt_s
    M[n:, n:] = F.T * dt_s
    E = _expm(M)
    phi = E[n:, n:].T
    qd = phi @ E[:n, n:]
    return phi, 0.5 * (qd + qd.T)


def discretize(F: Array, Qc: Array, dt_s: float) -> tuple[Array, Array]:
    """Phi, Qd over dt_s: decoupled scalar states (first-order Markov / random constants) in closed form,
    the coupled rest by Van Loan, one connected component at a time (the compiled kernels.errormodel.discretize;
    `discretize_reference` when a component's Van Loan matrix is too large for its Taylor series)."""
    n = F.shape[0]
    phi = np.empty((n, n))
    qd = np.empty((n, n))
    if ek.discretize(np.ascontiguousarray(F, dtype=float), np.ascontiguousarray(Qc, dtype=float), float(dt_s),
                     phi, qd):
        return phi, qd
    return discretize_reference(F, Qc, dt_s)


def discretize_reference(F: Array, Qc: Array, dt_s: float) -> tuple[Array, Array]:
    """Phi, Qd over dt_s: decoupled scalar states (first-order Markov / random constants) in closed form,
    the coupled rest by Van Loan. Same result as van_loan(F, Qc, dt_s), much cheaper with channel states.
    The readable numpy version: `discretize`'s test oracle."""
    n = F.shape[0]
    off = (F != 0.0) | (Qc != 0.0)
    np.fill_diagonal(off, False)
    lone = ~(off.any(axis=0) | off.any(axis=1))
    core = np.flatnonzero(~lone)
    phi = np.zeros((n, n))
    qd = np.zeros((n, n))
    if core.size:
        p_c, q_c = van_loan(F[np.ix_(core, core)], Qc[np.ix_(core, core)], dt_s)
        phi[np.ix_(core, core)] = p_c
        qd[np.ix_(core, core)] = q_c
    k = np.flatnonzero(lone)
    a = F[k, k]
    phi[k, k] = np.exp(a * dt_s)
    safe = np.where(a == 0.0, 1.0, a)
    qd[k, k] = Qc[k, k] * np.where(a == 0.0, dt_s, np.expm1(2.0 * a * dt_s) / (2.0 * safe))
    return phi, qd
