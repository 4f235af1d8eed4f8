"""The one place where a Monte Carlo run is composed: fly -> sense -> navigate -> score.

Stages are used through their public entry points only:

    flight      approachsim.flight.run.Approach(profile).fly(seed=, run=, nav_source=) -> FlightResult
    sensors     approachsim.sensors (the profile's sensor suite) -> sensor records
    navigation  approachsim.nav.system -> records.NavSolution (and, closed loop, a NavigationSource)
    scoring     approachsim.evaluate.score.score_run(truth, nav, cfg) -> scalars, arrays, series

A stage that is not importable makes `require_stages` raise PipelineUnavailable (the CLI prints it and
exits 1): numbers are never invented for a missing stage. So this module imports the stages it checks (flight,
sensors, nav, and the integrity bank, which imports nav) inside the functions that use them, after require_stages:
importing the pipeline never needs them (the function-local imports marked "stage" below).

Work sharing: runs come in fixed groups of consecutive runs (evaluation.flight_group); a task holds some
runs of one group, and the aircraft is parsed and linearized once per task. Open loop: every run of a group
navigates over the same truth, flown on truth navigation with the turbulence of the group's first run (a
task flies it once; tasks of the same group fly the identical, seeded flight), each run with its own sensor
and filter noise, batched over the task's runs; with [sensors.gnss] epoch = "per-run" (the default) each run
also has its own GPS sky (the batched records carry per-run satellite geometry), so the optimal filter's shared
covariance is one per run (measured: the open-loop navigation about 3-4x slower than with one fixed sky).
A run's numbers depend only on (seed, run, group size), not on the executor or the batch it shared (checked:
NavSystem.run gives bit-identical runs in a batch of 1 and of 6, with one sky and with per-run skies).
Closed loop: each run flies on its own navigation solution, one run per task.
Landing (closed loop, `evaluate --land`): each run flies on through the flare to main-gear touchdown
(Approach(profile, land=True)); its navigation is scored on the record down to where an approach run stops (the
lowest decision height less 20 ft: the same decision-height crossings, time averages and integrity epochs as an
approach campaign), and evaluate.touchdown scores the touchdown row (main-gear position and sink from the IMU
point's state and the main gears' lever arms). A run that does not put its main gear down on the runway is a
failed run with its reason ("failed landing: touchdown short of the threshold ..."), never dropped.
Integrity ([evaluation] integrity lists a category): after the flight, each run is also navigated by the
solution-separation bank (campaign.integrity_campaign.score_with_bank: K + 1 filters in one batched pass, open loop on
the run's flown truth with the run's own sensor draws): measured 1.86x the wall time of the default 20-run closed-loop
campaign, about 3x an open-loop one.
"""

from __future__ import annotations

import dataclasses
import functools
import importlib
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from approachsim import units
from approachsim.campaign.result import RunResult
from approachsim.config import ProfileError
from approachsim.evaluate.limits import CATEGORIES
from approachsim.evaluate.score import CATEGORY_KEYS, HEIGHT_GRID_FT, score_run
from approachsim.evaluate.touchdown import touchdown_scalars
from approachsim.memo import TruthMemo
from approachsim.seeding import stream

STAGES = (
    ("approachsim.flight.run", "Approach", "flight (JSBSim truth)"),
    ("approachsim.sensors.suite", "SensorSuite", "sensor suite"),
    ("approachsim.nav.system", "NavSystem", "navigation system"),
)
"""(module, required attribute, what) of every stage the pipeline needs."""
CLOSED_LOOP_STAGE = ("approachsim.loop.closed_loop", "NavInTheLoop", "closed-loop navigation source")
"""The extra stage closed-loop mode needs."""


class PipelineUnavailable(RuntimeError):
    """A stage of the per-run pipeline is not available in this installation (exit 1, not a user error)."""


def require_stages(mode: str = "open") -> None:
    """Raise PipelineUnavailable naming the first stage (of `mode`) that cannot be imported."""
    for mod, attr, what in STAGES + ((CLOSED_LOOP_STAGE,) if mode == "closed" else ()):
        try:
            m = importlib.import_module(mod)
        except ImportError as e:
            raise PipelineUnavailable(
                f"the {what} stage ({mod}) is not available: {e}; cannot evaluate without it"
            ) from None
        if attr is not None and not hasattr(m, attr):
            raise PipelineUnavailable(f"the {what} stage ({mod}) has no {attr} yet; cannot evaluate without it")


@dataclass(frozen=True)
class PipelineSpec:
    """What the campaign runner needs: the group function (picklable) and the group size."""

    group_fn: Any
    group_size: int
    closed_loop: bool
    land: bool = False
    """Each run flies on to touchdown and its touchdown is scored (closed loop only)."""


def spec_for(profile: Any, mode: str, land: bool = False) -> PipelineSpec:
    """The campaign functions of `mode` ("closed" or "open") for this profile (after require_stages); land: fly
    every run to touchdown (closed loop only: ProfileError naming --land otherwise)."""
    if land and mode != "closed":
        raise ProfileError("--land: landing runs are flown closed loop only (each run lands on its own navigation); "
                           "use --mode closed")
    require_stages(mode)
    _approach(profile, land)  # the aircraft file and the approach envelope: a profile outside it is refused (exit 2)
    # here, not as one failed run per worker
    size = profile.evaluation.flight_group
    if mode == "open":
        return PipelineSpec(open_loop_group, size, False)
    # closed loop shares no flight: one run per task, so each run is stored (and resumable) as it finishes
    if land:
        return PipelineSpec(functools.partial(closed_loop_group, land=True), 1, True, land=True)
    return PipelineSpec(closed_loop_group, 1, True)


def _score(
    profile: Any, run: int, truth: Any, nav: Any, clock_true: Any, gnss: Any = None, flight: Any = None,
    seed: int | None = None, bank_group: Any = None, memo: TruthMemo | None = None,
) -> RunResult:
    cfg = profile.evaluation
    fte = {}
    if flight is not None:  # closed loop: FTE is the deviation of the position guidance flew on
        g = flight.guidance_r_rwy
        fte = {"fte_lat_m": g[:, 1], "fte_vert_m": profile.runway.glidepath.deviation_rwy_m(g)}
    scalars, arrays, series = score_run(
        truth, nav, cfg, clock_bias_true_m=clock_true, keep_series=run < cfg.series_runs, memo=memo, **fte
    )
    if gnss is not None:
        scalars.update(_geometry_at_dh(gnss, scalars))
        g = profile.sensors.gnss
        if g is not None and g.service is not None:
            scalars.update(_lpv200_at_dh(gnss, scalars, g.service.sbas, truth))
    if series is not None and gnss is not None:
        series = {**series, **_geometry_series(gnss, series["t_s"])}
    counts = {}
    if cfg.integrity_on and gnss is not None and seed is not None:
        # the solution-separation bank, open loop on this run's (flown) truth with its own sensor draws
        from approachsim.campaign.integrity_campaign import score_with_bank  # stage (module docstring)

        s_int, counts, a_int = score_with_bank(profile, truth, seed, run, nav, HEIGHT_GRID_FT * units.FT,
                                               group=bank_group, memo=memo)
        scalars.update(s_int)
        arrays = {**arrays, **a_int}
    return RunResult(run=run, ok=True, scalars=scalars, arrays=arrays, series=series, counts=counts)


def _geometry_series(gnss: Any, t_s: Any) -> dict:
    """GPS geometry at the series times (latest GNSS sample): PDOP, and elevation / azimuth (deg) of each
    channel where it is above the mask (nan elsewhere), for the sky plot and DOP figure."""
    import numpy as np

    j = np.clip(np.searchsorted(gnss.t_s, t_s, side="right") - 1, 0, len(gnss.t_s) - 1)
    vis = np.asarray(gnss.visible)[j]
    out = {"pdop": np.asarray(gnss.pdop, dtype=float)[j]}
    el = np.where(vis, np.degrees(np.asarray(gnss.elevation_rad)[j]), np.nan)
    az = np.where(vis, np.degrees(np.asarray(gnss.azimuth_rad)[j]), np.nan)
    for c, prn in enumerate(np.asarray(gnss.prn)):
        out[f"el_deg_prn{int(prn):02d}"] = el[:, c]
        out[f"az_deg_prn{int(prn):02d}"] = az[:, c]
    return out


def _geometry_at_dh(gnss: Any, scalars: dict) -> dict:
    """One run's GPS geometry at each decision-height crossing (latest GNSS sample): PDOP / HDOP / VDOP of the
    channels used, satellites in view (above the mask) and used; the run's epoch offset (h) when drawn."""
    import numpy as np

    from approachsim.sensors.gnss.constellation import dops_ned  # stage (module docstring)

    out = {}
    for cat in CATEGORIES:
        key = CATEGORY_KEYS[cat]
        t = scalars.get(f"{key}_t_s")
        if t is None or not np.isfinite(t):
            continue
        j = int(np.clip(np.searchsorted(gnss.t_s, t, side="right") - 1, 0, len(gnss.t_s) - 1))
        used = np.asarray(gnss.valid)[j]
        p, h, v = dops_ned(np.asarray(gnss.elevation_rad)[j], np.asarray(gnss.azimuth_rad)[j], used)
        out.update({f"{key}_pdop": float(p), f"{key}_hdop": float(h), f"{key}_vdop": float(v),
                    f"{key}_sv_visible": float(np.sum(np.asarray(gnss.visible)[j])),
                    f"{key}_sv_used": float(np.sum(used))})
    if gnss.epoch_offset_s is not None:
        out["gnss_epoch_offset_h"] = float(gnss.epoch_offset_s) / 3600.0
    return out


def _lpv200_at_dh(gnss: Any, scalars: dict, sbas: bool, truth: Any) -> dict:
    """One run's LPV-200 columns (evaluate/lpv.py) from a GNSS service's record: the WLS protection levels with
    the broadcast sigmas (integrity/sbas.py) at the CAT I crossing's latest GNSS sample, LPV-200 available there,
    the fraction of GNSS epochs available up to it, whether the service is SBAS (an integrity basis), the epochs
    available, misleading and hazardously misleading down to it (evaluate/lpv.py count_misleading), and the
    snapshot WLS fix's vertical and horizontal error there (a stand-alone receiver's position error, the figure
    published SBAS accuracies describe; the navigation error blends it with the INS, baro and radar altimeter)."""
    import numpy as np

    from approachsim.evaluate.lpv import count_misleading  # stage (module docstring)
    from approachsim.integrity.sbas import (  # stage (module docstring)
        lpv200_available,
        protection_levels,
        snapshot_error_enu,
    )

    t = scalars.get("cat1_t_s")
    if t is None or not np.isfinite(t):
        return {}
    vpl, hpl = protection_levels(np.asarray(gnss.elevation_rad), np.asarray(gnss.azimuth_rad),
                                 np.asarray(gnss.valid), np.asarray(gnss.sigma_m))
    j = int(np.clip(np.searchsorted(gnss.t_s, t, side="right") - 1, 0, len(gnss.t_s) - 1))
    ok = lpv200_available(vpl, hpl)
    k = int(np.clip(np.searchsorted(truth.t_s, gnss.t_s[j], side="left"), 0, len(truth.t_s) - 1))
    r_sv = np.asarray(gnss.r_sv_ecef)[j]
    err = np.asarray(gnss.pseudorange_m)[j] - np.linalg.norm(r_sv - truth.r_ecef[k], axis=-1)
    # the snapshot fix's error at every GNSS epoch down to the DH (its latest sample j): MI / HMI against the PLs
    ks = np.clip(np.searchsorted(truth.t_s, gnss.t_s[: j + 1], side="left"), 0, len(truth.t_s) - 1)
    r_sv = np.asarray(gnss.r_sv_ecef)[: j + 1]
    err = np.asarray(gnss.pseudorange_m)[: j + 1] - np.linalg.norm(r_sv - truth.r_ecef[ks][:, None, :], axis=-1)
    d = snapshot_error_enu(np.asarray(gnss.elevation_rad)[: j + 1], np.asarray(gnss.azimuth_rad)[: j + 1],
                           np.asarray(gnss.valid)[: j + 1], np.asarray(gnss.sigma_m)[: j + 1], err)
    hor = np.hypot(d[:, 0], d[:, 1])
    n_av, n_mi, n_hmi = count_misleading(d[:, 2], hor, vpl[: j + 1], hpl[: j + 1])
    return {"lpv200_vpl_m": float(vpl[j]), "lpv200_hpl_m": float(hpl[j]), "lpv200_avail_dh": float(ok[j]),
            "lpv200_avail_fraction": float(np.mean(ok[: j + 1])), "lpv200_sbas": float(sbas),
            "lpv200_snapshot_vertical_m": float(d[-1, 2]), "lpv200_snapshot_horizontal_m": float(hor[-1]),
            "lpv200_available_epochs": float(n_av), "lpv200_mi_epochs": float(n_mi),
            "lpv200_hmi_epochs": float(n_hmi)}


def _gnss_closed_loop(source: Any, truth: Any) -> Any:
    """The GNSS record of a closed-loop run over its flown truth (geometry only: no receiver clock), or None."""
    import numpy as np

    e = source.errors.sensors.get("gnss")
    if e is None:
        return None
    keep = np.flatnonzero(e.rows < len(truth.t_s))
    return source.suite.sensors["gnss"].apply(truth, e.take(keep))


def _approach(profile: Any, land: bool = False) -> Any:
    """The Approach of a profile (flight.run), kept by the profile's value and `land` (`_approach_of`)."""
    return _approach_of(profile, bool(land))


@functools.lru_cache(maxsize=8)
def _approach_of(profile: Any, land: bool) -> Any:
    """The Approach of a profile, by (profile value, land): a profile's aircraft is parsed and its trimmed start
    solved once per worker process, not once per task (closed-loop tasks are one run each)."""
    from approachsim.flight.run import Approach  # stage (module docstring)

    if land:
        return Approach(profile, land=True)
    # fly a little below the lowest decision height so that its crossing is bracketed by samples
    return Approach(profile, stop_height_m=approach_stop_height_m(profile))


class _FlightKey:
    """A profile held by what its open-loop flight depends on (runway, aircraft, environment, terrain, rates and the
    stop height): the cases of a study that differ only in sensors or filter share one calm-air flight."""

    def __init__(self, profile: Any) -> None:
        self.profile = profile
        self.key = (profile.runway, profile.aircraft, profile.environment, profile.terrain, profile.rates,
                    approach_stop_height_m(profile))

    def __hash__(self) -> int:
        return hash(self.key)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, _FlightKey) and self.key == other.key


def _read_only(obj: Any, seen: set[int] | None = None) -> None:
    """Mark every numpy array reachable through obj's dataclass fields read-only (a flight shared by many groups:
    a write into it would reach the next group's runs; numpy raises instead)."""
    seen = set() if seen is None else seen
    if id(obj) in seen:
        return
    seen.add(id(obj))
    if isinstance(obj, np.ndarray):
        obj.flags.writeable = False
    elif dataclasses.is_dataclass(obj) and not isinstance(obj, type):
        for f in dataclasses.fields(obj):
            _read_only(getattr(obj, f.name), seen)


@functools.lru_cache(maxsize=2)
def _calm_flight(k: _FlightKey) -> Any:
    """The one flight of a calm-air profile (kept per worker process by its _FlightKey): without turbulence nothing
    of the flight depends on the seed or the run (the seed feeds only the Dryden noise), so every group's flight
    is this one, bit for bit (tests/unit/campaign: flights of two seeds and runs are equal); its arrays read-only."""
    flight = _approach(k.profile).fly(seed=0, run=0)
    _read_only(flight)
    return flight


def group_flight(profile: Any, seed: int, first: int) -> Any:
    """The open-loop flight of the group whose first run is `first`: flown with that run's turbulence, or, in calm
    air, the profile's one flight (_calm_flight)."""
    if profile.environment.turbulence == "none":
        return _calm_flight(_FlightKey(profile))
    return _approach(profile).fly(seed=seed, run=first)


def approach_stop_height_m(profile: Any) -> float:
    """Where an approach run (not a landing) stops: the IMU 20 ft below the lowest decision height, at least 5 ft
    above the threshold, m."""
    return max(min(profile.evaluation.dh_ft.values()) - 20.0, 5.0) * units.FT


def main_gear_lever_arms_m(approach: Any) -> Any:
    """(2, 3) the main gears' contact points relative to the IMU, body axes, m (the flight stage's
    Approach.main_gear_lever_arms_m, read once per Approach and so once per worker process and profile)."""
    return approach.main_gear_lever_arms_m


def _head(truth: Any, nav: Any, flight: Any, height_m: float) -> tuple[Any, Any, Any]:
    """The landing run's truth, navigation solution and flight result cut after the first row whose IMU height
    above the threshold is at or below height_m (where an approach run stops); unchanged when there is none."""
    import numpy as np

    below = np.flatnonzero(truth.r_rwy[:, 2] <= height_m)
    if below.size == 0:
        return truth, nav, flight
    m = int(below[0]) + 1
    n = len(truth)
    t_end = float(truth.t_s[m - 1])
    nav_kw = {}
    for f in dataclasses.fields(nav):
        v = getattr(nav, f.name)
        if isinstance(v, np.ndarray) and v.shape[:1] == (n,):
            nav_kw[f.name] = v[:m]
        elif f.name == "exclusions":
            nav_kw[f.name] = tuple(e for e in v if e.t_s <= t_end)
    head = truth.slice(slice(0, m))
    fl = dataclasses.replace(flight, truth=head, guidance_r_rwy=flight.guidance_r_rwy[:m],
                             guidance_v_ned=flight.guidance_v_ned[:m])
    return head, dataclasses.replace(nav, **nav_kw), fl


def _clock_truth(records: dict, k: int, t_s: Any) -> Any:
    """Run k's true receiver clock bias on the truth time base (linear between GNSS samples), or None."""
    import numpy as np

    g = records.get("gnss")
    if g is None:
        g = records.get("pseudolite")
    if g is None:
        return None
    return np.interp(t_s, g.t_s, np.asarray(g.clock_bias_m)[k])


def _reached_all(profile: Any, flight: Any, land: bool = False) -> str | None:
    """None when the flight was a successful approach through every decision height, else why not (a failed
    approach, flight.envelope's criteria, counts as a failed run with its reason; land: a landing run that failed
    below the lowest decision height is a failed landing)."""
    low = min(profile.evaluation.dh_ft.values())
    if not flight.ok:
        what = "failed landing" if land and flight.lowest_height_ft < low else "failed approach"
        return f"{what}: {flight.termination} (lowest {flight.lowest_height_ft:.0f} ft)"
    if flight.lowest_height_ft < low:
        return None
    return (f"flight ended above the {low:g} ft decision height ({flight.termination}, "
            f"lowest {flight.lowest_height_ft:.0f} ft)")


def open_loop_group(profile: Any, seed: int, runs: Sequence[int]) -> list[RunResult]:
    """Fly the group's truth once (turbulence of its first run), then sense, navigate and score each run.

    Sensors and filters run batched over the group's runs (run axis first); every run's noise comes from its
    own streams (seed, run, name), so a run's result does not depend on which runs share its batch. With the
    optimal filter the runs share their covariance and gains (NavSystem.shares_covariance; a run's covariance
    depends only on the truth and its own measurement schedule, so this holds there too).
    """
    from approachsim.loop.paths import open_loop_path  # stage (module docstring)
    from approachsim.nav.system import NavSystem  # stage (module docstring)
    from approachsim.sensors.states import start_states
    from approachsim.sensors.suite import SensorSuite

    size = profile.evaluation.flight_group
    first = (runs[0] // size) * size
    flight = group_flight(profile, seed, first)
    why = _reached_all(profile, flight)
    if why is not None:
        return [RunResult.failed(i, f"shared flight of runs {first}-{first + size - 1}: {why}") for i in runs]
    truth = flight.truth
    suite = SensorSuite.from_profile(profile)
    errors = suite.draw(truth.t_s, seed, list(runs))
    records = suite.apply(truth, errors)  # = suite.measure(truth, seed, runs)
    nav = NavSystem.from_profile(profile)
    memo = TruthMemo(truth)  # the group's shared work on its truth (approachsim/memo.py): this task owns it
    # optimal filter: one covariance per measurement schedule for all runs (linearized along the shared truth);
    # robust / adaptive configurations filter each run on its own
    # with the integrity bank: the pass keeps each run's start and INS for its bank (campaign/bankpass.py)
    keep = {} if profile.evaluation.integrity_on else None
    navruns = nav.run(truth, records, [stream(seed, i, "nav") for i in runs],
                      shared_covariance=nav.shares_covariance(), states=start_states(suite, truth, errors), keep=keep,
                      memo=memo)
    group = None
    if keep is not None:
        from approachsim.campaign.bankpass import GroupInputs  # stage (module docstring)

        group = GroupInputs(records, keep)
    out = []
    path = f"flight={flight.loop} {open_loop_path(nav)}"
    for k, (i, nr) in enumerate(zip(runs, navruns, strict=True)):
        try:
            g = records.get("gnss")
            r = _score(profile, i, truth, nr.solution, _clock_truth(records, k, truth.t_s),
                       None if g is None else g.run(k), seed=seed, bank_group=None if group is None else (group, k),
                       memo=memo)
            out.append(dataclasses.replace(r, path=path))
        except Exception as e:
            out.append(RunResult.failed(i, f"{type(e).__name__}: {e}"))
    return out


def closed_loop_group(profile: Any, seed: int, runs: Sequence[int], land: bool = False) -> list[RunResult]:
    """Each run flies on its own navigation solution (loop.closed_loop.NavInTheLoop as the flight's navigation
    source); the aircraft is parsed and linearized once per task. land: each run flies on to touchdown, its
    navigation is scored down to where an approach run stops and its touchdown is scored (module docstring)."""
    import numpy as np

    from approachsim.loop.closed_loop import NavInTheLoop  # stage (module docstring)

    approach = _approach(profile, land)
    gear = main_gear_lever_arms_m(approach) if land else None
    out = []
    for i in runs:
        try:
            source = NavInTheLoop(profile, seed, i, max_time_s=approach.time_budget_s)  # its draws cover the flight
            flight = approach.fly(seed=seed, run=i, nav_source=source)
            why = _reached_all(profile, flight, land)
            if why is not None:
                raise RuntimeError(why)
            truth = flight.truth
            nav = source.result(truth).solution
            td = {}
            if land:
                td = touchdown_scalars(truth, gear, approach.ground_contact_m, slope=approach.profile.runway.slope)
                truth, nav, flight = _head(truth, nav, flight, approach_stop_height_m(profile))
            clk = source.errors.clock
            clock_true = None if clk is None else np.interp(truth.t_s, clk.t_s, np.asarray(clk.series["bias"]))
            r = _score(profile, i, truth, nav, clock_true, _gnss_closed_loop(source, truth), flight, seed,
                       memo=TruthMemo(truth))
            if td:
                r = dataclasses.replace(r, scalars={**r.scalars, **td})
            out.append(dataclasses.replace(r, path=f"flight={flight.loop} {source.path.name}"))
        except Exception as e:
            out.append(RunResult.failed(i, f"{type(e).__name__}: {e}"))
    return out


closed_loop_group.kernels = "closed"  # type: ignore[attr-defined]  # its runs' kernels: core/manifests/closed.pkl
open_loop_group.kernels = "open"  # type: ignore[attr-defined]  # its runs' kernels: core/manifests/open.pkl
