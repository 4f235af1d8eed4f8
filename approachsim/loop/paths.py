"""Which code runs a closed-loop approach, chosen once per run by one function, by name and with its reasons.

The same navigation runs on one of several paths that give the same numbers (tools/closed_loop_identity.py): the
fast compiled ones where the configuration allows, the readable numpy ones (their test oracles) elsewhere. The
choice used to be made by predicates spread over the flight, the navigation source and the engine; `choose` makes it
from the configuration and the oracle switches, before the first row, and the run records the path's name
(RunResult.path, details.json "paths"), so a user sees which code produced the numbers.

    row     "compiled"  the navigation row inside the flight's compiled step (core/loop/nav_row.py)
            "generic"   NavInTheLoop.step in Python every row (a quantized or faulted IMU: not affine)
    epoch   "fused"     the compiled aiding epoch on inputs straight from the sensors' kernels (core/loop/aiding.py
                        direct_inputs, no records)
            "records"   the compiled aiding epoch on the sensors' one-row records
            "generic"   the Navigator's numpy epoch (online FDE, feedback, the robust or U-D filters, loose coupling,
                        an adaptive loop, carrier phase; or the oracle switch `fast_epochs = False`)
    baro    "compiled"  a plain altimeter's damping-loop samples made in the compiled row; "python": a faulted one's
            (or one sensing an inversion: sensors/baro.py) by its model at the row; "none"
    sigmas  "compiled"  the GPS channel sigmas of the compiled epoch compiled (core/loop/aiding.py channel_sigmas; a
                        GNSS service's: core/sensors/gnss.py service_channel_sigmas);
            "numpy": the numpy formulas (GBAS, or `compiled_sigmas = False`); "none": no compiled epoch or no GPS

The flight adds its own part, decided where JSBSim is (flight/run.py `flight_loop`): "direct" (JSBSim's C++ called
from compiled code) or "python" (JSBSim's Python wrapper every step).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from approachsim.nav.engine import EpochEngine
from approachsim.sensors.baro import Baro, PreparedBaro
from approachsim.sensors.gnss.receiver import PreparedGnss
from approachsim.sensors.radalt import PreparedRadalt


@dataclass(frozen=True)
class LoopPath:
    """The closed loop's path of one run: each part's name and why it took it."""

    row: str
    epoch: str
    baro: str
    sigmas: str
    reasons: tuple[tuple[str, str], ...]
    """(part, reason) for every part that did not take its fastest form."""

    @property
    def name(self) -> str:
        """One word a part, e.g. 'row=compiled epoch=fused baro=compiled sigmas=compiled'."""
        return f"row={self.row} epoch={self.epoch} baro={self.baro} sigmas={self.sigmas}"

    def reason(self, part: str) -> str | None:
        """Why `part` did not take its fastest form (None: it did)."""
        return dict(self.reasons).get(part)


def epoch_unavailable(source: Any) -> str | None:
    """Why the aiding epochs cannot run compiled (None: they can): the compiled epoch is the per-run EKF's
    (nav/engine.py: the optimal 'ekf', tight GPS coupling, a constant or no baro loop, no online FDE) with
    feed-forward output (feedback corrects the INS in numpy: Navigator._feedback), without carrier phase."""
    nav = source.nav
    if nav.nav.fde.enabled:
        return "online FDE ([nav.fde] enabled): nav/fde.py's epoch"
    if not EpochEngine.supports(nav):
        return "no compiled epoch for this filter configuration (nav/engine.py EpochEngine.supports)"
    if nav.nav.feedback:
        return "feedback ([nav] feedback = true): the INS reset in numpy"
    if nav.layout.has("amb"):
        return "carrier phase: the ambiguity resets at new arcs"
    return None


def _direct_unavailable(source: Any) -> str | None:
    """Why the compiled epoch's sensor inputs cannot come straight from the sensors' kernels (None: they can): every
    aiding sensor needs its direct form: a plain (not faulted) baro and radar altimeter, a one-run, one-sky GPS
    receiver of code ranging without GBAS or carrier phase, stand-alone or with a GNSS service (the pseudolite's
    record is made as before)."""
    ps = source.prepared.sensors
    for name, kind in (("baro", PreparedBaro), ("radalt", PreparedRadalt), ("gnss", PreparedGnss)):
        p = ps.get(name)
        if p is not None and type(p) is not kind:
            return f"the {name} is wrapped ({type(p).__name__}: a fault or another model): its records"
    b = ps.get("baro")
    if b is not None and b.baro.departs:
        return "the baro senses a departure from the constant-dT air (an inversion): its records"
    g = ps.get("gnss")
    if g is not None:
        if g.rx.budget.gbas is not None:
            return "GBAS corrections: the receiver's records"
        if g.rx.carrier is not None:
            return "carrier phase: the receiver's records"
        if g.per_run or g.errors.batched:
            return "a receiver of several skies or runs: its records"
    return None


def choose(source: Any) -> LoopPath:
    """The path of closed-loop source `source` (loop/closed_loop.py NavInTheLoop) for its run, from its
    configuration and its oracle switches (fast_epochs, direct_inputs, compiled_sigmas)."""
    reasons: list[tuple[str, str]] = []
    if source.imu_affine_terms() is None:
        row = "generic"
        reasons.append(("row", "the IMU is quantized or faulted (not affine): every sample through its model"))
    else:
        row = "compiled"
    why = epoch_unavailable(source) if source.fast_epochs else "fast_epochs = False (the oracle)"
    if why is not None:
        epoch = "generic"
        reasons.append(("epoch", why))
    else:
        direct = _direct_unavailable(source) if source.direct_inputs else "direct_inputs = False (the oracle)"
        epoch = "fused" if direct is None else "records"
        if direct is not None:
            reasons.append(("epoch", direct))
    baro = source.suite.sensors.get("baro")
    if baro is None or source.errors.sensors.get("baro") is None:
        baro_path = "none"
    elif type(baro) is Baro and row == "compiled" and not baro.departs:
        baro_path = "compiled"
    else:
        baro_path = "python"
        reasons.append(("baro", "a wrapped altimeter (a fault), an inversion or the generic row: its model at the "
                                "row"))
    b = source.nav.noise_model.sensors.gnss
    g = None if b is None else b.budget()
    if epoch == "generic" or g is None or source.nav.layout.n_sv == 0:
        sigmas = "none"
    elif g.gbas is not None or not source.compiled_sigmas:
        sigmas = "numpy"
        reasons.append(("sigmas", "GBAS channel sigmas" if g.gbas is not None else "compiled_sigmas = False"))
    else:
        sigmas = "compiled"
    return LoopPath(row, epoch, baro_path, sigmas, tuple(reasons))


def open_loop_path(nav: Any) -> str:
    """The open loop's path of a group of runs on one flown truth (campaign/pipeline.py open_loop_group):
    "epoch=shared" (the compiled epochs, one covariance per measurement schedule: NavSystem.shares_covariance, which
    nav/engine.py's compiled epoch needs too) or "epoch=generic" (the Navigator's numpy epochs, each run on its own:
    robust, adaptive, U-D, loose coupling, online FDE)."""
    return "epoch=shared" if nav.shares_covariance() else "epoch=generic"
