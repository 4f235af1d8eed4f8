"""The closed-loop navigation source, fed a truth row by row, gives the same navigation as the open-loop pass
over the sensor records of that truth (pre-drawn errors applied step by step = batch; prefix property)."""

from __future__ import annotations

import tomllib
from pathlib import Path

import numpy as np
import pytest

from approachsim import geo, synthetic
from approachsim.loop.closed_loop import NavInTheLoop
from approachsim.nav.system import NavSystem
from approachsim.profile import parse_profile
from approachsim.seeding import stream
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

PROFILES = Path(__file__).resolve().parents[3] / "profiles"


@pytest.mark.parametrize(("quantized", "feedback", "realistic"),
                         [(False, False, False), (True, False, False), (False, True, False), (False, False, True)])
def test_step_by_step_equals_open_loop_pass(quantized, feedback, realistic):
    """quantized: the IMU is not affine in the truth, so the source applies every sample (the other path);
    feedback: the estimate is fed back into the INS and the bias estimates into the increments; realistic: the
    radar altimeter's bias and Markov error and the terrain-database error at their defaults (the paper's
    profile zeroes them), so the closed loop sees the same database realization as the open-loop pass."""
    path = PROFILES / "gray-maybeck.toml"  # baro, radalt, GPS and a pseudolite
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    if realistic:
        data["sensors"]["radalt"] = {"max_range_ft": 3000.0}
        data["nav"].pop("terrain_database")
    if quantized:
        data.setdefault("sensors", {}).setdefault("imu", {})["gyro_quant_rad"] = 1e-7
    data.setdefault("nav", {})["feedback"] = feedback
    prof = parse_profile(data, source=path.resolve())
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=prof.rates.imu_hz, start_distance_m=70.0 * 6.0,
                                        ground_speed_mps=70.0)
    src = NavInTheLoop(prof, seed=4, run=2, max_time_s=30.0)
    assert (src.imu_affine_terms() is None) == quantized and (src.path.row == "generic") == quantized
    r_rwy = np.array([src.step(k, truth)[0] for k in range(len(truth))])
    closed = src.result(truth)
    assert (src.navigator.runs[0].db_error is not None) == realistic
    assert all(src.nav.layout.has(g) == realistic for g in ("rab", "ram", "tdb"))
    recs, st = measure_with_states(SensorSuite.from_profile(prof), truth, seed=4, runs=2)
    open_ = NavSystem.from_profile(prof).run(truth, recs, stream(4, 2, "nav"), states=st)
    np.testing.assert_allclose(closed.solution.r_ecef, open_.solution.r_ecef, rtol=0, atol=1e-6)
    np.testing.assert_allclose(closed.x, open_.x, rtol=1e-6, atol=1e-6)  # increments in another summation order
    assert list(closed.status.name) == list(open_.status.name)
    assert {"baro", "radalt", "pl0"} <= set(closed.status.name)
    # what guidance gets is the navigation solution in the runway frame, with the geodetic height above the
    # threshold as its third axis: identical by construction (exact up to rounding), and within 5 of the
    # filter's own sigmas of the truth
    frame = prof.runway.frame
    _, _, h_nav = geo.ecef_to_geodetic(closed.solution.r_ecef)
    np.testing.assert_allclose(r_rwy[:, :2], frame.from_ecef(closed.solution.r_ecef)[:, :2], rtol=0, atol=1e-6)
    np.testing.assert_allclose(r_rwy[:, 2], frame.height_above_threshold(h_nav), rtol=0, atol=1e-6)
    sd_up = np.sqrt(closed.solution.P_pos_ned[:, 2, 2])
    assert np.all(np.abs(r_rwy[:, 2] - truth.r_rwy[:, 2]) < 5.0 * sd_up)
