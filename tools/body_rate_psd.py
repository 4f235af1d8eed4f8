"""The flown airframe's rotation as white noise over the aided filter's velocity-error time: the source of
nav/noise.py BODY_ROTATION_Q.

    python tools/body_rate_psd.py PROFILE [--seeds 1 2 3 4 5 6] [--turbulence light moderate severe] [--lag-s 25]

Flies the profile (run 0 of each seed) at each turbulence level and prints, per body axis (roll, pitch, yaw), the
white-noise equivalent of the body's rotation over a lag T: Var(Theta(t + T) - Theta(t)) / T, rad^2/s, Theta(t) the
integral of the inertial body rate w_ib (its mean over the approach removed). A gyro scale-factor / misalignment
error (S + M) w_ib integrates into an attitude error (S + M) Theta(t), and the filter carries it as a white noise of
the attitude error's rate (nav/noise.py gyro_axis_q): that noise's increments over T have variance q T, the
truth's sf^2 Var(delta Theta(T)). T is the aided filter's horizontal velocity errors' correlation time (1/e of their
autocorrelation: 23-30 s on the default profile, seeds 1-2), the time over which the tilt error accelerates them
before the aiding takes it out. Turbulence's rotation is bounded (Theta's increments saturate at about 2 x
(0.026 rad)^2 beyond 25 s, light), so the equivalent falls as 1/T at longer lags; the body-rate spectrum over
0.01-0.05 Hz (also printed, the value this replaced) is its short-lag limit and overstated the pitch axis 2.7-fold
at 25 s (and understated the roll axis, whose rotation is slow).
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


def rate_psd(w: np.ndarray, dt: float) -> np.ndarray:
    """Two-sided PSD (rad^2/s^2/Hz) of each column of w (n, 3) averaged over RATE_BAND_HZ."""
    f, p = welch(w - w.mean(axis=0), fs=1.0 / dt, nperseg=min(len(w), int(round(128.0 / dt))), axis=0)
    m = (f >= RATE_BAND_HZ[0]) & (f <= RATE_BAND_HZ[1])
    return 0.5 * p[m].mean(axis=0)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("profile", type=Path)
    ap.add_argument("--seeds", type=int, nargs="+", default=[1, 2, 3, 4, 5, 6])
    ap.add_argument("--turbulence", nargs="+", default=["light", "moderate", "severe"])
    ap.add_argument("--lag-s", type=float, default=LAG_S)
    a = ap.parse_args()
    from approachsim.flight.run import Approach
    from approachsim.profile import parse_profile

    data = tomllib.loads(a.profile.read_text(encoding="utf-8"))
    prof0 = parse_profile(data, source=a.profile.resolve())
    for level in a.turbulence:
        prof = replace(prof0, environment=replace(prof0.environment, turbulence=level))
        q, r, v, t = [], [], [], []
        for seed in a.seeds:
            tr = Approach(prof).fly(seed=seed, run=0).truth
            w, dt = np.asarray(tr.w_ib_body), float(tr.t_s[1] - tr.t_s[0])
            q.append(rotation_q(w, dt, a.lag_s))
            r.append(rate_psd(w, dt))
            v.append(rotation_var(w, dt))
            t.append(rotation_tau(w, dt))
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


if __name__ == "__main__":
    main()
