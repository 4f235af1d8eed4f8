"""Third-order baro-inertial vertical damping loop, constant and adaptive gains (Sokolovic, Dikic & Stancic).

The INS vertical channel is unstable (gravity falls with height: the altitude error grows as
exp(t sqrt(2 g / R))). The loop drives the INS altitude towards the baro altitude through three gains on
the loop error e = h_ins - h_baro (seed 003, Fig. 1, eq. 3):

    h'  = v_up - k1(e)                     (C1 branch)
    v'  = f_up - g(h) - k2(e) - a_c        (C2 branch; a_c: compensator output)
    a_c' = C3 e                            (integral branch, removes the steady-state error)

The linear loop has k1 = C1 e, k2 = C2 e; its error dynamics (eq. 3) have the characteristic equation
(eq. 4) s^3 + C1 s^2 + (C2 - 2 g0 / R0) s + C3 = 0, with all three poles at -1/tau for the gains of eq. 5:
C1 = 3/tau, C2 = 3/tau^2 + 2 g0/R0, C3 = 1/tau^3. The adaptive forms (eq. 7, 16) replace the C1, C2
branches by C_KF tanh(b e) or C_KF sinh(b e); the integral branch stays linear.

Conventions: height and vertical velocity up-positive (v_up = -v_D); f_up is the vertical specific force,
up-positive (about +g at rest). Everything is a plain array function: pass arrays of shape (runs,) to step
many Monte Carlo runs at once. The nav core calls `step` once per IMU (or baro) interval.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

if TYPE_CHECKING:  # python-control imports matplotlib.pyplot (~0.5 s): loaded where a loop is analysed
    import control

Array = np.ndarray

G0_MPS2 = 9.80665
"""Standard gravity g0 (m/s^2) in the 2 g0 / R0 term of eq. 4-5."""
R0_M = 6_371_000.0
"""Mean Earth radius R0 (m) in the 2 g0 / R0 term of eq. 4-5."""

GainForm = Literal["constant", "tanh", "sinh"]
GAIN_FORMS: tuple[str, ...] = ("constant", "tanh", "sinh")


@dataclass(frozen=True)
class LoopGains:
    """Gains of the 3rd-order loop (seed 003 eq. 3, 7, 16).

    c1 (1/s for 'constant'; m/s for the adaptive forms, the amplitude C1KF), c2 (1/s^2 or m/s^2 for the
    adaptive forms, C2KF), c3 (1/s^3, always linear); form: 'constant' (k = C e), 'tanh' (k = C tanh(b e)) or
    'sinh' (k = C sinh(b e)); b1, b2 (1/m): the slopes inside tanh / sinh of the C1 and C2 branches.
    """

    c1: float
    c2: float
    c3: float
    form: GainForm = "constant"
    b1_per_m: float = 1.0
    b2_per_m: float = 1.0

    def __post_init__(self) -> None:
        if self.form not in GAIN_FORMS:
            raise ValueError(f"form: must be one of {', '.join(GAIN_FORMS)}; got {self.form!r}")
        for name in ("c1", "c2", "c3", "b1_per_m", "b2_per_m"):
            value = getattr(self, name)
            if not np.isfinite(value) or value <= 0.0:
                raise ValueError(f"{name}: must be a positive finite number; got {value!r}")

    def linearized(self) -> LoopGains:
        """The small-signal constant gains: C b for tanh and sinh (d/de C f(b e) at e = 0), unchanged else."""
        if self.form == "constant":
            return self
        return LoopGains(self.c1 * self.b1_per_m, self.c2 * self.b2_per_m, self.c3)


def constant_gains(tau_s: float, *, g0_mps2: float = G0_MPS2, r0_m: float = R0_M) -> LoopGains:
    """Seed 003 eq. 5: C1 = 3/tau, C2 = 3/tau^2 + 2 g0/R0, C3 = 1/tau^3 (all poles at -1/tau; tau in s)."""
    if not np.isfinite(tau_s) or tau_s <= 0.0:
        raise ValueError(f"tau_s: must be a positive finite time constant in s; got {tau_s!r}")
    return LoopGains(3.0 / tau_s, 3.0 / tau_s**2 + 2.0 * g0_mps2 / r0_m, 1.0 / tau_s**3)


def characteristic_polynomial(gains: LoopGains, *, g0_mps2: float = G0_MPS2, r0_m: float = R0_M) -> Array:
    """Seed 003 eq. 4: coefficients [1, C1, C2 - 2 g0/R0, C3] of the (linearized) loop, highest power first."""
    lin = gains.linearized()
    return np.array([1.0, lin.c1, lin.c2 - 2.0 * g0_mps2 / r0_m, lin.c3])


def error_dynamics(gains: LoopGains, *, g0_mps2: float = G0_MPS2, r0_m: float = R0_M) -> control.StateSpace:
    """Seed 003 eq. 3 as a python-control state-space system (linearized gains).

    States [dh (m), dv_up (m/s), da (m/s^2)]; inputs [dh_baro (m), dA_z (m/s^2)]; output dh (m):
        dh'  = dv - C1 (dh - dh_B)
        dv'  = dA_z - C2 (dh - dh_B) - da + 2 ws^2 dh,   2 ws^2 = 2 g0/R0
        da'  = C3 (dh - dh_B)
    """
    lin = gains.linearized()
    c = 2.0 * g0_mps2 / r0_m
    A = np.array([[-lin.c1, 1.0, 0.0], [c - lin.c2, 0.0, -1.0], [lin.c3, 0.0, 0.0]])
    B = np.array([[lin.c1, 0.0], [lin.c2, 1.0], [-lin.c3, 0.0]])
    C = np.array([[1.0, 0.0, 0.0]])
    D = np.zeros((1, 2))
    import control

    return control.ss(A, B, C, D)


def closed_loop_poles(gains: LoopGains, *, g0_mps2: float = G0_MPS2, r0_m: float = R0_M) -> Array:
    """Poles (1/s) of the linearized loop, from python-control (roots of eq. 4)."""
    import control

    return np.asarray(control.poles(error_dynamics(gains, g0_mps2=g0_mps2, r0_m=r0_m)))


def branch_corrections(gains: LoopGains, e_m: Array) -> tuple[Array, Array]:
    """The C1 and C2 branch signals k1(e) (m/s), k2(e) (m/s^2) for loop error e = h_ins - h_baro (m).

    constant: C e (eq. 3); tanh: C_KF tanh(b e) (eq. 7, 16); sinh: C_KF sinh(b e) (eq. 16).
    """
    e = np.asarray(e_m, dtype=float)
    if gains.form == "constant":
        return gains.c1 * e, gains.c2 * e
    f = np.tanh if gains.form == "tanh" else np.sinh
    return gains.c1 * f(gains.b1_per_m * e), gains.c2 * f(gains.b2_per_m * e)


@dataclass(frozen=True)
class VerticalChannel:
    """State of the damped vertical channel; arrays of one shape (e.g. (runs,)).

    h_m: INS altitude (m); v_up_mps: INS vertical velocity, up-positive (m/s); a_comp_mps2: compensator
    output a_c of the integral branch (m/s^2, an estimate of the vertical accelerometer error).
    """

    h_m: Array
    v_up_mps: Array
    a_comp_mps2: Array


def init_channel(
    h_m: Array | float, v_up_mps: Array | float = 0.0, a_comp_mps2: Array | float = 0.0
) -> VerticalChannel:
    """A channel at altitude h_m (m) and vertical velocity v_up_mps (m/s) with a zero compensator."""
    h = np.asarray(h_m, dtype=float)
    return VerticalChannel(
        h.copy(),
        np.broadcast_to(np.asarray(v_up_mps, dtype=float), h.shape).copy(),
        np.broadcast_to(np.asarray(a_comp_mps2, dtype=float), h.shape).copy(),
    )


def step(
    ch: VerticalChannel,
    f_up_mps2: Array | float,
    h_baro_m: Array | float,
    g_mps2: Array | float,
    dt_s: float,
    gains: LoopGains,
    *,
    coriolis_up_mps2: Array | float = 0.0,
) -> VerticalChannel:
    """Advance the damped vertical channel by dt_s (s): seed 003 eq. 3 (constant) / eq. 7 (adaptive).

    f_up_mps2: vertical specific force, up-positive (m/s^2); h_baro_m: baro altitude (m); g_mps2: gravity
    magnitude at the INS altitude (m/s^2; its decrease with height is what makes the channel unstable);
    coriolis_up_mps2: Coriolis and transport-rate terms of eq. 2, up-positive (m/s^2).
    Integration: the branches are evaluated on the loop error at the start of the interval; velocity
    explicitly, altitude with the trapezoid of the old and new velocity.
    """
    e = ch.h_m - np.asarray(h_baro_m, dtype=float)  # loop error e = h_ins - h_baro
    k1, k2 = branch_corrections(gains, e)
    a_comp = ch.a_comp_mps2 + gains.c3 * e * dt_s  # a_c' = C3 e
    v_up = ch.v_up_mps + (np.asarray(f_up_mps2) - np.asarray(g_mps2) + np.asarray(coriolis_up_mps2) - k2
                          - ch.a_comp_mps2) * dt_s  # v' = f - g - k2(e) - a_c
    h = ch.h_m + (0.5 * (ch.v_up_mps + v_up) - k1) * dt_s  # h' = v - k1(e)
    return VerticalChannel(h, v_up, a_comp)


def gravity_flat_mps2(h_m: Array | float, *, g0_mps2: float = G0_MPS2, r0_m: float = R0_M) -> Array:
    """Gravity magnitude g0 (R0 / (R0 + h))^2 (m/s^2) at height h_m (m), the model behind 2 g0 / R0 in eq. 4."""
    return g0_mps2 * (r0_m / (r0_m + np.asarray(h_m, dtype=float))) ** 2
