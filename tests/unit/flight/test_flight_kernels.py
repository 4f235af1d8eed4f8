"""The flight loop's IMU-point truth kernel against its vectorized numpy oracle (1e-12 relative), and the
kinematics it must reproduce without JSBSim: a zero lever arm leaves the CG's state, the quaternion is the
Euler angles' rotation, a pure lever arm on a steady turn gives the centripetal acceleration."""

from __future__ import annotations

import math
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from approachsim import geo, units
from approachsim.core import layouts
from approachsim.core.loop import flight_step as fk
from approachsim.flight import vectors as fv
from approachsim.nav import ins

pytestmark = pytest.mark.equality  # also run compiled for the generic CPU target (scripts/test.sh)

FRAME = geo.RunwayFrame(math.radians(37.6117), math.radians(-122.3581), 4.0, math.radians(298.0))
RWY = SimpleNamespace(frame=FRAME, elevation_m=4.0, glidepath_rad=math.radians(3.0), tch_m=15.0,
                      threshold_lat_rad=FRAME.threshold_lat_rad, threshold_lon_rad=FRAME.threshold_lon_rad,
                      heading_rad=FRAME.heading_rad)
DT = 1.0 / 120.0


def _raw(n, rng):
    """n sets of JSBSim reads (RAW_FIELDS order, JSBSim units) around a 737 on approach."""
    raw = np.empty((n, len(layouts.RAW_FIELDS)))
    raw[:, 0] = RWY.threshold_lat_rad + rng.normal(0.0, 0.01, n)
    raw[:, 1] = RWY.threshold_lon_rad + rng.normal(0.0, 0.01, n)
    raw[:, 2] = rng.uniform(100.0, 3500.0, n)
    raw[:, 3:6] = rng.normal([-120.0, 200.0, 12.0], 30.0, (n, 3))
    raw[:, 6:9] = rng.normal(0.0, 1.0, (n, 3)) * [0.2, 0.05, 2.0]
    raw[:, 9:12] = rng.normal(0.0, 0.05, (n, 3))
    raw[:, 12:15] = rng.normal(0.0, 0.1, (n, 3))
    raw[:, 15:18] = rng.normal([2e3, 0.0, -1.5e5], [5e2, 3e2, 2e4], (n, 3))
    raw[:, 18] = rng.uniform(3500.0, 4500.0, n)
    raw[:, 19] = rng.uniform(1900.0, 2116.0, n)
    raw[:, 20] = rng.uniform(500.0, 530.0, n)
    raw[:, 21] = rng.uniform(130.0, 150.0, n)
    raw[:, 22] = rng.normal(0.0, 0.01, n)
    raw[:, 23] = raw[:, 21] * 1.7
    return raw


def _kernel_rows(raw, const, along, height, t):
    out = np.full((len(raw), 36), np.nan)
    terr = np.array([fk.imu_point_row(raw[k], const, along, height, t[k], out[k]) for k in range(len(raw))])
    return out, terr


def _close(a, b, what):
    scale = np.maximum(np.abs(b), np.max(np.abs(b)) * 1e-3 + 1e-300)
    rel = np.max(np.abs(a - b) / scale)
    assert rel <= 1e-12, f"{what}: relative difference {rel:.2e}"


COLS = {"t": [0], "lat": [1], "lon": [2], "h": [3], "r_ecef": [4, 5, 6], "v_ned": [7, 8, 9],
        "q": [10, 11, 12, 13], "euler": [14, 15, 16], "w": [17, 18, 19], "f_body": [20, 21, 22], "p": [23],
        "T": [24], "h_agl": [25], "r_rwy_xy": [26, 27], "r_rwy_z": [28], "gs_dev": [29], "loc_dev": [30],
        "airspeed": [35]}


def test_kernel_equals_numpy_reference():
    rng = np.random.default_rng(12)
    raw = _raw(300, rng)
    const = fv.imu_point_constants([10.0, 0.4, -1.2], RWY.threshold_lat_rad, RWY, DT)
    along, height = np.array([-20000.0, 0.0, 5000.0]), np.array([30.0, 4.0, 2.0])
    t = np.arange(300) * DT
    got, terr = _kernel_rows(raw, const, along, height, t)
    ref = fv.imu_point_rows_reference(raw, const, along, height, t)
    for name, c in COLS.items():
        _close(got[:, c], ref[:, c], name)
    assert np.isnan(got[:, 31:35]).all()  # the controls stay the caller's
    np.testing.assert_allclose(terr, np.interp(got[:, 26], along, height), rtol=1e-14)
    flat, _ = _kernel_rows(raw[:5], const, np.array([0.0]), np.array([4.0]), t[:5])
    np.testing.assert_array_equal(flat[:, 25], flat[:, 3] - 4.0)


def test_zero_lever_arm_keeps_the_cg_state_and_the_quaternion_is_the_attitude():
    rng = np.random.default_rng(3)
    raw = _raw(50, rng)
    const = fv.imu_point_constants([0.0, 0.0, 0.0], RWY.threshold_lat_rad, RWY, DT)
    got, _ = _kernel_rows(raw, const, np.array([0.0]), np.array([4.0]), np.zeros(50))
    np.testing.assert_array_equal(got[:, 1:3], raw[:, 0:2])
    np.testing.assert_allclose(got[:, 3], raw[:, 2] * units.FT, rtol=0, atol=1e-9)
    np.testing.assert_allclose(got[:, 7:10], raw[:, 3:6] * units.FPS, rtol=0, atol=1e-12)
    np.testing.assert_allclose(got[:, 4:7], geo.geodetic_to_ecef(raw[:, 0], raw[:, 1], raw[:, 2] * units.FT),
                               rtol=0, atol=1e-6)
    np.testing.assert_allclose(got[:, 23], raw[:, 19] * units.PSF, rtol=1e-15)
    np.testing.assert_allclose(ins.cbn_from_quaternion(got[:, 10:14]), ins.cbn_from_euler(got[:, 14:17]),
                               rtol=0, atol=1e-14)


def test_lever_arm_on_a_steady_rotation_gives_the_centripetal_acceleration():
    """Level, no forces but the rotation: a constant body rate w about z with an IMU l = 10 m ahead of the CG
    feels w x (w x l) = -w^2 l (plus the sub-micro-g gravitation terms)."""
    raw = _raw(1, np.random.default_rng(1))
    raw[:, 6:9] = 0.0
    raw[:, 3:6] = 0.0
    w = 0.2
    raw[:, 0] = 0.0  # at the equator: the Earth's rate has no body z part, w_eb = w_ib - (Omega, 0, 0)
    raw[:, 9:12] = [0.0, 0.0, w]
    raw[:, 12:15] = 0.0
    raw[:, 15:18] = 0.0
    const = fv.imu_point_constants([10.0, 0.0, 0.0], RWY.threshold_lat_rad, RWY, 1e-4)
    got, _ = _kernel_rows(raw, const, np.array([0.0]), np.array([4.0]), np.zeros(1))
    np.testing.assert_allclose(got[0, 20:23], [-w * w * 10.0, 0.0, 0.0], rtol=0, atol=2e-4)
    np.testing.assert_allclose(got[0, 7:10], [0.0, w * 10.0, 0.0], rtol=0, atol=1e-4)  # w x l, east


@pytest.mark.slow
def test_kernel_reproduces_the_flight_loop_rows(monkeypatch):
    """On a 5 s JSBSim flight of the default profile, the kernel fed the reads the flight loop made gives the
    Truth rows the loop wrote (the kernel is the loop's kinematics, ready to be wired in)."""
    from approachsim.flight import fdm as fdm_mod
    from approachsim.flight.run import Approach
    from approachsim.flight.trim import start_condition
    from approachsim.profile import load_profile

    reads: list[tuple[str, float]] = []
    node = fdm_mod.FDM.node

    class Recorder:
        def __init__(self, n, name):
            self._n, self._name = n, name
            self.set_double_value = n.set_double_value

        def get_double_value(self):
            v = self._n.get_double_value()
            reads.append((self._name, v))
            return v

    def recording_node(self, name):
        n = node(self, name)
        return Recorder(n, name) if name in layouts.RAW_FIELDS else n

    monkeypatch.setattr(fdm_mod.FDM, "node", recording_node)
    prof = load_profile("profiles/default.toml")
    approach = Approach(prof)
    res = approach.fly(seed=1, run=0, max_time_s=5.0)
    truth = res.truth
    raw = np.array([v for name, v in reads]).reshape(-1, len(layouts.RAW_FIELDS))
    assert raw.shape[0] == len(truth)
    assert [name for name, _ in reads[:len(layouts.RAW_FIELDS)]] == list(layouts.RAW_FIELDS)
    ic = start_condition(prof, approach.aircraft)
    fdm = fdm_mod.FDM(approach.aircraft.jsbsim_model, approach.dt_s)
    approach._trim(fdm, ic)
    cg = (fdm["inertia/cg-x-in"], fdm["inertia/cg-y-in"], fdm["inertia/cg-z-in"])
    imu = approach.aircraft.imu_location_struct_m
    lever = [cg[0] * 0.0254 - imu[0], imu[1] - cg[1] * 0.0254, cg[2] * 0.0254 - imu[2]]
    const = fv.imu_point_constants(lever, ic.lat_rad, prof.runway, approach.dt_s)
    got, _ = _kernel_rows(raw, const, np.asarray(prof.terrain.along_m, float), np.asarray(prof.terrain.height_m,
                                                                                          float),
                          np.arange(len(truth)) * approach.dt_s)
    arrays = truth.arrays()
    for name, (c, w) in {"lat_rad": (1, 1), "lon_rad": (2, 1), "h_m": (3, 1), "r_ecef": (4, 3), "v_ned": (7, 3),
                         "q_nb": (10, 4), "euler_rad": (14, 3), "w_ib_body": (17, 3), "f_body": (20, 3),
                         "p_static_pa": (23, 1), "h_agl_m": (25, 1), "r_rwy": (26, 3), "gs_dev_m": (29, 1),
                         "loc_dev_m": (30, 1), "airspeed_mps": (35, 1)}.items():
        ref = np.asarray(arrays[name]).reshape(len(truth), w)
        _close(got[:, c:c + w], ref, name)


def test_every_glidepath_formula_is_the_cone():
    """The compiled truth row (gs_dev), the autopilot's per-step deviation and the stability monitor's write the
    glide path cone's deviation inline in scalars; each equals glidepath.GlidePath.deviation_m, the one source.
    Tolerance: the scalar and numpy forms round differently (math.sqrt of dx^2 + y^2 against np.hypot, the terms
    summed in another order): a few ulp of the largest operand, tan(gp) r + z <= 2 km here, so 16 eps x 2000 m."""
    from approachsim.flight.aircraft import load_aircraft
    from approachsim.flight.autopilot import Autopilot, Geometry, Trim
    from approachsim.flight.envelope import StabilityMonitor
    from approachsim.glidepath import GlidePath
    from approachsim.profile import load_profile

    tol = 16 * np.finfo(float).eps * 2000.0
    rng = np.random.default_rng(21)
    raw = _raw(50, rng)
    const = fv.imu_point_constants([10.0, 0.4, -1.2], RWY.threshold_lat_rad, RWY, DT)
    got, _ = _kernel_rows(raw, const, np.array([0.0]), np.array([4.0]), np.arange(50) * DT)
    cone = GlidePath.of(RWY)
    np.testing.assert_allclose(got[:, 29], cone.deviation_m(got[:, 26], got[:, 27], got[:, 28]), rtol=0, atol=tol)
    prof = load_profile(Path(__file__).resolve().parents[3] / "profiles" / "default.toml")
    ap = Autopilot(load_aircraft(prof).gains, Trim(0.02, 0.47, 72.0),
                   Geometry(RWY.heading_rad, RWY.glidepath_rad, RWY.tch_m, RWY.threshold_lat_rad), DT)
    mon = StabilityMonitor(RWY.glidepath_rad, RWY.tch_m, 72.0, DT, curvature=cone.curvature)
    for x, z in zip(rng.uniform(-18000.0, 0.0, 20), rng.uniform(0.0, 1000.0, 20), strict=True):
        ref = float(cone.deviation_m(x, 3.0, z))
        assert ap.deviations(x, 3.0, z, 70.0, 1.0, 3.0)[0] == pytest.approx(ref, rel=0, abs=tol)
        d_dots = mon.dots(x, 3.0, z)[0]
        r_gp = max(mon.x_gp_m - min(x, mon.x_floor_m), 1.0)
        assert d_dots == pytest.approx(ref / (r_gp * math.tan(mon.gs_dot_rad)), rel=1e-12, abs=1e-12)
