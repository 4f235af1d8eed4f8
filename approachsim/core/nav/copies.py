"""Copies of a filter on a given model (numba, cache=True): core/nav/epoch.shared_pass with the model given; the
integrity bank's main and sub-filters, and one run's filter on its reduced state (nav/reduced.py).

    bank_epochs(X, P3, phi, qd, ref, chan, ins, obs, new, rows, out, scr)     (core/nav/groups.py's groups)

shared_pass makes each epoch's model (F, Qc at the reference, Phi, Qd by Van Loan) itself, once per call; the bank
calls it once per run, so every run of an open-loop flight group made the same models again (they depend on the
shared truth only). Here Phi and Qd (E, n, n) come in, made once per truth on the full layout and cut to the run's
reduced state (nav/reduced.py `models`, `cut`); the rest is shared_pass's: per epoch, core/nav/epoch.pass_epoch
(each copy's channel states' Qd at its sky, its ambiguities reset at its new carrier arcs, class_epoch in shared
mode: the same function, so the same arithmetic). tests/unit/integrity/test_bankpass.py: equal to shared_pass bit
for bit; with carrier phase (the models are `models` with the carrier states: core/nav/carrier.dynamics)
tests/unit/integrity/test_bankpass_carrier.py.
"""

from __future__ import annotations

import numpy as np

from approachsim.core.jit import njit
from approachsim.core.nav import carrier as kcar
from approachsim.core.nav import epoch as ke
from approachsim.core.nav import errormodel as ek
from approachsim.core.nav.groups import ChannelQd, Obs, PassOut, Rows, Scratch


@njit(cache=True)
def carrier_models(lay: np.ndarray, q: np.ndarray, gse: np.ndarray, gmp: np.ndarray, loop: np.ndarray,
                   dt: np.ndarray, ref: np.ndarray, ref_cbn: np.ndarray, f_ref: np.ndarray, held: np.ndarray,
                   gio: np.ndarray, gio_tau: float, phi: np.ndarray, qd: np.ndarray) -> int:
    """Phi, Qd (E, n, n) of every epoch at the reference, as core/nav/epoch.shared_pass makes them: core/nav/
    errormodel.dynamics at ref[e] (E, 16) with ref_cbn[e], f_ref[e], the damping loop held where held[e] != 0, then
    core/nav/carrier.dynamics (gio Gauss-Markov of 1-sigma gio (n_sv,) m and correlation time gio_tau s; amb random
    constants; nothing without carrier phase), then discretize over dt[e]. Returns E, or -1 - e when epoch e's model
    is too large for the compiled discretization."""
    E = dt.shape[0]
    n = phi.shape[1]
    F = np.empty((n, n))
    Qc = np.empty((n, n))
    for e in range(E):
        y = ref[e]
        ek.dynamics(lay, q, gse, gmp, y[0], ek.interval_height(lay, y[2], y[5], dt[e]), y[3:6], f_ref[e], ref_cbn[e],
                    loop, held[e] != 0, F, Qc)
        kcar.dynamics(lay, gio, gio_tau, F, Qc)
        if not ek.discretize(F, Qc, dt[e], phi[e], qd[e]):
            return -1 - e
    return E


@njit(cache=True)
def models(lay: np.ndarray, q: np.ndarray, gse: np.ndarray, gmp: np.ndarray, loop: np.ndarray, dt: np.ndarray,
           ref: np.ndarray, ref_cbn: np.ndarray, f_ref: np.ndarray, held: np.ndarray, phi: np.ndarray,
           qd: np.ndarray) -> int:
    """carrier_models of a layout without carrier phase (no gio states: carrier.dynamics does nothing)."""
    return carrier_models(lay, q, gse, gmp, loop, dt, ref, ref_cbn, f_ref, held, np.zeros(0), 1.0, phi, qd)


@njit(cache=True)
def bank_epochs(X: np.ndarray, P3: np.ndarray, phi: np.ndarray, qd: np.ndarray, ref: np.ndarray, chan: ChannelQd,
                ins: np.ndarray, obs: Obs, new: np.ndarray, rows: Rows, out: PassOut, scr: Scratch) -> None:
    """Every epoch of every copy (core/nav/epoch.shared_pass's loop) with the epoch's model phi[e], qd[e] (E, n, n)
    given (the damping loop held or not as the copies' INS: the bank's copies share one): per epoch e,
    core/nav/epoch.pass_epoch at the reference ref[e] (E, 16). Arguments as shared_pass's (chan (N, E, k) and
    factors (E,), ins (N, E, 16), obs indexed [i, e], new (N, E, k) the copies' new carrier arcs: (N, E, 0), with
    obs.cp (N, E, 0) and chan.gio (N, E, 0), without carrier phase); out per copy and epoch: codes, nu, S, n_rows,
    x, pd, pnav after the epoch's updates (p33 and pcc when kept)."""
    N, E = X.shape[0], phi.shape[0]
    which = np.zeros((N, E), dtype=np.int64)
    for e in range(E):
        ke.pass_epoch(X, P3, phi[e:e + 1], qd[e:e + 1], which, ref[e], ins, chan, obs, new, rows, out, e, scr)
