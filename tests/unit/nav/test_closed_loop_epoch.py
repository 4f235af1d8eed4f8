"""The closed loop's compiled aiding epoch (nav/kernels/closed_loop_epoch.py, NavInTheLoop._fast_epoch) against its
oracle, the Navigator's numpy path around the same per-run EKF epoch (NavInTheLoop.fast_epochs = False): JSBSim
flies the same seconds of an approach with each, and everything the flight and the navigation give is the same bits.

Why exact and not a floor (tests/floors.py): the compiled epoch is the same kernels/epoch.own_epoch on the same
inputs (Observations.at's selections made directly from the one-row records, the GPS channel sigmas by the same
numpy formulas), plus copies and the one division f_sum / dt the numpy path makes too; no operation is reordered, so
there is no rounding to bound (and none under NUMBA_CPU_NAME=generic either: both paths call the one kernel)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim.flight.run import Approach
from approachsim.nav.closed_loop import NavInTheLoop
from approachsim.profile import parse_profile

pytestmark = pytest.mark.equality

PROFILES = Path(__file__).resolve().parents[3] / "profiles"


def _profile(name: str, **nav):
    path = PROFILES / name
    d = tomllib.loads(path.read_text(encoding="utf-8"))
    d.setdefault("nav", {}).update(nav)
    return parse_profile(d, source=path.resolve())


def _fly(prof, fast: bool, seconds: float = 12.0):
    a = Approach(prof)
    src = NavInTheLoop(prof, seed=3, run=5, max_time_s=a.time_budget_s)
    src.fast_epochs = fast
    res = a.fly(seed=3, run=5, nav_source=src, max_time_s=seconds)
    return src, res, src.result(res.truth)


@pytest.mark.parametrize("name", ["default.toml", "gray-maybeck.toml"])
def test_compiled_epoch_equals_the_navigator_path(name):
    """default: 24-channel GPS with channel states, baro damping loop, radar altimeter, converged start;
    gray-maybeck: baro, radar altimeter, GPS and a pseudolite."""
    prof = _profile(name)
    src, res, nav = _fly(prof, True)
    src0, res0, nav0 = _fly(prof, False)
    assert src.fast_epoch_unavailable() is None and src._fast.e == len(nav.t_epoch_s) > 10  # every epoch compiled
    assert src0._fast is None
    eq = np.testing.assert_array_equal
    eq(res.guidance_r_rwy, res0.guidance_r_rwy)
    eq(res.guidance_v_ned, res0.guidance_v_ned)
    eq(res.truth.r_ecef, res0.truth.r_ecef)
    for f in ("r_ecef", "v_ned", "euler_rad", "P_pos_ned", "clock_bias_m", "clock_bias_sigma_m"):
        eq(getattr(nav.solution, f), getattr(nav0.solution, f), err_msg=f)
    for f in ("t_epoch_s", "x", "P_diag", "P_nav", "true_error_nav"):
        eq(getattr(nav, f), getattr(nav0, f), err_msg=f)
    for f in ("t_s", "name", "innovation", "variance", "accepted"):
        eq(getattr(nav.status, f), getattr(nav0.status, f), err_msg=f)


@pytest.mark.parametrize(("nav", "why"), [({"feedback": True}, "feedback"),
                                          ({"fde": {"enabled": True}}, "FDE"),
                                          ({"filter": "rkf-gate"}, "compiled epoch")])
def test_configurations_without_the_compiled_epoch_take_the_navigator_path(nav, why):
    """Feedback, the online FDE and the robust filters run every epoch through the Navigator (nav/fde.py, the
    generic filters): the source says why, and flies."""
    prof = _profile("default.toml", **nav)
    src, res, run = _fly(prof, True, seconds=3.0)
    assert why in src.fast_epoch_unavailable()
    assert src._fast is None and len(run.t_epoch_s) > 0 and np.all(np.isfinite(run.solution.r_ecef))
