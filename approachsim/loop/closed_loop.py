"""Navigation in the loop: a NavigationSource that runs the INS + filter step by step inside the flight loop.

    source = NavInTheLoop(profile, seed, run)          # sensor errors drawn once, applied row by row
    result = Approach(profile).fly(seed, run, nav_source=source)
    errors = approach_errors(result.truth, result.guidance_r_rwy, profile.runway)   # loop/errors.py

The source reads truth rows <= k only (records.NavigationSource): at row k it applies the pre-drawn IMU
errors to the increment (k-1, k], steps the INS, and at aiding epochs applies the other sensors' pre-drawn
errors to row k and runs the filter (system.NavSystem.aid). Guidance gets the navigation output
(feed-forward INS - estimated error, or the fed-back INS) in the runway frame.

Flown by JSBSim (`inloop`), the row runs inside the flight's compiled step (core/loop/nav_row.py) and an aiding
epoch is one compiled call (core/loop/aiding.py: the per-run EKF's epoch and the Navigator's
bookkeeping) on the sensors' one-row records, when the configuration has the compiled epoch
(loop/paths.py chooses every part of the path once per run: not with feedback, the online FDE, the robust or U-D
filters, loose coupling, an adaptive loop, carrier phase); otherwise, and as its test oracle (`fast_epochs = False`),
the Navigator's numpy path. The compiled epoch's sensor inputs come straight from the baro's, radar altimeter's and
GPS receiver's kernels, fused in one compiled call (`_direct_inputs`, core/loop/aiding.direct_inputs, no records;
`direct_inputs = False` or a faulted sensor, GBAS, carrier: from the records) and the GPS channel sigmas partly
compiled (`_noise_arrays`; `compiled_sigmas = False`: numpy), the same bits either way
(tests/unit/nav/test_closed_loop_epoch.py; tools/closed_loop_identity.py against a saved reference).
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from approachsim import geo
from approachsim.core import layouts
from approachsim.core.entry import entry_point
from approachsim.core.loop import aiding as ce
from approachsim.core.loop import nav_row as ik
from approachsim.core.nav import groups as kg
from approachsim.core.nav import output as ko
from approachsim.core.nav import strapdown as sk
from approachsim.core.sensors import gnss as gk
from approachsim.loop import paths
from approachsim.nav import errormodel as em
from approachsim.nav import ins
from approachsim.nav.base import FilterState
from approachsim.nav.navigator import Navigator, NavRun
from approachsim.nav.observations import Observations
from approachsim.nav.system import NavSystem, tuned_records
from approachsim.records import Truth
from approachsim.seeding import stream
from approachsim.sensors.gnss.elevation import IONO_SHELL_M
from approachsim.sensors.gnss.receiver import PreparedGnss
from approachsim.sensors.states import start_states
from approachsim.sensors.suite import SensorSuite

Array = np.ndarray

_EMPTY = np.zeros((1, 3))
"""Placeholder for the affine IMU terms when the increments come from `apply` (quantized or faulted IMU)."""

_VEC3 = ("r_ecef", "v_ned", "euler_rad", "w_ib_body", "f_body", "r_rwy")

_AIDING = ("baro", "radalt", "gnss", "pseudolite")
"""The aiding sensors, in the order the epoch reads them."""

_NAN1 = np.full(1, math.nan)
_TRUE1 = np.ones(1, dtype=bool)
_EL_MIN = float(np.radians(2.0))
"""nav/noise.py's elevation floor, rad."""


class _BaroAt:
    """A plain baro's sample at an epoch row made without its record (NavInTheLoop._direct_inputs): what the
    damping loop reads of the record (h_baro_m (1,) m, valid (1,): a plain baro's samples are all valid)."""

    __slots__ = ("h_baro_m",)
    valid = _TRUE1

    def __init__(self, h_baro_m: Array) -> None:
        self.h_baro_m = h_baro_m




def _per_channel(a: Array | float, n_sv: int) -> Array:
    """a (one value, or one per channel) as a contiguous (n_sv,) float array: np.broadcast_to's values, without
    its cost when a is that already."""
    if isinstance(a, np.ndarray) and a.shape == (n_sv,) and a.dtype == np.float64 and a.flags.c_contiguous:
        return a
    return np.ascontiguousarray(np.broadcast_to(np.asarray(a, dtype=float), (n_sv,)))


@dataclass(frozen=True)
class InLoop:
    """The compiled per-row navigation of one closed-loop run (core/loop/nav_row.py): the work vector nw (NW,),
    the packed arrays fa (float64) and ia (int64) and, as views of them (inloop.views), the IMU error terms cg, ca
    (m, 3) by sample, the INS rows (1, n, 16), the guidance rows (n, 6), the snapshot index per row (n,), the baro
    sample per row, its errors and lag weights, scratch increments dth, dv (1, 1, 3); and act(k, truth, code): the
    source's Python part."""

    nw: Array
    fa: Array
    ia: Array
    cg: Array
    ca: Array
    rows3: Array
    snap: Array
    baro_j: Array
    """(n,) int64 the baro sample at each truth row (-1: none)."""
    baro_e: Array
    """(m, 2) the baro's bias and noise by sample, m (for the samples made in the kernel)."""
    lag_w: Array
    """The baro's lag weights (empty: no lag)."""
    dth: Array
    dv: Array
    guidance: Array
    """(n, 6) the guidance of every row (runway-frame position m, NED velocity m/s; nan until flown)."""
    act: Any

    @property
    def rows(self) -> Array:
        """(n, 16) the one run's INS rows (a view)."""
        return self.rows3[0]


@dataclass(frozen=True)
class _Act:
    """InLoop.act: the source's `act` through a weak reference, so that the source and its InLoop form no reference
    cycle (their ~20 MB of arrays are freed when the caller drops the source, not at the next cyclic collection)."""

    source: weakref.ref

    def __call__(self, k: int, truth: Truth, code: int) -> None:
        self.source().act(k, truth, code)


@dataclass
class FastEpoch:
    """The closed loop's compiled aiding epoch (core/loop/aiding.py loop_epoch): its constant
    arguments, scratch and the epoch history it writes (XS, PP, PC, PD, PN: one row per epoch, the Navigator's
    snapshots are views of them), made once at the start (loop/paths.py says when not)."""

    q: Array
    """The error model's scalar noise (errormodel.kernel_noise of the elevation-free noise; does not depend on the
    elevations)."""
    no_gnss: tuple[Array, Array, Array]
    """kernel_noise at no elevations (NoiseModel.kernel_arrays(None))."""
    budget: Any
    """The GNSS error budget (its channel_sigmas_m), or None without GNSS."""
    held_possible: bool
    """The layout has the damping loop's states and the INS has a loop (an interval without baro holds it)."""
    P: Array
    """The run's covariance, updated in place by the kernel (run.fs.P is this array after a compiled epoch)."""
    X: Array
    f_ned: Array
    XS: Array
    PP: Array
    PC: Array
    PD: Array
    PN: Array
    XD: Array
    """The estimate's rate after each epoch (core/nav/output.nav_rate), (epochs, 9)."""
    e: int = 0
    """The next history row."""
    call: Any = None
    """loop_epoch's compiled entry point for this run's argument types (`_entry`; made at the first epoch)."""
    sig: tuple | None = None
    """The compiled channel sigmas' scratch and constants (NavInTheLoop._noise_arrays): guarded elevations, the
    multipath curve's argument, cos, sin, exp, gse, gmp (n_sv,) and channel_sigmas' constants; a GNSS service's:
    guarded elevations, the argument, the elevations as (1, n_sv), slow, fast, total (1, n_sv), None and the filter's
    service parameters; None: the numpy formulas (GBAS budget, no GPS channels)."""
    direct: bool = False
    """The epoch's sensor inputs come straight from the sensors' kernels (NavInTheLoop._direct_inputs: plain baro,
    radar altimeter and stand-alone code GNSS of one run), not from their records (`_epoch_inputs`, the oracle)."""
    no_cp: Array = field(default_factory=lambda: np.zeros((1, 0)))
    """No carrier phase on this path (loop/paths.py): the epoch's empty carrier observations and ..."""
    no_gio: Array = field(default_factory=lambda: np.zeros(0))
    """... the error model's empty ionosphere states."""


_NO_RECS: dict[str, Any] = {}
"""`_recs` of an epoch row without a baro sample (read only)."""


@dataclass
class _Direct:
    """core/loop/aiding.direct_inputs' argument list for one run (NavInTheLoop._direct_arrays): the row and time
    (args[0], args[1]), the sample indices args[3:6] (baro, radar altimeter, GPS; -1: none at the row), the GPS
    selection plan args[6] (best4-fixed's is made per epoch: `plan`, PreparedGnss.plan; None for the other
    selections), each sensor's tuple, and the output buffers the epoch's inputs are read from."""

    args: list
    plan: Any
    baro_h: Array
    baro_r: float
    radalt_h: Array
    rho: Array
    r_sv: Array
    sig: Array
    el: Array
    no_rho: Array
    guard: bool
    """direct_inputs guards the GPS elevations for the compiled channel sigmas (FastEpoch.sig fits the channels)."""
    recs: dict[str, Any]
    """`_recs` of an epoch row with a baro sample: its height in the kernel's b_hold (1,)."""
    pseudolite: bool
    call: Any = None
    """direct_inputs' compiled entry point for these argument types (`_entry`)."""
    guarded: bool = False
    """The last call guarded the elevations (`_noise_arrays` reads them once)."""


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
        self.prepared = self.suite.prepare(self.errors)
        """The drawn errors laid out for one truth row at a time (sensors/suite.py PreparedSuite)."""
        self.epoch_rows = max(1, int(round(self.profile.rates.imu_hz / self.nav.nav.aiding_rate_hz)))
        self.gains = self.nav.loop_gains()
        self._imu_affine = self._imu_error_terms()
        self.navigator: Navigator | None = None
        """The navigation step object (nav/navigator.py), made at row 0."""
        self.h_baro_hold = math.nan
        self.h_baro_t = math.nan
        """The held baro sample and its time (s): the damping loop takes the INS height back to that time."""
        # the kernels' inputs and outputs, allocated once (kernels/strapdown.py inloop_step, guidance)
        self._dth, self._dv = np.zeros((1, 1, 3)), np.zeros((1, 1, 3))
        self._bg, self._ba, self._hb = np.zeros((1, 3)), np.zeros((1, 3)), np.full((1, 1), math.nan)
        self._hb_age = np.zeros(1)
        self._hb_interval = np.full(self.epoch_rows, math.nan)  # the baro the kernel got over the epoch interval
        self._loop = ins.loop_vector(self.gains)
        self._guide = np.zeros(6)
        self.x_nav = np.zeros(9)
        """The estimate in force (dp NED m, dv m/s, psi rad), its rate (core/nav/output.nav_rate) and time (s), and
        the estimate carried to a row's time (core/nav/output.estimate_at): the guidance's."""
        self.x_dot = np.zeros(9)
        self.t_est = 0.0
        self._x_now = np.zeros(9)
        self._c_rwy = np.ascontiguousarray(self.profile.runway.frame.c_ecef_to_rwy)
        self._o_rwy = np.ascontiguousarray(self.profile.runway.frame.origin_ecef)
        self._h_thr = float(self.profile.runway.elevation_m)
        self._inloop: InLoop | None = None
        self._fast: FastEpoch | None = None
        self._direct: _Direct | None = None
        """The direct inputs' kernel arguments (`_direct_arrays`, made at the first direct epoch)."""
        self._recs: tuple[int, dict[str, Any]] | None = None
        """The last epoch's sensor records (row, records): the baro's is the damping loop's sample at that row."""
        self.fast_epochs = True
        """Run the aiding epochs compiled when the configuration allows (loop/paths.py); False: always
        the Navigator's numpy path (the compiled epoch's test oracle)."""
        self.direct_inputs = True
        """The compiled epoch's sensor inputs straight from the sensors' kernels when possible (FastEpoch.direct);
        False: from their records (the direct inputs' test oracle)."""
        self.compiled_sigmas = True
        """The GPS channel sigmas of the compiled epoch partly compiled (FastEpoch.sig); False: numpy's formulas
        (their test oracle)."""
        self._path: paths.LoopPath | None = None

    @property
    def path(self) -> paths.LoopPath:
        """Which code runs this source (loop/paths.py `choose`), chosen at its first use from the configuration
        and the oracle switches above, then fixed for the run."""
        if self._path is None:
            self._path = paths.choose(self)
        return self._path

    def imu_affine_terms(self) -> tuple[Array, Array, Array, Array] | None:
        """The IMU's affine error terms (S_g + M_g, S_a + M_a, c_g, c_a; `_imu_error_terms`), or None when the IMU
        is quantized or faulted."""
        return self._imu_affine

    def _imu_error_terms(self) -> tuple[Array, Array, Array, Array] | None:
        """The IMU error model is affine in the true increments (sensors/imu.py):
            dtheta_k = (I + S_g + M_g) dtheta_true_k + c_g,k ,   dv_k = (I + S_a + M_a) dv_true_k + c_a,k
        so the error terms c_k of every sample come from one `apply` of the pre-drawn errors to a motionless
        (all-zero) truth, and the matrices from the drawn constants. Returns (S_g + M_g, S_a + M_a, c_g, c_a),
        or None when the IMU is quantized or fault-wrapped (not affine): then every sample goes through `apply`."""
        imu = self.suite.sensors.get("imu")
        e = self.errors.sensors.get("imu")
        if imu is None or e is None or type(imu).__name__ == "Faulted":
            return None
        if getattr(imu.grade, "gyro_quant_rad", 0.0) > 0.0 or getattr(imu.grade, "accel_quant_mps", 0.0) > 0.0:
            return None
        n = self.t_s.shape[0]
        shared: dict[tuple, Array] = {}  # one zero array per shape, shared by the fields (read only)
        zeros = {f.name: shared.setdefault(s, np.zeros(s)) for f in fields(Truth) if f.name != "runway"
                 for s in [(n,) + (3,) * (f.name in _VEC3) + (4,) * (f.name in ("q_nb", "controls"))]}
        zeros["t_s"] = self.t_s
        zero_truth = Truth(**zeros, runway=self.profile.runway.frame)
        rec = imu.apply(zero_truth, e)
        # a row of c is the increment ending at truth row j + 1 (e.rows = 1 .. n-1): index by row k - 1
        return (np.ascontiguousarray(e.constants["gyro_m"], dtype=float),
                np.ascontiguousarray(e.constants["accel_m"], dtype=float),
                np.ascontiguousarray(rec.dtheta_body, dtype=float), np.ascontiguousarray(rec.dv_body, dtype=float))

    def _apply(self, name: str, k: int, truth: Truth) -> Any:
        """The record of sensor `name` at truth row k (one sample: exactly SensorSuite.apply's for that sample), or
        None when it has no sample there."""
        return self.prepared.one(name, truth, k)

    def _records(self, k: int, truth: Truth) -> dict[str, Any]:
        """The aiding sensors' records at truth row k (their pre-drawn errors applied to the row), as the filter
        weighs them ([nav] gps_sigma_scale)."""
        one = self.prepared.one
        recs = {name: r for name in _AIDING if (r := one(name, truth, k)) is not None}
        return dict(tuned_records(recs, self.nav.nav.gps_sigma_scale))  # [nav] gps_sigma_scale (R tuning)

    def _observations(self, k: int, truth: Truth, recs: dict[str, Any] | None = None
                      ) -> tuple[Observations, dict[str, Any]]:
        """The aiding sensors' samples at truth row k (their pre-drawn errors applied to the row; recs: those
        records when already made)."""
        recs = self._records(k, truth) if recs is None else recs
        return Observations.at(recs, float(truth.t_s[k]), 0.25 * self.dt, False), recs

    def step(self, k: int, truth: Truth) -> tuple[Array, Array]:
        """Runway-frame position (m) and NED velocity (m/s) of the navigation output at truth row k.

        The IMU increment of (k-1, k] (the truth sample k-1 held, sensors/imu.py) and the INS step run in one
        compiled call (kernels.strapdown.inloop_step); the filter runs at the aiding epochs (Navigator.epoch)."""
        nav = self.nav
        if k == 0:
            obs, recs = self._observations(0, truth)
            el = recs["gnss"].elevation_rad[0] if "gnss" in recs else None
            s, runs = nav.start(truth, [stream(self.seed, self.run, "nav")], 0, elevation_rad=el, obs=obs,
                                states=start_states(self.suite, truth, self.errors))
            self.navigator = Navigator(nav, s, runs, float(truth.t_s[0]), self.t_s.shape[0])
            self.x_nav = np.array(runs[0].fs.x[0:9], dtype=float)
            xd, self.t_est = self.navigator.rate_in_force()
            self.x_dot = xd[0]
        navigator = self.navigator
        run = navigator.runs[0]
        if k > 0:
            affine = self._imu_affine is not None
            if affine:
                m_g, m_a, c_g, c_a = self._imu_affine
            else:
                imu = self._apply("imu", k, truth)
                self._dth[0, 0], self._dv[0, 0] = imu.dtheta_body.reshape(3), imu.dv_body.reshape(3)
                m_g = m_a = c_g = c_a = _EMPTY
            if nav.nav.feedback:
                self._bg[0], self._ba[0] = run.bg_fb, run.ba_fb
            self._hb[0, 0] = self.h_baro_hold
            self._hb_age[0] = truth.t_s[k - 1] - self.h_baro_t
            self._hb_interval[(k - 1) % self.epoch_rows] = self.h_baro_hold
            sk.inloop_step(k, truth.w_ib_body, truth.f_body, affine, (m_g, m_a, c_g, c_a), self._dth, self._dv,
                           self.dt, self._bg, self._ba, self._hb, self._hb_age, self._loop, navigator.x,
                           navigator.f_sum)
            if k % self.epoch_rows == 0:
                obs, _ = self._observations(k, truth)
                if self.gains is not None:  # the kernel's loop held over the interval (no baro, or excluded)
                    obs = obs.with_loop_held([not np.any(np.isfinite(self._hb_interval))])
                    self._hb_interval[:] = np.nan
                navigator.epoch(k, float(truth.t_s[k]), obs, truth)
                self.x_nav = np.array(run.fs.x[0:9], dtype=float)
                xd, self.t_est = navigator.rate_in_force()
                self.x_dot = xd[0]
        if self.gains is not None and (b := self._apply("baro", k, truth)) is not None:
            # nan (an outage, or the baro excluded by FDE): the INS kernel's damping loop holds
            held = run.baro_excluded() or not bool(np.ravel(b.valid)[0])
            self.h_baro_hold = math.nan if held else float(np.ravel(b.h_baro_m)[0])
            self.h_baro_t = float(truth.t_s[k])
            if k == 0 and nav.nav.initial_error.start == "prior" and math.isfinite(self.h_baro_hold):
                # the converged start's height error stands
                navigator.x[0, 2] = self.h_baro_hold
        navigator.record_row(k)
        g = self._guide
        ko.estimate_at(self.x_nav, self.x_dot, self.t_est, float(truth.t_s[k]), self._x_now)
        sk.guidance(navigator.x, self._x_now, self._c_rwy, self._o_rwy, self._h_thr, g)  # feed-forward INS - x_hat(t)
        return g[0:3].copy(), g[3:6].copy()  # copies: the kernel's buffer is rewritten at the next step

    # --- the compiled row (core/loop/nav_row.py): the flight loop steps the navigation in its own compiled call

    def inloop(self) -> InLoop | None:
        """The arrays of the compiled per-row navigation (records.NavigationSource), or None when the IMU errors
        are not affine (quantized or faulted IMU: every sample goes through its model, `step`)."""
        if self.path.row != "compiled":
            return None
        if self._inloop is None:
            m_g, m_a, c_g, c_a = self._imu_affine
            n = self.t_s.shape[0]
            nw = np.zeros(layouts.NW)
            nw[layouts.W_LOOP:layouts.W_LOOP + 6] = self._loop
            nw[layouts.W_HB] = nw[layouts.W_HB_T] = math.nan
            nw[layouts.W_DT] = self.dt
            nw[layouts.W_MG:layouts.W_MG + 9] = m_g.reshape(9)
            nw[layouts.W_MA:layouts.W_MA + 9] = m_a.reshape(9)
            nw[layouts.W_CRWY:layouts.W_CRWY + 6] = self._c_rwy[0:2].reshape(6)
            nw[layouts.W_ORWY:layouts.W_ORWY + 3] = self._o_rwy
            nw[layouts.W_HTHR] = self._h_thr
            nw[layouts.W_EPOCH_ROWS] = self.epoch_rows
            nw[layouts.W_BARO_LOOP] = 1.0 if self.gains is not None else 0.0
            baro_j = np.full(n, -1, dtype=np.int64)
            baro_e, lag_w = np.zeros((0, 2)), np.zeros(0)
            e = self.errors.sensors.get("baro")
            if e is not None:
                rows = np.asarray(e.rows)
                keep = rows < n
                baro_j[rows[keep]] = np.flatnonzero(keep)
                baro = self.suite.sensors["baro"]
                if self.path.baro == "compiled":  # a plain altimeter: its samples made in the kernel
                    nw[layouts.W_BARO_KERNEL] = 1.0
                    (nw[layouts.W_BSET], nw[layouts.W_BT0L], nw[layouts.W_BEXP], nw[layouts.W_BFLD],
                     nw[layouts.W_BCM1]) = baro.kernel_constants()
                    nw[layouts.W_BSF] = float(np.ravel(e.constants["scale_factor"])[0])
                    baro_e = np.ascontiguousarray(np.column_stack([e.series["bias"], e.series["noise"]]))
                    lag_w = np.ascontiguousarray(baro.lag_weights(self.dt), dtype=float)
            m = c_g.shape[0]
            nw[layouts.W_N], nw[layouts.W_M] = n, m
            nw[layouts.W_NBE], nw[layouts.W_NLAG] = baro_e.shape[0], lag_w.shape[0]
            n_f, n_i = ik.packed_sizes(n, m, baro_e.shape[0], lag_w.shape[0])
            fa, ia = np.empty(n_f), np.empty(n_i, dtype=np.int64)
            cg, ca, rows, snap, bj, be, lw, dth, dv, guidance = ik.views(nw, fa, ia)
            cg[...], ca[...], be[...], lw[...], bj[...], snap[...] = c_g, c_a, baro_e, lag_w, baro_j, 0
            rows[...], guidance[...], dth[...], dv[...] = np.nan, np.nan, 0.0, 0.0
            self._inloop = InLoop(nw, fa, ia, cg, ca, rows[None], snap, bj, be, lw, dth, dv, guidance,
                                  _Act(weakref.ref(self)))
        return self._inloop

    def act(self, k: int, truth: Truth, code: int) -> None:
        """What the compiled row leaves to Python at row k (its NAV_* bits): the start, an aiding epoch, a baro
        sample of the damping loop; then row k is recorded again (the epoch may have corrected the INS)."""
        lp = self._inloop
        nw = lp.nw
        nav = self.nav
        if code & ik.NAV_START:
            obs, recs = self._observations(0, truth)
            el = recs["gnss"].elevation_rad[0] if "gnss" in recs else None
            s, runs = nav.start(truth, [stream(self.seed, self.run, "nav")], 0, elevation_rad=el, obs=obs,
                                states=start_states(self.suite, truth, self.errors))
            self.navigator = Navigator(nav, s, runs, float(truth.t_s[0]), self.t_s.shape[0], rows=lp.rows3)
            self.navigator.bind(nw[layouts.W_X:layouts.W_X + layouts.NX].reshape(1, layouts.NX),
                                nw[layouts.W_FSUM:layouts.W_FSUM + 3].reshape(1, 3),
                                lp.rows3, lp.snap)
            self._estimate_in_force()
            self._recs = (0, recs)
            if self.path.epoch != "generic":
                self._fast = self._fast_epoch_arrays()
        navigator = self.navigator
        run = navigator.runs[0]
        if code & ik.NAV_EPOCH:
            t = float(truth.t_s[k])
            fe = self._fast
            recs = None
            if fe is not None and fe.direct:  # the inputs straight from the sensors' kernels (no records)
                done = self._fast_epoch(k, t, self._direct_inputs(k, t, truth))
            else:
                recs = self._records(k, truth)
                self._recs = (k, recs)
                done = fe is not None and self._fast_epoch(k, t, self._epoch_inputs(t, recs))
            if not done:
                if recs is None:
                    recs = self._records(k, truth)
                    self._recs = (k, recs)
                obs, _ = self._observations(k, truth, recs)
                if self.gains is not None:  # the kernel's loop held over the interval (no baro, or excluded)
                    obs = obs.with_loop_held([nw[layouts.W_ANY_BARO] == 0.0])
                    nw[layouts.W_ANY_BARO] = 0.0
                navigator.epoch(k, t, obs, truth)
                self._estimate_in_force()
        if code & ik.NAV_BARO:
            # the baro sample of this row: the epoch's (or the start's) record when it made one
            b = self._recs[1].get("baro") if self._recs is not None and self._recs[0] == k else \
                self._apply("baro", k, truth)
            if b is not None:
                # nan (an outage, or the baro excluded by FDE): the INS kernel's damping loop holds
                held = run.baro_excluded() or not bool(np.ravel(b.valid)[0])
                nw[layouts.W_HB] = math.nan if held else float(np.ravel(b.h_baro_m)[0])
                nw[layouts.W_HB_T] = truth.t_s[k]
                if k == 0 and nav.nav.initial_error.start == "prior" and math.isfinite(nw[layouts.W_HB]):
                    nw[layouts.W_X + 2] = nw[layouts.W_HB]  # the converged start's height error stands
        navigator.record_row(k)

    # --- the compiled aiding epoch (core/loop/aiding.py) -------------------------------------------

    def _fast_epoch_arrays(self) -> FastEpoch:
        """The compiled epoch's constants, scratch and history rows (one per possible epoch)."""
        nav = self.navigator
        lay = nav.layout
        nm = self.nav.noise_model
        n_ep = self.t_s.shape[0] // self.epoch_rows + 2
        n = lay.n
        g = nm.sensors.gnss
        return FastEpoch(
            q=em.kernel_noise(nm.noise(None), lay.n_sv)[0], no_gnss=nm.kernel_arrays(None),
            budget=None if g is None else g.budget(), held_possible=lay.has("ac") and self.gains is not None,
            P=np.array(nav.runs[0].fs.P, dtype=float), X=np.zeros((1, n)), f_ned=np.zeros(3),
            XS=np.zeros((n_ep, n)), PP=np.zeros((n_ep, 3, 3)), PC=np.zeros(n_ep), PD=np.zeros((n_ep, n)),
            PN=np.zeros((n_ep, 9, 9)), XD=np.zeros((n_ep, 9)), direct=self.path.epoch == "fused",
            sig=self._sigma_scratch(None if g is None else g.budget(), lay.n_sv))

    def _sigma_scratch(self, b: Any, n_sv: int) -> tuple | None:
        """FastEpoch.sig for the budget b (None: no GPS) and n_sv channels: None unless stand-alone with channels
        (and `compiled_sigmas`)."""
        if self.path.sigmas != "compiled":
            return None
        if b.service is not None:  # the filter's own channel model (service.py filter_channel_sigmas_m)
            g, arg = np.zeros(n_sv), np.zeros(n_sv)
            return (g, arg, g.reshape(1, n_sv), *(np.zeros((1, n_sv)) for _ in range(3)), None,
                    b.service.filter_params())
        do253 = b.multipath_model == "do253"
        gmp = np.zeros(n_sv) if do253 else _per_channel(b.multipath_m, n_sv).copy()
        return (*(np.zeros(n_sv) for _ in range(6)), gmp,
                (geo.A_WGS84, IONO_SHELL_M, float(b.clock_ephemeris_m**2), float(b.iono_zenith_m),
                 float(b.tropo_zenith_m), do253))

    def _noise_arrays(self, el: Array | None) -> tuple[Array, Array, Array]:
        """NoiseModel.kernel_arrays(el) (nav/noise.py) with the elevation-free scalars kept: the GPS channel
        states' sigmas at el by the receiver budget's formulas, the same bits (el is finite or nan): a stand-alone
        budget's with numpy's cos, sin, exp and the rest compiled in numpy's order (closed_loop_epoch
        channel_guard, channel_sigmas; FastEpoch.sig), a GNSS service's by its one kernel (core/sensors/gnss.py
        service_channel_sigmas, as ServiceModel.filter_channel_sigmas_m), else the budget's numpy
        (`_noise_arrays_numpy`, the oracle)."""
        fe = self._fast
        sg = fe.sig
        if el is None or sg is None or el.shape[0] != sg[0].shape[0]:
            return self._noise_arrays_numpy(el)
        g, arg, c, s, ex, gse, gmp, consts = sg
        d = self._direct
        if d is not None and d.guarded:  # direct_inputs guarded el into g, arg (`_direct_inputs`)
            d.guarded = False
        else:
            ce.channel_guard(el, _EL_MIN, g, arg)
        if gmp is None:  # a GNSS service: (g (1, k), slow, fast, total, None, the filter's parameters)
            gk.service_channel_sigmas(c, consts, False, s, ex, gse)
            return fe.q, s[0], ex[0]
        np.cos(g, out=c)
        np.sin(g, out=s)
        if consts[-1]:  # do253
            np.exp(arg, out=ex)
        ce.channel_sigmas(c, s, ex, *consts, gse, gmp)
        return fe.q, gse, gmp

    def _noise_arrays_numpy(self, el: Array | None) -> tuple[Array, Array, Array]:
        """`_noise_arrays` by the receiver budget's numpy formulas (receiver.GnssErrorBudget.channel_sigmas_m)."""
        fe = self._fast
        n_sv = self.nav.layout.n_sv
        if el is None or fe.budget is None or n_sv == 0:
            return fe.no_gnss
        el = np.maximum(np.where(np.isnan(el), 0.5, el), np.radians(2.0))  # nav/noise.py's guard
        return (fe.q, *(_per_channel(a, n_sv) for a in fe.budget.channel_sigmas_m(el)))

    def _epoch_inputs(self, t: float, recs: dict[str, Any]) -> tuple:
        """The compiled epoch's sensor inputs at time t from the sensors' one-row records recs (`_records`):
        Observations.at's values for one run (nan where a record has no sample at t or it is invalid): (baro_h (1,),
        baro_r, radalt_h (1,), rho (1, k), r_sv (k, 3), sig (k,), el (k,) or None, pl_rho, r_pl, pl_sig)."""
        eng = self.navigator.engine
        tol = 0.25 * self.dt
        b = recs.get("baro")
        if b is not None and abs(b.t_s[0] - t) <= tol:
            baro_h = np.array([b.h_baro_m[0] if b.valid[0] else math.nan])
            baro_r = float(b.sigma_m[0]) ** 2
        else:
            baro_h, baro_r = _NAN1, 0.0
        r = recs.get("radalt")
        radalt_h = (np.array([r.h_agl_m[0] if r.valid[0] else math.nan]) if r is not None
                    and abs(r.t_s[0] - t) <= tol else _NAN1)
        g = recs.get("gnss")
        el = None
        if g is not None and abs(g.t_s[0] - t) <= tol:
            rho = np.where(g.valid[0:1], g.pseudorange_m[0:1], np.nan)
            r_sv = np.ascontiguousarray(g.r_sv_ecef[0], dtype=float)
            sig = eng._code_sig if eng.channel_states else np.ascontiguousarray(g.sigma_m[0], dtype=float)
            el = g.elevation_rad[0]
        else:
            rho, r_sv, sig = np.zeros((1, 0)), eng._none3, eng._none1
        return (baro_h, baro_r, radalt_h, rho, r_sv, sig, el, *self._pseudolite_inputs(t, recs.get("pseudolite")))

    def _pseudolite_inputs(self, t: float, p: Any) -> tuple[Array, Array, Array]:
        """The compiled epoch's pseudolite inputs (pl_rho, r_pl, pl_sig) at time t from its record p (or None)."""
        eng = self.navigator.engine
        if p is not None and abs(p.t_s[0] - t) <= 0.25 * self.dt:
            pl_rho = np.where(p.valid[0:1], p.pseudorange_m[0:1], np.nan)
            r_pl = np.ascontiguousarray(p.r_pl_ecef, dtype=float)
            pl_sig = eng._pl_sig if eng.pl_states else np.ascontiguousarray(p.sigma_m[0], dtype=float)
            return pl_rho, r_pl, pl_sig
        return np.zeros((1, 0)), eng._none3, eng._none1

    def _direct_inputs(self, k: int, t: float, truth: Truth) -> tuple:
        """`_epoch_inputs` at truth row k without the records (FastEpoch.direct): the baro's, radar altimeter's and
        GPS receiver's numbers by their kernels on the same values (sensors' h_one / channels_one) in one compiled
        call (closed_loop_epoch.direct_inputs, into buffers made at the first epoch: `_direct_arrays`), the same
        bits; the baro's sample is kept for the damping loop (`_recs`). The GPS channels' guarded elevations are
        made there too (FastEpoch.sig: `_noise_arrays` finishes them)."""
        ps = self.prepared
        eng = self.navigator.engine
        d = self._direct
        if d is None:
            d = self._direct = self._direct_arrays(truth)
        args = d.args
        args[0], args[1] = k, t
        for c, name in ((3, "baro"), (4, "radalt"), (5, "gnss")):
            j = ps.sample(name, k)
            args[c] = -1 if j is None else j
        if d.plan is not None:
            args[6] = d.plan(truth)
        if d.call is None:
            d.call = entry_point(ce.direct_inputs, *args)
        flags = d.call(*args)
        baro_h, baro_r, radalt_h, el = _NAN1, 0.0, _NAN1, None
        rho, r_sv, sig = d.no_rho, eng._none3, eng._none1
        if flags & ce.BARO_IN:
            baro_h, baro_r = d.baro_h, d.baro_r
        if flags & ce.RADALT_IN:
            radalt_h = d.radalt_h
        if flags & ce.GNSS_IN:
            rho, r_sv, el = d.rho, d.r_sv, d.el
            sig = eng._code_sig if eng.channel_states else d.sig
        d.guarded = d.guard and el is not None  # the guarded elevations made: `_noise_arrays` goes on from them
        self._recs = (k, d.recs if flags & ce.HAS_BARO else _NO_RECS)
        pl = ps.one("pseudolite", truth, k) if d.pseudolite else None
        return (baro_h, baro_r, radalt_h, rho, r_sv, sig, el, *self._pseudolite_inputs(t, pl))

    def _direct_arrays(self, truth: Truth) -> _Direct:
        """closed_loop_epoch.direct_inputs' arguments (constants, the sensors' drawn errors, scratch and outputs)
        for this run, the sensors absent given as empty (their sample index stays -1)."""
        ps = self.prepared.sensors
        z1, z2 = np.zeros(0), np.zeros((1, 0))
        b = ps.get("baro")
        if b is not None:
            lag, w, kc, _ = b.one_constants(truth)
            baro = (truth.p_static_pa, w, *kc, b.sf, b.bias, b.noise, b.errors.t_s, np.empty((1, lag.shape[0])),
                    np.empty((1, 1)))
            baro_r = float(b.baro.noise_sigma_m) ** 2
        else:
            baro = (z1, z1, 0.0, 1.0, 1.0, 0.0, 0.0, z1, z2, z2, z1, np.empty((1, 1)), np.empty((1, 1)))
            baro_r = 0.0
        hold, baro_h, radalt_h = np.zeros(1), np.full(1, math.nan), np.full(1, math.nan)
        r = ps.get("radalt")
        out = (np.empty((1, 1)), np.empty((1, 1)), np.empty((1, 1), dtype=bool))
        if r is not None:
            a = r.ra
            radalt = (truth.h_agl_m, truth.euler_rad, r.bias, r.markov, r.noise, r.errors.t_s,
                      float(a.percent_sigma), a.floor_m**2, float(a.max_range_m), float(a.max_pitch_rad),
                      float(a.max_roll_rad), np.empty((3, 1)), *out, radalt_h)
        else:
            radalt = (z1, np.zeros((0, 3)), z1, z2, z2, z1, 0.0, 0.0, 0.0, 0.0, 0.0, np.empty((3, 1)), *out,
                      radalt_h)
        g = ps.get("gnss")
        fe = self._fast
        sg = fe.sig
        plan = None
        if g is not None:
            mode, consts, series = g.direct_constants()
            n_ch = g.r_sv.shape[2]
            guard = sg is not None and sg[0].shape[0] == n_ch
            plan0 = g.plan(truth)
            gnss = (truth.r_ecef, g.r_sv, float(g.rx.mask_rad), mode, *consts, *series, g.bias,
                    g.errors.t_s, float(self.nav.nav.gps_sigma_scale), np.empty((1, 3)),
                    np.empty((g.r_sv.shape[0], 1) + g.r_sv.shape[2:]))
            service = g.direct_service()
            plan = g.plan if g.rx.selection == "best4-fixed" else None
        else:
            n_ch, guard = 0, False
            s3 = np.zeros((1, 0, 0))
            plan0 = np.zeros((1, 0), dtype=bool)
            gnss = (np.zeros((0, 3)), np.zeros((1, 0, 0, 3)), 0.0, 0, 0.0, False,
                    0.0, 0.0, 0.0, 0.0, 0.0, s3, s3, s3, s3, s3, z2, z1, 1.0, np.empty((1, 3)), np.zeros((1, 1, 0, 3)))
            service = PreparedGnss.no_service()
        rho, r_sv, sig, el = np.empty((1, n_ch)), np.empty((n_ch, 3)), np.empty(n_ch), np.empty(n_ch)
        gs = (sg[0], sg[1]) if guard else (z1, z1)
        args = [0, 0.0, 0.25 * self.dt, -1, -1, -1, plan0, (*baro, hold, baro_h), radalt, gnss, service,
                (rho, r_sv, sig, el), (guard, _EL_MIN, *gs)]
        return _Direct(args=args, plan=plan, baro_h=baro_h, baro_r=baro_r, radalt_h=radalt_h,
                       rho=rho, r_sv=r_sv, sig=sig, el=el, no_rho=np.zeros((1, 0)), guard=guard,
                       recs={"baro": _BaroAt(hold)}, pseudolite="pseudolite" in ps)

    def _fast_epoch(self, k: int, t: float, inputs: tuple) -> bool:
        """The aiding epoch at truth row k (time t) in one compiled call (closed_loop_epoch.loop_epoch) on the sensor
        inputs (`_epoch_inputs` / `_direct_inputs`): the per-run EKF's epoch (nav/engine.py own), the Navigator's
        snapshot and history, the estimate in force. False, with nothing changed, when the model needs the numpy
        discretization."""
        fe, nav, lp = self._fast, self.navigator, self._inloop
        nw = lp.nw
        run = nav.runs[0]
        eng = nav.engine
        baro_h, baro_r, radalt_h, rho, r_sv, sig, el, pl_rho, r_pl, pl_sig = inputs
        q, gse, gmp = self._noise_arrays(el)
        gse_r = fe.no_gio
        if eng.gbas_scale is not None and el is not None:  # the channel states at the INS geometry: nav/gbas_scale.py
            g, m, r = eng.gbas_scale.interval(np.reshape(el, (1, -1)), nw[layouts.W_X:layouts.W_X + layouts.NX],
                                              t - nav.t_last)
            n_sv = gse.shape[0]
            gse, gmp, gse_r = (np.ascontiguousarray(np.broadcast_to(a[0], (n_sv,))) for a in (g, m, r))
        held = fe.held_possible and nw[layouts.W_ANY_BARO] == 0.0
        if run.fs.P is not fe.P:  # the Navigator's path ran an epoch (or the start): its P from now on
            fe.P = np.array(run.fs.P, dtype=float)
        fe.X[0] = run.fs.x
        db = nav.dbs[0]
        e = fe.e
        obs = kg.Obs(baro_h, baro_r, radalt_h, 0.0, 0.0, db.dbp2, db.db_x, db.db_u2, rho, r_sv, sig, fe.no_cp, pl_rho,
                     r_pl, pl_sig)
        model = kg.ErrorModel(eng.lay, q, gse, gmp, eng.loop, fe.no_gio, 1.0, gse_r, fe.no_gio)
        args = (nw, fe.X, fe.P, e, model, held,
                t - nav.t_last, fe.f_ned, eng.rows, obs, kg.Out(eng.codes, eng._nu[:1], eng.S), eng.scr,
                (fe.XS, fe.PP, fe.PC, fe.PD, fe.PN, nav._ic, fe.XD))
        if fe.call is None:
            fe.call = entry_point(ce.loop_epoch, *args)
        n_rows = fe.call(*args)
        if n_rows < 0:
            return False
        fe.e = e + 1
        run.statuses.add_epoch(eng.codes[:n_rows], t, eng._nu[0, :n_rows], eng.S[:n_rows])
        run.fs = FilterState(x=fe.XS[e].copy(), P=fe.P, memory=run.fs.memory)
        nav.epoch_done(k, t, fe.XS[e:e + 1], fe.PP[e:e + 1], fe.PC[e:e + 1], fe.PD[e:e + 1], fe.PN[e:e + 1],
                       fe.XD[e:e + 1])
        nw[layouts.W_T_EST] = t
        nw[layouts.W_SNAP] = nav.snap_index
        return True

    def _estimate_in_force(self) -> None:
        """The compiled row's copy of the filter's state: the estimate for the guidance, the bias feedback, the
        snapshot index."""
        nw = self._inloop.nw
        run = self.navigator.runs[0]
        nw[layouts.W_XNAV:layouts.W_XNAV + 9] = run.fs.x[0:9]
        xd, t_est = self.navigator.rate_in_force()
        nw[layouts.W_XDOT:layouts.W_XDOT + 9] = xd[0]
        nw[layouts.W_T_EST] = t_est
        if self.nav.nav.feedback:
            nw[layouts.W_BG:layouts.W_BG + 3] = run.bg_fb
            nw[layouts.W_BA:layouts.W_BA + 3] = run.ba_fb
        nw[layouts.W_SNAP] = self.navigator.snap_index
        nw[layouts.W_BARO_EXCL] = 1.0 if run.baro_excluded() else 0.0

    def result(self, truth: Truth) -> NavRun:
        """The navigation run over the flown truth (call after the flight)."""
        return self.navigator.results(truth, len(truth))[0]
