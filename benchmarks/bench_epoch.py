"""Filter-epoch benchmark (issue 12): numpy vs compiled costs of one aiding epoch of one run, default profile.

    python benchmarks/bench_epoch.py [--repeat 7] [--number 200]

The default profile's 70-state layout (dp dv psi bg ba bb clk(2) ac gse(24) gmp(24) rab ram tdb) on one fixed GPS
sky, linearized 3 km before the threshold of a synthetic 3-degree descent; P is the converged covariance of the
start (600 s of the epoch's rows: kernels.kalman.riccati), so b = P h has the sparsity a real epoch has (only the
channels in view are correlated with the rest). Rows of the epoch: baro, radar altimeter, 4 pseudoranges.

Columns: `numpy` the readable versions (errormodel.dynamics_reference, discretize_reference, base.predict_reference
and joseph_reference: what KalmanFilter did before the kernels; nav/measurements.py rows), `API` the public
wrappers that now call the kernels (errormodel.dynamics / discretize, KalmanFilter.predict / update: they copy the
frozen state and allocate), `kernel` the compiled kernel alone on preallocated arrays (what a per-run loop calls).
The epoch rows: all of it for one run from Python (10 kernel calls per epoch from Python; a compiled per-run loop
would drop the call overheads, about 0.3-1 us each). Times are the minimum over --repeat of the mean of --number
calls, in microseconds, with the machine's load average (shared machine: read the ratios). No pass/fail.
"""

from __future__ import annotations

import argparse
import os
import timeit
from dataclasses import replace
from pathlib import Path

import numpy as np

from approachsim import geo, synthetic
from approachsim.core.nav import errormodel as ek
from approachsim.core.nav import kalman as kk
from approachsim.core.nav import measurements as mk
from approachsim.nav import errormodel as em
from approachsim.nav import initial, ins
from approachsim.nav import measurements as meas
from approachsim.nav import terrain_db as tdb
from approachsim.nav.base import KalmanFilter, ScalarMeasurement, joseph_reference, predict_reference, workspace
from approachsim.nav.system import NavSystem
from approachsim.profile import load_profile
from approachsim.sensors.states import measure_with_states
from approachsim.sensors.suite import SensorSuite

ROOT = Path(__file__).resolve().parents[1]


def load() -> str:
    return "load average " + ", ".join(f"{v:.2f}" for v in os.getloadavg())


def us(f, repeat: int, number: int) -> float:
    """Minimum over `repeat` of the mean time of `number` calls of f, microseconds."""
    f()
    return min(timeit.repeat(f, number=number, repeat=repeat)) / number * 1e6


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--repeat", type=int, default=7)
    ap.add_argument("--number", type=int, default=200)
    a = ap.parse_args()
    rep, num = a.repeat, a.number
    print(f"start: {load()}")

    prof = load_profile(ROOT / "profiles" / "default.toml")
    prof = replace(prof, sensors=replace(prof.sensors, gnss=replace(prof.sensors.gnss, epoch="fixed")))
    truth = synthetic.glidepath_descent(prof.runway.frame, rate_hz=10.0, start_distance_m=3000.0,
                                        ground_speed_mps=70.0)
    recs, _ = measure_with_states(SensorSuite.from_profile(prof), truth, seed=2, runs=[0])
    nav = NavSystem.from_profile(prof)
    lay, n = nav.layout, nav.layout.n
    k = 10
    t = float(truth.t_s[k])
    obs = nav.observations(recs, t, 0.025, True)
    el = recs["gnss"].elevation_rad[0]
    noise, gains = nav.noise(obs.get("gnss_el")), nav.loop_gains()
    s = ins.InsState(truth.lat_rad[k:k + 1], truth.lon_rad[k:k + 1], truth.h_m[k:k + 1], truth.v_ned[k:k + 1],
                     ins.cbn_from_quaternion(truth.q_nb[k:k + 1]), np.zeros(1))
    lat, lon, h, v, c_bn = float(s.lat_rad[0]), float(s.lon_rad[0]), float(s.h_m[0]), s.v_ned[0], s.c_bn[0]
    f_ned = c_bn @ truth.f_body[k]
    # a realistic covariance: the converged start (600 s of the epoch's rows)
    P0 = nav.initial_covariance(el)
    phi0, qd0, rows0 = initial._segment(nav, truth, obs, k, P0)
    P = np.array(P0)
    kk.riccati(P, phi0, qd0, np.stack([m.h for m in rows0]), np.array([m.r for m in rows0]), 600)
    x = np.random.default_rng(1).normal(size=n) * np.sqrt(np.diag(P)) * 0.5
    err = tdb.draw(nav.nav.terrain_database, np.random.default_rng(3))
    print(f"layout n = {n}, rows per epoch {len(rows0)}, nonzeros of P h for a pseudorange row: "
          f"{np.count_nonzero(P @ rows0[-1].h)} of {n}")

    rows: list[tuple[str, float, float]] = []

    def row(name: str, t_np: float, t_api: float, t_k: float) -> None:
        rows.append((name, t_np, t_api, t_k))
        api = f"{t_api:9.1f}" if t_api == t_api else f"{'-':>9}"
        print(f"{name:<34}{t_np:9.1f}{api}{t_k:9.1f}{t_np / t_k:9.1f}x")

    print(f"{'us per call':<34}{'numpy':>9}{'API':>9}{'kernel':>9}{'numpy/kernel':>13}")
    # error model
    dyn_args = (lay, lat, h, v, f_ned, c_bn, noise, gains)
    F, Qc = em.dynamics(*dyn_args)
    lay_a, q_a, gse_a, gmp_a, loop_a = em.kernel_inputs(lay, noise, gains)
    Fb, Qb = np.empty((n, n)), np.empty((n, n))
    row("dynamics F, Qc", us(lambda: em.dynamics_reference(*dyn_args), rep, num),
        us(lambda: em.dynamics(*dyn_args), rep, num),
        us(lambda: ek.dynamics(lay_a, q_a, gse_a, gmp_a, lat, h, v, f_ned, c_bn, loop_a, False, Fb, Qb), rep, num))
    phi, qd = em.discretize(F, Qc, 1.0)
    pb, qb = np.empty((n, n)), np.empty((n, n))
    row("discretize Phi, Qd (Van Loan)", us(lambda: em.discretize_reference(F, Qc, 1.0), rep, num),
        us(lambda: em.discretize(F, Qc, 1.0), rep, num), us(lambda: ek.discretize(F, Qc, 1.0, pb, qb), rep, num))
    # filter
    kf = KalmanFilter()
    fs = kf.init(x, P)
    ws = workspace(n)
    xw, Pw = x.copy(), P.copy()

    def k_predict() -> None:
        xw[:] = x
        Pw[:] = P
        kk.predict(xw, Pw, phi, qd, ws)

    t_copy = us(lambda: (xw.__setitem__(slice(None), x), Pw.__setitem__(slice(None), P)), rep, num)
    row("predict (x, P)", us(lambda: predict_reference(x, P, phi, qd), rep, num),
        us(lambda: kf.predict(fs, phi, qd), rep, num), us(k_predict, rep, num) - t_copy)
    h_pr = rows0[-1].h
    m_pr = ScalarMeasurement(float(h_pr @ x + 1.0), h_pr, rows0[-1].r, "gps")
    b = np.empty(n)

    def k_update(hh: np.ndarray, Pin: np.ndarray) -> None:
        xw[:] = x
        Pw[:] = Pin
        kk.update(xw, Pw, hh, 1.0, 4.0, b, ws)

    row("scalar update (pseudorange row)", us(lambda: joseph_reference(x, P, h_pr, 4.0, 1.0), rep, num),
        us(lambda: kf.update(fs, m_pr), rep, num), us(lambda: k_update(h_pr, P), rep, num) - t_copy)
    Pd = P + 1e-6 * np.ones((n, n))  # every state correlated with the row: the update's dense case
    row("scalar update, P h dense (worst)", us(lambda: joseph_reference(x, Pd, h_pr, 4.0, 1.0), rep, num),
        float("nan"), us(lambda: k_update(h_pr, Pd), rep, num) - t_copy)
    # measurement rows: numpy builders (nav/measurements.py via NavSystem) and kernels
    r_ins = ins.position_ecef(s)[0]
    builders = nav._measurements(s, 0, r_ins, fs, obs, t, db_error=err)
    names = [bld(x).name for bld in builders]
    tx, th, rv = meas.terrain_arrays(nav.runway, prof.terrain)
    dbp, db_x, db_u = meas.database_arrays(nav.nav.terrain_database, err)
    c_en = geo.c_ecef_to_ned(lat, lon)
    hb = np.empty(n)
    hr = float(obs["radalt_h"][0])
    sr = float(np.sqrt((nav.sensors.radalt.percent_sigma * hr) ** 2 + nav.sensors.radalt.floor_m**2))
    code = nav.sensors.gnss.budget().code_noise_m
    chans = [int(nm[3:]) for nm in names if nm.startswith("gps")]
    rsv = obs["gnss_rsv"]
    rho = obs["gnss_rho"][0]
    lp = lay.packed

    def k_rows() -> list:
        out = [mk.baro(lp, x, h, float(obs["baro_h"][0]), float(obs["baro_sigma"]), hb)]
        out.append(mk.radalt(lp, x, lat, lon, h, hr, sr, tx, th, rv, dbp, db_x, db_u, hb))
        for c in chans:
            out.append(mk.pseudorange(lp, x, r_ins, c_en, rsv[c], float(rho[c]), code, c, -1, hb))
        return out

    assert names[:2] == ["baro", "radalt"] and len(chans) == len(names) - 2, names
    row(f"measurement rows ({len(names)}: {', '.join(names[:3])}..)", us(lambda: [bld(x) for bld in builders],
                                                                          rep, num),
        float("nan"), us(k_rows, rep, num))

    # a whole epoch of one run
    def epoch_numpy() -> None:
        F_, Q_ = em.dynamics_reference(*dyn_args)
        p_, q_ = em.discretize_reference(F_, Q_, 1.0)
        x_, P_ = predict_reference(x, P, p_, q_)
        for bld in builders:
            m = bld(x_)
            x_, P_ = joseph_reference(x_, P_, m.h, m.r, float(m.z - m.h @ x_))

    hbufs = np.empty((len(names), n))

    def epoch_kernel() -> None:
        xw[:] = x
        Pw[:] = P
        ek.dynamics(lay_a, q_a, gse_a, gmp_a, lat, h, v, f_ned, c_bn, loop_a, False, Fb, Qb)
        ek.discretize(Fb, Qb, 1.0, pb, qb)
        kk.predict(xw, Pw, pb, qb, ws)
        nu, r = mk.baro(lp, xw, h, float(obs["baro_h"][0]), float(obs["baro_sigma"]), hbufs[0])
        kk.update(xw, Pw, hbufs[0], nu, r, b, ws)
        nu, r = mk.radalt(lp, xw, lat, lon, h, hr, sr, tx, th, rv, dbp, db_x, db_u, hbufs[1])
        kk.update(xw, Pw, hbufs[1], nu, r, b, ws)
        for j, c in enumerate(chans):
            nu, r = mk.pseudorange(lp, xw, r_ins, c_en, rsv[c], float(rho[c]), code, c, -1, hbufs[2 + j])
            kk.update(xw, Pw, hbufs[2 + j], nu, r, b, ws)

    def epoch_api() -> None:
        F_, Q_ = em.dynamics(*dyn_args)
        p_, q_ = em.discretize(F_, Q_, 1.0)
        st = kf.predict(fs, p_, q_)
        for bld in builders:
            st, _ = kf.update(st, bld(st.x))

    row(f"epoch: model, predict, {len(names)} updates", us(epoch_numpy, rep, max(num // 10, 5)),
        us(epoch_api, rep, max(num // 10, 5)), us(epoch_kernel, rep, num))
    # shared covariance: one class of M runs, the epoch's rows
    M = 100
    X = np.tile(x, (M, 1))
    nus = np.random.default_rng(2).normal(size=M)

    def shared_numpy() -> None:
        P_, X_ = P.copy(), X.copy()
        for m0 in rows0:
            hh = m0.h
            K = P_ @ hh / float(hh @ P_ @ hh + m0.r)
            X_ = X_ + nus[:, None] * K[None, :]
            A = np.eye(n) - np.outer(K, hh)
            P_ = A @ P_ @ A.T + m0.r * np.outer(K, K)
            P_ = 0.5 * (P_ + P_.T)

    Xw = X.copy()

    def shared_kernel() -> None:
        Pw[:] = P
        Xw[:] = X
        for m0 in rows0:
            kk.shared_update(Xw, nus, Pw, m0.h, m0.r, b, ws)

    row(f"shared P: {len(rows0)} rows x {M} runs", us(shared_numpy, rep, max(num // 10, 5)), float("nan"),
        us(shared_kernel, rep, max(num // 10, 5)))
    print(f"end: {load()}")


if __name__ == "__main__":
    main()
