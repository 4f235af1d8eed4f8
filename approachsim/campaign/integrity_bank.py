"""The sub-filter bank of solution-separation integrity over one run's records, and its protection levels.

The main filter uses every measurement; sub-filter k is the same navigation system on the same records with
GNSS channel k never used (every channel the main filter used during the run is a fault mode). With
`sensor_modes` (run_bank) the baro, the radar altimeter and each pseudolite unit are fault modes too: sub-filter k
then never uses that source (its record invalid throughout, as an outage: the navigation holds the baro damping
loop without a baro, nav/fde.py). Mode codes (`BankEpochs.channels`, campaign/bank_modes.py): a GNSS channel index
>= 0, BARO_MODE, RADALT_MODE, PSEUDOLITE_MODE - u for pseudolite unit u. The bank runs
as K + 1 copies of the run in one batched pass (same sensor draws, same initial-error draw: the
copies differ only in the excluded channel), with the shared covariance where the configuration allows it: with
the compiled optimal filter and per-run GPS skies (the default) one compiled call on the states the copies can move
(campaign/bankpass.py; in an open-loop campaign from the start and INS its flight group's pass left), elsewhere
NavSystem.run(copies=True). Both give the same numbers (tests/unit/campaign/test_bankpass.py).

At each filter epoch, in the approach frame (vertical up; lateral = cross-track, + right of the runway
heading), the separation of sub-solution k is e_k - e_0 (the difference of the output errors against truth,
which is the difference of the outputs: the truth cancels, in feed-forward and feedback alike), and the
variances are those of the filters' navigation-error covariances projected on the two axes; the detection
test, the H0 / H1 protection levels and the exclusion are integrity.separation's. Every category is scored at
the filter epochs (not the 120 Hz samples between them, where P does not change): availability PL < AL with
the category's alert limit at the aircraft's distance and height, misleading information |e_0| > PL.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from approachsim.campaign import bankpass
from approachsim.campaign.bank_modes import BARO_MODE, PSEUDOLITE_MODE, RADALT_MODE, mode_name
from approachsim.integrity.requirements import (
    REQUIREMENTS,
    IntegrityRequirement,
    lateral_alert_limit_m,
    vertical_alert_limit_m,
)
from approachsim.integrity.separation import SeparationResult, identify_statistic, separation
from approachsim.memo import TruthMemo
from approachsim.nav.system import NavSystem
from approachsim.seeding import stream
from approachsim.sensors.states import start_states
from approachsim.sensors.suite import SensorSuite

Array = np.ndarray


def sensor_modes(records: dict[str, Any]) -> list[int]:
    """Mode codes of the non-GNSS sources in `records` (one run): baro, radar altimeter, each pseudolite unit with a
    valid sample."""
    out = []
    if "baro" in records:
        out.append(BARO_MODE)
    if "radalt" in records:
        out.append(RADALT_MODE)
    if "pseudolite" in records:
        v = np.asarray(records["pseudolite"].valid, bool)
        v = v.reshape(-1, v.shape[-1])
        out.extend(PSEUDOLITE_MODE - u for u in np.nonzero(np.any(v, axis=0))[0])
    return out


def used_channels(valid: Array) -> Array:
    """Indices of the GNSS channels valid at any sample (valid (m, channels) of one run)."""
    return np.nonzero(np.any(np.asarray(valid, bool), axis=0))[0]


def bank_records(records: dict[str, Any], channels: Array) -> dict[str, Any]:
    """K + 1 copies of one run's records (run axis first): copy 0 as given, copy k + 1 without mode channels[k]
    (a GNSS channel index, or a sensor mode code: that source's samples invalid and nan, as an outage). Records
    must come from SensorSuite.measure(..., runs=[i] * (K + 1))."""
    g = records["gnss"]
    valid = np.array(g.valid, dtype=bool, copy=True)
    if valid.ndim != 3 or valid.shape[0] != len(channels) + 1:
        raise ValueError("bank_records: measure the run K + 1 times (runs=[i] * (K + 1)) first")
    out = dict(records)
    for k, c in enumerate(channels):
        c = int(c)
        if c >= 0:
            valid[k + 1, :, c] = False
        else:
            name = "baro" if c == BARO_MODE else "radalt" if c == RADALT_MODE else "pseudolite"
            if name not in out:
                raise ValueError(f"bank_records: mode {mode_name(c)} but no {name} record")
            out[name] = _without(out[name], k + 1, None if name != "pseudolite" else PSEUDOLITE_MODE - c)
    out["gnss"] = dataclasses.replace(g, valid=valid)
    return out


def _without(rec: Any, copy: int, unit: int | None) -> Any:
    """The record with copy `copy`'s samples (unit `unit` only, when given) invalid and their values nan."""
    valid = np.array(rec.valid, dtype=bool, copy=True)
    sl = (copy, slice(None)) if unit is None else (copy, slice(None), unit)
    valid[sl] = False
    upd: dict[str, Any] = {"valid": valid}
    for f in ("h_baro_m", "h_agl_m", "pseudorange_m"):
        v = getattr(rec, f, None)
        if v is not None:
            v = np.array(v, dtype=float, copy=True)
            v[sl] = np.nan
            upd[f] = v
    return dataclasses.replace(rec, **upd)


@dataclass(frozen=True)
class BankEpochs:
    """Per filter epoch of one run (axis 0): the main and sub-solution errors and variances on the approach
    axes (last axis: 0 vertical, 1 lateral), m and m^2, and where the aircraft was."""

    t_s: Array
    e0: Array
    """(e, 2) main-solution error (output - truth)."""
    p0: Array
    """(e, 2) its variances."""
    ek: Array
    """(e, K, 2) sub-solution errors."""
    pk: Array
    """(e, K, 2) their variances."""
    channels: Array
    """(K,) the GNSS channel each sub-filter leaves out."""
    along_m: Array
    """(e,) runway-frame x of the aircraft (negative before the threshold), m."""
    height_m: Array
    """(e,) height above the threshold, m."""
    wtest: Array | None = None
    """(e, K) the identification statistic of each fault mode over the 9 navigation states
    (integrity.separation.identify_statistic); None: made from `separations` when asked (`identification`), or
    without them identify on the two approach axes only."""
    separations: tuple[Array, Array] | None = field(default=None, repr=False, compare=False)
    """(d9 (e, K, 9), p9 (e, K, 9, 9)): the sub-solutions' navigation-state separations x_k - x_0 and their
    covariances P_k - P_0, from which `identification` makes the statistic (only runs with a detection need it)."""
    tested: Array | None = field(default=None, repr=False, compare=False)
    """(K, 2) bool: the axes on which each mode's separation is a detection test (None: every one; own_ins_bank)."""

    def identification(self) -> Array | None:
        """wtest, or the statistic made from `separations` (once; kept), or None: identify on the approach axes."""
        if self.wtest is not None or self.separations is None:
            return self.wtest
        w = identify_statistic(*self.separations)
        object.__setattr__(self, "wtest", w)
        return w


def _axes(heading_rad: float) -> Array:
    """(2, 3) rows mapping NED to (up, right of the runway heading)."""
    return np.array([[0.0, 0.0, -1.0], [-np.sin(heading_rad), np.cos(heading_rad), 0.0]])


def bank_epochs(main: Any, subs: list[Any], channels: Array, truth: Any, heading_rad: float) -> BankEpochs:
    """Project the NavRuns of the main filter and the sub-filters on the approach axes at the epochs."""
    err = np.stack([np.asarray(r.true_error_nav) for r in [main, *subs]])
    pnav = np.stack([np.asarray(r.P_nav) for r in [main, *subs]])
    return bank_epochs_arrays(np.asarray(main.t_epoch_s), err, pnav, channels, truth, heading_rad)


def bank_epochs_arrays(t: Array, err: Array, pnav: Array, channels: Array, truth: Any, heading_rad: float
                       ) -> BankEpochs:
    """`bank_epochs` from the copies' arrays: t (e,) epoch times, err (K + 1, e, 9) output errors and pnav
    (K + 1, e, 9, 9) navigation covariances, copy 0 the main filter."""
    A = _axes(heading_rad)

    def axes(k: int) -> tuple[Array, Array]:
        e = err[k][:, 0:3] @ A.T
        p = np.einsum("ij,ejk,ik->ei", A, pnav[k][:, 0:3, 0:3], A)
        return e, p

    e0, p0 = axes(0)
    subs_ep = [axes(k) for k in range(1, err.shape[0])]
    ek = np.stack([s[0] for s in subs_ep], axis=1) if subs_ep else np.zeros((t.size, 0, 2))
    pk = np.stack([s[1] for s in subs_ep], axis=1) if subs_ep else np.zeros((t.size, 0, 2))
    r = np.stack([np.interp(t, truth.t_s, truth.r_rwy[:, i]) for i in range(3)], axis=1)
    sep = None
    if subs_ep:  # full navigation-state separations e_k - e_0 (9 states) and their covariances P_k - P_0
        d9 = np.stack([err[k] - err[0] for k in range(1, err.shape[0])], axis=1)
        p9 = np.stack([pnav[k] - pnav[0] for k in range(1, err.shape[0])], axis=1)
        sep = (d9, p9)
    return BankEpochs(t, e0, p0, ek, pk, np.asarray(channels), r[:, 0], r[:, 2], None, sep)


@dataclass(frozen=True)
class CategoryIntegrity:
    """One category's integrity over one run's epochs (after `start_height_m`, before the DH or the run end)."""

    category: str
    epochs: int
    available: Array
    """(e,) PL < AL on both axes."""
    misleading: Array
    """(e,) output error > PL on either axis (the output: main solution, after an exclusion the sub-solution)."""
    hazardous: Array
    """(e,) output error > AL on either axis while PL < AL (hazardously misleading)."""
    detected: Array
    """(e,) the separation test fired."""
    pl_m: Array
    """(e, 2) protection levels of the output (vertical, lateral); after an exclusion the excluded
    sub-solution's fault-free level K_ff sigma_k (no second-level bank monitors it)."""
    al_m: Array
    """(e, 2) alert limits."""
    result: SeparationResult
    """The main filter's separation test and protection levels (before any exclusion)."""
    excluded_channel: int
    """Mode excluded at the first detection: a GNSS channel, or a sensor mode code (-1: none)."""
    t_detect_s: float
    """Time of the first detection (nan: none), s."""
    time_to_alert_s: float
    """First detection minus the first epoch at which the main solution's error exceeded its protection level
    (negative: detected before; nan: the error never exceeded it), s."""
    alert: Array
    """(e,) the output cannot be protected: PL >= AL (unavailable), the flag a crew would see."""
    err_m: Array | None = None
    """(e, 2) |error| of the output (the main solution; after an exclusion the excluded sub-solution), m."""


SECOND_LEVEL_RATIO = 2.0
"""Second-level identification: the candidate's statistic must be at least this multiple of the runner-up's."""
SECOND_LEVEL_EPOCHS = 3
"""Second-level identification: ... for this many consecutive detected epochs before its exclusion."""


def second_level(detected: Array, stat: Array, ratio: float = SECOND_LEVEL_RATIO,
                 epochs: int = SECOND_LEVEL_EPOCHS, at_once: bool = False) -> tuple[Array, Array]:
    """Confirmed identification with a second look (issue 26: the misidentified ramp of run 44).

    From the first detection on, at each detected epoch the candidate is the mode with the largest identification
    statistic stat (epochs, modes) if it is at least `ratio` times the runner-up, else none (ambiguous). A mode is
    excluded once it has been the candidate at `epochs` consecutive detected epochs, and kept (replacing it when
    another mode was confirmed the same way made the satellite-ramp study worse: 30 instead of 2 HMI in 3000 at
    CAT II, docs/integrity.md). The output is protected (confirmed) only at epochs where the excluded
    mode is not contradicted (a later detected epoch whose clear candidate is another mode contradicts it; an
    ambiguous one does not); elsewhere from the first detection on it is not: the caller raises the alert
    (PL = inf). at_once: a first detection whose candidate is clear excludes it at once (protected, as the first
    look), so only an ambiguous first detection waits for the confirmation (docs/integrity.md: the confirmation's
    alerts on every detected ramp cost the continuity allocation). Returns (excluded mode per epoch, -1 none;
    confirmed (epochs,))."""
    det = np.asarray(detected, bool)
    st = np.asarray(stat, float)
    n = det.size
    mode = np.full(n, -1)
    ok = np.ones(n, bool)
    if not det.any():
        return mode, ok
    order = np.argsort(st, axis=1)
    top = order[:, -1]
    second = st[np.arange(n), order[:, -2]] if st.shape[1] > 1 else np.zeros(n)
    clear = st[np.arange(n), top] >= ratio * np.maximum(second, 0.0)
    current, last, run, first = -1, -2, 0, True
    for e in range(int(np.argmax(det)), n):
        if det[e]:
            c = int(top[e]) if clear[e] else -1
            run = run + 1 if (c == last and c >= 0) else (1 if c >= 0 else 0)
            last = c
            if c >= 0 and current < 0 and (run >= epochs or (at_once and first)):  # a confirmed exclusion is
                current = c  # kept: a contradiction alerts
            first = False
            ok[e] = current >= 0 and c in (current, -1)  # an ambiguous epoch does not contradict an exclusion
        else:
            ok[e] = current >= 0
        mode[e] = current
    return mode, ok


def own_ins_bank(ep: BankEpochs) -> BankEpochs:
    """The bank whose baro mode's sub-filter runs its own INS (the damping loop drives the INS: run_bank): that
    mode tested on the vertical axis only, and identification by the tested separations (no full-state
    statistic). The baro measures height, so a baro fault reaches the lateral solution only through the INS
    couplings, and with its own INS P_k - P_0 is not the separation's covariance there (the premise of
    integrity/separation.py: a sub-filter on the same INS and model; with a shared INS, no loop, it holds). Measured
    fault-free (tests/data/default-py.toml, run 5, physical baro): lateral P_k - P_0 from -7e-4 to 0.015 m^2 against
    P_0 3.9 m^2, negative at some epochs, and separations up to 0.19 m: a normalized separation of 1e7, an alert
    that says nothing about the baro. Its vertical axis, where the baro's information is (P_k - P_0 0.06 m^2), stays
    tested (the fault-free normalized separation's largest 2.2, rms 0.8). For the same reason a bank with the baro
    mode identifies by the tested separations (the largest normalized one, SeparationResult.suspect), not by the
    full-state statistic Delta' (P_k - P_0)^+ Delta, which needs P_k - P_0 to be the separation's covariance: with
    the baro's own INS it is indefinite (a 20 m baro step: the baro's statistic -9, the radar altimeter's 20759, and
    the radar altimeter excluded while the baro's vertical separation alone was over its threshold)."""
    tested = np.ones((len(ep.channels), 2), bool)
    tested[np.asarray(ep.channels, dtype=int) == BARO_MODE, 1] = False
    return dataclasses.replace(ep, wtest=None, separations=None, tested=tested)


def score_category(ep: BankEpochs, req: IntegrityRequirement, epoch_hz: float, window: Array | None = None,
                   confirm: bool = False, at_once: bool = False) -> CategoryIntegrity:
    """Protection levels, detection and the per-epoch counts of one category (Annex 10 alert limits at the
    aircraft's distance from the threshold and height above it). confirm: identify with the second look
    (second_level: the output is not protected until a mode's exclusion is confirmed, and again whenever a later
    detection names another mode; at_once: a clear first detection excluded at once, second_level); default:
    exclude the first detection's suspect for good."""
    sel = np.ones(ep.t_s.shape, bool) if window is None else np.asarray(window, bool)
    n_modes = max(ep.ek.shape[1], 1)
    # K_md with the mode count: the faulted allocation is shared by the n_modes monitored modes (requirements.p_md)
    r = separation(ep.e0[sel], ep.p0[sel], ep.ek[sel], ep.pk[sel], req.k_ff(), req.k_fa(epoch_hz, 2 * n_modes),
                   req.k_md(n_modes), ep.tested) if ep.ek.shape[1] else _no_modes(ep, sel, req)
    al = np.stack([vertical_alert_limit_m(req, ep.height_m[sel]), lateral_alert_limit_m(req, ep.along_m[sel])],
                  axis=1)
    t = ep.t_s[sel]
    e_main = np.abs(ep.e0[sel])
    err, pl = e_main.copy(), r.pl_m.copy()
    excluded, t_det = -1, float("nan")
    if r.detected.any() and confirm:
        w = ep.identification()
        stat = w[sel] if w is not None else np.max(r.test_ratio, axis=2)
        mode, ok = second_level(r.detected, stat, at_once=at_once)
        t_det = float(t[int(np.argmax(r.detected))])
        on = mode >= 0
        kk = np.where(on, mode, 0)
        err = np.where(on[:, None], np.abs(ep.ek[sel][np.arange(kk.size), kk]), err)
        pl = np.where(on[:, None], req.k_ff() * np.sqrt(ep.pk[sel][np.arange(kk.size), kk]), pl)
        pl = np.where(ok[:, None], pl, np.inf)
        excluded = int(ep.channels[mode[-1]]) if mode[-1] >= 0 else -1
    elif r.detected.any():  # exclude the suspect from the first detection on: its sub-solution is the output
        i = int(np.argmax(r.detected))
        # identification: the full navigation-state statistic (Baarda's w-test squared) where the bank has it,
        # else the largest two-axis normalized separation
        w = ep.identification()
        k = int(np.argmax(w[sel][i])) if w is not None else int(r.suspect[i])
        excluded, t_det = int(ep.channels[k]), float(t[i])
        err[i:] = np.abs(ep.ek[sel][i:, k])
        pl[i:] = req.k_ff() * np.sqrt(ep.pk[sel][i:, k])
    exceed = np.any(e_main > r.pl_m, axis=1)
    tta = float(t_det - t[np.argmax(exceed)]) if exceed.any() and np.isfinite(t_det) else float("nan")
    if exceed.any() and not np.isfinite(t_det):
        tta = float("inf")  # the error exceeded the PL and nothing was ever detected
    avail = np.all(pl < al, axis=1)
    mi = np.any(err > pl, axis=1)
    hmi = np.any(err > al, axis=1) & avail
    return CategoryIntegrity(req.category, int(sel.sum()), avail, mi, hmi, r.detected, pl, al, r, excluded, t_det,
                             tta, ~avail, err)


def _no_modes(ep: BankEpochs, sel: Array, req: IntegrityRequirement) -> SeparationResult:
    """No redundant channel (e.g. best-four selection): no fault can be detected, so no H1 protection:
    PL = inf (unavailable)."""
    n = int(sel.sum())
    inf = np.full((n, 2), np.inf)
    return SeparationResult(req.k_ff() * np.sqrt(ep.p0[sel]), inf, inf, np.zeros((n, 0, 2)),
                            np.zeros(n, bool), np.full(n, -1))


def score_run(ep: BankEpochs, epoch_hz: float, start_height_m: float, dh_m: dict[str, float]
              ) -> dict[str, CategoryIntegrity]:
    """Every category, from start_height_m above the threshold down to its decision height."""
    out = {}
    for cat, req in REQUIREMENTS.items():
        window = (ep.height_m <= start_height_m) & (ep.height_m >= dh_m[cat])
        out[cat] = score_category(ep, req, epoch_hz, window)
    return out


def run_bank(profile: Any, truth: Any, seed: int, run: int, sensor_modes_on: bool = False, *,
             compiled: bool = True, group: tuple[Any, int] | None = None, memo: TruthMemo | None = None,
             pre: Any = None) -> tuple[BankEpochs, Any]:
    """Measure run `run` of the campaign seeded `seed` on `truth`, navigate it with the main filter and the
    sub-filter bank (one batched pass) and project on the approach axes; returns (epochs, main NavRun).
    sensor_modes_on: the baro, radar altimeter and pseudolite units are fault modes too (module docstring).

    Where campaign.bankpass applies (the compiled optimal filter, feed-forward, per-run GPS skies: the default),
    the run is measured once and bankpass.bank_pass navigates every copy in one compiled call on the reduced
    state (the same numbers; the main NavRun then has no solution and the reduced layout). Elsewhere the copies
    share the run's IMU record and its INS (NavSystem.run(copies=True), feed-forward): the IMU is
    drawn and applied once; the other sensors are measured for the K + 1 copies (the same draws: the same
    streams), whose GNSS records then lose one channel each (bank_records). compiled=False: always the latter (the
    oracle of campaign/bankpass.py). group: (bankpass.GroupInputs, k) what the open-loop flight group's pass left
    for this run, its run k (campaign/pipeline.py): nothing is drawn, started or integrated again (the same numbers,
    bankpass.bank_pass_group). memo: the truth's TruthMemo (approachsim/memo.py) from the caller that shares the
    truth among runs (an open-loop group, a study's flown truth): the converged start, the reference and the epoch
    models are then made once. pre: a fault present at the start (campaign.preapproach.PreFault; the compiled
    pass only: ValueError elsewhere)."""
    from dataclasses import fields, replace

    if compiled and group is not None and not sensor_modes_on:
        g, k = group
        nav = NavSystem.from_profile(profile)
        if g.usable(nav) and bankpass.applicable(nav, g.records):
            channels = used_channels(np.asarray(g.records["gnss"].valid)[k])
            bp = bankpass.bank_pass_group(nav, truth, g, k, channels, memo)
            if bp is not None:
                ep = bank_epochs_arrays(bp.t_s, bp.true_error_nav, bp.P_nav, channels, truth,
                                        profile.runway.heading_rad)
                return ep, bp.main_run()
    suite = SensorSuite.from_profile(profile)
    errors = suite.draw(truth.t_s, seed, [run])
    one = suite.apply(truth, errors)
    if "gnss" not in one:
        raise ValueError("integrity bank: the profile has no GNSS receiver")
    channels = used_channels(np.asarray(one["gnss"].valid)[0])
    if sensor_modes_on:
        channels = np.concatenate([channels, np.asarray(sensor_modes(one), dtype=int)]).astype(int)
    copies = len(channels) + 1
    nav = NavSystem.from_profile(profile)
    states = start_states(suite, truth, errors)
    # a sub-filter without the baro has its own INS when the baro damping loop drives the INS vertical channel
    own_ins = bool(sensor_modes_on and "baro" in one and nav.loop_gains() is not None)
    share = not nav.nav.feedback and "imu" in one and not own_ins
    if compiled and share and bankpass.applicable(nav, one):  # the compiled reduced pass (campaign/bankpass.py)
        bp = bankpass.bank_pass(nav, truth, one, channels, stream(seed, run, "nav"), states, memo, pre=pre)
        if bp is not None:
            ep = bank_epochs_arrays(bp.t_s, bp.true_error_nav, bp.P_nav, channels, truth, profile.runway.heading_rad)
            return ep, bp.main_run()
    if pre is not None:
        raise ValueError("a fault present before the approach needs the compiled bank pass (campaign/bankpass.py)")
    rest = suite.without("imu") if share else suite  # feed-forward: one IMU record for every copy
    recs = rest.apply(truth, rest.draw(truth.t_s, seed, [run] * copies))
    if share:
        recs["imu"] = one["imu"]
    recs = bank_records(recs, channels)
    states = replace(states, **{f.name: np.repeat(getattr(states, f.name), copies, axis=0)
                                for f in fields(states) if isinstance(getattr(states, f.name), np.ndarray)})
    # every copy starts from the main filter's converged state (the first copy's schedule: all channels)
    navs = nav.run(truth, recs, [stream(seed, run, "nav") for _ in range(copies)],
                   shared_covariance=nav.shares_covariance(), states=states, copies=share, memo=memo)
    ep = bank_epochs(navs[0], navs[1:], channels, truth, profile.runway.heading_rad)
    return (own_ins_bank(ep) if own_ins else ep), navs[0]
