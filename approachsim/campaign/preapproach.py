"""Faults already present when the approach starts: the pre-approach aided segment's response of every bank copy
(issue 41 item 3).

A fault whose onset is `age_s` seconds before the run start has been in the measurements of the aided flight
before the final. The filter has been absorbing it: a slow pseudorange ramp goes partly into the channel's range-error
state, the clock and the position, a baro step into the baro bias. The converged start (nav/initial.py) is the
fault-free filter after that segment; this module adds what the fault did to each copy's estimate over it.

The filter is linear in the measurements, so the fault's part of the estimate, delta (x_hat with the fault minus
x_hat without), obeys on its own, per aiding epoch k (errormodel sign convention: the rows' innovation
z = predicted - measured, so a fault +b on the measured value adds d b with d = -1 on the source's rows):

    delta_k = (I - K H) Phi delta_{k-1} + K d b_k          delta_0 = 0 at the onset

with the segment flown at the start state (as the converged start: Phi, Qd and the rows of the truth's first row,
`initial._segment`), b_k the fault's value (a step m; a ramp rate x time since the onset), and the gain the
converged filter's, K = P- H' (H P- H' + R)^-1 with P- = Phi P_conv Phi' + Qd: a fixed gain over the segment (the
converged start's covariance; a fault older than the 600 s convergence segment is taken through the same gain:
the approximation of a fixed geometry that the converged start already makes). The segment is flown level at the
start's height (the intermediate segment before the glidepath): with a baro scale-factor state sb the split of a
vertical disturbance between the baro bias and sb (h - H_ref) depends on the height's change, so the response is
that of a level segment, not of a descent (tests/unit/campaign/test_preapproach.py gives the numbers). The bank
copies: copy 0 (the main filter) uses every row; the copy that leaves out the faulted source never sees the fault
and starts clean (as a bank that ran through the segment would); every other copy takes the main filter's response
(an approximation: with its own rows its response would differ by its separation's share); every copy starts from
the main filter's converged covariance (the bank's own convention). The recursion is evaluated as the
N steps of the augmented matrix [[A, g, g beta], [0, 1, beta], [0, 0, 1]] on (delta, b, 1), N = age x aiding rate,
beta the ramp's increment per epoch (with the loop's x_f ahead of delta: `estimate_offsets`).

The shared INS was reset by the main filter's estimate (nav/initial.py), so the main filter's nav-state part of
delta is in the INS error (INS error -delta_main,nav: `apply`) and its sensor-state part in its estimate; copy c's
estimate is its own delta with the nav part relative to the main's (delta_c,nav - delta_main,nav).

Not modelled: a detection during the segment itself (the bank sees the separation at the first epoch of the
approach instead, and excludes there: a fault large enough to be caught before the final is caught at the
approach's first epoch); the segment's changing geometry.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any

import numpy as np

from approachsim.campaign.bank_modes import mode_name
from approachsim.nav import initial, ins

Array = np.ndarray

NAV_GROUPS = initial.NAV_GROUPS


@dataclass(frozen=True)
class PreFault:
    """A fault present at the run start: its source's row name ("gps07", "baro", "radalt", "pl0"), kind (step |
    ramp), step magnitude m or ramp rate m/s, and its age at the start, s."""

    row: str
    kind: str
    value: float
    age_s: float


def row_name(code: int) -> str:
    """The measurement row name of a bank mode code (campaign/bank_modes.py; nav/observations.Source.name)."""
    kind, _, k = mode_name(code).partition(" ")
    return {"gnss": f"gps{int(k or 0):02d}", "pseudolite": f"pl{k}"}.get(kind, kind)


def estimate_offsets(nav: Any, truth: Any, obs: Any, P_conv: Array, modes: Array, fault: PreFault
                     ) -> tuple[Array, Array]:
    """(the fault's part of the true INS error x_f (n,), nonzero only where the source drives the INS: the baro
    through the damping loop; (C, n) its part of each copy's estimate delta) at the run start (module docstring);
    copy 0 the main filter, copy k + 1 without mode k. Zeros when the source has no row at the start."""
    phi, qd, rows = initial._segment(nav, truth, obs, 0, P_conv)
    lay = nav.layout
    n = P_conv.shape[0]
    modes = np.asarray(modes, dtype=int)
    C = modes.size + 1
    names = [m.name for m in rows]
    if fault.row not in names or fault.age_s <= 0.0:
        return np.zeros(n), np.zeros((C, n))
    H = np.stack([m.h for m in rows])
    R = np.array([float(m.r) for m in rows])
    d = np.array([-1.0 if nm == fault.row else 0.0 for nm in names])
    Pm = phi @ P_conv @ phi.T + qd
    K = np.linalg.solve(H @ Pm @ H.T + np.diag(R), H @ Pm).T  # Pm H' S^-1 (S, Pm symmetric)
    nav_idx = _nav_index(lay)
    Pn = np.zeros((n, n))
    Pn[nav_idx, nav_idx] = 1.0
    # the damping loop takes the measured baro: a baro fault drives the true INS as the baro bias state would
    gam = np.zeros(n)
    if fault.row == "baro" and lay.has("ac") and lay.has("bb"):
        gam = Pn @ phi[:, lay.i("bb")]
    steps = int(round(fault.age_s * nav.nav.aiding_rate_hz))
    beta = fault.value / nav.nav.aiding_rate_hz if fault.kind == "ramp" else 0.0
    b0 = 0.0 if fault.kind == "ramp" else fault.value
    # zeta = (x_f, delta, b, 1): x_k = Pn Phi x + gam b_k; delta_k = A delta + K (H x_k + d b_k); b_k = b + beta
    A = (np.eye(n) - K @ H) @ phi
    X = Pn @ phi
    M = np.zeros((2 * n + 2, 2 * n + 2))
    ib, i1 = 2 * n, 2 * n + 1
    M[:n, :n], M[:n, ib], M[:n, i1] = X, gam, gam * beta
    KH, Kd = K @ H, K @ d
    M[n:ib, :n], M[n:ib, n:ib] = KH @ X, A
    M[n:ib, ib] = KH @ gam + Kd
    M[n:ib, i1] = (KH @ gam + Kd) * beta
    M[ib, ib], M[ib, i1], M[i1, i1] = 1.0, beta, 1.0
    z0 = np.zeros(2 * n + 2)
    z0[ib], z0[i1] = b0, 1.0
    z = z0
    for _ in range(steps):  # N matrix-vector products (cheaper than the matrix power's N log N-free squarings here)
        z = M @ z
    x_f, delta = z[:n], z[n:ib]
    # the copies that measure the source share the main filter's response; the one without it never saw the fault
    out = np.repeat(delta[None], C, axis=0)
    for c, code in enumerate(modes):
        if row_name(int(code)) == fault.row:
            out[c + 1] = 0.0
    return x_f, out


def _nav_index(layout: Any) -> Array:
    return np.concatenate([np.atleast_1d(np.arange(layout.n)[layout.index[g]]) for g in NAV_GROUPS
                           if layout.has(g)])


def apply(layout: Any, s: ins.InsState, x_f: Array, delta: Array) -> tuple[ins.InsState, Array]:
    """(the INS state at the start with the fault's true part x_f and the main filter's reset in its error, the
    (C, n) offsets of the copies' start estimates): module docstring."""
    nav_idx = _nav_index(layout)
    main = delta[0] - x_f  # the INS error moves by x_f - delta_main on the nav states
    s = ins.perturb(s, -main[None, layout.index["dp"]], -main[None, layout.index["dv"]],
                    -main[None, layout.index["psi"]])
    if layout.has("ac"):
        s = replace(s, a_comp_mps2=s.a_comp_mps2 - main[layout.index["ac"]])
    off = np.array(delta, dtype=float)
    off[:, nav_idx] -= delta[0, nav_idx]
    return s, off
