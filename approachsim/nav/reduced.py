"""The open-loop pass of runs that are each their own class (per-run GPS skies) on each run's reduced state.

Navigator.compiled_pass filters such runs with core/nav/epoch.shared_pass on the full layout: 24 GPS channels' gse /
gmp states, of which a run measures 4-6 with best-four selection. The channels a run never measures are lone
first-order Gauss-Markov states, uncorrelated with the rest at the start (checked: a correlated one is kept), which
no row touches: dropping them removes exact zeros from every sum and keeps the others' order, so the kept states
are the same floating-point numbers (campaign/bankpass.py's module docstring gives the argument; the reduced
models here, `models` and `cut`, and the compiled pass core/nav/copies.bank_epochs serve both). The dropped
states are then carried in closed form exactly as the full pass computes them (x <- 0 + phi x; P <- Qd + phi (0 +
phi P)): x_out, P's diagonal and the final X, P are those of shared_pass bit for bit
(tests/unit/nav/test_reduced_pass.py). The cost of an epoch falls with the square of the state count: 70 -> ~32.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from approachsim.core.nav import copies as kcp
from approachsim.core.nav import epoch as ke
from approachsim.core.nav import groups as kg
from approachsim.core.nav import reduced as kred
from approachsim.memo import TruthMemo, memoized
from approachsim.nav import errormodel as em

Array = np.ndarray


@dataclass(frozen=True)
class ReducedRun:
    """One run's pass on its reduced state (the layout with the GPS channels `kept` only), per epoch: estimates x,
    variances pd (E, n_r), navigation covariance pnav (E, 9, 9), and its rows as core/nav/epoch.class_epoch writes
    them (codes with the reduced channel index, counts, innovations, their variances)."""

    kept: Array
    x: Array
    pd: Array
    pnav: Array
    codes: Array
    n_rows: Array
    nu: Array
    S: Array


CHANNEL_GROUPS = ("gse", "gmp", "gio", "amb")
"""The per-GPS-channel state groups (gio, amb: carrier phase only), each a lone state per channel (module
docstring)."""


def kept_channels(lay: em.StateLayout, used: Array, P0: Array) -> Array:
    """The channels whose states stay: those measured, and any whose states are correlated with another state in the
    start covariance P0 (a dropped state must be uncorrelated with all others: campaign/bankpass.py's docstring)."""
    n_sv = lay.n_sv
    keep = np.zeros(n_sv, dtype=bool)
    keep[np.asarray(used, dtype=int)] = True
    off = P0 != 0.0
    np.fill_diagonal(off, False)
    coupled = np.any(off, axis=1)
    for g in CHANNEL_GROUPS:
        if lay.has(g):
            i0 = lay.i(g)
            keep |= coupled[i0:i0 + n_sv]
    return np.flatnonzero(keep)


def reduced_layout(lay: em.StateLayout, kept: Array) -> tuple[em.StateLayout, Array]:
    """The layout with the channel states of `kept` only, and the full-layout index of each of its states (in
    order)."""
    red = dataclasses.replace(lay, n_sv=int(kept.size))
    idx = []
    for g in red.groups:
        if g in CHANNEL_GROUPS:
            idx.extend(lay.i(g) + kept)
        else:
            sl = lay.index[g]
            idx.extend(range(sl.start, sl.stop))
    return red, np.asarray(idx, dtype=int)


@dataclass(frozen=True, eq=False)
class EpochModels:
    """`models`' compact Phi, Qd of every epoch (E, n1, n1) on `layout` (the layout with one GPS channel), and the
    cuts of them to the reduced layouts asked for so far (`cut`: the runs of a flight group mostly share a few
    channel counts), which this object owns and keeps as long as it lives."""

    phi: Array
    qd: Array
    layout: em.StateLayout
    cuts: dict = field(default_factory=dict, repr=False)


def models(nav: Any, truth: Any, q: Array, gse: Array, gmp: Array, loop: Array, dt: Array, ref: Array,
           ref_cbn: Array, f_ref: Array, held: Array, memo: TruthMemo | None = None) -> EpochModels | None:
    """Phi, Qd of every epoch (kernels/copies.models: what shared_pass makes) in compact form: (E, n1, n1) on the
    layout with one GPS channel (the channels' states are lone, their rows and columns zero off the diagonal:
    checked; Phi's diagonal is the same for every channel, the Qd diagonal each copy's own, set in the kernel), and
    that layout. Discretized on that layout: the same numbers as on the full one (the module docstring's argument:
    lone states are closed form, the coupled component the same matrix). None when an epoch's model is too large
    for the compiled discretization or the channels are not lone.

    memo: the truth's TruthMemo (approachsim/memo.py): the model is made once for the runs and banks of a flight
    group that share the layout, the noise, the damping-loop gains, the epoch intervals dt and the loop's holds
    `held` (the reference ref, ref_cbn, f_ref is the truth's at the epochs dt gives); the last one is kept."""
    lay = nav.layout
    gio = gio_tau = None
    if lay.has("amb"):  # the ionosphere's Gauss-Markov (kernels/carrier.dynamics; the ambiguities are random constants)
        gio, gio_tau = em.kernel_carrier(nav.noise(None), lay.n_sv)
    key = (lay.packed.tobytes(), q.tobytes(), gse.tobytes(), gmp.tobytes(), loop.tobytes(), dt.tobytes(),
           held.tobytes(), None if gio is None else (gio.tobytes(), gio_tau))
    return memoized(memo, truth, "reduced.models", key,
                    lambda: _make_models(lay, q, gse, gmp, loop, dt, ref, ref_cbn, f_ref, held, gio, gio_tau), keep=1)


def _make_models(lay: em.StateLayout, q: Array, gse: Array, gmp: Array, loop: Array, dt: Array, ref: Array,
                 ref_cbn: Array, f_ref: Array, held: Array, gio: Array | None, gio_tau: float | None
                 ) -> EpochModels | None:
    carrier = gio is not None
    if lay.n_sv:  # one channel stands for all: its states' F, Qc depend on the channel only through the sigma, which
        # enters Qc alone (kernels/errormodel.dynamics: a Markov state of the common tau), and each copy's Qd sets it
        lay1, _ = reduced_layout(lay, np.array([0]))
        gse, gmp = np.ascontiguousarray(gse[:1]), np.ascontiguousarray(gmp[:1])
        if carrier:
            gio = np.ascontiguousarray(gio[:1])
    else:
        lay1 = lay
    E, n = dt.shape[0], lay1.n
    phi, qd = np.zeros((E, n, n)), np.zeros((E, n, n))
    if carrier:
        done = kcp.carrier_models(lay1.packed, q, gse, gmp, loop, dt, ref, ref_cbn, f_ref, held, gio, gio_tau, phi, qd)
    else:
        done = kcp.models(lay1.packed, q, gse, gmp, loop, dt, ref, ref_cbn, f_ref, held, phi, qd)
    if done != E:
        return None  # an epoch's model is too large for the compiled discretization
    if lay1.n_sv:  # the channel's states lone: their rows and columns zero off the diagonal
        ch = np.array([lay1.i(g) for g in CHANNEL_GROUPS if lay1.has(g)])
        rest = np.setdiff1d(np.arange(n), ch)
        off = ~np.eye(ch.size, dtype=bool)
        for a in (phi, qd):
            if (np.any(a[:, ch][:, :, rest]) or np.any(a[:, rest][:, :, ch])
                    or np.any(a[:, ch[:, None], ch[None, :]][:, off])):
                return None
    return EpochModels(phi, qd, lay1)


def cut(model: EpochModels, red: em.StateLayout) -> tuple[Array, Array]:
    """Phi, Qd (E, n_r, n_r) of the reduced layout `red` from `models`' compact form: the one channel's lone states
    repeated on the diagonal of each kept channel's, every other entry as the full model's. Kept per layout on the
    model (EpochModels.cuts; the kernel only reads them)."""
    key = red.packed.tobytes()
    if key not in model.cuts:
        model.cuts[key] = _make_cut(model, red)
    return model.cuts[key]


def _make_cut(model: EpochModels, red: em.StateLayout) -> tuple[Array, Array]:
    phi1, qd1, lay1 = model.phi, model.qd, model.layout
    if not red.has("gse"):
        return phi1, qd1
    src, chan = [], []
    for g in red.groups:
        sl = red.index[g]
        if g in CHANNEL_GROUPS:
            src.extend([lay1.i(g)] * (sl.stop - sl.start))
            chan.extend(range(sl.start, sl.stop))
        else:
            src.extend(range(lay1.index[g].start, lay1.index[g].stop))
    src_a, chan_a = np.asarray(src), np.asarray(chan, dtype=int)
    out = []
    for a in (phi1, qd1):
        r = a[:, src_a[:, None], src_a[None, :]]
        d = r[:, chan_a, chan_a].copy()
        r[:, chan_a, :] = 0.0
        r[:, :, chan_a] = 0.0
        r[:, chan_a, chan_a] = d
        out.append(np.ascontiguousarray(r))
    return out[0], out[1]




def reduced_singletons(system: Any, truth: Any, eng: Any, args: tuple, out: tuple, ic: int,
                       runs_out: list | None = None, valid: Array | None = None, memo: TruthMemo | None = None) -> int:
    """shared_pass for per-run-sky runs, each on its reduced state. args: shared_pass's inputs (X, P3, lay, q, gse,
    gmp, loop, dt, ref, ref_cbn, f_ref, ref_agl, ref_sb, held, ch_gse, ch_gmp, f_gse, f_gmp, gse_r, ins_y, baro_h,
    baro_r,
    radalt_h, dbp, db_x, db_u, rho, r_sv, sig, pl_rho, r_pl, pl_sig) without carrier phase; out: its outputs
    (codes, nu, S, n_rows, x_out, p33, pcc, pd, pnav), filled here; ic the clock state's index; runs_out: each
    run's ReducedRun appended (what the integrity bank's copy 0 computes again: campaign/bankpass.py); valid (N, k):
    the channels each run's record has valid (kept as the bank keeps them, so that its copy 0 is this); memo: the
    truth's TruthMemo, where the runs' banks find the models (`models`). Returns E, or -1 with nothing changed when a
    model cannot be reduced (the caller runs shared_pass)."""
    (X, P3, lay, q, gse, gmp, loop, dt, ref, ref_cbn, f_ref, ref_agl, ref_sb, held, ch_gse, ch_gmp, f_gse, f_gmp, gse_r,
     ins_y, baro_h, baro_r, radalt_h, dbp, db_x, db_u, rho, r_sv, sig, pl_rho, r_pl, pl_sig) = args
    codes, nu, S, n_rows, x_out, p33, pcc, pd, pnav = out
    N, E = held.shape
    run_models = []
    for i in range(N):  # every run's model first: nothing is changed when one cannot be reduced
        model = models(system, truth, q, gse, gmp, loop, dt, ref, ref_cbn, f_ref, np.ascontiguousarray(held[i]), memo)
        if model is None:
            return -1
        run_models.append(model)
    measured = np.any(np.isfinite(rho), axis=1)  # (N, k); any kept superset is exact (the module docstring)
    if valid is not None and valid.shape == measured.shape:
        measured = measured | valid
    ig, im = lay.i("gse"), lay.i("gmp")
    ws: dict[int, tuple] = {}
    for i in range(N):
        phi1, lay1 = run_models[i].phi, run_models[i].layout
        kept = kept_channels(lay, np.flatnonzero(measured[i]), P3[i])
        red, idx = reduced_layout(lay, kept)
        phi, qd = cut(run_models[i], red)
        n_r, kr = red.n, kept.size
        Xr = np.ascontiguousarray(X[i:i + 1, idx])
        Pr = np.ascontiguousarray(P3[i][np.ix_(idx, idx)][None])
        R_r = 2 + kr + pl_rho.shape[2]
        c_r, n_r_rows = np.zeros((1, E, R_r), dtype=np.int64), np.zeros((1, E), dtype=np.int64)
        nu_r, S_r = np.zeros((1, E, R_r)), np.zeros((1, E, R_r))
        x_r, pd_r, pnav_r = np.zeros((1, E, n_r)), np.zeros((1, E, n_r)), np.zeros((1, E, 9, 9))
        if n_r not in ws:
            ws[n_r] = kg.scratch(n_r)
        sel = (slice(i, i + 1), slice(None), kept)
        none = np.zeros((1, E, 0))
        kcp.bank_epochs(Xr, Pr, phi, qd, ref,
                        kg.ChannelQd(np.ascontiguousarray(ch_gse[sel]), np.ascontiguousarray(ch_gmp[sel]), none, f_gse,
                                     f_gmp, np.zeros(E), np.ascontiguousarray(gse_r[sel] if gse_r.shape[2] else
                                                                              gse_r[i:i + 1]), none), ins_y[i:i + 1],
                        kg.Obs(baro_h[i:i + 1], baro_r, radalt_h[i:i + 1], ref_agl, ref_sb, dbp[i:i + 1], db_x,
                               db_u[i:i + 1],
                               np.ascontiguousarray(rho[sel]), np.ascontiguousarray(r_sv[sel]),
                               np.ascontiguousarray(sig[sel]), none, pl_rho[i:i + 1], r_pl, pl_sig),
                        np.zeros((1, E, 0), np.int64), eng.rows._replace(lay=red.packed),
                        kg.PassOut(c_r, nu_r, S_r, n_r_rows, x_r, pd_r, pnav_r, np.zeros((1, E, 0, 0)),
                                   np.zeros((1, 0)), 0), ws[n_r])
        if runs_out is not None:
            runs_out.append(ReducedRun(kept, x_r[0], pd_r[0], pnav_r[0], c_r[0], n_r_rows[0], nu_r[0], S_r[0]))
        # the rows: the reduced channel c is the full layout's kept[c]
        gps = (c_r[0] >= ke.CODE_GPS) & (c_r[0] < ke.CODE_PL)
        codes[i, :, :R_r] = np.where(gps, ke.CODE_GPS + kept[np.clip(c_r[0] - ke.CODE_GPS, 0, max(kr - 1, 0))],
                                     c_r[0]) if kr else c_r[0]
        nu[i, :, :R_r], S[i, :, :R_r], n_rows[i] = nu_r[0], S_r[0], n_r_rows[0]
        # the kept states
        x_out[i][:, idx] = x_r[0]
        pd[i][:, idx] = pd_r[0]
        pnav[i] = pnav_r[0]
        p33[i] = pnav_r[0][:, 0:3, 0:3]
        pcc[i] = pd_r[0][:, int(np.flatnonzero(idx == ic)[0])]
        # the dropped channels' states, lone: as the full pass's predict makes them, every epoch
        drop = np.setdiff1d(np.arange(lay.n_sv), kept)
        xg, xm = X[i, ig + drop].copy(), X[i, im + drop].copy()
        pg, pm = P3[i, ig + drop, ig + drop].copy(), P3[i, im + drop, im + drop].copy()
        kred.lone_states(np.ascontiguousarray(phi1[:, lay1.i("gse"), lay1.i("gse")]),
                    np.ascontiguousarray(phi1[:, lay1.i("gmp"), lay1.i("gmp")]),
                    kg.ChannelQd(ch_gse[i], ch_gmp[i], np.zeros((E, 0)), f_gse, f_gmp, np.zeros(E), gse_r[i],
                                 np.zeros((E, 0))),
                    drop, ig, im, xg, xm, pg, pm, x_out[i], pd[i])
        # the final state and covariance (the dropped states' rows and columns stay zero off the diagonal)
        X[i, idx] = Xr[0]
        X[i, ig + drop], X[i, im + drop] = xg, xm
        P3[i][np.ix_(idx, idx)] = Pr[0]
        P3[i, ig + drop, ig + drop], P3[i, im + drop, im + drop] = pg, pm
    return E
