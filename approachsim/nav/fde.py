"""Online fault detection and exclusion (FDE) of the filter's measurements, run inside every aiding epoch.

Every epoch, before its updates, the measurements of the epoch (z = h' x + v, rows linearized at the predicted
estimate x-, P- its covariance) give the innovation vector nu = z - H x- with covariance S = H P- H' + R:

    residual test   q = nu' S^-1 nu ~ chi^2(m) under no fault          detection: q > chi2.isf(P_fa,q, m)
    w-test          w_j = (S^-1 nu)_j / sqrt((S^-1)_jj) ~ N(0, 1)       (Baarda's normalized residual)
    gradual test    M_j = |sum_{last N epochs} w_j| / sqrt(n_j)         detection: M_j > Q^-1(P_fa,M / 2)

(Teunissen's DIA procedure: detection, identification, adaptation). The innovation sequence of an optimal
filter is white, so the w_j of one measurement at successive epochs are independent N(0, 1) and the moving sum
M_j is N(0, 1) too; a bias b on measurement j moves E[w_j] = b sqrt((S^-1)_jj) at every epoch, so the moving
sum gains sqrt(N) in power over the single epoch -- the case of a slow ramp that the snapshot test sees only
late. Seed 004's F-ratio (the sample variance of the normalized residuals about their window mean) is blind to
exactly that mean shift, so the moving sum replaces it here (docs/integrity.md gives the measured delays).

Allocation (category from [nav.fde]): the continuity budget C per 15 s (integrity.requirements) is spread over
the 15 f epochs of 15 s and split half to the residual test, half to the moving sums of the m measurements of
the epoch: P_fa,q = C / (15 f 2), P_fa,M = C / (15 f 2 m) (union bound; overlapping windows make the sums
correlated in time, so the real rate is lower).

Identification and exclusion: the residual test names argmax |w_j|, the moving sum the measurement whose sum
fired (largest ratio); its source (a GNSS channel, a pseudolite unit, the baro, the radar altimeter) is
excluded from every later update (a GNSS satellite's code and carrier rows together: `Source.unit`). A slow
fault has contaminated the state before it is detected, so the
filter is rolled back: it restarts from its state `rollback_epochs` epochs ago and re-runs the stored epochs
(predictions, rows) without the excluded source (with feedback, the corrections the INS received in between
are subtracted as they were applied: y+ = y - c_e). Then the epoch is tested again (several exclusions per
epoch are possible).

Protection (per epoch, approach axes vertical / lateral, the output's covariance P+), the formula of
integrity.protection that the offline solution-separation bank uses too (one source; there T_k = K_fa sigma_ss,k):
    PL_H0 = K_ff sigma,  PL_H1 = max_j |a' K_j| sqrt(lambda / (S^-1)_jj) + K_md sigma
with K_j the gain column of measurement j and lambda the non-centrality with P(chi^2(m, lambda) < T) = P_md
(the largest single-epoch bias the residual test misses with P_md: the slope method of snapshot RAIM, Brown
1992, applied to the filter's innovations). It bounds a fault arriving at this epoch, not one accumulated over
earlier epochs. The solution is *flagged* once any source is excluded; an *alert* is raised when it cannot be
protected: PL >= AL (Annex 10 at the aircraft's distance and height), fewer than 4 ranging sources left (no
position-and-clock fix to check the INS against), or a detection that nothing is left to exclude.
"""

from __future__ import annotations

import math
from collections import deque
from dataclasses import dataclass, field
from functools import lru_cache
from typing import TYPE_CHECKING, Any

import numpy as np
from scipy.optimize import brentq
from scipy.stats import chi2, ncx2, norm

from approachsim.integrity.protection import epoch_shift, protection_levels
from approachsim.integrity.requirements import (
    lateral_alert_limit_m,
    vertical_alert_limit_m,
)
from approachsim.nav.base import FilterState, NavFilter, ScalarMeasurement, UpdateStatus
from approachsim.nav.config import FdeConfig
from approachsim.nav.errormodel import MeanModel
from approachsim.nav.observations import FIX, Source
from approachsim.records import ExclusionEvent

if TYPE_CHECKING:
    from approachsim.nav.rows import Row

Array = np.ndarray

MIN_RANGING = 4
"""Ranging sources (GNSS channels + pseudolites) needed for a position-and-clock fix (3 + 1 unknowns)."""

RESET_GROUPS = ("dp", "dv", "psi", "bg", "ba")
"""Error-state groups the feedback mode resets into the INS (NavSystem._feedback)."""


def _ranging(sources: set[Source]) -> int:
    """Ranging sources among `sources`, a satellite's code and carrier as one (a loose-coupling GNSS fix counts as a
    full fix)."""
    n = len({s.unit for s in sources if s.ranging})
    return n + (MIN_RANGING if any(s.kind == FIX for s in sources) else 0)


@lru_cache(maxsize=4096)
def _chi2_threshold(p_fa: float, dof: int) -> float:
    return float(chi2.isf(p_fa, dof))


@lru_cache(maxsize=4096)
def _noncentrality(threshold: float, dof: int, p_md: float) -> float:
    """lambda with P(chi^2(dof, lambda) < threshold) = p_md."""
    f = lambda lam: float(ncx2.cdf(threshold, dof, lam)) - p_md  # noqa: E731
    hi = 4.0 * threshold + 100.0
    while f(hi) > 0.0:
        hi *= 2.0
    return float(brentq(f, 1e-9, hi, xtol=1e-6))


@dataclass(frozen=True)
class _Test:
    """The epoch's residual statistics (measurements in processing order)."""

    names: list[str]
    """Measurement names (the moving sums' keys: the three axes of a loose fix are apart)."""
    sources: list[Source]
    q: float
    w: Array
    s_inv_diag: Array
    gain: Array
    """(n, m) batch gain P- H' S^-1."""


@dataclass
class _Epoch:
    """What a rollback needs of one past epoch."""

    index: int
    fs_prev: FilterState
    """Filter state before this epoch's prediction."""
    phi: Array
    qd: Array
    rows: list[Row]
    mean: MeanModel | None = None
    """The estimate's own model over the interval when the covariance's differs (nav/errormodel.loop_jacobian)."""
    correction: Array | None = None
    """Feedback: the error estimate the INS received after this epoch's updates (reset groups only)."""


@dataclass
class FdeState:
    """One run's FDE: exclusions, moving-sum windows, rollback history and the per-epoch flags."""

    config: FdeConfig
    epoch_hz: float
    reset_index: Array | None
    """Feedback: state indices reset into the INS (None: feed-forward)."""
    heading_rad: float
    excluded: set[str] = field(default_factory=set)
    windows: dict[str, deque] = field(default_factory=dict)
    history: deque = field(default_factory=deque)
    events: list[ExclusionEvent] = field(default_factory=list)
    alert: list[bool] = field(default_factory=list)
    flagged: list[bool] = field(default_factory=list)
    pl_m: list[Array] = field(default_factory=list)
    count: int = 0

    def __post_init__(self) -> None:
        req = self.config.requirement
        self._p_fa_q = req.p_fa(self.epoch_hz, 2)
        self._k_ff, self._k_md = req.k_ff(), req.k_md()
        self._p_md = min(0.5, req.p_h0_axis() / (req.n_es * req.p_fault_per_sat))
        h = self.heading_rad
        self._axes = np.array([[0.0, 0.0, -1.0], [-math.sin(h), math.cos(h), 0.0]])  # NED -> (up, right)
        self.history = deque(maxlen=self.config.rollback_epochs + 1)

    # --- statistics -----------------------------------------------------------------------------------------

    def _rows(self, rows: list[Row], x: Array) -> list[tuple[Source, ScalarMeasurement]]:
        return [(r.source, r.build(x)) for r in rows if r.source.unit not in self.excluded]

    @staticmethod
    def _test(filt: NavFilter, fs: FilterState, built: list[tuple[Source, ScalarMeasurement]]) -> _Test | None:
        if not built:
            return None
        ms = [m for _, m in built]
        P = filt.covariance(fs)
        H = np.stack([m.h for m in ms])
        nu = np.array([m.z for m in ms]) - H @ fs.x
        PH = P @ H.T
        S = H @ PH + np.diag([m.r for m in ms])
        s_inv = np.linalg.inv(0.5 * (S + S.T))
        a = s_inv @ nu
        d = np.diag(s_inv)
        return _Test([m.name for m in ms], [src for src, _ in built], float(nu @ a), a / np.sqrt(d), d, PH @ s_inv)

    def _sums(self, k: int, test: _Test) -> Array:
        """Moving-sum statistic M_j of each measurement of the epoch, with its current w_j."""
        n_win = self.config.window
        out = np.zeros(len(test.names))
        for j, name in enumerate(test.names):
            past = [w for i, w in self.windows.get(name, ()) if i > k - n_win and i < k]
            n = len(past) + 1
            out[j] = abs(sum(past) + test.w[j]) / math.sqrt(n) if n >= min(2, n_win) else 0.0
        return out

    def _commit(self, k: int, test: _Test | None) -> None:
        if test is None:
            return
        for name, w in zip(test.names, test.w.tolist(), strict=True):
            win = self.windows.setdefault(name, deque(maxlen=self.config.window))
            win.append((k, w))

    def _detect(self, k: int, test: _Test) -> tuple[Source, str, float, float] | None:
        """(source of the measurement, test, statistic, threshold) of a detection, or None."""
        m = len(test.names)
        t_q = _chi2_threshold(self._p_fa_q, m)
        if test.q > t_q:
            j = int(np.argmax(np.abs(test.w)))
            return test.sources[j], "chi2", test.q, t_q
        if self.config.window > 1:
            k_m = float(norm.isf(self.config.requirement.p_fa(self.epoch_hz, 2 * m) / 2.0))
            sums = self._sums(k, test)
            j = int(np.argmax(sums))
            if sums[j] > k_m:
                return test.sources[j], "sum", float(sums[j]), k_m
        return None

    # --- the epoch --------------------------------------------------------------------------------------------

    def _rollback(self, filt: NavFilter) -> FilterState:
        """Re-run the stored past epochs without the excluded sources; the state before the current epoch's
        prediction. The moving-sum windows are rebuilt from the re-run innovations."""
        hist = list(self.history)
        fs = hist[0].fs_prev
        first = hist[0].index
        for name in list(self.windows):
            self.windows[name] = deque([(i, w) for i, w in self.windows[name] if i < first],
                                       maxlen=self.config.window)
        for e, nxt in zip(hist[:-1], hist[1:], strict=True):
            fs = MeanModel.predict_state(filt, fs, e.phi, e.qd, e.mean)
            self._commit(e.index, self._test(filt, fs, self._rows(e.rows, fs.x)))
            for r in e.rows:
                if r.source.unit not in self.excluded:
                    fs, _ = filt.update(fs, r.build(fs.x))
            if e.correction is not None:  # the INS was corrected by c_e then: y+ = y - c_e
                fs = FilterState(x=fs.x - e.correction, P=fs.P, U=fs.U, d=fs.d, memory=fs.memory)
            nxt.fs_prev = fs
        return fs

    def epoch(self, filt: NavFilter, fs_prev: FilterState, phi: Array, qd: Array,
              rows: list[Row], t_s: float, r_rwy_m: Array, mean: MeanModel | None = None
              ) -> tuple[FilterState, list[UpdateStatus]]:
        """Predict, test, exclude (rolling back), update with the remaining measurements, protect.

        r_rwy_m (3,): the aircraft in the runway frame (along, cross, height above the threshold), m, for the
        alert limits. mean: the estimate's own model over the interval where the covariance's phi differs
        (nav/errormodel.MeanModel). Returns the filter state after the updates and the status of every measurement
        (excluded ones with weight 0, not accepted)."""
        k = self.count
        self.count += 1
        self.history.append(_Epoch(k, fs_prev, phi, qd, rows, mean))
        fs = MeanModel.predict_state(filt, fs_prev, phi, qd, mean)
        unprotectable = False
        while True:
            test = self._test(filt, fs, self._rows(rows, fs.x))
            hit = None if test is None else self._detect(k, test)
            if hit is None:
                break
            src, kind, stat, thr = hit
            if len({s.unit for s in test.sources}) <= 1:  # nothing left to compare it with
                unprotectable = True
                break
            self.excluded.add(src.unit)  # a satellite's code and carrier go together (observations.Source.unit)
            self.events.append(ExclusionEvent(t_s, src.unit, src.channel, kind, stat, thr))
            fs = MeanModel.predict_state(filt, self._rollback(filt), phi, qd, mean)
        self._commit(k, test)
        statuses: list[UpdateStatus] = []
        used: set[Source] = set()
        for r in rows:
            m = r.build(fs.x)
            if r.source.unit in self.excluded:
                P = filt.covariance(fs)
                nu = float(m.z - m.h @ fs.x)
                s = float(m.h @ P @ m.h + m.r)
                statuses.append(UpdateStatus(m.name, m.t_s, nu, s, nu * nu / s, 0.0, False))
                continue
            fs, st = filt.update(fs, m)
            statuses.append(st)
            used.add(r.source)
        pl = self._protection(filt, fs, test)
        al = np.array([float(vertical_alert_limit_m(self.config.requirement, r_rwy_m[2])),
                       float(lateral_alert_limit_m(self.config.requirement, r_rwy_m[0]))])
        self.pl_m.append(pl)
        self.flagged.append(bool(self.excluded))
        self.alert.append(bool(unprotectable or _ranging(used) < MIN_RANGING or np.any(pl >= al)))
        if self.reset_index is not None:
            c = np.zeros_like(fs.x)
            c[self.reset_index] = fs.x[self.reset_index]
            self.history[-1].correction = c
        return fs, statuses

    def _protection(self, filt: NavFilter, fs: FilterState, test: _Test | None) -> Array:
        """(vertical, lateral) protection level of the output after the updates, m (module docstring)."""
        A = self._axes
        P = filt.covariance(fs)[0:3, 0:3]
        sigma = np.sqrt(np.maximum(np.einsum("ij,jk,ik->i", A, P, A), 0.0))
        if test is None:  # no measurement this epoch: nothing can be faulted in it
            return self._k_ff * sigma
        m = len(test.names)
        lam = _noncentrality(_chi2_threshold(self._p_fa_q, m), m, self._p_md)
        t = epoch_shift(A, test.gain[0:3], test.s_inv_diag, lam)  # (m, 2): the largest undetected bias's effect
        return protection_levels(sigma, t, sigma[None, :], self._k_ff, self._k_md)[2]

    # --- output -----------------------------------------------------------------------------------------------

    def solution_fields(self, snap: Array) -> dict[str, Any]:
        """NavSolution fields at the samples whose filter snapshot is `snap` (0: the start, e + 1: after epoch
        e): alert, flagged, protection_level_m (nan before the first epoch), exclusions."""
        alert = np.concatenate([[False], np.array(self.alert, dtype=bool)])
        flagged = np.concatenate([[False], np.array(self.flagged, dtype=bool)])
        pl = np.concatenate([np.full((1, 2), np.nan), np.array(self.pl_m, dtype=float).reshape(-1, 2)])
        s = np.asarray(snap, dtype=int)
        return {"alert": alert[s], "flagged": flagged[s], "protection_level_m": pl[s],
                "exclusions": tuple(self.events)}
