"""The closed loop's compiled aiding epoch (core/loop/aiding.py, NavInTheLoop._fast_epoch) against its
oracle, the Navigator's numpy path around the same per-run EKF epoch (NavInTheLoop.fast_epochs = False): JSBSim
flies the same seconds of an approach with each, and everything the flight and the navigation give is the same bits.

Why exact and not a floor (tests/floors.py): the compiled epoch is the same core/nav/epoch.run_epoch on the same
inputs (Observations.at's selections made directly from the one-row records, the GPS channel sigmas by the same
numpy formulas), plus copies and the one division f_sum / dt the numpy path makes too; no operation is reordered, so
there is no rounding to bound (and none under NUMBA_CPU_NAME=generic either: both paths call the one kernel)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim.flight.run import Approach
from approachsim.loop.closed_loop import NavInTheLoop
from approachsim.profile import parse_profile

pytestmark = pytest.mark.equality

PROFILES = Path(__file__).resolve().parents[3] / "profiles"
PY_DEFAULT = PROFILES.parent / "tests" / "data" / "default-py.toml"
"""The P(Y) default the tests of its receiver load (tests/data/default-py.toml says why)."""


SBAS_DEFAULT = "sbas-default"
"""The shipped default (profiles/default.toml: SBAS L1), by this name here ("default.toml" is the P(Y) file)."""


def _profile(name: str, baro: dict | None = None, gnss: dict | None = None, **nav):
    path = PY_DEFAULT if name == "default.toml" else PROFILES / ("default.toml" if name == SBAS_DEFAULT else name)
    d = tomllib.loads(path.read_text(encoding="utf-8"))
    d.setdefault("nav", {}).update(nav)
    if gnss:
        d["sensors"]["gnss"].update(gnss)
    if baro:
        d["sensors"]["baro"].update(baro)
    return parse_profile(d, source=path.resolve())


def _fly(prof, fast: bool, seconds: float = 12.0):
    a = Approach(prof)
    src = NavInTheLoop(prof, seed=3, run=5, max_time_s=a.time_budget_s)
    src.fast_epochs = fast
    res = a.fly(seed=3, run=5, nav_source=src, max_time_s=seconds)
    return src, res, src.result(res.truth)


@pytest.mark.parametrize("name", ["default.toml", "gray-maybeck.toml", SBAS_DEFAULT])
def test_compiled_epoch_equals_the_navigator_path(name):
    """default: 24-channel GPS with channel states, baro damping loop, radar altimeter, converged start;
    gray-maybeck: baro, radar altimeter, GPS and a pseudolite; the SBAS default: a GNSS service's correlated truth
    and the filter's own channel model (sensors/gnss/service.py)."""
    prof = _profile(name)
    src, res, nav = _fly(prof, True)
    src0, res0, nav0 = _fly(prof, False)
    assert src.path.epoch == "fused" and src.path.reason("epoch") is None
    assert src._fast.e == len(nav.t_epoch_s) > 10  # every epoch compiled
    assert src0._fast is None and src0.path.epoch == "generic" and "oracle" in src0.path.reason("epoch")
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
    assert src.path.epoch == "generic" and why in src.path.reason("epoch")
    assert src._fast is None and len(run.t_epoch_s) > 0 and np.all(np.isfinite(run.solution.r_ecef))


def _fly_inputs(prof, direct: bool, seconds: float = 8.0):
    a = Approach(prof)
    src = NavInTheLoop(prof, seed=3, run=5, max_time_s=a.time_budget_s)
    src.direct_inputs = direct
    res = a.fly(seed=3, run=5, nav_source=src, max_time_s=seconds)
    return src, res, src.result(res.truth)


def _eq_inputs(got, want):
    assert len(got) == len(want)
    for i, (g, w) in enumerate(zip(got, want, strict=True)):
        if w is None:
            assert g is None, i
        else:
            np.testing.assert_array_equal(np.asarray(g), np.asarray(w), err_msg=str(i))
            assert np.shape(g) == np.shape(w) and np.asarray(g).dtype == np.asarray(w).dtype, i


@pytest.mark.parametrize(("name", "nav", "baro", "gnss"), [
    ("default.toml", {}, None, None), ("gray-maybeck.toml", {}, None, None),
    ("hot-high-crosswind.toml", {}, None, None),
    # no channel states: the pseudorange sigmas scaled in the fused kernel
    ("default.toml", {"channel_states": False, "gps_sigma_scale": 1.5}, None, None),
    # a lagged static system: its weights at the start, before the truth's row 1 is flown (the draw's grid step)
    ("default.toml", {}, {"lag_s": 1.0}, None),
    # GNSS services: SBAS L1's correlated iono field, DFMC's per-channel residual, every term per channel (truth =
    # "broadcast"), and the broadcast sigma_i scaled without channel states
    (SBAS_DEFAULT, {}, None, None), ("dfmc-sbas.toml", {}, None, None),
    (SBAS_DEFAULT, {}, None, {"truth": "broadcast"}),
    (SBAS_DEFAULT, {"channel_states": False, "gps_sigma_scale": 1.5}, None, None)])
def test_direct_epoch_inputs_equal_the_records(name, nav, baro, gnss):
    """The compiled epoch's sensor inputs made straight from the baro's, radar altimeter's and GPS receiver's
    kernels in one compiled call (NavInTheLoop._direct_inputs, closed_loop_epoch.direct_inputs) are the inputs made
    from their one-row records (`_epoch_inputs`, the oracle) at every epoch row of a flown approach and at rows
    between (no sample there: the empty inputs), and the flight they steer is the same bits."""
    prof = _profile(name, baro, gnss, **nav)
    src, res, nav = _fly_inputs(prof, True)
    src0, res0, nav0 = _fly_inputs(prof, False)
    assert src._fast.direct and not src0._fast.direct
    truth = res.truth
    rows = list(range(src.epoch_rows, len(truth), src.epoch_rows)) + [src.epoch_rows + 7, 2 * src.epoch_rows - 1]
    n_gnss = 0
    for k in rows:
        t = float(truth.t_s[k])
        got = src._direct_inputs(k, t, truth)
        want = src._epoch_inputs(t, src._records(k, truth))
        _eq_inputs(got, want)
        n_gnss += got[6] is not None
        b = src._records(k, truth).get("baro")  # the damping loop's sample at the row (`_recs`)
        assert (b is None) == ("baro" not in src._recs[1])
        if b is not None:
            np.testing.assert_array_equal(src._recs[1]["baro"].h_baro_m, b.h_baro_m)
            np.testing.assert_array_equal(src._recs[1]["baro"].valid, b.valid)
    assert n_gnss > 3  # the GPS epochs were compared
    eq = np.testing.assert_array_equal
    eq(res.guidance_r_rwy, res0.guidance_r_rwy)
    eq(res.truth.r_ecef, res0.truth.r_ecef)
    for f in ("r_ecef", "v_ned", "P_pos_ned"):
        eq(getattr(nav.solution, f), getattr(nav0.solution, f), err_msg=f)
    for f in ("t_epoch_s", "x", "P_diag"):
        eq(getattr(nav, f), getattr(nav0, f), err_msg=f)
    eq(nav.status.innovation, nav0.status.innovation)


@pytest.mark.parametrize(("name", "faults"), [("gbas-cat3-candidate.toml", None),
                                              ("default.toml", [{"sensor": "baro", "kind": "step", "start_s": 2.0,
                                                                 "magnitude": 5.0}])])
def test_configurations_without_direct_inputs_take_the_records(name, faults):
    """GBAS ranging and a faulted sensor have no direct form: the compiled epoch takes its inputs from the
    records (FastEpoch.direct False) and flies."""
    path = PY_DEFAULT if name == "default.toml" else PROFILES / name
    d = tomllib.loads(path.read_text(encoding="utf-8"))
    if faults is not None:
        d["faults"] = faults
    prof = parse_profile(d, source=path.resolve())
    src, res, nav = _fly_inputs(prof, True, seconds=3.0)
    assert src._fast is not None and not src._fast.direct
    assert len(nav.t_epoch_s) > 0 and np.all(np.isfinite(nav.solution.r_ecef))


@pytest.mark.parametrize("multipath_model", ["do253", "nrc1995", "sbas-l1", "dfmc-sbas"])
def test_compiled_channel_sigmas_equal_the_budget_numpy(multipath_model):
    """The compiled epoch's GPS channel sigmas (numpy's cos, sin, exp, the rest compiled in numpy's order:
    NavInTheLoop._noise_arrays; a GNSS service's: the filter's own model by the one service kernel) are the receiver
    budget's numpy formulas' (`_noise_arrays_numpy`) bit for bit, at elevations over the whole sky, below the noise
    model's 2 deg floor and nan (no elevation: 0.5 rad)."""
    if multipath_model.startswith(("sbas", "dfmc")):
        path = PROFILES / ("default.toml" if multipath_model == "sbas-l1" else "dfmc-sbas.toml")
        d = tomllib.loads(path.read_text(encoding="utf-8"))
        assert d["sensors"]["gnss"]["service"] == multipath_model
    else:
        path = PY_DEFAULT
        d = tomllib.loads(path.read_text(encoding="utf-8"))
        d["sensors"]["gnss"]["multipath_model"] = multipath_model
    prof = parse_profile(d, source=path.resolve())
    src, _, _ = _fly_inputs(prof, True, seconds=1.5)
    assert src._fast.sig is not None
    rng = np.random.default_rng(26)
    for i in range(400):
        el = rng.uniform(-0.2, np.pi / 2, 24)
        el[rng.uniform(size=24) < 0.1] = np.nan
        if i == 0:
            el[:4] = [0.0, np.radians(2.0), np.nextafter(np.radians(2.0), 0.0), np.pi / 2]
        q, gse, gmp = src._noise_arrays(el)
        q0, gse0, gmp0 = src._noise_arrays_numpy(el)
        assert q is q0
        np.testing.assert_array_equal(gse, gse0)
        np.testing.assert_array_equal(gmp, gmp0)
    assert src.path.sigmas == "compiled"
    src.compiled_sigmas = False  # the path is chosen once per run: a switch set after the start changes nothing
    assert src.path.sigmas == "compiled"
    fresh = NavInTheLoop(prof, seed=3, run=5, max_time_s=10.0)
    fresh.compiled_sigmas = False  # the numpy formulas: the fallback the flight takes when asked
    assert fresh.path.sigmas == "numpy" and "compiled_sigmas" in fresh.path.reason("sigmas")
    assert fresh._sigma_scratch(fresh.nav.noise_model.sensors.gnss.budget(), 24) is None
