"""The flight loop's compiled step with the closed loop's navigation row, on the packed navigation arrays
(core/loop/nav_row.py `views`): core/loop/flight_step.py fly_step, then the navigation's row (inloop.nav_row), the
guidance and fly_control, with three navigation arguments (the work vector nw and the packed fa, ia) instead of the
twelve arrays of the earlier fly_step_nav it replaced. The flight makes one such call per JSBSim step, and numba
unboxes every array argument of every call (~0.13 us each): nine fewer arrays save ~1.2 us a step, ~35 ms of a
31,000-step approach. The same kernels in the same order as fly_step_nav ran them, on views of the same numbers, so
the same bits (the closed-loop baselines of `approachsim regress` stay identical; the flown closed loop against the
open-loop pass: tests/integration/test_nav_inloop_baro.py, test_nav_closed_loop.py)."""

from __future__ import annotations

from typing import Any

import numpy as np

from approachsim.core.jit import njit
from approachsim.core.layouts import ROW_T
from approachsim.core.loop import flight_step as fk
from approachsim.core.loop import nav_row as ik

Array = np.ndarray


@njit(cache=True)
def fly_step_closed(k: int, raw: Any, buf: Array, nu: Array, par: Array, st: Array, nw: Array, fa: Array,
                    ia: Array) -> tuple[int, int, float, float, float, float, float, float, float, float, bool]:
    """One closed-loop step on the packed arrays: fly_step, the navigation's row k (inloop.nav_row), and when it
    needs nothing of Python the guidance into its row k and the autopilot on it. Returns (TERM_* code, NAV_* bits,
    elevator, aileron, rudder, throttle, gusts (ft/s), terrain (ft), read the gear next step)."""
    code, de, da, dr, thr, gn, ge, gd, terr_ft, near = fk.fly_step(k, raw, buf, nu, par, st, False)
    cg, ca, rows, snap, baro_j, baro_e, lag_w, dth, dv, guidance = ik.views(nw, fa, ia)
    ncode = ik.nav_row(k, buf, nw, cg, ca, rows, snap, baro_j, baro_e, lag_w, dth, dv)
    if ncode == 0:
        ik.nav_guidance(nw, buf[k, ROW_T], guidance[k])
        if code == fk.TERM_NONE:
            de, da, dr, thr = fk.fly_control(k, guidance, buf, par, st)
    return code, ncode, de, da, dr, thr, gn, ge, gd, terr_ft, near


@njit(cache=True)
def fly_control_closed(k: int, buf: Array, par: Array, st: Array, nw: Array, fa: Array, ia: Array
                       ) -> tuple[float, float, float, float]:
    """On the packed arrays: after Python acted at row k, the guidance into its row k and the autopilot on it."""
    guidance = ik.views(nw, fa, ia)[9]
    ik.nav_guidance(nw, buf[k, ROW_T], guidance[k])
    return fk.fly_control(k, guidance, buf, par, st)
