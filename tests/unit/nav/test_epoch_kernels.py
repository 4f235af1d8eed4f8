"""The compiled filter-epoch kernels (core/nav/errormodel.py, kalman.py, measurements.py) against their numpy
oracles on the same inputs: the error model F, Qc (equal to 1e-12 relative, entry by entry) and Phi, Qd (1e-12
relative, norm-wise per matrix) over random linearization points and layouts; the filter's predict and scalar
Joseph update (max|dP| <= 1e-12 max|P|, x to 1e-12 relative), the shared-covariance update (a run's numbers
independent of the batch) and the Riccati segment of the converged start (1e-9 of the sigmas); the measurement
rows (baro and radar altimeter: h to 1e-12, nu to 1e-9 m; pseudoranges to their floors from the operands,
tests/floors.py). Each tolerance says why it holds on any CPU (docs/tolerances.md)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
from floors import assert_within, floor

from approachsim import geo, synthetic
from approachsim.core.nav import errormodel as ek
from approachsim.core.nav import kalman as kk
from approachsim.core.nav import measurements as mk
from approachsim.nav import errormodel as em
from approachsim.nav import ins
from approachsim.nav import measurements as meas
from approachsim.nav import terrain_db as tdb
from approachsim.nav import vertical_loop as vl
from approachsim.nav.base import KalmanFilter, ScalarMeasurement, joseph_reference, predict_reference, workspace
from approachsim.nav.robust import AdaptivePolicy
from approachsim.profile import load_profile

pytestmark = pytest.mark.equality  # also run compiled for the generic CPU target (scripts/test.sh)

PROFILE = load_profile(Path(__file__).resolve().parents[3] / "tests" / "data" / "default-py.toml")
RTOL = 1e-12
"""Kernel vs numpy oracle on the same inputs, relative: 4500 eps. An error-model entry is a sum of at most three
products (k ~ 6, 1.3e-15), a Joseph update's entry a few n-term sums (n <= 70, k ~ 3n ~ 200 eps = 5e-14): 1e-12 holds
unless an entry cancels its terms by more than 20x-1000x, which the random linearization points do not produce
(checked on this CPU and compiled for the generic target without FMA)."""
K_ROW = 8
"""Operations from the large operands to a measurement row's value, doubled for two computations (kernel, oracle):
the ECEF difference, the norm's squares, sum and root, the subtraction from the measurement, h x."""

LAYOUTS = {
    "minimal": em.StateLayout(baro_scale=False, clock=False),
    "sb-clock": em.StateLayout(),
    "loop": em.StateLayout(baro_scale=False, loop=True),
    "loop-sb-channels": em.StateLayout(loop=True, n_sv=5),
    "pseudolites": em.StateLayout(clock=True, n_sv=3, n_pl=2),
    "pseudolite-clocks-radalt": em.StateLayout(loop=True, n_sv=2, n_pl=3, pl_clock=True, radalt_bias=True,
                                               radalt_markov=True, terrain_db=True),
    "pseudolite-sync-radalt": em.StateLayout(loop=True, n_sv=2, n_pl=2, pl_sync=True, radalt_bias=True,
                                             terrain_db=True),
    "default": em.StateLayout(baro_scale=False, loop=True, n_sv=24, radalt_bias=True, radalt_markov=True,
                              terrain_db=True),
    "sbas-zenith-states": em.StateLayout(loop=True, n_sv=24, iono_zenith=True, tropo_zenith=True, radalt_bias=True,
                                         radalt_markov=True, terrain_db=True),
}


def _noise(n_sv: int, rng: np.random.Generator) -> em.ErrorNoise:
    """Noise of realistic magnitudes, the per-channel sigmas by elevation (arrays) or one scalar."""
    per = rng.uniform(0.5, 3.0, n_sv) if rng.random() < 0.5 else 2.5
    return em.ErrorNoise(
        gyro_arw_rad_sqrts=4.8e-8 * rng.uniform(0.5, 2), accel_vrw_mps_sqrts=4.2e-7, gyro_bias_rw=1e-9,
        accel_bias_rw=2e-7, baro_bias_sigma_m=1.0, baro_bias_tau_s=100.0, clock_sf=0.009, clock_sg=0.035,
        gse_sigma_m=per, gmp_sigma_m=rng.uniform(0.1, 0.3, n_sv), gmp_tau_s=100.0, pmp_sigma_m=0.3,
        pclk_sf=0.01, pclk_sg=0.02, ram_sigma_m=0.2155, baro_ref_m=rng.uniform(0.0, 1700.0), psy_sigma_m=0.9,
        psy_tau_s=600.0, giz_sigma_m=rng.uniform(0.1, 2.0), giz_gradient_sigma_m=rng.uniform(0.05, 1.0),
        giz_tau_s=1800.0, gtz_sigma_m=0.06, gtz_tau_s=3600.0,
        **dict(zip(("gyro_axis_q_x", "gyro_axis_q_y", "gyro_axis_q_z"), rng.uniform(0.0, 3e-12, 3).tolist(),
                   strict=True)))


def _point(rng: np.random.Generator) -> tuple:
    """A linearization point: lat, h, v_ned, f_ned, c_bn (a descent, a turn, the ground, a pole-ward case)."""
    lat = rng.uniform(-1.3, 1.3)
    h = rng.uniform(-50.0, 3000.0)
    v = rng.normal(0.0, 60.0, 3) * [1.0, 1.0, 0.1]
    if rng.random() < 0.1:
        v[:2] = rng.normal(0.0, 0.3, 2)  # below 1 m/s: the terrain-database time constant's floor
    f = np.array([0.0, 0.0, -9.8]) + rng.normal(0.0, 1.5, 3)
    c = ins.cbn_from_euler(rng.uniform(-1.0, 1.0, 3) * [0.4, 0.2, 3.1])
    return lat, h, v, f, c


def _loop(rng: np.random.Generator) -> vl.LoopGains:
    form = ("constant", "tanh", "sinh")[int(rng.integers(3))]
    return vl.LoopGains(0.03 * rng.uniform(0.5, 2), 3e-4, 1e-6, form=form, b1_per_m=0.5, b2_per_m=0.8)


def _cases(n: int, seed: int):
    """(name, layout, args) over every layout: n random linearization points each, loop held or not."""
    rng = np.random.default_rng(seed)
    for name, lay in LAYOUTS.items():
        for _ in range(n):
            lat, h, v, f, c = _point(rng)
            loop = _loop(rng) if lay.has("ac") else None
            yield name, lay, (lay, lat, h, v, f, c, _noise(lay.n_sv, rng), loop, bool(rng.random() < 0.3))


def _rel_entrywise(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| / |b| over the entries (zeros must be equal)."""
    d = np.abs(a - b)
    if np.any(d[b == 0.0] != 0.0):
        return np.inf
    nz = b != 0.0
    return float(np.max(d[nz] / np.abs(b[nz]), initial=0.0))


def _rel_norm(a: np.ndarray, b: np.ndarray) -> float:
    """max |a - b| / max |b| (norm-wise per matrix)."""
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


# --- error model ------------------------------------------------------------------------------------------------

def test_packed_layout_and_noise_hold_every_group_and_field():
    lay = LAYOUTS["pseudolite-clocks-radalt"]
    p = lay.packed
    assert p[ek.L_N] == lay.n and p[ek.L_NSV] == 2 and p[ek.L_NPL] == 3
    for k, g in enumerate(ek.LAY_GROUPS):
        assert p[1 + k] == (lay.index[g].start if lay.has(g) else -1), g
    noise = _noise(2, np.random.default_rng(0))
    q, gse, gmp = em.kernel_noise(noise, 2)
    assert [q[i] for i in range(ek.Q_SIZE)] == [float(getattr(noise, f)) for f in ek.Q_FIELDS]
    np.testing.assert_array_equal(gse, np.broadcast_to(noise.gse_sigma_m, 2))
    np.testing.assert_array_equal(gmp, noise.gmp_sigma_m)
    again = em.kernel_noise(noise, 2)  # packed once per object and channel count, each caller its own copy
    assert list(noise._kernel_arrays) == [2] and again[0] is not q and np.array_equal(again[0], q)
    # a layout without channel states ignores the noise's per-channel sigmas (a loosely coupled GPS)
    noise24 = _noise(24, np.random.default_rng(1))
    args = (LAYOUTS["minimal"], 0.6, 100.0, np.array([50.0, 3.0, 2.0]), np.array([0.0, 0.1, -9.8]), np.eye(3), noise24)
    for a, b in zip(em.dynamics(*args), em.dynamics_reference(*args), strict=True):
        assert _rel_entrywise(a, b) <= RTOL
    with pytest.raises(ValueError, match="loop gains"):
        em.dynamics(LAYOUTS["loop"], 0.6, 100.0, np.zeros(3), np.zeros(3), np.eye(3), noise)


@pytest.mark.parametrize("name", list(LAYOUTS))
def test_dynamics_kernel_equals_reference(name):
    """F and Qc from the kernel against errormodel.dynamics_reference: every entry within 1e-12 relative (the
    same zeros), 40 random linearization points per layout, the loop running and held."""
    worst = 0.0
    for lay_name, _, args in _cases(40, seed=1):
        if lay_name != name:
            continue
        F, Qc = em.dynamics(*args)
        F0, Q0 = em.dynamics_reference(*args)
        worst = max(worst, _rel_entrywise(F, F0), _rel_entrywise(Qc, Q0))
    assert worst <= RTOL, worst


@pytest.mark.parametrize("dt_s", [0.1, 1.0, 2.0, 5.0])
@pytest.mark.parametrize("name", list(LAYOUTS))
def test_discretize_kernel_equals_reference(name, dt_s):
    """Phi, Qd: the kernel (closed form for lone states, Van Loan per connected component, squared in blocks)
    against errormodel.discretize_reference (Van Loan on the whole coupled core): 1e-12 relative norm-wise per
    matrix; the lone states' diagonal entries within 1e-12 relative each."""
    for lay_name, lay, args in _cases(10, seed=2):
        if lay_name != name:
            continue
        F, Qc = em.dynamics_reference(*args)
        phi, qd = em.discretize(F, Qc, dt_s)
        p0, q0 = em.discretize_reference(F, Qc, dt_s)
        assert _rel_norm(phi, p0) <= RTOL and _rel_norm(qd, q0) <= RTOL, (_rel_norm(phi, p0), _rel_norm(qd, q0))
        np.testing.assert_array_equal(qd, qd.T)  # exact: the kernel mirrors one triangle into the other
        off = (F != 0.0) | (Qc != 0.0)
        np.fill_diagonal(off, False)
        lone = ~(off.any(axis=0) | off.any(axis=1))
        assert lone.sum() >= (2 * lay.n_sv + lay.n_pl)
        assert _rel_entrywise(np.diag(qd)[lone], np.diag(q0)[lone]) <= RTOL
        assert _rel_entrywise(np.diag(phi)[lone], np.diag(p0)[lone]) <= RTOL


def test_discretize_falls_back_to_scipy_beyond_the_taylor_range():
    """A Van Loan matrix of 1-norm > 1e3 (a 500 s interval) goes to discretize_reference (scipy's expm): the
    same result exactly; a nan in F goes there too (which refuses it)."""
    _, _, args = next(_cases(1, seed=3))
    F, Qc = em.dynamics_reference(*args)
    n = F.shape[0]
    assert not ek.discretize(F, Qc, 500.0, np.empty((n, n)), np.empty((n, n)))
    phi, qd = em.discretize(F, Qc, 500.0)
    p0, q0 = em.discretize_reference(F, Qc, 500.0)
    np.testing.assert_array_equal(phi, p0)  # bit-identical: the kernel hands the case to the same scipy call
    np.testing.assert_array_equal(qd, q0)
    F[3, 7] = np.nan  # a linearization gone wrong: the numpy path's error, not nan matrices
    assert not ek.discretize(F, Qc, 1.0, np.empty((n, n)), np.empty((n, n)))
    with pytest.raises(ValueError):
        em.discretize(F, Qc, 1.0)


def test_van_loan_kernel_on_a_clock_closed_form():
    """Integrated random walk: Phi = [[1, dt], [0, 1]], Qd = q [[dt^3/3, dt^2/2], [dt^2/2, dt]] (several squarings
    at dt = 40 s)."""
    q, dt = 0.3, 40.0
    phi, qd = np.empty((2, 2)), np.empty((2, 2))
    assert ek.van_loan(np.array([[0.0, 1.0], [0.0, 0.0]]), np.diag([0.0, q]), dt, phi, qd)
    # a Taylor series of ~12 terms and ~6 squarings of 2x2 blocks: k ~ 2 (12 + 2 x 6) ~ 50 roundings of the entries
    np.testing.assert_allclose(phi, [[1.0, dt], [0.0, 1.0]], rtol=float(floor(64, 1.0)))
    np.testing.assert_allclose(qd, q * np.array([[dt**3 / 3, dt**2 / 2], [dt**2 / 2, dt]]), rtol=float(floor(64, 1.0)))


# --- filter -----------------------------------------------------------------------------------------------------

def _spd(n: int, rng: np.random.Generator, cond: float = 1e4) -> np.ndarray:
    """A symmetric positive definite P with eigenvalues from 1/cond to 1 times a scale per state."""
    Q, _ = np.linalg.qr(rng.normal(size=(n, n)))
    s = np.exp(rng.uniform(-3.0, 3.0, n))
    P = (Q * np.geomspace(1.0 / cond, 1.0, n)) @ Q.T
    P = s[:, None] * P * s[None, :]
    return 0.5 * (P + P.T)


def _default_model(seed: int = 4) -> tuple[np.ndarray, np.ndarray]:
    rng = np.random.default_rng(seed)
    lay = LAYOUTS["default"]
    lat, h, v, f, c = _point(rng)
    F, Qc = em.dynamics_reference(lay, lat, h, v, f, c, _noise(24, rng), _loop(rng))
    return em.discretize_reference(F, Qc, 1.0)


def _sparse_row(n: int, rng: np.random.Generator, k: int = 5) -> np.ndarray:
    h = np.zeros(n)
    h[rng.choice(n, k, replace=False)] = rng.normal(size=k)
    return h


def test_predict_kernel_equals_dense_product():
    """x = Phi x, P = Phi P Phi' + Qd: the default layout's model and random dense models."""
    rng = np.random.default_rng(5)
    phi, qd = _default_model()
    models = [(phi, qd)] + [(np.eye(7) + 0.2 * rng.normal(size=(7, 7)), _spd(7, rng)) for _ in range(3)]
    for phi, qd in models:
        n = phi.shape[0]
        for _ in range(5):
            x, P = rng.normal(size=n), _spd(n, rng)
            x1, P1 = x.copy(), P.copy()
            kk.predict(x1, P1, phi, qd, workspace(n))
            x0, P0 = predict_reference(x, P, phi, qd)
            assert np.max(np.abs(P1 - P0)) <= RTOL * np.max(np.abs(P0))
            assert np.max(np.abs(x1 - x0)) <= RTOL * np.max(np.abs(x0))
            np.testing.assert_array_equal(P1, P1.T)  # exact: the kernel mirrors one triangle into the other


@pytest.mark.parametrize(("w", "psi_prime"), [(1.0, 1.0), (0.7, 0.5), (1.0, 0.0), (0.0, 0.3)])
def test_scalar_update_equals_the_joseph_product_form(w, psi_prime):
    """The O(n^2) update P - Kc b' - b Kc' + S Kc Kc' against (I - Kc h') P (I - Kc h')' + r Kc Kc' (dense), on
    well-conditioned P, sparse and dense rows; S and the exact symmetry of P+."""
    rng = np.random.default_rng(6)
    for n, k in ((70, 4), (70, 70), (9, 3)):
        for _ in range(10):
            x, P, h, r = rng.normal(size=n), _spd(n, rng), _sparse_row(n, rng, k), float(rng.uniform(0.1, 4.0))
            nu = float(rng.normal())
            x1, P1, b = x.copy(), P.copy(), np.empty(n)
            S = kk.gain(P1, h, r, b)
            kk.joseph(x1, P1, b, S, nu, w, 1.0 - np.sqrt(1.0 - psi_prime), workspace(n))
            x0, P0 = joseph_reference(x, P, h, r, nu, w, psi_prime)
            assert S == pytest.approx(float(h @ P @ h + r), rel=RTOL)
            assert np.max(np.abs(P1 - P0)) <= RTOL * np.max(np.abs(P0))
            assert np.max(np.abs(x1 - x0)) <= RTOL * np.max(np.abs(x0))
            np.testing.assert_array_equal(P1, P1.T)  # exact: the kernel mirrors one triangle into the other


def test_update_leaves_states_uncorrelated_with_the_row_exactly():
    """Where b = P h is zero (a channel out of view, uncorrelated with the measured states), P's rows and
    columns are left bit for bit."""
    rng = np.random.default_rng(7)
    n = 12
    P = np.zeros((n, n))
    P[:8, :8] = _spd(8, rng)
    P[8:, 8:] = np.diag(rng.uniform(1.0, 2.0, 4))
    h = np.zeros(n)
    h[[0, 3]] = [1.0, -0.5]
    x, P1 = rng.normal(size=n), P.copy()
    S = kk.update(x, P1, h, 0.3, 1.0, np.empty(n), workspace(n))
    np.testing.assert_array_equal(P1[8:, :], P[8:, :])
    np.testing.assert_array_equal(P1[:, 8:], P[:, 8:])
    assert S == pytest.approx(h @ P @ h + 1.0, rel=RTOL)
    assert not np.allclose(P1[:8, :8], P[:8, :8])


def test_kalman_filter_runs_the_kernels_as_the_reference_does():
    """KalmanFilter (kernels) against predict_reference / joseph_reference over 30 epochs of the default layout's
    model with 6 sparse rows each and the adaptive robust policy (w = psi' < 1 on outliers): x, P, nu and S
    (1e-10: the two roundings drift apart over the 180 updates; one step from the same inputs is 1e-12, above)."""
    rng = np.random.default_rng(8)
    phi, qd = _default_model(9)
    n = phi.shape[0]
    f = KalmanFilter(policy=AdaptivePolicy(3.0))
    P0 = np.diag(rng.uniform(0.5, 20.0, n))
    s = f.init(np.zeros(n), P0)
    x, P = np.zeros(n), P0.copy()
    rows = [_sparse_row(n, rng, k) for k in (1, 2, 4, 4, 6, 8)]
    rows[0][:] = 0.0
    rows[0][2] = -1.0  # a baro-like row
    for epoch in range(30):
        s = f.predict(s, phi, qd)
        x, P = predict_reference(x, P, phi, qd)
        for j, h in enumerate(rows):
            m = ScalarMeasurement(float(h @ s.x + rng.normal() * (8.0 if (epoch, j) == (7, 3) else 1.0)), h, 0.5)
            s, st = f.update(s, m)
            nu0 = float(m.z - h @ x)
            S0 = float(h @ P @ h + m.r)
            assert st.innovation == pytest.approx(nu0, rel=1e-10, abs=1e-12)
            assert st.variance == pytest.approx(S0, rel=1e-10)
            x, P = joseph_reference(x, P, h, m.r, nu0, st.weight, st.weight)
    print("drift P", np.max(np.abs(s.P - P)) / np.max(np.abs(P)), "x", np.max(np.abs(s.x - x)) / np.max(np.abs(x)))
    # 180 Joseph updates of n-term sums (n = 70 here): 180 x 3n eps ~ 8e-12 of max|P| if every rounding added up;
    # the recursion forgets most of it. 1e-10 leaves 10x above that sum.
    assert np.max(np.abs(s.P - P)) <= 1e-10 * np.max(np.abs(P))
    assert np.max(np.abs(s.x - x)) <= 1e-10 * np.max(np.abs(x))


def test_shared_update_equals_each_runs_own_update_and_is_batch_independent():
    """One P, M runs each with its own innovation: each run's x equals the single-run update with its nu, P the
    same; a run's numbers are bit-identical in a batch of 1 and of 5."""
    rng = np.random.default_rng(10)
    n, M = 70, 5
    P, X, h, r = _spd(n, rng), rng.normal(size=(M, n)), _sparse_row(n, rng), 0.7
    nu = rng.normal(size=M)
    X5, P5 = X.copy(), P.copy()
    S5 = kk.shared_update(X5, nu, P5, h, r, np.empty(n), workspace(n))
    for m in range(M):
        x1, P1 = X[m].copy(), P.copy()
        S1 = kk.update(x1, P1, h, float(nu[m]), r, np.empty(n), workspace(n))
        np.testing.assert_array_equal(X5[m], x1)
        np.testing.assert_array_equal(P5, P1)
        assert S5 == S1
        Xm, Pm = X[m:m + 1].copy(), P.copy()
        kk.shared_update(Xm, nu[m:m + 1], Pm, h, r, np.empty(n), workspace(n))
        np.testing.assert_array_equal(Xm[0], X5[m])


def test_riccati_segment_equals_the_converged_covariance_reference():
    """The Riccati kernel (never-measured decoupled states reduced to their scalar recursion) against
    initial.converged_covariance_reference over the default profile's 600 s segment: sigmas within 1e-9."""
    from approachsim.nav import initial
    from approachsim.nav.system import NavSystem
    from approachsim.sensors.states import measure_with_states
    from approachsim.sensors.suite import SensorSuite

    prof = replace(PROFILE, sensors=replace(PROFILE.sensors, gnss=replace(PROFILE.sensors.gnss, epoch="fixed")))
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=10.0, start_distance_m=350.0,
                                        ground_speed_mps=70.0)
    recs, _ = measure_with_states(SensorSuite.from_profile(prof), truth, seed=2, runs=[0])
    nav = NavSystem.from_profile(prof)
    obs = nav.observations(recs, float(truth.t_s[0]), 0.025, True)
    P0 = nav.initial_covariance(recs["gnss"].elevation_rad[0])
    phi, qd, rows = initial._segment(nav, truth, obs, 0, P0)
    H = np.stack([m.h for m in rows])
    R = np.array([m.r for m in rows])
    unmeasured = np.flatnonzero(~H.any(axis=0))
    assert len(rows) >= 5 and unmeasured.size >= 30  # channels out of view: the reduction has work to do
    epochs = int(round(600.0 * nav.nav.aiding_rate_hz))
    P = np.array(P0, dtype=float)
    kk.riccati(P, phi, qd, H, R, epochs)
    P_ref = initial.converged_covariance_reference(nav, truth, obs, 0, P0, 600.0)
    sd = np.sqrt(np.diag(P_ref))
    # 600 Riccati steps of n-term sums (n ~ 60): 600 x 3n eps = 2.4e-11 if nothing were forgotten; 1e-9 is 40x that
    assert np.max(np.abs(np.sqrt(np.diag(P)) - sd) / sd) < 1e-9
    assert np.max(np.abs(P - P_ref) / np.outer(sd, sd)) < 1e-9
    assert not np.allclose(P, P0)


# --- measurement rows -------------------------------------------------------------------------------------------

LAY_M = em.StateLayout(baro_scale=True, clock=True, loop=True, n_sv=6, n_pl=2, pl_clock=True, radalt_bias=True,
                       radalt_markov=True, terrain_db=True)
LAY_PLAIN = em.StateLayout(baro_scale=False, clock=True, n_pl=1)
LAY_SYNC = em.StateLayout(baro_scale=True, clock=True, loop=True, n_sv=3, n_pl=2, pl_sync=True, radalt_bias=True)
"""Synchronized pseudolites: a time-sync state psy per transmitter (and no pclk)."""
LAY_GIZ = em.StateLayout(baro_scale=True, clock=True, loop=True, n_sv=6, n_pl=1, iono_zenith=True, tropo_zenith=True)
"""A single-frequency service: the zenith ionospheric field giz and troposphere gtz in every satellite's row."""


def _x_hat(lay: em.StateLayout, rng: np.random.Generator) -> np.ndarray:
    x = rng.normal(size=lay.n) * 0.3
    x[lay.index["dp"]] = rng.normal(0.0, 20.0, 3)
    if lay.has("ptr"):
        x[lay.index["ptr"]] = rng.normal(0.0, 1e-3, lay.n_pl)
    return x


def test_interp_kernel_is_numpys():
    rng = np.random.default_rng(11)
    xp = np.sort(rng.uniform(-100.0, 100.0, 9))
    xp[4] = xp[3]  # a repeated abscissa (a step)
    fp = rng.normal(size=9)
    pts = np.concatenate([rng.uniform(-150.0, 150.0, 300), xp, [np.nan]])
    for x in pts:
        got, want = mk.interp(float(x), xp, fp), float(np.interp(x, xp, fp))
        assert got == want or (np.isnan(got) and np.isnan(want)), x
    assert mk.interp(3.0, np.zeros(1), np.array([4.5])) == 4.5


@pytest.mark.parametrize("lay", [LAY_M, LAY_PLAIN], ids=["all-states", "plain"])
def test_baro_row_kernel_equals_reference(lay):
    """The scale factor's column -(h - H_ref) with H_ref from sea level to a 5434 ft field, h the navigation's height
    h_ins + dp_D_hat (the oracle is handed x_hat's dp_D, as nav/rows.py does)."""
    rng = np.random.default_rng(12)
    h = np.empty(lay.n)
    for _ in range(20):
        x, h_ins, h_ref = _x_hat(lay, rng), rng.uniform(0.0, 3000.0), rng.uniform(0.0, 1656.0)
        h_baro = h_ins + rng.normal(0.0, 5.0)
        m = meas.baro(lay, h_ins, h_baro, 1.5, 0.0, h_ref_m=h_ref, dp_d_hat_m=float(x[lay.i("dp", 2)]),
                      sb_hat=float(x[lay.i("sb")]) if lay.has("sb") else 0.0)
        nu, r = mk.baro(lay.packed, x, h_ins, h_baro, 1.5, h, h_ref)
        np.testing.assert_array_equal(h, m.h)  # constant entries (-1, the scale factor's h): the same operations
        assert r == m.r
        assert abs(nu - (m.z - m.h @ x)) <= 1e-9  # heights <= 3000 m: floor 8 eps 3000 = 5e-12 m, 200x below


def _terrain_case(kind: str):
    rwy = PROFILE.runway.frame
    if kind == "flat":
        return rwy, None
    if kind == "profile":
        assert PROFILE.terrain is not None
        return rwy, PROFILE.terrain
    from approachsim.profile import Terrain
    return rwy, Terrain(along_m=(-20000.0, -8000.0, -3000.0, -900.0, 0.0),
                        height_m=(250.0, 180.0, 40.0, 12.0, rwy.threshold_h_m))


@pytest.mark.parametrize("db", [False, True], ids=["exact-db", "db-error"])
@pytest.mark.parametrize("kind", ["flat", "profile", "synthetic"])
def test_radalt_row_kernel_equals_reference(kind, db):
    """Against nav/measurements.radalt with the NavSystem terrain database (TerrainDatabase) and the run's database
    error at the INS along-track position, as nav/system.py passes them: h to 1e-12, nu to 1e-9 m."""
    from approachsim.nav.system import TerrainDatabase

    rng = np.random.default_rng(13)
    rwy, terrain = _terrain_case(kind)
    cfg = tdb.TerrainDbConfig()
    err = tdb.draw(cfg, np.random.default_rng(5)) if db else None
    tx, th, rv = meas.terrain_arrays(rwy, terrain)
    dbp, db_x, db_u = meas.database_arrays(cfg, err)
    T = TerrainDatabase(rwy, terrain)
    h = np.empty(LAY_M.n)
    for lay in (LAY_M, LAY_PLAIN):
        h = np.empty(lay.n)
        for _ in range(25):
            along = rng.uniform(-15000.0, 500.0)
            r_ins = rwy.to_ecef(np.array([along, rng.normal(0.0, 80.0), 3.0 + 0.05 * -along]))
            lat, lon, h_ins = (float(v) for v in geo.ecef_to_geodetic(r_ins))
            x = _x_hat(lay, rng)
            h_agl = float(h_ins - T(r_ins)) + rng.normal(0.0, 3.0)
            a = float(rwy.from_ecef(geo.geodetic_to_ecef(lat, lon, h_ins))[0])
            ts = float(cfg.sigma_at(a))
            de = 0.0 if err is None else float(err(a))
            m = meas.radalt(lay, x, lat, lon, h_ins, h_agl, 2.0, T, 0.0, tdb_sigma_m=ts, db_error_m=de)
            nu, r = mk.radalt(lay.packed, x, lat, lon, h_ins, h_agl, 2.0, tx, th, rv, dbp, db_x, db_u, h)
            # h: -1 and the terrain slope (<= 0.03), 1e-12 is 4500 eps; nu: heights <= 1000 m and the along-track
            # position from a 6.4e6 m ECEF position (1.4e-9 m) times the slope: floor ~ 8 eps 6.4e6 x 0.03 = 3e-10 m
            assert np.max(np.abs(h - m.h)) <= 1e-12
            assert r == m.r
            assert abs(nu - (m.z - m.h @ x)) <= 1e-9


def _geometry(rng: np.random.Generator):
    lat, lon, hh = rng.uniform(-1.2, 1.2), rng.uniform(-3.0, 3.0), rng.uniform(0.0, 3000.0)
    r_ins = geo.geodetic_to_ecef(lat, lon, hh)
    return r_ins, geo.c_ecef_to_ned(lat, lon)


@pytest.mark.parametrize("tx", ["satellite", "satellite-no-channels", "satellite-zenith-states", "pseudolite",
                                "pseudolite-no-states", "pseudolite-sync"])
def test_pseudorange_row_kernel_equals_reference(tx):
    """Satellites (gse / gmp channel states or none) and pseudolites (pmp, ptr, pclk, psy or none): h and nu equal to
    their rounding floors from the operands (2e7 m satellite ranges, 6.4e6 m ECEF coordinates): 7e-8 m for a
    satellite's nu, however small nu is (one ulp of a 2.2e7 m range is 3.7e-9 m)."""
    rng = np.random.default_rng(14)
    lay = {"satellite": LAY_M, "pseudolite": LAY_M, "pseudolite-sync": LAY_SYNC,
           "satellite-zenith-states": LAY_GIZ}.get(tx, LAY_PLAIN)
    sat = tx.startswith("satellite")
    h = np.empty(lay.n)
    worst = 0.0
    for k in range(40):
        r_ins, c_en = _geometry(rng)
        if sat:
            u = c_en.T @ np.array([*rng.normal(size=2), -abs(rng.normal()) - 0.2])
            r_tx = r_ins + 2.2e7 * u / np.linalg.norm(u)
        else:
            r_tx = r_ins + c_en.T @ np.array([*rng.uniform(-3000.0, 3000.0, 2), rng.uniform(0.0, 400.0)])
        x = _x_hat(lay, rng)
        rho = float(np.linalg.norm(r_ins - r_tx)) + rng.normal(0.0, 30.0)
        ch = k % 2
        kw = {"sv": ch if lay.has("gse") else None} if sat else {"pl": ch % max(lay.n_pl, 1) if lay.has("pmp")
                                                                   else None}
        m = meas.pseudorange(lay, x, r_ins, c_en, r_tx, rho, 1.2, 0.0, "r", **kw)
        sv = -1 if kw.get("sv") is None else kw["sv"]
        pl = -1 if kw.get("pl") is None else kw["pl"]
        nu, r = mk.pseudorange(lay.packed, x, r_ins, c_en, r_tx, rho, 1.2, sv, pl, h)
        # h: the unit line of sight (r_ins - r_tx) / |..|, a difference of ECEF vectors divided by the range: its
        # relative floor is K eps (|r_ins| + |r_tx|) / range (1 for a satellite, ~2000 for a pseudolite at 3 km)
        rng_m = float(np.linalg.norm(r_ins - r_tx))
        ops = float(np.linalg.norm(r_ins) + np.linalg.norm(r_tx))
        assert_within(h, m.h, floor(K_ROW, ops / rng_m, 1.0) * np.max(np.abs(m.h)), "h")
        assert r == m.r  # the same variance formula on the same inputs: one rounding, bit-identical
        # nu = rho - |r_ins - r_tx| - h x: operands rho and the range (2.2e7 m for a satellite) and the ECEF
        # coordinates; its floor K eps (|rho| + range + |r_ins| + |r_tx|) = 7e-8 m for a satellite, however small nu
        worst = max(worst, abs(nu - (m.z - m.h @ x)) / float(floor(K_ROW, rho, rng_m, ops)))
    assert worst <= 1.0, worst


def test_innovations_over_runs_equal_the_single_run_kernels():
    """The *_nu_many forms (the shared-covariance path) give each run bit for bit the single-run kernel's nu,
    in a batch of any size."""
    rng = np.random.default_rng(15)
    lay, M = LAY_M, 6
    pk = lay.packed
    X = np.stack([_x_hat(lay, rng) for _ in range(M)])
    geoms = [_geometry(rng) for _ in range(M)]
    r_ins = np.stack([g[0] for g in geoms])
    c_en = np.stack([g[1] for g in geoms])
    lat, lon, hh = (np.array(v, dtype=float) for v in geo.ecef_to_geodetic(r_ins))
    r_tx = r_ins + 2.0e7 * np.array([0.3, -0.5, 0.81])
    rho = np.linalg.norm(r_ins - r_tx, axis=1) + rng.normal(0.0, 10.0, M)
    h = np.empty(lay.n)
    nu = np.empty(M)
    mk.pseudorange_nu_many(pk, X, r_ins, c_en, r_tx, rho, 3, -1, nu)
    for m in range(M):
        assert nu[m] == mk.pseudorange(pk, X[m], r_ins[m], c_en[m], r_tx[m], rho[m], 1.0, 3, -1, h)[0]
    hb = hh + rng.normal(0.0, 3.0, M)
    mk.baro_nu_many(pk, X, hh, hb, 12.5, nu)
    for m in range(M):
        assert nu[m] == mk.baro(pk, X[m], hh[m], hb[m], 1.0, h, 12.5)[0]
    rwy = PROFILE.runway.frame
    tx, th, rv = meas.terrain_arrays(rwy, PROFILE.terrain)
    cfg = tdb.TerrainDbConfig()
    errs = [tdb.draw(cfg, np.random.default_rng(20 + m)) for m in range(M)]
    arrs = [meas.database_arrays(cfg, e) for e in errs]
    dbp = np.stack([a[0] for a in arrs])
    db_u = np.stack([a[2] for a in arrs])[::-1].copy()  # the realizations in another order, found by db_row
    db_row = np.arange(M)[::-1].copy()
    agl = rng.uniform(30.0, 600.0, M)
    mk.radalt_nu_many(pk, X, lat, lon, hh, agl, tx, th, rv, dbp, arrs[0][1], db_u, db_row, nu)
    for m in range(M):
        want = mk.radalt(pk, X[m], lat[m], lon[m], hh[m], agl[m], 1.0, tx, th, rv, dbp[m], arrs[m][1], arrs[m][2],
                         h)[0]
        assert nu[m] == want
    one = np.empty(1)
    mk.radalt_nu_many(pk, X[2:3], lat[2:3], lon[2:3], hh[2:3], agl[2:3], tx, th, rv, dbp[2:3], arrs[0][1], db_u,
                      db_row[2:3], one)
    assert one[0] == nu[2]


def test_baro_row_is_the_jacobian_of_the_scaled_baro():
    """The baro row is the EKF's linearization of g(x) = -dp_D - bb - (h_ins + dp_D - H_ref) sb (the baro reads
    (1 + S) of a height change): h = dg/dx at x_hat, so the dp_D entry is -(1 + sb_hat) (issue 39: with -1 the
    filter's height was over-claimed 9 % at ISA -30), and the innovation is the exact z - g(x_hat) for the kernel and
    for the oracle's z - h x_hat. g is linear in each state alone, so a 1 m (or 0.01) step's difference is the
    derivative exactly; what is left is rounding of g, whose terms are below 5e3 m (h <= 3000 m, |sb| < 1.5): 8 eps
    5e3 = 9e-12 m, the bound 1e-9 m is 100x that."""
    lay = LAY_M
    rng = np.random.default_rng(13)
    h = np.empty(lay.n)
    idp, ibb, isb = lay.i("dp", 2), lay.i("bb"), lay.i("sb")
    for _ in range(20):
        x, h_ins, h_ref = _x_hat(lay, rng), rng.uniform(0.0, 3000.0), rng.uniform(0.0, 1656.0)
        x[isb] = rng.normal(0.0, 0.12)
        h_baro = h_ins + rng.normal(0.0, 5.0)

        def g(v: np.ndarray, h_ins: float = h_ins, h_ref: float = h_ref) -> float:
            return -v[idp] - v[ibb] - (h_ins + v[idp] - h_ref) * v[isb]

        nu, _ = mk.baro(lay.packed, x, h_ins, h_baro, 1.5, h, h_ref)
        m = meas.baro(lay, h_ins, h_baro, 1.5, 0.0, h_ref_m=h_ref, dp_d_hat_m=float(x[idp]), sb_hat=float(x[isb]))
        for i, step in ((idp, 1.0), (ibb, 1.0), (isb, 0.01)):
            xs = x.copy()
            xs[i] += step
            assert abs((g(xs) - g(x)) / step - h[i]) <= 1e-9 / step, i
        assert h[idp] == -(1.0 + x[isb])
        np.testing.assert_array_equal(m.h, h)
        assert abs(nu - ((h_ins - h_baro) - g(x))) <= 1e-9
        assert abs((m.z - m.h @ x) - nu) <= 1e-9
