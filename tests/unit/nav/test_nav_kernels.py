"""Compiled navigation kernels against their numpy oracles: equal to 1e-12 relative on the same inputs, and a
run's bits independent of the batch it is stepped in."""

from __future__ import annotations

import numpy as np
import pytest
from floors import assert_within, floor

from approachsim import geo
from approachsim.core import geodesy as gk
from approachsim.nav import ins
from approachsim.nav import vertical_loop as vl

pytestmark = pytest.mark.equality  # also run compiled for the generic CPU target (scripts/test.sh)

RTOL = 1e-12
"""Kernel vs numpy oracle, relative: 4500 eps. A strapdown step is ~100 operations on its own state (k ~ 2 x 100 =
4.4e-14), 300 steps of a marginally stable integration add up to ~300 x that = 1.3e-11 if every rounding survived;
what the runs show is 1e-13..1e-14 (the errors do not all add), and the generic-target pass checks it."""


def _close(a, b, what):
    """|a - b| <= 1e-12 |b|, elementwise, with |b| floored at 1e-12 of the field's largest magnitude (a
    velocity component crossing zero has no relative error of its own)."""
    a, b = np.asarray(a), np.asarray(b)
    scale = np.maximum(np.abs(b), np.max(np.abs(b)) * 1e-3 + 1e-300)
    rel = np.max(np.abs(a - b) / scale)
    assert rel <= RTOL, f"{what}: relative difference {rel:.2e} > {RTOL:g}"


def _states(n, rng):
    lat = rng.uniform(-1.2, 1.2, n)
    lon = rng.uniform(-3.0, 3.0, n)
    h = rng.uniform(0.0, 3000.0, n)
    v = rng.normal(0.0, 60.0, (n, 3))
    c = ins.cbn_from_euler(rng.uniform(-1.0, 1.0, (n, 3)) * [0.5, 0.3, 3.0])
    return ins.init_state(lat, lon, h, v, c)


def _increments(n, m, rng, dt=1.0 / 120.0):
    dth = rng.normal(0.0, 0.2, (n, m, 3)) * dt
    dth[0] *= 1e-4  # one run with tiny rotations: the Rodrigues series branch
    dv = (rng.normal(0.0, 2.0, (n, m, 3)) + [0.0, 0.0, -9.8]) * dt
    return dth, dv


@pytest.mark.parametrize("form", ["none", "constant", "tanh", "sinh"])
def test_strapdown_kernel_equals_numpy_reference(form):
    """300 steps of 6 runs, with and without the baro damping loop: every state field within 1e-12 relative."""
    rng = np.random.default_rng(12)
    n, m, dt = 6, 300, 1.0 / 120.0
    s0 = _states(n, rng)
    dth, dv = _increments(n, m, rng, dt)
    loop = None if form == "none" else vl.LoopGains(0.3, 0.03, 0.001, form=form, b1_per_m=0.05, b2_per_m=0.08)
    hb = s0.h_m[:, None] + rng.normal(0.0, 5.0, (n, m))
    age = rng.uniform(0.0, 0.5, m)  # the held sample's age (s)
    a = b = s0
    for j in range(m):
        a = ins.step(a, dth[:, j], dv[:, j], dt, h_baro_m=hb[:, j], baro_age_s=age[j], loop=loop)
        b = ins.step_reference(b, dth[:, j], dv[:, j], dt, h_baro_m=hb[:, j], baro_age_s=age[j], loop=loop)
    for f in ("lat_rad", "lon_rad", "h_m", "v_ned", "c_bn", "a_comp_mps2"):
        if form == "none" and f == "a_comp_mps2":
            np.testing.assert_array_equal(getattr(a, f), 0.0)
            continue
        _close(getattr(a, f), getattr(b, f), f)
    assert not np.allclose(a.h_m, s0.h_m)  # the states did move


def test_propagate_many_intervals_with_bias_and_outputs():
    """One `propagate` call over m intervals = m reference steps on bias-corrected increments; the rows it
    writes are the intermediate states; f_sum is the sum of C(-) dv."""
    rng = np.random.default_rng(5)
    n, m, dt = 4, 120, 1.0 / 120.0
    s0 = _states(n, rng)
    dth, dv = _increments(n, m, rng, dt)
    bg = rng.normal(0.0, 1e-5, (n, 3))
    ba = rng.normal(0.0, 1e-2, (n, 3))
    x = ins.pack(s0)
    out = np.full((n, m + 3, 16), np.nan)
    f_sum = np.zeros((n, 3))
    ins.propagate(x, dth, dv, dt, bias_g=bg, bias_a=ba, f_sum=f_sum, out=out, row0=2)
    b = s0
    f_ref = np.zeros((n, 3))
    for j in range(m):
        dvj = dv[:, j] - ba * dt
        f_ref += np.einsum("nij,nj->ni", b.c_bn, dvj)
        b = ins.step_reference(b, dth[:, j] - bg * dt, dvj, dt)
        if j == m // 2:
            _close(ins.unpack(out[:, 2 + j + 1]).v_ned, b.v_ned, "row written mid-way")
    got = ins.unpack(x)
    for f in ("lat_rad", "lon_rad", "h_m", "v_ned", "c_bn"):
        _close(getattr(got, f), getattr(b, f), f)
    _close(f_sum, f_ref, "f_sum")
    np.testing.assert_array_equal(out[:, m + 2], x)
    assert np.isnan(out[:, 0:3]).all()


def test_a_run_has_the_same_bits_in_any_batch():
    rng = np.random.default_rng(8)
    n, m, dt = 7, 50, 1.0 / 120.0
    s0 = _states(n, rng)
    dth, dv = _increments(n, m, rng, dt)
    loop = vl.LoopGains(0.3, 0.03, 0.001)
    hb = rng.normal(1000.0, 5.0, (n, m))
    age = rng.uniform(0.0, 0.1, m)
    x_all = ins.propagate(ins.pack(s0), dth, dv, dt, h_baro_m=hb, baro_age_s=age, loop=loop)
    for i in (0, 3, 6):
        x_one = ins.propagate(ins.pack(s0)[i:i + 1], dth[i:i + 1], dv[i:i + 1], dt, h_baro_m=hb[i:i + 1],
                              baro_age_s=age, loop=loop)
        np.testing.assert_array_equal(x_one[0], x_all[i])


def test_the_loop_compares_a_held_sample_with_the_ins_height_at_the_samples_time():
    """On a descent at v_D = 4 m/s, a baro sample taken a = 0.05 s before the interval start reads h + v_D a. Taken
    back to its time, the INS agrees with it: no loop error, so the compensator does not move (exactly: the same
    products). Compared with the height now, as a zero-order hold does, the loop sees the INS v_D a = 0.2 m low and
    drives the compensator by C3 e dt, the lag that biased the height high (docs/baro-loop-hold-bias.md)."""
    loop = vl.LoopGains(0.3, 0.03, 0.001)
    s = ins.init_state(np.array([0.6]), np.array([-2.1]), np.array([300.0]), np.array([[70.0, 0.0, 4.0]]),
                       np.eye(3)[None])
    a, dt = 0.05, 1.0 / 120.0
    hb = s.h_m + s.v_ned[:, 2] * a
    dth, dv = np.zeros((1, 3)), np.array([[0.0, 0.0, -9.80 * dt]])
    aligned = ins.step(s, dth, dv, dt, h_baro_m=hb, baro_age_s=a, loop=loop)
    held = ins.step(s, dth, dv, dt, h_baro_m=hb, loop=loop)
    assert aligned.a_comp_mps2[0] == 0.0
    assert held.a_comp_mps2[0] == pytest.approx(loop.c3 * (-4.0 * a) * dt, rel=1e-12)


def test_geodesy_kernels_equal_geo():
    rng = np.random.default_rng(1)
    for lat, lon, h in zip(rng.uniform(-1.5, 1.5, 50), rng.uniform(-3, 3, 50), rng.uniform(-100, 1e4, 50),
                           strict=True):
        r_n, r_e = geo.radii(lat)
        _close(gk.radii(lat), (r_n, r_e), "radii")
        _close(gk.geodetic_to_ecef(lat, lon, h), geo.geodetic_to_ecef(lat, lon, h), "ecef")
        g = geo.gravity_ned(lat, h)
        _close(gk.gravity_nd(lat, h), (g[0], g[2]), "gravity")


@pytest.mark.parametrize(("feedback", "cold"), [(False, False), (True, False), (False, True)])
def test_closed_loop_steps_equal_the_open_loop_pass_to_rounding(feedback, cold):
    """The closed loop (kernels.strapdown.inloop_step, increments made in the loop from truth sample k-1) and the
    open-loop pass (IMU record from sensors/imu.py, `propagate`) share one kernel: the same navigation to
    rounding (nanometres), not merely to the 1e-6 m of two different increment definitions. cold: an ISA -25 day
    at a 5434 ft field with the baro's aerodrome-temperature correction and the damping loop on, whose baro samples
    the closed loop makes in its own kernel (inloop.baro_sample) and the open loop in sensors/baro.py."""
    import tomllib
    from pathlib import Path

    from approachsim import synthetic
    from approachsim.loop.closed_loop import NavInTheLoop
    from approachsim.nav.system import NavSystem
    from approachsim.profile import parse_profile
    from approachsim.seeding import stream
    from approachsim.sensors.states import measure_with_states
    from approachsim.sensors.suite import SensorSuite

    path = Path("profiles/gray-maybeck.toml")
    data = tomllib.loads(path.read_text(encoding="utf-8"))
    data.setdefault("nav", {})["feedback"] = feedback
    if cold:
        data["nav"]["baro_loop"] = "constant"
        data["nav"]["initial_error"]["start"] = "converged"  # as the default profile (the loop's start is its own)
        data["runway"]["elevation_ft"] = 5434.0
        data["environment"]["isa_dev_C"] = -25.0
        data["sensors"]["baro"]["temperature_correction"] = "aerodrome"
    prof = parse_profile(data, source=path.resolve())
    if cold:
        assert SensorSuite.from_profile(prof).sensors["baro"].temperature_ratio < 0.92
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=prof.rates.imu_hz, start_distance_m=300.0,
                                        ground_speed_mps=70.0)
    src = NavInTheLoop(prof, seed=4, run=2, max_time_s=30.0)
    guide = np.array([np.concatenate(src.step(k, truth)) for k in range(len(truth))])
    closed = src.result(truth)
    recs, st = measure_with_states(SensorSuite.from_profile(prof), truth, seed=4, runs=2)
    open_ = NavSystem.from_profile(prof).run(truth, recs, stream(4, 2, "nav"), states=st)
    # one strapdown kernel fed increments made in two places (in the loop, in sensors/imu.py): they may round
    # differently on another CPU. r_ecef: the geodetic -> ECEF composition of a 4.9e6 m position, ~8 operations
    # per component, doubled: 16 eps |r| = 1.7e-8 m (measured equal here); v: 1e-12 m/s is 85 eps of 53 m/s, the
    # increments' rounding (measured 1.3e-15); x: 1e-12 relative, the filter's epochs on equal inputs.
    assert_within(closed.solution.r_ecef, open_.solution.r_ecef, floor(16, open_.solution.r_ecef), "r_ecef")
    np.testing.assert_allclose(closed.solution.v_ned, open_.solution.v_ned, rtol=0, atol=1e-12)
    np.testing.assert_allclose(closed.x, open_.x, rtol=1e-12, atol=1e-15)
    # guidance flew on the feed-forward output in the runway frame (without feedback: INS - x_hat of the epoch);
    # 1e-6 m / 1e-9 m/s: the guidance's own runway-frame rotation of a 6.4e6 m ECEF difference, far above its floor
    r_rwy = prof.runway.frame.from_ecef(open_.solution.r_ecef)
    np.testing.assert_allclose(guide[:, 0:2], r_rwy[:, 0:2], rtol=0, atol=1e-6)
    np.testing.assert_allclose(guide[:, 3:6], open_.solution.v_ned, rtol=0, atol=1e-9)


def test_output_kernel_equals_perturb_ecef_and_euler():
    """kernels/output.corrected (the NavSolution of every row: INS - x_hat(t), the snapshot in force carried to
    the row's time by its rate) against the numpy path: x + (t - T) xd, ins.perturb with -x_hat(t),
    geo.geodetic_to_ecef, ins.euler_from_cbn."""
    rng = np.random.default_rng(11)
    s = _states(500, rng)
    rows = ins.pack(s)
    X = np.concatenate([rng.normal(0.0, 5.0, (40, 3)), rng.normal(0.0, 0.1, (40, 3)),
                        rng.normal(0.0, 1e-3, (40, 3)), rng.normal(0.0, 1.0, (40, 4))], axis=1)
    X[0, 6:9] = 1e-9  # tiny attitude correction: the Rodrigues series branch
    XD = np.concatenate([rng.normal(0.0, 0.1, (40, 3)), rng.normal(0.0, 1e-3, (40, 3)),
                         rng.normal(0.0, 1e-5, (40, 3))], axis=1)
    T = np.sort(rng.uniform(0.0, 40.0, 40))
    snap = rng.integers(0, 40, 500)
    t = T[snap] + rng.uniform(0.0, 1.0, 500)
    from approachsim.core.nav import output as ko

    r, v, e = ko.corrected(rows, t, X, XD, T, snap)
    xs = X[snap][:, 0:9] + (t - T[snap])[:, None] * XD[snap]  # the same two operations per element
    o = ins.perturb(s, -xs[:, 0:3], -xs[:, 3:6], -xs[:, 6:9])
    _close(r, geo.geodetic_to_ecef(o.lat_rad, o.lon_rad, o.h_m), "r_ecef")
    _close(v, o.v_ned, "v_ned")
    eu = ins.euler_from_cbn(o.c_bn)
    d = np.abs(e - eu)
    d[:, 2] = np.minimum(d[:, 2], 2.0 * np.pi - d[:, 2])  # heading wraps at 2 pi
    assert np.max(d) < 1e-12
