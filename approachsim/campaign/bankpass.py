"""The integrity bank's navigation pass (issue 26, speed): the main filter and the K sub-filters of one open-loop run
over the run's records in one compiled call, on the states the bank can move.

What campaign.integrity_bank.run_bank did before through NavSystem.run(copies=True) (and still does where this pass does
not apply, `applicable`), with the same arithmetic:

- one draw of the run's sensors (every copy's records are the same draws: the same streams), one converged start
  (the copies share the main filter's: nav/system.py NavSystem.start), one INS over every row (feed-forward: the
  INS does not depend on the filter), the copies' observations stacked once and copy k + 1 without its mode's
  samples (campaign.integrity_bank.bank_records: an invalid sample is no measurement);
- the model of every epoch (Phi, Qd at the reference: the truth) made once per flight group's truth on the full
  layout (core/nav/copies.models, kept in the group truth's memo, approachsim/memo.py), cut to the run's
  reduced state; then every epoch of every copy, each its own class (per-run GPS sky), in one call of
  core/nav/copies.bank_epochs (core/nav/epoch.shared_pass's loop with the model given), on the *reduced*
  state: the GPS channel states (gse, gmp) of the channels the run never measures are dropped.

Why the reduced state changes no bit. A dropped channel's two states are first-order Gauss-Markov (diagonal
Phi, Qd: kernels/errormodel.py makes them lone states, closed form) that no measurement row touches, and at the
start they are uncorrelated with every other state (nav/initial.py: a channel not updated in the converged
segment keeps its prior row exactly; checked here, else the channel is kept). So their rows and columns of P stay
exactly zero off the diagonal: in the prediction W = Phi P, Phi W' + Qd their terms are exact zeros, and the
scalar updates (core/nav/kalman.gain and _joseph_cov) skip the rows where P h is zero and add exact zeros in the
other rows' dropped columns. Every remaining term is summed in the same order (the kept states keep their order),
so the kept states' estimates and covariances are the same floating-point numbers (tests/unit/campaign/
test_bankpass.py compares them with the full-state pass bit for bit). The bank needs only the navigation states'
estimates and covariance block: the dropped states never reach it. The cost of an epoch falls with the square
of the state count: 70 states (24 channels) to 22 + 2 x (channels used), about 32 with best-four selection.

Carrier phase (the layout's gio and amb groups, core/nav/carrier.py). A channel's four states (gse, gmp, gio,
amb) go together (`rd.CHANNEL_GROUPS`): gio is a Gauss-Markov state and amb a random constant, both lone (diagonal
Phi, Qd: kernels/errormodel.discretize's closed form), and a channel never measured has no carrier phase and no
arc, so its ambiguity is never reset; the argument above holds for them unchanged. The model adds kernels/carrier.
dynamics (core/nav/copies.carrier_models); each copy's epoch is shared_pass's carrier step (core/nav/copies.
bank_epochs): the gio states' Qd at the copy's sky, then its ambiguities reset where its carrier arc begins
(engine.stacked_new_arcs over the copy's arc ids: a copy without channel c has no phase and no arc there,
bank.bank_records, so it never resets amb_c), the reset zeroing a kept row and column of Phi (a copy) and Qd as on
the full layout, then class_epoch with the carrier rows after the code rows. The copies start with no arc (the
converged start is code only: nav/initial.py). The candidate's 121 states (24 channels) to 25 + 4 x (channels used)
(tests/unit/campaign/test_bankpass_carrier.py: bit for bit against the copies' full-state pass, with an outage
that opens a new arc).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from typing import Any

import numpy as np

from approachsim import geo
from approachsim.campaign import preapproach
from approachsim.campaign.bank_modes import BARO_MODE, PSEUDOLITE_MODE, RADALT_MODE
from approachsim.core.nav import copies as kcp
from approachsim.core.nav import groups as kg
from approachsim.memo import TruthMemo, memoized
from approachsim.nav import errormodel as em
from approachsim.nav import ins
from approachsim.nav import reduced as rd
from approachsim.nav.engine import EpochEngine, RunDatabase, StatusBuffer, stacked_new_arcs
from approachsim.nav.initial import sb_reference
from approachsim.nav.navigator import NavRun, StatusLog, _stacked_observations, true_error_rows
from approachsim.nav.observations import Observations
from approachsim.nav.system import tuned_records

Array = np.ndarray



@dataclass(frozen=True)
class BankPass:
    """The copies' filter history at the epochs (copy 0 the main filter, copy k + 1 without mode k)."""

    t_s: Array
    """(E,) epoch times, s."""
    true_error_nav: Array
    """(C, E, 9) output error of each copy at each epoch (dp NED m, dv m/s, psi rad)."""
    P_nav: Array
    """(C, E, 9, 9) its navigation-error covariance after the epoch's updates."""
    x: Array
    """(C, E, n_r) the reduced state's estimates after the updates."""
    P_diag: Array
    """(C, E, n_r) their variances."""
    layout: em.StateLayout
    """The reduced layout (the GPS channel states of `channels_kept` only)."""
    channels_kept: Array
    """(k_r,) the GPS channels whose error states the pass carries."""
    main_rows: tuple[Array, Array, Array, Array]
    """The main filter's measurement rows: codes, their counts per epoch, innovations, their variances (E, R)
    (core/nav/epoch.shared_pass)."""

    def main_run(self) -> NavRun:
        """The main filter's NavRun without its solution (None: the bank needs the epoch history only), on the
        reduced layout."""
        buf = StatusBuffer()
        codes, counts, nu, S = self.main_rows
        buf.add_epochs(codes, counts, self.t_s, nu, S)
        return NavRun(solution=None, status=StatusLog.from_buffer(buf), t_epoch_s=self.t_s, x=self.x[0],
                      P_diag=self.P_diag[0], P_nav=self.P_nav[0], true_error_nav=self.true_error_nav[0],
                      layout=self.layout)


def applicable(nav: Any, records: dict[str, Any]) -> bool:
    """Whether `bank_pass` runs the bank of this navigation system on these records (one run, run axis first): the
    compiled epoch (the optimal filter, tight coupling, constant or no damping loop, no FDE: nav/engine.py), with or
    without carrier phase, feed-forward, an IMU record, and each run its own GPS sky (the default "per-run" epoch;
    a fixed sky takes NavSystem.run's per-epoch path)."""
    g = records.get("gnss")
    if g is None or not bool(g.per_run_sky) or "imu" not in records or nav.nav.feedback:
        return False
    return EpochEngine.of(nav) is not None


def bank_pass(nav: Any, truth: Any, records: dict[str, Any], modes: Array, rng: np.random.Generator,
              states: Any, memo: TruthMemo | None = None, pre: Any = None) -> BankPass | None:
    """The main filter and one sub-filter per mode of `modes` (campaign/bank_modes.py codes) over one run's records
    (`applicable`; run axis of length one), started from the run's realized sensor states `states`
    (sensors.states.start_states) with its "nav" stream `rng` (module docstring). None when an epoch's model is
    too large for the compiled discretization (the caller takes NavSystem.run, which falls back to numpy's). memo:
    the truth's TruthMemo (its converged start, reference and epoch models kept for the other runs on it). pre: a
    fault present at the start (campaign.preapproach.PreFault): each copy's start carries what the pre-approach
    segment's aiding made of it (campaign/preapproach.py)."""
    records = tuned_records(records, nav.nav.gps_sigma_scale)
    imu = records["imu"]
    dth, dvb = np.asarray(imu.dtheta_body)[:1], np.asarray(imu.dv_body)[:1]
    m = dth.shape[1]
    dt = float(imu.dt_s)
    epoch_rows = max(1, int(round(1.0 / dt / nav.nav.aiding_rate_hz)))
    tol = 0.25 * dt
    gnss = records["gnss"]
    # the start, as NavSystem.run's: the copies share the main filter's (one draw, repeated)
    obs0 = Observations.at(records, float(truth.t_s[0]), tol, True)
    el0 = np.asarray(gnss.elevation_rad)[:, 0]
    s, runs = nav.start(truth, [rng], elevation_rad=el0[0], obs=obs0, states=states, elevation_per_run=el0,
                        memo=memo)
    x_off = None
    if pre is not None:
        x_f, delta = preapproach.estimate_offsets(nav, truth, obs0, np.asarray(runs[0].fs.P, dtype=float), modes,
                                                  pre)
        s, x_off = preapproach.apply(nav.layout, s, x_f, delta)
    # the INS once (Navigator.propagate: feed-forward, no bias feedback), with the damping loop's baro
    held = _baro_held(nav, records, truth, m)
    hb_full, age = (None, None) if held is None else held
    x = ins.pack(s)
    rows = np.full((1, m + 1, ins.NX), np.nan)
    rows[:, 0] = x
    z3 = np.zeros((1, 3))
    ins.propagate(x, dth, dvb, dt, bias_g=z3, bias_a=z3, h_baro_m=hb_full, baro_age_s=age, loop=nav.loop_gains(),
                  f_sum=np.zeros((1, 3)), out=rows, row0=0)
    o = _stacked_observations(records, np.asarray(truth.t_s, dtype=float)[epoch_rows::epoch_rows], tol, True, 1)
    used = np.flatnonzero(np.any(np.asarray(gnss.valid, dtype=bool)[0], axis=0))
    return _core(nav, truth, modes, m, epoch_rows, (runs[0].fs.x, np.asarray(runs[0].fs.P, dtype=float),
                 runs[0].db_error), rows[0, epoch_rows::epoch_rows], None if hb_full is None else hb_full[0], o, used,
                 runs[0].arcs, memo=memo, x_off=x_off, sb_ref=sb_reference(states))


def _baro_held(nav: Any, records: dict[str, Any], truth: Any, m: int) -> tuple[Array, Array] | None:
    """(N, m) the baro height held at each IMU interval start for the damping loop (nan: none) and (m,) its age
    (s), as NavSystem.run (ins.held_baro); None without a loop or a baro."""
    baro = records.get("baro")
    if nav.loop_gains() is None or baro is None:
        return None
    return ins.held_baro(baro.valid, baro.h_baro_m, baro.t_s, truth.t_s[:m])


class GroupInputs:
    """What an open-loop flight group's navigation pass leaves for its runs' banks (campaign/pipeline.py): the
    group's records (run axis first) and NavSystem.run's `keep` (each run's filter start, terrain-database error
    and INS states at the epochs); the runs' stacked observations are made once, on the first bank's call."""

    def __init__(self, records: dict[str, Any], keep: dict[str, Any]) -> None:
        self.records = records
        self.keep = keep
        self._obs: dict[str, Any] | None = None

    def usable(self, nav: Any) -> bool:
        """Whether the pass kept everything, feed-forward, on this system's layout."""
        k = self.keep
        return (bool(k.get("feed_forward")) and "ins_epoch_rows" in k and "start" in k
                and k["start"][0][0].shape == (nav.layout.n,))

    def observations(self, nav: Any, truth: Any) -> dict[str, Any]:
        """_stacked_observations of every run of the group at the epochs (once)."""
        if self._obs is None:
            recs = tuned_records(self.records, nav.nav.gps_sigma_scale)
            dt = float(recs["imu"].dt_s)
            er = self.keep["epoch_rows"]
            n = int(np.shape(recs["imu"].dtheta_body)[0])
            self._obs = _stacked_observations(recs, np.asarray(truth.t_s, dtype=float)[er::er], 0.25 * dt, True, n)
        return self._obs


def bank_pass_group(nav: Any, truth: Any, group: GroupInputs, k: int, modes: Array,
                    memo: TruthMemo | None = None) -> BankPass | None:
    """`bank_pass` for run k of an open-loop flight group from what the group's pass left (GroupInputs): its start,
    its INS at the epochs and its records; nothing drawn or integrated again (the same numbers: the pass's start and
    INS are the run's own, whatever the batch). memo: the group truth's TruthMemo (the pass's epoch models; the
    reference made once for the group's banks)."""
    recs = group.records
    imu = recs["imu"]
    m = int(np.shape(imu.dtheta_body)[1])
    er = group.keep["epoch_rows"]
    o_all = group.observations(nav, truth)
    o = {key: (v[k:k + 1] if isinstance(v, np.ndarray) and key not in ("baro_r", "r_pl", "pl_sig", "el0")
               else v) for key, v in o_all.items()}
    baro = recs.get("baro")
    one_baro = {} if baro is None else {"baro": dataclasses.replace(baro, valid=np.asarray(baro.valid)[k:k + 1],
                                                                    h_baro_m=np.asarray(baro.h_baro_m)[k:k + 1])}
    held = _baro_held(nav, one_baro, truth, m)
    hb = None if held is None else held[0]
    used = np.flatnonzero(np.any(np.asarray(recs["gnss"].valid, dtype=bool)[k], axis=0))
    x_hat, P = group.keep["start"][k]
    main = group.keep["reduced_runs"][k] if "reduced_runs" in group.keep else None
    return _core(nav, truth, modes, m, er, (x_hat, P, group.keep["db"][k]), group.keep["ins_epoch_rows"][k],
                 None if hb is None else hb[0], o, used, main=main, memo=memo, sb_ref=group.keep.get("sb_ref", 0.0))


def _core(nav: Any, truth: Any, modes: Array, m: int, epoch_rows: int, start: tuple[Array, Array, Any],
          ins_ep: Array, hb1: Array | None, o: dict[str, Any], used: Array,
          arcs0: Array | None = None, main: Any = None, memo: TruthMemo | None = None,
          x_off: Array | None = None, sb_ref: float = 0.0) -> BankPass | None:
    """The pass from the run's start = (x_hat, P_conv, its terrain-database error), its INS states at the epochs
    ins_ep (E, 16), its baro held for the damping loop hb1 (m,) or None, its stacked observations o (one run) and
    the GNSS channels it measures; carrier phase: arcs0 (k,) the start's carrier arc ids (None: none yet), from
    which each copy's new arcs (its ambiguity resets) follow as in Navigator.compiled_pass. main: the group pass's
    own filter of the run on its reduced state (nav/reduced.ReducedRun), which is copy 0 (the same start, INS,
    observations and models in the same compiled pass): taken as copy 0 when its channels are the copies' (only the
    sub-filters are run), else None. memo: the truth's TruthMemo (the reference, the epoch models). sb_ref: the
    reference's baro scale factor (nav/initial.sb_reference, as the group's pass took it)."""
    x_hat, P_conv, db_error = start
    lay = nav.layout
    eng = EpochEngine(nav)
    # the epochs and the reference (the truth at the epoch rows: nav/shared.py)
    e_rows = np.arange(epoch_rows, m + 1, epoch_rows)
    E = e_rows.shape[0]
    C = len(modes) + 1
    t_e = np.asarray(truth.t_s, dtype=float)[e_rows]
    dt_e = np.diff(np.concatenate([[float(truth.t_s[0])], t_e]))
    held1 = np.zeros(E, dtype=np.int64)
    if lay.has("ac") and hb1 is not None:
        held1[:] = np.all(np.isnan(hb1[:E * epoch_rows]).reshape(E, epoch_rows), axis=1)  # the epochs' intervals
    ref, ref_cbn, f_ref, ref_agl = memoized(memo, truth, "bankpass.reference", (m, epoch_rows, nav.terrain_h),
                                            lambda: _reference(nav, truth, m, epoch_rows, e_rows), keep=2)
    # the copies' observations: copy 0 all, copy k + 1 without mode k (bank.bank_records)
    baro_h = np.repeat(o["baro_h"], C, axis=0)
    radalt_h = np.repeat(o["radalt_h"], C, axis=0)
    rho_all = o["rho"]
    pl_rho = np.repeat(o["pl_rho"], C, axis=0)
    kept = rd.kept_channels(lay, used, P_conv) if lay.has("gse") else used
    if lay.has("gse"):
        red, idx = rd.reduced_layout(lay, kept)
    else:
        red, idx = lay, np.arange(lay.n)
    col = {int(c): j for j, c in enumerate(kept)}
    rho = np.repeat(rho_all[:, :, kept], C, axis=0)
    for k, c in enumerate(np.asarray(modes, dtype=int)):
        if c >= 0:
            rho[k + 1, :, col[c]] = np.nan
        elif c == BARO_MODE:
            baro_h[k + 1] = np.nan
        elif c == RADALT_MODE:
            radalt_h[k + 1] = np.nan
        else:
            pl_rho[k + 1, :, PSEUDOLITE_MODE - c] = np.nan
    if not np.all(np.isnan(np.delete(rho_all, kept, axis=2))):
        raise RuntimeError("bank_pass: a measured channel was dropped")
    kr = kept.size
    carrier = eng.carrier and o.get("cp") is not None
    if carrier:  # the copies' carrier phases and arc ids (an excluded channel: no phase, no arc: bank_records)
        cp_all, arc_all = o["cp"], o["arc"]
        if not (np.all(np.isnan(np.delete(cp_all, kept, axis=2))) and np.all(np.delete(arc_all, kept, axis=2) < 0)):
            raise RuntimeError("bank_pass: a channel with carrier phase was dropped")
        cp = np.repeat(cp_all[:, :, kept], C, axis=0)
        arc = np.repeat(arc_all[:, :, kept], C, axis=0)
        for k, c in enumerate(np.asarray(modes, dtype=int)):
            if c >= 0:
                cp[k + 1, :, col[c]] = np.nan
                arc[k + 1, :, col[c]] = -1
        last = np.full(lay.n_sv, -1, dtype=np.int64) if arcs0 is None else np.asarray(arcs0, dtype=np.int64)
        if np.any(np.delete(last, kept) >= 0):
            raise RuntimeError("bank_pass: a dropped channel has a carrier arc at the start")
        new, _ = stacked_new_arcs(np.repeat(last[kept][None], C, axis=0), arc)
    r_sv = np.ascontiguousarray(np.broadcast_to(o["r_sv"][:, :, kept], (C, E, kr, 3)))
    el = o["el"][0][:, kept]
    sig = np.ascontiguousarray(np.broadcast_to(eng._code_sig[kept] if eng.channel_states else o["sig"][0][:, kept],
                                               (C, E, kr)), dtype=float)
    r_pl = o["r_pl"] if o["r_pl"] is not None else eng._none3
    # a writable copy (a read-only view is another type to compiled code: class_epoch compiled twice)
    pl_sig = np.array(np.broadcast_to(eng._pl_sig if eng.pl_states else o["pl_sig"],
                                      (E, pl_rho.shape[2])), dtype=float)
    noise = nav.noise(None)
    q, gse_full, gmp_full = em.kernel_noise(noise, lay.n_sv)
    loop = em.kernel_loop(nav.loop_gains() if lay.has("ac") else None)
    ch_gio = np.zeros((C, E, 0))
    gse_r = gio_r = np.zeros((C, E, 0))
    if red.has("gse") and kr and carrier:  # the slow state without the ionosphere (gio): Navigator.compiled_pass
        # (numpy elementwise, on every channel as the navigation's pass, then the kept ones; GBAS: at the truth's
        # geometry, gse and gio scaled apart)
        if eng.gbas_scale is not None:
            sky = eng.gbas_scale.carrier_interval(o["el"][0], ref, dt_e)
            ch_gse, ch_gio, ch_gmp, gse_r, gio_r = (np.ascontiguousarray(np.broadcast_to(a[:, kept], (C, E, kr)))
                                                    for a in sky)
        else:
            sky = eng.carrier_channel_sigmas(o["el"][0])
            ch_gse, ch_gio, ch_gmp = (np.ascontiguousarray(np.broadcast_to(a[:, kept], (C, E, kr))) for a in sky)
    elif red.has("gse") and kr and eng.gbas_scale is not None:  # Navigator.compiled_pass: the truth's geometry
        g1, m1, r1 = eng.gbas_scale.interval(el, ref, dt_e)
        ch_gse, ch_gmp, gse_r = (np.ascontiguousarray(np.broadcast_to(a, (C, E, kr))) for a in (g1, m1, r1))
    elif red.has("gse") and kr:
        g1, m1 = eng.channel_sigmas(el)
        ch_gse = np.ascontiguousarray(np.broadcast_to(g1, (C, E, kr)))
        ch_gmp = np.ascontiguousarray(np.broadcast_to(m1, (C, E, kr)))
    else:
        ch_gse = ch_gmp = np.zeros((C, E, 0))
    nz = nav.noise_model.noise(None)
    f_gse = -np.expm1(-2.0 * dt_e / nz.gse_tau_s) if lay.has("gse") else np.zeros(E)
    f_gmp = -np.expm1(-2.0 * dt_e / nz.gmp_tau_s) if lay.has("gse") else np.zeros(E)
    db = RunDatabase.of(nav.nav.terrain_database, db_error)
    dbp, db_x, db_u = EpochEngine.stack([db] * C)
    n = red.n
    X = np.repeat(x_hat[idx][None], C, axis=0)
    if x_off is not None:  # a fault present at the start: each copy's own pre-approach response (preapproach.py)
        X = X + x_off[:, idx]
    P3 = np.repeat(P_conv[np.ix_(idx, idx)][None], C, axis=0)
    R = 2 + (2 if carrier else 1) * kr + pl_rho.shape[2]
    codes, nu, S = np.zeros((C, E, R), dtype=np.int64), np.zeros((C, E, R)), np.zeros((C, E, R))
    n_rows = np.zeros((C, E), dtype=np.int64)
    x_out, pd, pnav = np.zeros((C, E, n)), np.zeros((C, E, n)), np.zeros((C, E, 9, 9))
    ins_y = np.ascontiguousarray(np.broadcast_to(ins_ep, (C, E, ins.NX)))
    model = rd.models(nav, truth, q, gse_full, gmp_full, loop, dt_e, ref, ref_cbn, f_ref, held1, memo)
    if model is None:
        return None
    phi, qd = rd.cut(model, red)
    rows, scr = eng.rows._replace(lay=red.packed), kg.scratch(n)
    if carrier:  # core/nav/epoch.shared_pass's carrier step (core/nav/copies.bank_epochs with the carrier states)
        f_gio = -np.expm1(-2.0 * dt_e / nz.gio_tau_s)
        kcp.bank_epochs(X, P3, phi, qd, ref, kg.ChannelQd(ch_gse, ch_gmp, ch_gio, f_gse, f_gmp, f_gio, gse_r, gio_r),
                        ins_y,
                        kg.Obs(baro_h, o["baro_r"], radalt_h, ref_agl, sb_ref, dbp, db_x, db_u, rho, r_sv, sig, cp,
                               pl_rho,
                               r_pl, pl_sig), new, rows,
                        kg.PassOut(codes, nu, S, n_rows, x_out, pd, pnav, np.zeros((C, E, 0, 0)), np.zeros((C, 0)), 0),
                        scr)
    elif main is not None and C > 1 and np.array_equal(main.kept, kept) and main.x.shape == (E, n):
        # copy 0 is the group pass's own filter of the run: the sub-filters only
        c = np.ascontiguousarray
        s1 = (codes[1:].copy(), nu[1:].copy(), S[1:].copy(), n_rows[1:].copy(), x_out[1:].copy(), pd[1:].copy(),
              pnav[1:].copy())
        none = np.zeros((C - 1, E, 0))
        kcp.bank_epochs(X[1:].copy(), P3[1:].copy(), phi, qd, ref,
                        kg.ChannelQd(c(ch_gse[1:]), c(ch_gmp[1:]), none, f_gse, f_gmp, np.zeros(E), c(gse_r[1:]),
                                     none),
                        c(ins_y[1:]),
                        kg.Obs(c(baro_h[1:]), o["baro_r"], c(radalt_h[1:]), ref_agl, sb_ref, c(dbp[1:]), db_x,
                               c(db_u[1:]),
                               c(rho[1:]), c(r_sv[1:]), c(sig[1:]), none, c(pl_rho[1:]), r_pl, pl_sig),
                        np.zeros((C - 1, E, 0), np.int64), rows,
                        kg.PassOut(*s1, np.zeros((C - 1, E, 0, 0)), np.zeros((C - 1, 0)), 0), scr)
        for a, b, first in zip((codes, nu, S, n_rows, x_out, pd, pnav), s1,
                               (main.codes, main.nu, main.S, main.n_rows, main.x, main.pd, main.pnav), strict=True):
            a[0] = first
            a[1:] = b
    else:
        none = np.zeros((C, E, 0))
        kcp.bank_epochs(X, P3, phi, qd, ref, kg.ChannelQd(ch_gse, ch_gmp, none, f_gse, f_gmp, np.zeros(E), gse_r, none),
                        ins_y,
                        kg.Obs(baro_h, o["baro_r"], radalt_h, ref_agl, sb_ref, dbp, db_x, db_u, rho, r_sv, sig, none,
                               pl_rho,
                               r_pl, pl_sig), np.zeros((C, E, 0), np.int64), rows,
                        kg.PassOut(codes, nu, S, n_rows, x_out, pd, pnav, np.zeros((C, E, 0, 0)), np.zeros((C, 0)), 0),
                        scr)
    # the outputs' errors at the epochs: the INS rows - x_hat against the truth rows (Navigator.results)
    xe = x_out[:, :, 0:9].reshape(C * E, 9)
    o_s = ins.perturb(ins.unpack(np.tile(ins_ep, (C, 1))), -xe[:, 0:3], -xe[:, 3:6], -xe[:, 6:9])
    err = true_error_rows(o_s, truth, np.tile(e_rows, C)).reshape(C, E, 9)
    return BankPass(t_e, err, pnav, x_out, pd, red, kept, (codes[0], n_rows[0], nu[0], S[0]))


def _reference(nav: Any, truth: Any, m: int, epoch_rows: int, e_rows: Array) -> tuple[Array, Array, Array, Array]:
    """The reference at the epochs (nav/shared.py, Navigator.compiled_pass): packed truth rows (E, 16), their
    body-to-NED matrices (E, 3, 3), the interval's mean specific force NED (E, 3) m/s^2, the height above the
    terrain database nav.terrain_h (E,) m: a function of the truth, m and epoch_rows (e_rows = epoch_rows, 2
    epoch_rows, ... <= m) and the terrain, kept in the truth's memo by `_core` (the kernel only reads it)."""
    E = e_rows.shape[0]
    c_bn = ins.cbn_from_quaternion(truth.q_nb[:m + 1])
    f_ned = np.einsum("nij,nj->ni", c_bn[:m], truth.f_body[:m])
    ref_cbn = np.ascontiguousarray(c_bn[::epoch_rows].copy()[e_rows // epoch_rows])
    ref = np.zeros((E, ins.NX))
    ref[:, 0], ref[:, 1], ref[:, 2] = truth.lat_rad[e_rows], truth.lon_rad[e_rows], truth.h_m[e_rows]
    ref[:, 3:6] = truth.v_ned[e_rows]
    ref[:, 6:15] = ref_cbn.reshape(E, 9)
    f_ref = np.stack([f_ned[r - epoch_rows:r].mean(axis=0) for r in e_rows]) if E else np.zeros((0, 3))
    r_ref = geo.geodetic_to_ecef(ref[:, 0], ref[:, 1], ref[:, 2])
    ref_agl = ref[:, 2] - nav.terrain_h(r_ref) if E else np.zeros(0)
    return ref, ref_cbn, f_ref, ref_agl
