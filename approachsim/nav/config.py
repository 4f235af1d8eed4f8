"""The profile's [nav] table: which filter and its tuning, aiding rate, feedback, baro loop, initial errors.

    [nav]
    filter = "ekf"                 # a name in nav/registry.py FILTERS
    aiding_rate_hz = 1.0           # filter predict / update rate (seed 002: 1 s)
    feedback = false               # false: feed-forward (output = INS - estimated error, seed 002); true: resets
    gps_coupling = "tight"         # "tight" (pseudoranges) or "loose" (position fixes from the pseudoranges)
    channel_states = true          # per-channel range-error states (honest covariance) or white-noise R only
    gps_sigma_scale = 1.0          # channel_states = false only: the filter's pseudorange 1-sigma = this x the
                                   #   receiver's nominal (R tuning for the correlated errors left out of the states)
    clock_q_scale = 1.0            # the filter's receiver-clock process noise Q = this x the oscillator's (Q tuning
                                   #   of the 2-state clock, Gray & Maybeck sec. 6; the truth's clock is unchanged)
    baro_loop = "none"             # "none" | "constant" | "tanh" | "sinh": INS 3rd-order damping loop (seed 003)
    baro_loop_tau_s = 100.0        # loop time constant (seed 003 eq. 5), s
    baro_loop_b_per_m = 0.5        # adaptive slope b of tanh / sinh (eq. 7, 16), 1/m
    [nav.filter_tuning]            # passed to the filter factory (robust gates, U-D options ...)
    [nav.initial_error]            # 1-sigma INS errors at the start of the approach (seed 002 assumption 12:
    position_m = 5.0               #   after an 8-min alignment and an hour of GPS-aided flight)
    velocity_mps = 0.05
    tilt_mrad = 0.05
    heading_mrad = 0.5
    start = "converged"            #   "converged": the converged pre-approach state (nav/initial.py) built from
    converge_s = 600.0             #   this prior and converge_s of aiding at the start; "prior": drawn from it
    [nav.fde]                      # online fault detection and exclusion (nav/fde.py), off by default
    enabled = false
    category = "CAT II"            # whose continuity budget sets the false-alert allocation
    window = 20                    # epochs of the w-test moving sum (gradual failures)
    rollback_epochs = 30           # epochs re-run without the excluded source after an exclusion
    [nav.terrain_database]         # the filter's terrain database = truth + bias + along-track Gauss-Markov
    bias_sigma_m = 0.430           #   (nav/terrain_db.py: ICAO Annex 15 Area 4 / Area 2 accuracies); all zero:
    sigma_m = 0.430                #   the truth terrain exactly
    outer_sigma_m = 1.772
    area4_length_m = 900.0
    correlation_m = 300.0

A bad key or value raises ProfileError naming the field; an unknown filter fails here, at load.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

from approachsim.config import ProfileError, Section
from approachsim.integrity.requirements import REQUIREMENTS, IntegrityRequirement
from approachsim.nav import registry
from approachsim.nav import terrain_db as tdb
from approachsim.nav import vertical_loop as vl

LOOP_FORMS = ("none",) + tuple(vl.GAIN_FORMS)
START_MODES = ("converged", "prior")
"""[nav.initial_error] start: the converged pre-approach state, or today's independent draw from the prior."""


@dataclass(frozen=True)
class InitialError:
    """1-sigma INS errors of the prior P0, SI, and how the run starts from it: start "prior" draws the INS
    errors from P0 (independent of the sensor errors, zero sensor-state estimates); "converged" (default) from
    the filter's covariance after converge_s (s) of aiding at the start state, jointly with the realized
    sensor errors (nav/initial.py)."""

    position_m: float = 5.0
    velocity_mps: float = 0.05
    tilt_rad: float = 0.05e-3
    heading_rad: float = 0.5e-3
    start: str = "converged"
    converge_s: float = 600.0


@dataclass(frozen=True)
class FdeConfig:
    """[nav.fde]: enabled, the category whose continuity budget sets the thresholds, the moving-sum window
    (epochs) and the rollback depth (epochs) after an exclusion."""

    enabled: bool = False
    category: str = "CAT II"
    window: int = 20
    rollback_epochs: int = 30

    def __post_init__(self) -> None:
        if self.category not in REQUIREMENTS:
            raise ValueError(f"category must be one of {', '.join(REQUIREMENTS)}; got {self.category!r}")
        if int(self.window) != self.window or not 1 <= self.window <= 600:
            raise ValueError(f"window must be an integer in [1, 600] epochs; got {self.window!r}")
        if int(self.rollback_epochs) != self.rollback_epochs or not 0 <= self.rollback_epochs <= 600:
            raise ValueError(f"rollback_epochs must be an integer in [0, 600]; got {self.rollback_epochs!r}")

    @property
    def requirement(self) -> IntegrityRequirement:
        """The category's integrity requirement."""
        return REQUIREMENTS[self.category]


@dataclass(frozen=True)
class NavConfig:
    """The navigation system of a profile (module docstring lists the keys)."""

    filter: str = "ekf"
    filter_tuning: tuple[tuple[str, Any], ...] = ()
    """The filter's tuning keywords as (key, value) pairs (a tuple: the profile stays hashable and picklable)."""
    aiding_rate_hz: float = 1.0
    feedback: bool = False
    gps_coupling: str = "tight"
    channel_states: bool = True
    gps_sigma_scale: float = 1.0
    """The filter's pseudorange 1-sigma as a multiple of the receiver's nominal one (channel_states = false: the
    white-noise R that stands for the range errors the filter has no states for); 1.0: R = their full variance."""
    clock_q_scale: float = 1.0
    """The filter's receiver-clock process noise (both spectral densities S_f, S_g) as a multiple of the
    oscillator's (nav/noise.py): Q tuning; the truth's clock draws the oscillator's own."""
    baro_loop: str = "none"
    baro_loop_tau_s: float = 100.0
    baro_loop_b_per_m: float = 0.5
    initial_error: InitialError = field(default_factory=InitialError)
    fde: FdeConfig = field(default_factory=FdeConfig)
    terrain_database: tdb.TerrainDbConfig = field(default_factory=tdb.TerrainDbConfig)

    def make_filter(self) -> Any:
        """The filter object named by `filter`, with its tuning."""
        return registry.make_filter(self.filter, **dict(self.filter_tuning))

    def loop_gains(self) -> vl.LoopGains | None:
        """The damping-loop gains (None without a loop). Adaptive forms keep the constant small-signal gains:
        C_KF = C / b so that C_KF f(b e) has slope C at e = 0 (seed 003 eq. 7 linearizes to eq. 3)."""
        if self.baro_loop == "none":
            return None
        g = vl.constant_gains(self.baro_loop_tau_s)
        if self.baro_loop == "constant":
            return g
        b = self.baro_loop_b_per_m
        return vl.LoopGains(g.c1 / b, g.c2 / b, g.c3, form=self.baro_loop, b1_per_m=b, b2_per_m=b)


DEFAULT_NAV = NavConfig()


def parse_nav(s: Section) -> NavConfig:
    """Parse [nav]; absent keys take the defaults above."""
    name = s.string("filter", "ekf")
    tuning = s.raw("filter_tuning", {})  # the filter factory validates its own keys
    if not isinstance(tuning, dict):
        raise ProfileError(f"{s.path}.filter_tuning: must be a table, got {type(tuning).__name__}")
    rate = s.number("aiding_rate_hz", 1.0, lo=0.01, hi=100.0, unit="Hz")
    feedback = s.boolean("feedback", False)
    coupling = s.string("gps_coupling", "tight", choices=("tight", "loose"))
    channel = s.boolean("channel_states", True)
    sigma_scale = s.number("gps_sigma_scale", 1.0, lo=1.0, hi=1000.0)
    if channel and sigma_scale != 1.0:
        raise ProfileError(f"{s.path}.gps_sigma_scale: tunes the white-noise R of a filter without channel states; "
                           "set channel_states = false or leave gps_sigma_scale at 1.0")
    clock_q = s.number("clock_q_scale", 1.0, lo=1e-3, hi=1e6)
    loop = s.string("baro_loop", "none", choices=LOOP_FORMS)
    tau = s.number("baro_loop_tau_s", 100.0, lo=1.0, hi=10000.0, unit="s")
    b = s.number("baro_loop_b_per_m", 0.5, lo=0.0, lo_open=True, hi=100.0, unit="1/m")
    ie = s.section("initial_error")
    init = InitialError(
        position_m=ie.number("position_m", 5.0, lo=0.0, hi=1e5, unit="m"),
        velocity_mps=ie.number("velocity_mps", 0.05, lo=0.0, hi=100.0, unit="m/s"),
        tilt_rad=ie.number("tilt_mrad", 0.05, lo=0.0, hi=100.0, unit="mrad") * 1e-3,
        heading_rad=ie.number("heading_mrad", 0.5, lo=0.0, hi=1000.0, unit="mrad") * 1e-3,
        start=ie.string("start", "converged", choices=START_MODES),
        converge_s=ie.number("converge_s", 600.0, lo=0.0, hi=36000.0, unit="s"),
    )
    ie.done()
    fs = s.section("fde")
    fde = FdeConfig(
        enabled=fs.boolean("enabled", False),
        category=fs.string("category", "CAT II", choices=tuple(REQUIREMENTS)),
        window=fs.integer("window", 20, lo=1, hi=600),
        rollback_epochs=fs.integer("rollback_epochs", 30, lo=0, hi=600),
    )
    fs.done()
    terrain_database = tdb.parse(s.section("terrain_database"))
    s.done()
    cfg = NavConfig(
        filter=name, filter_tuning=tuple(sorted(tuning.items())), aiding_rate_hz=rate, feedback=feedback,
        gps_coupling=coupling, channel_states=channel, gps_sigma_scale=sigma_scale, clock_q_scale=clock_q,
        baro_loop=loop, baro_loop_tau_s=tau, baro_loop_b_per_m=b, initial_error=init, fde=fde,
        terrain_database=terrain_database,
    )
    try:
        cfg.make_filter()  # unknown filter or bad tuning fails at load, not an hour into a campaign
    except ProfileError:
        raise
    except (TypeError, ValueError) as e:
        raise ProfileError(f"{s.path}.filter_tuning: {e}") from None
    return cfg
