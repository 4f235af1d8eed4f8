"""The grouped arguments of the filter-epoch kernels (core/nav/epoch.py, core/nav/copies.py): named tuples of
arrays and scalars, built once by the Python caller (nav/engine.py, nav/navigator.py, integrity/bankpass.py,
nav/reduced.py), read by attribute in the compiled code (numba types a named tuple by its fields).

    Rows        the measurement rows' constants of a navigation system          built once per EpochEngine
    Obs         the observations of an epoch (one class, or N copies at once: a leading copy axis; a pass: copy
                and epoch axes)
    Out         where an epoch writes its rows: codes, innovations, their variances
    PassOut     where a pass writes every copy's epochs (rows, estimates, covariances)
    ErrorModel  the error model's constants (core/nav/errormodel.dynamics, core/nav/carrier.dynamics)
    Track       the reference trajectory a pass's models are made along
    ChannelQd   the GPS channel states' Qd entries at each copy's own sky
    Scratch     the kernels' work arrays for an n-state filter (`scratch`)

Shapes and units in each class; n the filter's states, M the members of a class, N the copies, E the epochs, s the
GNSS channels, p the pseudolites, k the database's nodes, R the rows an epoch can have.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from approachsim.core.nav import kalman as kk


class Rows(NamedTuple):
    """The measurement rows' constants (core/nav/measurements.py, core/nav/carrier.py)."""

    lay: np.ndarray
    """The state layout (core/nav/errormodel L_*)."""
    tx: np.ndarray
    """The filter's terrain: profile abscissae (core/nav/measurements.terrain_h)."""
    th: np.ndarray
    """... and heights, m."""
    rwy: np.ndarray
    """... and the runway frame."""
    ra_pct: float
    """Radar altimeter sigma = sqrt((ra_pct h)^2 + ra_floor^2), m."""
    ra_floor: float
    """... its floor, m."""
    channel_states: bool
    """The pseudorange rows carry the gse / gmp channel states."""
    pl_states: bool
    """The pseudolite rows carry their states."""
    cp_r: float
    """The carrier-phase rows' noise variance, m^2 (0 without carrier phase)."""
    amb_prior: float
    """A float ambiguity's prior variance at a new carrier arc, m^2."""
    baro_ref: float
    """The baro scale factor's reference H_ref: the altimeter-setting reference (the field), m (the sb row's
    -(h - H_ref))."""


class Obs(NamedTuple):
    """The observations of an epoch: of the M members of a class (class_epoch), of N copies (copies_epoch: the
    per-copy arrays have a leading copy axis N), or of a pass (shared_pass, bank_epochs: copy and epoch axes (N, E),
    the per-epoch ones (E,)). nan: no observation."""

    baro_h: np.ndarray
    """Baro heights (M,), m."""
    baro_r: float
    """Their noise variance, m^2."""
    radalt_h: np.ndarray
    """Radar altimeter heights above the terrain (M,), m."""
    ref_agl: float
    """The reference's height above the terrain (shared rows' radar-altimeter sigma), m."""
    ref_sb: float
    """The reference's baro scale factor (the shared baro row's dp_D coefficient -(1 + sb); the day's,
    sensors/states.SensorStates.sb_day; 0 without a baro scale-factor state)."""
    dbp: np.ndarray
    """Each member's terrain-database error parameters (M, 4) (core/nav/measurements.database_error)."""
    db_x: np.ndarray
    """The database error's nodes (k,), m."""
    db_u: np.ndarray
    """Each member's database error at the nodes (M, k)."""
    rho: np.ndarray
    """Pseudoranges (M, s), m."""
    r_sv: np.ndarray
    """The satellites (s, 3), ECEF m (copies: (N, s, 3))."""
    sig: np.ndarray
    """The pseudoranges' 1-sigma (s,), m (copies: (N, s))."""
    cp: np.ndarray
    """Carrier phases (M, s), m; (M, 0) without carrier phase."""
    pl_rho: np.ndarray
    """Pseudolite pseudoranges (M, p), m."""
    r_pl: np.ndarray
    """The pseudolites (p, 3), ECEF m."""
    pl_sig: np.ndarray
    """Their 1-sigma (p,), m."""


class Out(NamedTuple):
    """An epoch's rows: codes (R,) (core/nav/epoch CODE_*), innovations nu (M, R) m, their variances S (R,) m^2
    (copies: codes, S (N, R))."""

    codes: np.ndarray
    nu: np.ndarray
    S: np.ndarray


class PassOut(NamedTuple):
    """A pass's outputs per copy and epoch, after the epoch's updates."""

    codes: np.ndarray
    """Row codes (N, E, R)."""
    nu: np.ndarray
    """Innovations (N, E, R), m."""
    S: np.ndarray
    """Their variances (N, E, R), m^2."""
    n_rows: np.ndarray
    """Rows of each epoch (N, E)."""
    x: np.ndarray
    """Estimates (N, E, n)."""
    pd: np.ndarray
    """P's diagonal (N, E, n)."""
    pnav: np.ndarray
    """P's navigation block (N, E, 9, 9)."""
    p33: np.ndarray
    """P's position block (N, E, 3, 3); (N, E, 0, 0): not kept."""
    pcc: np.ndarray
    """P[ic, ic] (N, E) (the clock's); (N, 0): not kept."""
    ic: int
    """The index pcc reads."""


class ErrorModel(NamedTuple):
    """The error model's constants: F and Qc about a navigation state (core/nav/errormodel.dynamics, then
    core/nav/carrier.dynamics)."""

    lay: np.ndarray
    """The state layout."""
    q: np.ndarray
    """The noise scalars at errormodel.Q_* (nav/errormodel.kernel_noise)."""
    gse: np.ndarray
    """The channels' slow-error 1-sigma (n_sv,), m."""
    gmp: np.ndarray
    """... and fast-error 1-sigma (n_sv,), m."""
    loop: np.ndarray
    """The damping loop's constant gains (nav/errormodel.kernel_loop)."""
    gio: np.ndarray
    """The ionosphere states' 1-sigma (n_sv,), m; (0,) without carrier phase."""
    gio_tau: float
    """Their correlation time, s."""
    gse_r: np.ndarray
    """The slow channel states' scale over the interval (n_sv,): Phi[gse_c, gse_c] times gse_r[c] (GBAS: the
    channel's sigma at the epoch's geometry over the interval start's, nav/gbas_scale.py); (0,): none."""
    gio_r: np.ndarray
    """... and the ionosphere states' (carrier phase under GBAS; (0,): none)."""


class Track(NamedTuple):
    """The reference trajectory at a pass's E epochs: the interval before each dt (E,) s, the packed truth rows
    ref (E, 16) (core/nav/strapdown layout), their body-to-NED ref_cbn (E, 3, 3) and the interval's mean specific
    force f_ref (E, 3), NED m/s^2."""

    dt: np.ndarray
    ref: np.ndarray
    ref_cbn: np.ndarray
    f_ref: np.ndarray


class ChannelQd(NamedTuple):
    """The GPS channel states' Qd at each copy's own sky: Qd[c, c] = sigma_c^2 f, sigma the channel's 1-sigma (m) and
    f = 1 - exp(-2 dt / tau). Copies of an epoch: sigmas (N, k), factors scalars; a pass: (N, E, k) and (E,).
    k = 0: nothing changed (one sky: the model's own)."""

    gse: np.ndarray
    gmp: np.ndarray
    gio: np.ndarray
    """The ionosphere states' (carrier phase; (N, 0) without)."""
    f_gse: float
    f_gmp: float
    f_gio: float
    gse_r: np.ndarray
    """The slow channel states' scale over the interval per copy (N, k) (a pass: (N, E, k)): copy i's gse_c
    estimate and P row and column times gse_r[i, c] before the predict (ErrorModel.gse_r's D Phi, as D P D: the
    channel states' rows and columns of Phi hold only their diagonal); (N, 0): none."""
    gio_r: np.ndarray
    """... and the ionosphere states' (carrier phase under GBAS; (N, 0): none)."""


class Scratch(NamedTuple):
    """Work arrays of an n-state filter: h, b (n,) a row and P h; ws the kalman workspace (kalman.workspace);
    F, Qc, phi, qd, phi_tmp (n, n) a model, its discretization, and a copy's Qd and Phi (qd doubles as that Qd)."""

    h: np.ndarray
    b: np.ndarray
    ws: tuple
    F: np.ndarray
    Qc: np.ndarray
    phi: np.ndarray
    qd: np.ndarray
    phi_tmp: np.ndarray


def scratch(n: int) -> Scratch:
    """The work arrays of an n-state filter (allocate once per filter size)."""
    return Scratch(np.zeros(n), np.zeros(n), kk.workspace(n), *(np.zeros((n, n)) for _ in range(5)))
