"""The flown airframe's rotation and what a gyro scale-factor / misalignment error makes of it: the source of
nav/noise.py's gyro axis figures (SF_DRIFT_Q; on branch i39g also BODY_ROTATION, the eps states').

    python tools/body_rate_psd.py PROFILE [--seeds 1 2 3 4 5 6] [--turbulence light moderate] [--lag-s 25]
        [--drift [--draws 200]]

Flies the profile (run 0 of each seed) at each turbulence level and prints per body axis (roll, pitch, yaw), Theta(t)
the integral of the inertial body rate w_ib (its mean over the approach removed):
- the white-noise equivalent of the rotation over a lag T, Var(Theta(t + T) - Theta(t)) / T (rad^2/s; the filter's
  gyro axis noise before 2026-12-05, at T = 25 s), and the body-rate PSD over 0.01-0.05 Hz (the one before that);
- Var(Theta - mean) (rad^2) and the 1/e time of Theta's autocorrelation (s): the bounded first-order attitude error
  (S + M) Theta's variance per unit sf^2 and its correlation time (light: 4.29e-4 / 6.45e-4 / 4.86e-4 rad^2, 1.1 /
  5.0 / 3.3 s; the structure function saturates at 2 Var by 10 s: the rotation is bounded);
- with --drift, sf_drift_q: the exact attitude error -int C_bn (S + M) w_ib dt over `draws` unit draws of S and of M,
  less its first-order part, its variance fitted as q t (rad^2/s per unit sf^2 and per unit mis^2): the unbounded
  part (the mean rate's ramp and the Dutch roll's coning rectified into the pitch axis) that the filter carries.
"""

from __future__ import annotations

import argparse
import tomllib
from dataclasses import replace
from pathlib import Path

import numpy as np
from scipy.signal import welch

LAG_S = 25.0
RATE_BAND_HZ = (0.01, 0.05)


def rotation_q(w: np.ndarray, dt: float, lag_s: float = LAG_S) -> np.ndarray:
    """Var(Theta(t + T) - Theta(t)) / T (rad^2/s) per column of w (n, 3) (body rates, rad/s, sampled every dt s;
    Theta the integral of w less its mean), T = lag_s."""
    th = np.cumsum(w - w.mean(axis=0), axis=0) * dt
    k = int(round(lag_s / dt))
    d = th[k:] - th[:-k]
    return (d * d).mean(axis=0) / (k * dt)


def rotation_var(w: np.ndarray, dt: float) -> np.ndarray:
    """Var(Theta - its mean over the approach) (rad^2) per column of w (n, 3): the stationary variance of the
    rotation a gyro scale-factor / misalignment error acts on (Theta as in rotation_q)."""
    th = np.cumsum(w - w.mean(axis=0), axis=0) * dt
    return th.var(axis=0)


def rotation_tau(w: np.ndarray, dt: float, max_lag_s: float = 120.0) -> np.ndarray:
    """Correlation time (s) of Theta per column of w (n, 3): the first lag at which the autocorrelation of Theta
    (its mean removed) falls to 1/e (max_lag_s when it does not)."""
    th = np.cumsum(w - w.mean(axis=0), axis=0) * dt
    th = th - th.mean(axis=0)
    out = np.full(w.shape[1], max_lag_s)
    var = (th * th).mean(axis=0)
    for c in range(w.shape[1]):
        for k in range(1, int(round(max_lag_s / dt))):
            if (th[k:, c] * th[:-k, c]).mean() < var[c] / np.e:
                out[c] = k * dt
                break
    return out


def _offdiag(m: np.ndarray) -> np.ndarray:
    """(3, 3) matrix with the 6 values m off the diagonal (sensors/imu.py's misalignment order does not matter for
    a variance of independent draws)."""
    out = np.zeros((3, 3))
    out[[0, 0, 1, 1, 2, 2], [1, 2, 0, 2, 0, 1]] = m
    return out


def sf_drift_q(w: np.ndarray, c_bn: np.ndarray, dt: float, draws: int = 200, seed: int = 0) -> np.ndarray:
    """(2, 3) white rate-noise equivalents (rad^2/s per unit sf^2, row 0, and per unit mis^2, row 1; body axes x, y,
    z) of the part of the exact scale-factor / misalignment attitude error that the bounded first-order tilt leaves.

    Exact: psi(t) = -int_0^t C_bn (S + M) w_ib dt' (nav frame; the INS attitude error of a gyro error (S + M) w_ib).
    First order: -C_bn(0) (S + M) (Theta(t) - Theta(0)), Theta the integral of w_ib less its mean (the eps states).
    The rest d(t) (in the start's body axes, C_bn(0)' d) holds (S + M) times the mean body rate (the Earth and
    transport rates, the attitude's trend: a ramp) and the rectification of the rotating C_bn over the airframe's
    oscillation (coning: Theta x (S + M) Theta', second order in the rotation), both unbounded; its variance over
    `draws` unit draws of S (diagonal) and of M (off-diagonal), fitted as q t through the origin over the approach."""
    rng = np.random.default_rng(seed)
    th = np.cumsum(w - w.mean(axis=0), axis=0) * dt
    th = th - th[0]
    t = np.arange(1, len(w) + 1) * dt
    c0t = c_bn[0].T
    out = np.zeros((2, 3))
    for row in range(2):
        acc = np.zeros((len(w), 3))
        for _ in range(draws):
            m = np.diag(rng.standard_normal(3)) if row == 0 else _offdiag(rng.standard_normal(6))
            exact = -np.cumsum(np.einsum("nij,nj->ni", c_bn, w @ m.T), axis=0) * dt
            d = exact @ c0t.T + th @ m.T  # C0' exact - (-(S + M) Theta), body axes of the start
            acc += d * d
        v = acc / draws
        out[row] = (t @ v) / (t @ t)
    return out


def rate_psd(w: np.ndarray, dt: float) -> np.ndarray:
    """Two-sided PSD (rad^2/s^2/Hz) of each column of w (n, 3) averaged over RATE_BAND_HZ."""
    f, p = welch(w - w.mean(axis=0), fs=1.0 / dt, nperseg=min(len(w), int(round(128.0 / dt))), axis=0)
    m = (f >= RATE_BAND_HZ[0]) & (f <= RATE_BAND_HZ[1])
    return 0.5 * p[m].mean(axis=0)


def _one_flight(profile: Path, level: str, seed: int, lag_s: float, drift: bool, draws: int) -> tuple:
    """One flight (run 0 of `seed`) at turbulence `level`: (rotation_q, rate_psd, rotation_var, rotation_tau,
    sf_drift_q or None)."""
    from approachsim.flight.run import Approach
    from approachsim.nav import ins
    from approachsim.profile import parse_profile

    prof0 = parse_profile(tomllib.loads(profile.read_text(encoding="utf-8")), source=profile.resolve())
    prof = replace(prof0, environment=replace(prof0.environment, turbulence=level))
    tr = Approach(prof).fly(seed=seed, run=0).truth
    w, dt = np.asarray(tr.w_ib_body), float(tr.t_s[1] - tr.t_s[0])
    dq = sf_drift_q(w, ins.cbn_from_quaternion(np.asarray(tr.q_nb)), dt, draws) if drift else None
    return rotation_q(w, dt, lag_s), rate_psd(w, dt), rotation_var(w, dt), rotation_tau(w, dt), dq


def main() -> None:
    from concurrent.futures import ProcessPoolExecutor

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("profile", type=Path)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5, 6])
    ap.add_argument("--turbulence", nargs="+", default=["light", "moderate", "severe"])
    ap.add_argument("--lag-s", type=float, default=LAG_S)
    ap.add_argument("--drift", action="store_true", help="also sf_drift_q (slow: 400 exact propagations a seed)")
    ap.add_argument("--draws", type=int, default=200)
    ap.add_argument("--workers", type=int, default=1)
    a = ap.parse_args()
    for level in a.turbulence:
        with ProcessPoolExecutor(max_workers=a.workers) as ex:
            res = list(ex.map(_one_flight, *zip(*[(a.profile, level, s, a.lag_s, a.drift, a.draws)
                                                    for s in a.seeds], strict=True)))
        q, r, v, t, dq = (list(x) for x in zip(*res, strict=True))
        s, se = np.mean(q, axis=0), np.std(q, axis=0, ddof=1) / np.sqrt(len(q))
        b = np.mean(r, axis=0)
        print(f"{level:9s} rotation over {a.lag_s:g} s: roll {s[0]:.3g} pitch {s[1]:.3g} yaw {s[2]:.3g} rad^2/s "
              f"(+- {se[0]:.2g}, {se[1]:.2g}, {se[2]:.2g}; seeds {a.seeds}); body-rate PSD 0.01-0.05 Hz: roll "
              f"{b[0]:.3g} pitch {b[1]:.3g} yaw {b[2]:.3g} rad^2/s^2/Hz")
        vm, vs = np.mean(v, axis=0), np.std(v, axis=0, ddof=1) / np.sqrt(len(v))
        tm, ts = np.mean(t, axis=0), np.std(t, axis=0, ddof=1) / np.sqrt(len(t))
        print(f"{level:9s} Var(Theta - mean): roll {vm[0]:.3g} pitch {vm[1]:.3g} yaw {vm[2]:.3g} rad^2 "
              f"(+- {vs[0]:.2g}, "
              f"{vs[1]:.2g}, {vs[2]:.2g}); 1/e time of Theta: roll {tm[0]:.3g} pitch {tm[1]:.3g} yaw {tm[2]:.3g} s "
              f"(+- {ts[0]:.2g}, {ts[1]:.2g}, {ts[2]:.2g}); per seed tau {np.round(t, 1).tolist()}")
        if a.drift:
            dm, ds = np.mean(dq, axis=0), np.std(dq, axis=0, ddof=1) / np.sqrt(len(dq))
            print(f"{level:9s} unbounded scale-factor tilt, rad^2/s per unit sf^2: x {dm[0, 0]:.3g} y {dm[0, 1]:.3g} "
                  f"z {dm[0, 2]:.3g} (+- {ds[0, 0]:.2g}, {ds[0, 1]:.2g}, {ds[0, 2]:.2g}); per unit mis^2: x "
                  f"{dm[1, 0]:.3g} y {dm[1, 1]:.3g} z {dm[1, 2]:.3g} (+- {ds[1, 0]:.2g}, {ds[1, 1]:.2g}, "
                  f"{ds[1, 2]:.2g}); per seed y (sf): {np.round(np.array(dq)[:, 0, 1], 7).tolist()}")


if __name__ == "__main__":
    main()
